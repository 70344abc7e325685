// Semihosting (ARM's debug-call convention: BKPT 0xAB with the operation in r0 and its argument in
// r1): text to the host's console, files on the host, exit with a status. QEMU implements it with
// `-semihosting-config enable=on,target=native`. Our own few calls instead of newlib's rdimon: no
// stdio buffers, no heap.
#pragma once
#include <stddef.h>
#include <stdint.h>

namespace fw {

// Writes a NUL-terminated string to the host's stdout (":tt" opened once).
void print(const char* text);
// Decimal and hexadecimal numbers (nano printf has no %ll).
void print_u64(uint64_t value);
void print_hex32(uint32_t value);
// A line "key value\n".
void print_kv(const char* key, uint64_t value);

// Opens a host file for writing (binary); -1 on failure.
int file_open_write(const char* path);
// True when every byte was written.
bool file_write(int handle, const void* bytes, size_t n);
void file_close(int handle);

// Ends the program: QEMU exits with status 0 when ok, else 1. Never returns.
[[noreturn]] void exit(bool ok);

}  // namespace fw

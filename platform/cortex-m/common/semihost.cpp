#include "platform/cortex-m/common/semihost.h"

namespace fw {
namespace {

enum : uint32_t { kSysOpen = 0x01, kSysClose = 0x02, kSysWrite = 0x05, kSysExit = 0x18 };
constexpr uint32_t kApplicationExit = 0x20026, kRunTimeErrorUnknown = 0x20023;

uint32_t call(uint32_t op, const void* arg) {
  register uint32_t r0 asm("r0") = op;
  register const void* r1 asm("r1") = arg;
  asm volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

size_t length(const char* s) {
  size_t n = 0;
  while (s[n]) ++n;
  return n;
}

int g_console = -2;  // -2: not opened yet

}  // namespace

int file_open_write(const char* path) {
  const uint32_t block[3] = {uint32_t(reinterpret_cast<uintptr_t>(path)), 5 /* "wb" */, uint32_t(length(path))};
  return int(call(kSysOpen, block));
}

bool file_write(int handle, const void* bytes, size_t n) {
  const uint32_t block[3] = {uint32_t(handle), uint32_t(reinterpret_cast<uintptr_t>(bytes)), uint32_t(n)};
  return call(kSysWrite, block) == 0;  // the bytes not written
}

void file_close(int handle) {
  const uint32_t block[1] = {uint32_t(handle)};
  call(kSysClose, block);
}

void print(const char* text) {
  if (g_console == -2) {
    static const char kTt[] = ":tt";
    const uint32_t block[3] = {uint32_t(reinterpret_cast<uintptr_t>(kTt)), 4 /* "w": stdout */, 3};
    g_console = int(call(kSysOpen, block));
  }
  if (g_console >= 0) file_write(g_console, text, length(text));
}

void print_u64(uint64_t value) {
  char buf[24];
  int i = sizeof buf - 1;
  buf[i] = 0;
  // Digit by digit with 32-bit divisions where possible (a 64-bit division would pull in
  // __aeabi_uldivmod just for printing).
  do {
    uint32_t hi = uint32_t(value >> 32), lo = uint32_t(value);
    const uint32_t qhi = hi / 10, rhi = hi % 10;
    // (rhi * 2^32 + lo) / 10 by long division in 16-bit digits: a = rhi * 2^16 + lo's high half
    // (< 10 * 2^16), then b = (a % 10) * 2^16 + lo's low half (< 10 * 2^16).
    const uint32_t a = (rhi << 16) | (lo >> 16);
    const uint32_t qa = a / 10, ra = a % 10;
    const uint32_t b = (ra << 16) | (lo & 0xFFFF);
    const uint32_t qb = b / 10, rb = b % 10;
    value = (uint64_t(qhi) << 32) + (uint64_t(qa) << 16) + qb;
    buf[--i] = char('0' + rb);
  } while (value != 0);
  print(buf + i);
}

void print_hex32(uint32_t value) {
  char buf[11] = "0x";
  for (int i = 0; i < 8; ++i) buf[2 + i] = "0123456789abcdef"[(value >> (28 - 4 * i)) & 15];
  buf[10] = 0;
  print(buf);
}

void print_kv(const char* key, uint64_t value) {
  print(key);
  print(" ");
  print_u64(value);
  print("\n");
}

void exit(bool ok) {
  call(kSysExit, reinterpret_cast<const void*>(uintptr_t(ok ? kApplicationExit : kRunTimeErrorUnknown)));
  for (;;) asm volatile("wfi");
}

}  // namespace fw

// What every board's firmware gets from common/startup.cpp: the instruction counter (SysTick), the
// memory layout the linker script defines, the painted stack's high-water mark.
#pragma once
#include <stddef.h>
#include <stdint.h>

namespace fw {

// SysTick on the processor clock, 24 bits, with a wrap count kept by its interrupt. Under QEMU's
// `-icount shift=0,sleep=off` virtual time advances 1 ns per guest instruction, so with a core
// clock of f MHz one tick is 1000 / f instructions (board.h: kInstructionsPerTick).
void ticks_start();
uint64_t ticks_now();

// From the linker script (common/sections.ld).
struct MemoryMap {
  uint32_t flash_start, flash_size, flash_used;  // flash_used: text + tables + scene + .data image
  uint32_t text_bytes, tables_bytes, scene_bytes, data_bytes;
  uint32_t ram_start, ram_size;
  uint32_t static_bytes;                          // .data + .bss
  uint8_t* free_start;                            // first byte after .bss (the arena starts here)
  uint8_t* stack_bottom;                          // lowest address the stack may reach
  uint32_t stack_bytes;                           // the stack's reserve (painted at reset)
};
MemoryMap memory_map();

// Bytes of the painted stack reserve that were written since reset (the high-water mark). Equal to
// the reserve when the stack overflowed it.
uint32_t stack_high_water();

}  // namespace fw

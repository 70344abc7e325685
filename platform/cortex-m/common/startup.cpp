// Reset, vector table and C++ runtime support shared by the Cortex-M boards (ARMv6-M and ARMv7-M).
// Reset_Handler paints the stack reserve, copies .data, zeroes .bss, runs the static constructors
// and calls main(). Faults print a line over semihosting and exit with a failure status, so a
// crashing firmware never hangs a test.
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "platform/cortex-m/common/runtime.h"
#include "platform/cortex-m/common/semihost.h"

extern "C" {
// Linker script symbols (common/sections.ld).
extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
extern uint32_t __stack_bottom, __flash_start, __flash_size, __ram_start, __ram_size;
extern uint8_t __text_start, __text_end, __tables_start, __tables_end, __scene_start, __scene_end;
extern void (*__preinit_array_start[])(), (*__preinit_array_end[])();
extern void (*__init_array_start[])(), (*__init_array_end[])();

int main();
void Reset_Handler();
void Fault_Handler();
void SysTick_Handler();
void Default_Handler();
}

namespace {

constexpr uint32_t kPaint = 0x5AC35AC3u;
volatile uint32_t g_tick_wraps = 0;

struct SysTickRegs {
  volatile uint32_t ctrl, load, val, calib;
};
SysTickRegs* const kSysTick = reinterpret_cast<SysTickRegs*>(0xE000E010);

}  // namespace

// The vector table: initial stack pointer, then the 15 system exceptions. Board interrupts are not
// used (the firmware polls its peripherals).
__attribute__((section(".vectors"), used)) void* const g_vectors[16] = {
    &_estack,
    reinterpret_cast<void*>(Reset_Handler),
    reinterpret_cast<void*>(Fault_Handler),  // NMI
    reinterpret_cast<void*>(Fault_Handler),  // HardFault
    reinterpret_cast<void*>(Fault_Handler),  // MemManage
    reinterpret_cast<void*>(Fault_Handler),  // BusFault
    reinterpret_cast<void*>(Fault_Handler),  // UsageFault
    nullptr, nullptr, nullptr, nullptr,
    reinterpret_cast<void*>(Default_Handler),  // SVCall
    reinterpret_cast<void*>(Default_Handler),  // DebugMonitor
    nullptr,
    reinterpret_cast<void*>(Default_Handler),  // PendSV
    reinterpret_cast<void*>(SysTick_Handler),
};

extern "C" void Reset_Handler() {
  // Paint the stack reserve up to a little below the current stack pointer (this function's frame).
  uint32_t sp;
  asm volatile("mov %0, sp" : "=r"(sp));
  for (volatile uint32_t* p = &__stack_bottom; p < reinterpret_cast<uint32_t*>(sp - 64); ++p) *p = kPaint;
  for (uint32_t *src = &_sidata, *dst = &_sdata; dst < &_edata;) *dst++ = *src++;
  for (volatile uint32_t* dst = &_sbss; dst < &_ebss;) *dst++ = 0;
  for (auto f = __preinit_array_start; f < __preinit_array_end; ++f) (*f)();
  for (auto f = __init_array_start; f < __init_array_end; ++f) (*f)();
  const int rc = main();
  fw::exit(rc == 0);
}

extern "C" void Fault_Handler() {
  uint32_t ipsr;
  asm volatile("mrs %0, ipsr" : "=r"(ipsr));
  fw::print("firmware: fault, exception ");
  fw::print_u64(ipsr & 0x1FF);
  fw::print("\n");
  fw::exit(false);
}

extern "C" void Default_Handler() {
  fw::print("firmware: unexpected exception\n");
  fw::exit(false);
}

extern "C" void SysTick_Handler() { g_tick_wraps = g_tick_wraps + 1; }

namespace fw {

void ticks_start() {
  kSysTick->ctrl = 0;
  kSysTick->load = 0xFFFFFF;
  kSysTick->val = 0;
  g_tick_wraps = 0;
  kSysTick->ctrl = 7;  // enable, interrupt on wrap, processor clock
}

uint64_t ticks_now() {
  // Read the wrap count around the counter so a wrap between the two reads is not lost.
  for (;;) {
    const uint32_t w0 = g_tick_wraps;
    const uint32_t v = kSysTick->val & 0xFFFFFF;
    const uint32_t w1 = g_tick_wraps;
    if (w0 == w1) return uint64_t(w0) * 0x1000000u + (0xFFFFFFu - v);
  }
}

MemoryMap memory_map() {
  MemoryMap m;
  m.flash_start = uint32_t(reinterpret_cast<uintptr_t>(&__flash_start));
  m.flash_size = uint32_t(reinterpret_cast<uintptr_t>(&__flash_size));
  m.text_bytes = uint32_t(&__text_end - &__text_start);
  m.tables_bytes = uint32_t(&__tables_end - &__tables_start);
  m.scene_bytes = uint32_t(&__scene_end - &__scene_start);
  m.data_bytes = uint32_t(reinterpret_cast<uint8_t*>(&_edata) - reinterpret_cast<uint8_t*>(&_sdata));
  m.flash_used = uint32_t(reinterpret_cast<uintptr_t>(&_sidata)) - m.flash_start + m.data_bytes;
  m.ram_start = uint32_t(reinterpret_cast<uintptr_t>(&__ram_start));
  m.ram_size = uint32_t(reinterpret_cast<uintptr_t>(&__ram_size));
  m.static_bytes = uint32_t(reinterpret_cast<uint8_t*>(&_ebss) - reinterpret_cast<uint8_t*>(&_sdata));
  m.free_start = reinterpret_cast<uint8_t*>(&_ebss);
  m.stack_bottom = reinterpret_cast<uint8_t*>(&__stack_bottom);
  m.stack_bytes = uint32_t(reinterpret_cast<uint8_t*>(&_estack) - m.stack_bottom);
  return m;
}

uint32_t stack_high_water() {
  const uint32_t* p = &__stack_bottom;
  while (p < &_estack && *p == kPaint) ++p;
  return uint32_t(reinterpret_cast<const uint8_t*>(&_estack) - reinterpret_cast<const uint8_t*>(p));
}

}  // namespace fw

// C++ runtime pieces the core's classes need on bare metal. Nothing is ever allocated on the heap:
// the deleting destructors of polymorphic classes (ml::Sink has a virtual destructor) only reference
// operator delete.
void operator delete(void*) noexcept {}
void operator delete(void*, size_t) noexcept {}
extern "C" void __cxa_pure_virtual() {
  fw::print("firmware: pure virtual call\n");
  fw::exit(false);
}
// newlib's abort() (reached only from library code that cannot succeed) as a failing exit.
extern "C" void abort() { fw::exit(false); }
extern "C" void _init() {}
extern "C" void _fini() {}

/* Counting shims for runtime helpers (ARMv7-M): linked with -Wl,--wrap=NAME, every call the core makes
   to NAME goes through __wrap_NAME, which calls fw_count_call(INDEX, return address) (common/call_count.h)
   and then jumps to the real helper with every argument register as it was. Used by the
   mps2-an385-calls firmware (docs/firmware.md). */
  .syntax unified
  .thumb
  .text

  .macro counted name, index
  .balign 2
  .global __wrap_\name
  .thumb_func
  .type __wrap_\name, %function
__wrap_\name:
  push {r0, r1, r2, r3, r4, lr}
  movs r0, #\index
  mov r1, lr
  bl fw_count_call
  pop {r0, r1, r2, r3, r4, lr}
  b.w __real_\name
  .endm

  counted __aeabi_ldivmod, 0
  counted __aeabi_uldivmod, 1
  counted __ctzdi2, 2

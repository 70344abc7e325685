/* Counting shims for runtime helpers (ARMv7-M): linked with -Wl,--wrap=NAME, every call the core makes
   to NAME goes through __wrap_NAME, which adds one to fw_calls_NAME and jumps to the real helper with
   every register as it was. Used by the mps2-an385-calls firmware (docs/firmware.md). */
  .syntax unified
  .thumb

  .macro counted name
  .bss
  .balign 4
  .global fw_calls_\name
fw_calls_\name:
  .word 0
  .text
  .balign 2
  .global __wrap_\name
  .thumb_func
  .type __wrap_\name, %function
__wrap_\name:
  push {r4, r5}
  ldr r4, =fw_calls_\name
  ldr r5, [r4]
  adds r5, #1
  str r5, [r4]
  pop {r4, r5}
  b.w __real_\name
  .ltorg
  .endm

  counted __aeabi_ldivmod
  counted __aeabi_uldivmod
  counted __ctzdi2

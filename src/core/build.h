// Attributes the compilers take differently.
#pragma once
#include <stdint.h>

// A function optimized for size, not speed, on GCC (the boards' flash is short: the Cortex-M0+ image is
// within a few hundred bytes of its budget). Clang, which the fuzz builds use, has no per-function
// optimize attribute and warns of it: there the build's own level.
#if defined(__GNUC__) && !defined(__clang__)
#define ML_OPTIMIZE_SIZE [[gnu::optimize("Os")]]
#else
#define ML_OPTIMIZE_SIZE
#endif

// Inlining decided for 64-bit hosts, where a hot function's call and saved registers show, and left
// to the compiler (-Os) on the boards, whose flash a second copy would take.
#if UINTPTR_MAX > 0xFFFFFFFFu
#define ML_HOST_INLINE [[gnu::always_inline]]
#define ML_HOST_NOINLINE [[gnu::noinline]]
#else
#define ML_HOST_INLINE
#define ML_HOST_NOINLINE
#endif

// Out of line on the boards (one copy in flash for a function inlined at several calls), the
// compiler's choice on 64-bit hosts.
#if UINTPTR_MAX > 0xFFFFFFFFu
#define ML_BOARD_NOINLINE
#else
#define ML_BOARD_NOINLINE [[gnu::noinline]]
#endif

// Optimized for size on the boards only, the build's level on 64-bit hosts (with ML_BOARD_NOINLINE: a
// helper the boards keep one small copy of and the hosts inline as they see fit).
#if UINTPTR_MAX > 0xFFFFFFFFu
#define ML_BOARD_SIZE
#else
#define ML_BOARD_SIZE ML_OPTIMIZE_SIZE
#endif

// Before a loop of a few passes written as a loop for the boards' flash: unrolled on 64-bit hosts,
// where GCC's -O2 would keep the loop (and its arrays in memory rather than registers).
#if UINTPTR_MAX > 0xFFFFFFFFu
#define ML_HOST_UNROLL _Pragma("GCC unroll 3")
#else
#define ML_HOST_UNROLL
#endif

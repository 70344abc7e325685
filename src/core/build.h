// Attributes the compilers take differently.
#pragma once
#include <stdint.h>

// ML_TEXTURES=0 builds the renderers without texture mapping, sampling and paging: for a board whose
// scenes have no textures and whose flash is short (the Cortex-M0+ image, docs/firmware.md). Every
// material is then drawn in its base colour, as in a scene compiled without its images, and each of a
// scene's textures with texels counts as a fallback (Stats::texture_fallbacks).
#ifndef ML_TEXTURES
#define ML_TEXTURES 1
#endif
constexpr bool kTextures = ML_TEXTURES != 0;

// ML_VERTEX_CACHE=0 builds the renderers without their vertex cache (view/vertex_cache.h): for a board
// whose RAM leaves no room for it (the Cortex-M0+ image's 16 KB, docs/firmware.md). The images are the
// same either way.
#ifndef ML_VERTEX_CACHE
#define ML_VERTEX_CACHE 1
#endif

// A function optimized for size, not speed, on GCC (rare code; the boards' flash is short). Clang, which
// the fuzz builds use, has no per-function optimize attribute and warns of it: there the build's own level.
// ML_OPTIMIZE_SIZE_BEGIN ... ML_OPTIMIZE_SIZE_END: the same for every function defined between them (a
// rare path of several functions, whose callees one attribute would leave out of line at -O2).
#if defined(__GNUC__) && !defined(__clang__)
#define ML_OPTIMIZE_SIZE [[gnu::optimize("Os")]]
#define ML_OPTIMIZE_SIZE_BEGIN _Pragma("GCC push_options") _Pragma("GCC optimize(\"Os\")")
#define ML_OPTIMIZE_SIZE_END _Pragma("GCC pop_options")
#else
#define ML_OPTIMIZE_SIZE
#define ML_OPTIMIZE_SIZE_BEGIN
#define ML_OPTIMIZE_SIZE_END
#endif

// Inlining decided for 64-bit hosts, where a hot function's call and saved registers show, and left
// to the compiler (-Os) on the boards, whose flash a second copy would take. ML_BOARD_NOINLINE: the
// compiler's choice on hosts, one copy on the boards (a helper inlined at several call sites).
#if UINTPTR_MAX > 0xFFFFFFFFu
#define ML_HOST_INLINE [[gnu::always_inline]]
#define ML_HOST_NOINLINE [[gnu::noinline]]
#define ML_BOARD_NOINLINE
#else
#define ML_HOST_INLINE
#define ML_HOST_NOINLINE
#define ML_BOARD_NOINLINE [[gnu::noinline]]
#endif

// Before a loop of a few passes written as a loop for the boards' flash: unrolled on 64-bit hosts,
// where GCC's -O2 would keep the loop (and its arrays in memory rather than registers).
#if UINTPTR_MAX > 0xFFFFFFFFu
#define ML_HOST_UNROLL _Pragma("GCC unroll 3")
#else
#define ML_HOST_UNROLL
#endif

// Before a loop of many passes whose body is a few instructions (a pixel's or a column's): unrolled by
// 8 (2) on 64-bit hosts, where the loop's count, compare and branch are a good part of each pass; as
// written on the boards (flash).
#if UINTPTR_MAX > 0xFFFFFFFFu
#define ML_HOST_UNROLL_8 _Pragma("GCC unroll 8")
#define ML_HOST_UNROLL_2 _Pragma("GCC unroll 2")
#else
#define ML_HOST_UNROLL_8
#define ML_HOST_UNROLL_2
#endif

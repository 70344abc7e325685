// Attributes the compilers take differently.
#pragma once

// A function optimized for size, not speed, on GCC (the boards' flash is short: the Cortex-M0+ image is
// within a few hundred bytes of its budget). Clang, which the fuzz builds use, has no per-function
// optimize attribute and warns of it: there the build's own level.
#if defined(__GNUC__) && !defined(__clang__)
#define ML_OPTIMIZE_SIZE [[gnu::optimize("Os")]]
#else
#define ML_OPTIMIZE_SIZE
#endif

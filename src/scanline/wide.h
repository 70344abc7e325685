// 128-bit intermediates for the scanline renderer's per-triangle setup (depth plane), without
// relying on a compiler's __int128: 32-bit boards have none. Values are two's complement in (hi, lo).
// Only setup uses these (once per activated triangle), so the portable division is bit-serial.
#pragma once
#include <stdint.h>

namespace ml {
namespace scan {

struct Wide {
  uint64_t hi, lo;
};

inline Wide wide_from(int64_t v) { return Wide{v < 0 ? ~uint64_t(0) : 0, uint64_t(v)}; }

inline Wide wide_add(Wide a, Wide b) {
  Wide r;
  r.lo = a.lo + b.lo;
  r.hi = a.hi + b.hi + (r.lo < a.lo ? 1 : 0);
  return r;
}

inline Wide wide_neg(Wide a) {
  Wide r;
  r.lo = ~a.lo + 1;
  r.hi = ~a.hi + (r.lo == 0 ? 1 : 0);
  return r;
}

inline bool wide_negative(Wide a) { return (a.hi >> 63) != 0; }

// Full product of two signed 64-bit values.
inline Wide wide_mul(int64_t a, int64_t b) {
  const bool neg = (a < 0) != (b < 0);
  const uint64_t x = a < 0 ? uint64_t(0) - uint64_t(a) : uint64_t(a);
  const uint64_t y = b < 0 ? uint64_t(0) - uint64_t(b) : uint64_t(b);
  const uint64_t x0 = x & 0xFFFFFFFFu, x1 = x >> 32, y0 = y & 0xFFFFFFFFu, y1 = y >> 32;
  const uint64_t p00 = x0 * y0, p01 = x0 * y1, p10 = x1 * y0, p11 = x1 * y1;
  const uint64_t mid = (p00 >> 32) + (p01 & 0xFFFFFFFFu) + (p10 & 0xFFFFFFFFu);
  Wide r;
  r.lo = (p00 & 0xFFFFFFFFu) | (mid << 32);
  r.hi = p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32);
  return neg ? wide_neg(r) : r;
}

// a << s for 0 < s < 64.
inline Wide wide_shl(Wide a, int s) { return Wide{(a.hi << s) | (a.lo >> (64 - s)), a.lo << s}; }

// n / d rounded to nearest (ties away from zero), d > 0; returns the low 64 bits of the quotient
// (callers use wrapping arithmetic, see scanline.cpp: the plane is exact modulo 2^64).
inline uint64_t wide_div_round_low(Wide n, int64_t d) {
  const bool neg = wide_negative(n);
  Wide mag = neg ? wide_neg(n) : n;
  mag = wide_add(mag, wide_from(d / 2));
  const uint64_t den = uint64_t(d);
  uint64_t rem = 0, q_lo = 0;
  // Bit-serial long division; rem < den < 2^63 so rem << 1 never overflows. The high quotient word
  // is not needed.
  for (int i = 127; i >= 0; --i) {
    const uint64_t bit = i >= 64 ? (mag.hi >> (i - 64)) & 1 : (mag.lo >> i) & 1;
    rem = (rem << 1) | bit;
    uint64_t qbit = 0;
    if (rem >= den) { rem -= den; qbit = 1; }
    if (i < 64) q_lo |= qbit << i;
  }
  return neg ? uint64_t(0) - q_lo : q_lo;
}

// (a0 b0 + a1 b1 + a2 b2) * 2^shift / d rounded, low 64 bits. The portable version is always
// available so tests can compare it with the fast path.
inline uint64_t mul_add3_div_round_low_portable(const int64_t a[3], const int64_t b[3], int shift, int64_t d) {
  Wide n = wide_mul(a[0], b[0]);
  n = wide_add(n, wide_mul(a[1], b[1]));
  n = wide_add(n, wide_mul(a[2], b[2]));
  if (shift > 0) n = wide_shl(n, shift);
  return wide_div_round_low(n, d);
}

// Fast path where the compiler has a 128-bit integer (x86-64, AArch64); same results.
#if defined(__SIZEOF_INT128__) && !defined(ML_PORTABLE_WIDE)
inline uint64_t mul_add3_div_round_low(const int64_t a[3], const int64_t b[3], int shift, int64_t d) {
  __int128 n = 0;
  for (int i = 0; i < 3; ++i) n += static_cast<__int128>(a[i]) * b[i];
  n *= static_cast<__int128>(1) << shift;
  const __int128 half = d / 2;
  const __int128 q = n >= 0 ? (n + half) / d : -((-n + half) / d);
  return uint64_t(q);
}
#else
inline uint64_t mul_add3_div_round_low(const int64_t a[3], const int64_t b[3], int shift, int64_t d) {
  return mul_add3_div_round_low_portable(a, b, shift, d);
}
#endif

}  // namespace scan
}  // namespace ml

// 128-bit intermediates for the scanline renderer's per-triangle setup (depth plane), without
// relying on a compiler's __int128: 32-bit boards have none. Values are two's complement in (hi, lo).
// Setup runs once per activated triangle; the portable division takes 32-bit quotient digits (two or
// four 64-by-32-bit divisions), since a bit-serial loop cost about half of a Cortex-M3 frame.
#pragma once
#include <stdint.h>

#include "core/fixed.h"

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

// floor((u1 2^64 + u0) / v) for v != 0 and u1 < v (so the quotient fits 64 bits), and the remainder
// when asked: Hacker's Delight's divlu with 32-bit digits. Each digit is estimated by one 64-by-32-bit
// division (udiv64: udiv_64_32 on a 32-bit board) of the top of the normalized numerator and
// corrected at most twice.
inline uint64_t udiv_128_64(uint64_t u1, uint64_t u0, uint64_t v, uint64_t* remainder) {
  constexpr uint64_t b = uint64_t(1) << 32;
  const int s = 64 - bit_length(v);  // normalize: top bit of the divisor set
  v <<= s;
  const uint64_t vn1 = v >> 32, vn0 = v & 0xFFFFFFFFu;
  const uint64_t un32 = s == 0 ? u1 : (u1 << s) | (u0 >> (64 - s));
  const uint64_t un10 = u0 << s;
  const uint64_t un1 = un10 >> 32, un0 = un10 & 0xFFFFFFFFu;
  uint64_t rhat;
  uint64_t q1 = udiv64(un32, vn1, &rhat);
  while (q1 >= b || q1 * vn0 > ((rhat << 32) | un1)) {  // q1 < b before the product: no overflow
    --q1;
    rhat += vn1;
    if (rhat >= b) break;
  }
  const uint64_t un21 = (un32 << 32) + un1 - q1 * v;  // modulo 2^64; the true value is below v
  uint64_t q0 = udiv64(un21, vn1, &rhat);
  while (q0 >= b || q0 * vn0 > ((rhat << 32) | un0)) {
    --q0;
    rhat += vn1;
    if (rhat >= b) break;
  }
  if (remainder) *remainder = ((un21 << 32) + un0 - q0 * v) >> s;
  return (q1 << 32) | q0;
}

// n / d rounded to nearest (ties away from zero), d > 0; returns the low 64 bits of the quotient
// (callers use wrapping arithmetic, see scanline.cpp: the plane is exact modulo 2^64).
inline uint64_t wide_div_round_low(Wide n, int64_t d) {
  const bool neg = wide_negative(n);
  Wide mag = neg ? wide_neg(n) : n;
  mag = wide_add(mag, wide_from(d / 2));
  const uint64_t den = uint64_t(d);
  // The quotient's high word is not needed, only the high word's remainder, which keeps the
  // second division's quotient within 64 bits.
  uint64_t hi = mag.hi;
  if (hi >= den) udiv_128_64(0, hi, den, &hi);
  const uint64_t q_lo = udiv_128_64(hi, mag.lo, den, nullptr);
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

// Fast path where the compiler has a 128-bit integer (x86-64, AArch64); same results. When the sum
// fits int64 and d < 2^(62 - shift) (a piece's depth steps: sums below 2^58, d = area2 den), two
// 64-bit divisions give it: floor((|N| 2^s + h) / d) = floor(|N| / d) 2^s + floor((r 2^s + h) / d)
// for |N| = floor(|N| / d) d + r, h = floor(d / 2) (r 2^s + h < 2^63), the first term taken modulo
// 2^64 as the quotient's low bits are. Else (a plane's value at sample (0, 0), whose sum reaches
// 2^76) 128-bit arithmetic and its library division.
#if defined(__SIZEOF_INT128__) && !defined(ML_PORTABLE_WIDE)
inline uint64_t mul_add3_div_round_low(const int64_t a[3], const int64_t b[3], int shift, int64_t d) {
  int64_t p[3], sum;
  if (!__builtin_mul_overflow(a[0], b[0], &p[0]) && !__builtin_mul_overflow(a[1], b[1], &p[1]) &&
      !__builtin_mul_overflow(a[2], b[2], &p[2]) && !__builtin_add_overflow(p[0], p[1], &sum) &&
      !__builtin_add_overflow(sum, p[2], &sum) && shift < 62 && d < (int64_t(1) << (62 - shift))) {
    const uint64_t m = magnitude(sum), ud = uint64_t(d);
    const uint64_t q = ((m / ud) << shift) + (((m % ud) << shift) + ud / 2) / ud;
    return sum < 0 ? uint64_t(0) - q : q;
  }
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

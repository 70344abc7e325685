#include "core/fixed.h"

#include "core/build.h"

namespace ml {

// Both roots are built for every target, so the host tests run the boards' too (fixed.h selects one;
// on the boards the linker drops the other, --gc-sections).

namespace {

// floor(sqrt(v)) bit by bit in 32-bit arithmetic (16 steps).
uint32_t isqrt32(uint32_t v) {
  uint32_t result = 0, bit = uint32_t(1) << 30;
  while (bit > v) bit >>= 2;
  while (bit != 0) {
    if (v >= result + bit) {
      v -= result + bit;
      result = (result >> 1) + bit;
    } else {
      result >>= 1;
    }
    bit >>= 2;
  }
  return result;
}

// ceil(16 sqrt(t + 1)) for t = 0..63: 16 times an upper bound of the root of any number whose top
// bits are t.
constexpr uint8_t kRootCeil16[64] = {16,  23,  28,  32,  36,  40,  43,  46,  48,  51,  54,  56,  58,
                                     60,  62,  64,  66,  68,  70,  72,  74,  76,  77,  79,  80,  82,
                                     84,  85,  87,  88,  90,  91,  92,  94,  95,  96,  98,  99,  100,
                                     102, 103, 104, 105, 107, 108, 109, 110, 111, 112, 114, 115, 116,
                                     117, 118, 119, 120, 121, 122, 123, 124, 125, 126, 127, 128};

}  // namespace

// The boards' root (no 64-bit divide instruction): a bit-by-bit root in 64-bit arithmetic costs about
// 32 steps of 64-bit operations (some 650 instructions on a Cortex-M3, on every shaded triangle).
// Here: r0 = the 32-bit root of v's top 30 to 32 bits, scaled back (r0 <= sqrt(v), relative error
// below 2^-14); one Newton step r1 = (r0 + v / r0) / 2 (r0 < 2^32: one udiv_64_32) is never below
// floor(sqrt(v)) (integer Newton from any positive start) and at most a few units above it (the
// error squares); then r1 is stepped down to the floor.
uint64_t isqrt64_root32(uint64_t v) {
  if (v <= 0xFFFFFFFFu) return isqrt32(uint32_t(v));
  const int s = (bit_length(v) - 31) & ~1;                   // even; v >> s has 31 or 32 bits
  const uint32_t r0 = isqrt32(uint32_t(v >> s)) << (s / 2);  // in [2^15, 2^32)
  uint32_t remainder;
  uint64_t r1 = (r0 + udiv_64_32(v, r0, &remainder)) / 2;
  if (r1 > 0xFFFFFFFFu) r1 = 0xFFFFFFFFu;  // floor(sqrt(v)) < 2^32, and r1^2 must not overflow
  while (r1 * r1 > v) --r1;
  return r1;
}

// The 64-bit hosts' root (a 64-bit divide is one instruction). Integer Newton from above: from any
// r >= floor(sqrt(v)), r' = (r + v / r) / 2 falls strictly until it reaches floor(sqrt(v)), where it
// stops falling. The start is v's top 5 or 6 bits' root rounded up (a table), at most about 5 % high,
// so four or five steps (each a divide, an add and a shift) replace the 16 of a bit-by-bit 32-bit
// root and a Newton step (some 150 instructions a call, on every shaded triangle).
uint64_t isqrt64_newton(uint64_t v) {
  if (v < 2) return v;
  const int s = max_of(0, (bit_length(v) - 5) & ~1);  // even; v >> s < 64
  // sqrt(v) < sqrt((v >> s) + 1) 2^(s/2): rounded up, at most 2^32 (v < 2^64), so r + v / r < 2^34.
  uint64_t r = ((uint64_t(kRootCeil16[v >> s]) << (s / 2)) + 15) >> 4;
  for (;;) {
    const uint64_t next = (r + v / r) >> 1;
    if (next >= r) return r;
    r = next;
  }
}

// Compiled for size: a frame's camera and light take it, not its triangles (flat shading's light
// comes from the cross product: shade/shade.h face_lambert_q8).
ML_OPTIMIZE_SIZE bool normalize_q30(const Vec3i& v, Vec3i* out) {
  // Bring the vector to about 2^20 per component so the squared length fits comfortably and
  // isqrt keeps about 20 bits of precision.
  int64_t x = v.x, y = v.y, z = v.z;
  const int64_t largest = max_of(abs64(x), max_of(abs64(y), abs64(z)));
  if (largest == 0) return false;
  const int shift = bit_length(uint64_t(largest)) - 21;
  if (shift > 0) { x >>= shift; y >>= shift; z >>= shift; }
  else if (shift < 0) { x = shift_left(x, -shift); y = shift_left(y, -shift); z = shift_left(z, -shift); }
  const uint64_t len2 = uint64_t(x * x + y * y + z * z);   // < 3 * 2^42
  // len with 10 extra fraction bits: sqrt(len2 << 20) = len * 2^10.
  const int64_t len_q10 = int64_t(isqrt64(len2 << 20));
  if (len_q10 == 0) return false;
  // component / len in Q1.30 = (c << 40) / len_q10; |c| <= 2^21 so c << 40 < 2^62.
  out->x = int32_t(clamp_to<int64_t>(div_round(shift_left(x, 40), len_q10), -kUnitOne, kUnitOne));
  out->y = int32_t(clamp_to<int64_t>(div_round(shift_left(y, 40), len_q10), -kUnitOne, kUnitOne));
  out->z = int32_t(clamp_to<int64_t>(div_round(shift_left(z, 40), len_q10), -kUnitOne, kUnitOne));
  return true;
}

// tan(d degrees) in Q8.24 for d = 0..89.
static const int32_t kTanTableQ24[90] = {
0, 292847, 585873, 879257, 1173177, 1467816,
    1763356, 2059983, 2357884, 2657250, 2958276, 3261160,
    3566107, 3873326, 4183030, 4495441, 4810789, 5129310,
    5451248, 5776859, 6106407, 6440170, 6778435, 7121506,
    7469698, 7823344, 8182795, 8548419, 8920604, 9299763,
    9686330, 10080768, 10483568, 10895251, 11316375, 11747533,
    12189361, 12642539, 13107798, 13585922, 14077756, 14584211,
    15106273, 15645007, 16201569, 16777216, 17373316, 17991361,
    18632986, 19299979, 19994307, 20718136, 21473857, 22264118,
    23091857, 23960348, 24873246, 25834647, 26849158, 27921976,
    29058991, 30266899, 31553354, 32927140, 34398390, 35978856,
    37682244, 39524644, 41525067, 43706142, 46095022, 48724573,
    51634961, 54875801, 58509105, 62613423, 67289738, 72670106,
    78930596, 86311294, 95148320, 105927173, 119376095, 136639459,
    159624548, 191764456, 239925367, 320128352, 480436607, 961166061
};

int32_t tan_deg_q16(int32_t degrees_q16) {
  if (degrees_q16 <= 0) return 0;
  if (degrees_q16 >= (89 << kAngleBits)) return int32_t(kTanTableQ24[89] >> 8);  // fov is at most 170
  const int32_t whole = degrees_q16 >> kAngleBits;
  const int64_t frac = degrees_q16 & ((1 << kAngleBits) - 1);
  // tan(a + b) = (tan a + tan b) / (1 - tan a tan b), with b < 1 degree: tan b = b + b^3/3 in
  // radians is exact to 1e-9, so the result is as good as the Q24 table (relative error ~1e-6).
  const int64_t b = (frac * 292818) >> kAngleBits;  // radians, Q24 (292818 = pi/180 in Q24)
  const int64_t tan_b = b + ((b * b >> 24) * b >> 24) / 3;
  const int64_t tan_a = kTanTableQ24[whole];
  const int64_t num = tan_a + tan_b;
  const int64_t den = (int64_t(1) << 24) - ((tan_a * tan_b) >> 24);
  return int32_t(div_round(num << 16, den));
}

uint64_t udiv_64_32(uint64_t n, uint32_t d, uint32_t* remainder) {
  const uint32_t hi = uint32_t(n >> 32), lo = uint32_t(n);
  if (hi == 0) {  // one 32-bit divide
    *remainder = lo % d;
    return lo / d;
  }
  // High word first (its quotient is the result's high word), then (rest : lo) / d, where rest < d
  // makes the quotient fit 32 bits: Knuth's algorithm D on two 16-bit digits.
  const uint32_t q_hi = hi / d;
  const uint32_t u1 = hi - q_hi * d;
  const int s = __builtin_clz(d);  // normalize: top bit of the divisor set
  const uint32_t v = d << s;
  const uint32_t vn1 = v >> 16, vn0 = v & 0xFFFFu;
  const uint32_t un32 = s == 0 ? u1 : (u1 << s) | (lo >> (32 - s));
  const uint32_t un10 = lo << s;
  const uint32_t un1 = un10 >> 16, un0 = un10 & 0xFFFFu;
  uint32_t q1 = un32 / vn1, rhat = un32 - q1 * vn1;
  while (q1 >= 0x10000u || q1 * vn0 > ((rhat << 16) | un1)) {
    --q1;
    rhat += vn1;
    if (rhat >= 0x10000u) break;
  }
  const uint32_t un21 = (un32 << 16) + un1 - q1 * v;
  uint32_t q0 = un21 / vn1;
  rhat = un21 - q0 * vn1;
  while (q0 >= 0x10000u || q0 * vn0 > ((rhat << 16) | un0)) {
    --q0;
    rhat += vn1;
    if (rhat >= 0x10000u) break;
  }
  *remainder = ((un21 << 16) + un0 - q0 * v) >> s;
  return uint64_t(q_hi) << 32 | (q1 << 16 | q0);
}

}  // namespace ml

// Every number format used in src/, with its range and precision, and the integer math on them.
// This is the one place formats are defined; other headers refer to these names.
//
// Notation: Qm.n is a signed two's-complement integer with n fractional bits.
//
// | quantity                  | type     | format / unit                        | range (enforced where)                 |
// |---------------------------|----------|--------------------------------------|----------------------------------------|
// | stored vertex position    | int16    | per-batch quantized, see Batch       | full int16                             |
// | world coordinate          | int32    | world unit (scene compiler sets it)  | scene inside ±2^16 (compiler); eye,    |
// |                           |          |                                      | target and any point |c| < 2^24 (view) |
// | unit vector / rotation    | int32    | Q1.30                                | [-1, 1]                                |
// | stored normal             | int16    | Q1.14                                | [-1, 1]                                |
// | view-space coordinate     | int32    | 1/16 world unit, camera frame        | |c| < 2^30 (follows from the above)    |
// |                           |          | (x right, y down, z forward)         |                                        |
// | screen coordinate         | int32    | 1/256 pixel (kSubpixelBits = 8)      | |c| < 2^22 after guard-band clipping   |
// | edge function value       | int64    | (1/256 px)^2                         | |E| < 2^47 inside the guard band       |
// | depth                     | uint32   | near * 2^30 / z_view (1/z, 2^30 at   | (0, 2^30]; larger = nearer             |
// |                           |          | the near plane)                      |                                        |
// | barycentric weight        | int32    | Q16 (the three sum to 65536)         | [0, 65536] inside the triangle         |
// | colour channel            | uint8    | 0..255 sRGB-ish, no gamma handling   |                                        |
// | screen-linear value       | int64    | Q20 (kPlaneBits), at pixel centres   | inputs |v| < 2^16, slope <= 2^20/pixel |
// | texture coordinate        | int32    | Q16.16                               | full int32                             |
// | angle                     | int32    | degrees Q16.16                       | field of view in [1, 170] degrees      |
// | focal length              | int64    | 1/256 pixel per unit of x/z          | (0, 2^27)                              |
#pragma once
#include <stdint.h>

namespace ml {

constexpr int kSubpixelBits = 8;
constexpr int32_t kSubpixelOne = 1 << kSubpixelBits;
constexpr int32_t kSubpixelHalf = kSubpixelOne / 2;

constexpr int kUnitBits = 30;
constexpr int32_t kUnitOne = 1 << kUnitBits;

constexpr int kNormalBits = 14;
constexpr int32_t kNormalOne = 1 << kNormalBits;

constexpr int kWorldSceneBits = 16;         // the compiler fits the scene inside ±2^16 world units
constexpr int32_t kWorldLimit = 1 << 24;    // any world point handed to the view pipeline
// What read_scene accepts from a blob (docs/scene-blob.md, validation): the compiler stays far inside.
constexpr int32_t kWorldPositionLimit = 1 << 18;          // |dequantized vertex position| < 2^18
constexpr int32_t kSceneLimit = 1 << 18;                  // bounds, sphere centre, BSP node bounds
constexpr int32_t kRadiusLimit = 1 << 20;                 // bounding sphere radius
constexpr int32_t kBspBoundsLimit = 1 << 21;              // decoded BSP node box (whole grid cells)
constexpr int kMaxBoundsShift = 12;                       // BSP bounds cell at most 2^12 world units
constexpr int kViewFractionBits = 4;     // view space keeps 4 bits below the world unit
constexpr int kViewLimitBits = 30;

// Screen-space guard band: after clipping, every vertex lies within ±kGuardBandPixels of the screen
// centre, so screen coordinates stay below 2^22 subpixels and edge functions below 2^47.
constexpr int32_t kGuardBandPixels = 1 << 13;
constexpr int32_t kMaxScreenDim = 4096;     // widest/tallest render (in pixels) the pipeline supports
constexpr int kMaxTilerAa = 8;              // the tiler's samples per pixel per axis: 1, 2, 4 or 8
constexpr int32_t kMaxSampleDim = kMaxScreenDim * kMaxTilerAa;  // the tiler's samples per side

// Scanline renderer (docs/scanline.md): l x l samples per pixel, l <= kMaxSamplesPerAxis; sample
// lattice indices up to kMaxScreenDim * (l - 1) fit int16 (edge boundaries) and uint16 (spans, rows).
constexpr int kMaxSamplesPerAxis = 8;
constexpr int32_t kMaxLatticeIndex = kMaxScreenDim * (kMaxSamplesPerAxis - 1);
static_assert(kMaxLatticeIndex < (1 << 15) - 1, "lattice indices must fit int16 with one to spare");
// ySortList references pack triangle id * 16 + back-facing * 8 + piece (< 8) into 32 bits.
constexpr uint32_t kMaxScanlineTriangles = 1u << 28;

constexpr int kDepthBits = 30;
constexpr uint32_t kDepthNear = 1u << kDepthBits;

constexpr int kWeightBits = 16;
constexpr int32_t kWeightOne = 1 << kWeightBits;

// Quantities linear in screen space (shade.h LinearPlane: Gouraud colour channels).
constexpr int kPlaneBits = 20;

constexpr int kTexcoordBits = 16;
// Textures (scene/blob_format.h TextureTexels): power-of-two sides up to 2^10 texels, so a texel
// coordinate u * width (u Q16.16) stays below 2^41 and a texture below 2 MiB.
constexpr int kMaxTextureDimBits = 10;
constexpr uint32_t kMaxTextureDim = 1u << kMaxTextureDimBits;
constexpr int kAngleBits = 16;
constexpr int kFocalBits = 8;

// ---- integer helpers -------------------------------------------------------------------------

// The common type of two integer types of the same signedness (the wider one).
template <typename A, typename B>
struct CommonIntOf {
  static_assert((A(-1) < A(0)) == (B(-1) < B(0)), "mixing signed and unsigned operands");
  using type = decltype(A(0) + B(0));
};

inline int64_t abs64(int64_t v) { return v < 0 ? -v : v; }
inline int32_t abs32(int32_t v) { return v < 0 ? -v : v; }
// min_of, max_of and clamp_to take operands of one signedness and any widths: on arm-none-eabi
// int32_t is long, so an int32_t meets an int literal in ordinary code. The result has the wider
// type (common type); mixing signed and unsigned is a compile error rather than a silent conversion.
template <typename A, typename B>
using CommonInt = typename CommonIntOf<A, B>::type;
template <typename A, typename B>
inline CommonInt<A, B> min_of(A a, B b) {
  using T = CommonInt<A, B>;
  return T(a) < T(b) ? T(a) : T(b);
}
template <typename A, typename B>
inline CommonInt<A, B> max_of(A a, B b) {
  using T = CommonInt<A, B>;
  return T(a) > T(b) ? T(a) : T(b);
}
template <typename A, typename B, typename C>
inline CommonInt<CommonInt<A, B>, C> clamp_to(A v, B lo, C hi) {
  using T = CommonInt<CommonInt<A, B>, C>;
  return T(v) < T(lo) ? T(lo) : (T(v) > T(hi) ? T(hi) : T(v));
}

// Arithmetic shift right that rounds to nearest (ties away from zero). s in [1, 62].
inline int64_t shift_round(int64_t v, int s) {
  const int64_t half = int64_t(1) << (s - 1);
  return v >= 0 ? (v + half) >> s : -((-v + half) >> s);
}

// floor(v / 2^s) for signed v, s in [0, 62]: an arithmetic shift (GCC and Clang shift negative values
// arithmetically; the tests check it).
inline int64_t floor_shift(int64_t v, int s) { return v >> s; }

// v * 2^s for signed v (a left shift of a negative value is undefined in C++17). |v * 2^s| < 2^63.
inline int64_t shift_left(int64_t v, int s) { return v * (int64_t(1) << s); }

// (a * b) >> s rounded to nearest. Caller guarantees |a * b| < 2^63 (true for the formats above
// when one factor is Q1.30 or smaller and the other below 2^32).
inline int64_t mul_shift(int64_t a, int64_t b, int s) { return shift_round(a * b, s); }

// Q16.16 multiply: |result| must fit int32 (checked by callers through the documented ranges).
inline int32_t mul_q16(int32_t a, int32_t b) { return int32_t(mul_shift(a, b, 16)); }

// ---- division -------------------------------------------------------------------------------
// A Cortex-M has no 64-bit divide instruction (an M3 divides 32 by 32 bits; an M0+ not at all), and
// the compiler's 64-bit helper (__aeabi_ldivmod) costs about 70 instructions. Most of maskline's
// divisions have a 64-bit numerator and a divisor below 2^32 (a depth, an edge coefficient), so on
// 32-bit targets they go through udiv_64_32: exact, with three 32-bit divides at most. The results
// are the native division's, bit for bit (property-tested on the host against it).

// floor(n / d) and n mod d for d != 0, from 32-bit divides (Hacker's Delight, divlu, with 16-bit digits).
uint64_t udiv_64_32(uint64_t n, uint32_t d, uint32_t* remainder);

// floor(n / d) for d != 0, and the remainder when asked.
inline uint64_t udiv64(uint64_t n, uint64_t d, uint64_t* remainder = nullptr) {
#if UINTPTR_MAX == 0xFFFFFFFFu  // 32-bit target: no 64-bit divide instruction
  if (d <= 0xFFFFFFFFu) {
    uint32_t r32;
    const uint64_t q = udiv_64_32(n, uint32_t(d), &r32);
    if (remainder) *remainder = r32;
    return q;
  }
#endif
  if (remainder) *remainder = n % d;
  return n / d;
}

// |v| as an unsigned value (exact for INT64_MIN too).
inline uint64_t magnitude(int64_t v) { return v < 0 ? uint64_t(0) - uint64_t(v) : uint64_t(v); }

// Division rounding to nearest, ties away from zero. d != 0.
inline int64_t div_round(int64_t n, int64_t d) {
  const uint64_t ud = magnitude(d);
  const uint64_t q = udiv64(magnitude(n) + ud / 2, ud);
  return int64_t((n < 0) != (d < 0) ? uint64_t(0) - q : q);  // unsigned negation: exact for 2^63
}

// Floor division (rounds toward minus infinity). d > 0.
inline int64_t div_floor(int64_t n, int64_t d) {
  if (n >= 0) return int64_t(udiv64(uint64_t(n), uint64_t(d)));
  uint64_t r;
  const uint64_t q = udiv64(magnitude(n), uint64_t(d), &r);
  return int64_t(uint64_t(0) - q - (r != 0 ? 1 : 0));
}

// Reciprocal 2^bits / d rounded, for d > 0, bits <= 62.
inline int64_t reciprocal(int64_t d, int bits) { return div_round(int64_t(1) << bits, d); }

// floor(sqrt(v)) for any uint64, exact, no float (fixed.cpp), two ways that give the same roots:
// isqrt64_newton, Newton steps from a table's start (64-bit divides), and isqrt64_root32, a 32-bit
// root of v's top bits, one Newton step and a correction (32-bit divides). Both are built everywhere,
// so the host tests both; isqrt64 is the 64-bit hosts' newton and the 32-bit boards' root32.
uint64_t isqrt64_newton(uint64_t v);
uint64_t isqrt64_root32(uint64_t v);
inline uint64_t isqrt64(uint64_t v) {
#if UINTPTR_MAX == 0xFFFFFFFFu
  return isqrt64_root32(v);
#else
  return isqrt64_newton(v);
#endif
}

// Number of significant bits of v (0 for v == 0).
inline int bit_length(uint64_t v) { return v ? 64 - __builtin_clzll(v) : 0; }

// Set bits of v. On 64-bit hosts summed in place (__builtin_popcountll is a library call on the
// baseline x86-64: about 20 instructions and a call); the boards keep the library's, whose one copy
// is smaller than these 64-bit steps inline (Cortex-M0+: about 150 bytes a use).
inline int bit_count64(uint64_t v) {
#if UINTPTR_MAX == 0xFFFFFFFFu
  return __builtin_popcountll(v);
#else
  v -= (v >> 1) & 0x5555555555555555u;
  v = (v & 0x3333333333333333u) + ((v >> 2) & 0x3333333333333333u);
  v = (v + (v >> 4)) & 0x0F0F0F0F0F0F0F0Fu;
  return int((v * 0x0101010101010101u) >> 56);
#endif
}

// Exact floor(n / d) without a division per call, for a divisor used many times (a triangle's doubled
// area in its Gouraud weights): one 32-bit reciprocal r = floor(2^44 / (d' + 1)) of d normalized to
// d' in [2^19, 2^20) is made once (one 64-by-32-bit division); each quotient is a multiply, a shift and
// at most two correction steps. Ranges: d in [1, 2^46], n < 2^17 d (quotients below 2^17; the
// normalized n stays below 2^38, so n' r < 2^63). Property-tested against the native division.
constexpr int kReciprocalBits = 44;
constexpr int kReciprocalNormBits = 20;
constexpr int kReciprocalDivisorBits = 46;
// The normalizing shift of d (right when > 0, left when < 0).
inline int reciprocal_shift(uint64_t d) { return bit_length(d) - kReciprocalNormBits; }
inline uint64_t reciprocal_normalize(uint64_t v, int shift) { return shift >= 0 ? v >> shift : v << -shift; }
inline uint32_t make_reciprocal(uint64_t d) {
  const uint64_t dn = reciprocal_normalize(d, reciprocal_shift(d));
  return uint32_t(udiv64(uint64_t(1) << kReciprocalBits, dn + 1));
}
inline uint32_t divide_by_reciprocal(uint64_t n, uint64_t d, uint32_t r) {
  // q never exceeds floor(n / d): n' <= n / 2^s and r < 2^44 2^s / d. It falls short by at most 2.
  uint64_t q = (reciprocal_normalize(n, reciprocal_shift(d)) * r) >> kReciprocalBits;
  uint64_t rem = n - q * d;
  while (rem >= d) { ++q; rem -= d; }
  return uint32_t(q);
}

struct Vec3i {
  int32_t x, y, z;
};

inline int64_t dot64(const Vec3i& a, const Vec3i& b) {
  return int64_t(a.x) * b.x + int64_t(a.y) * b.y + int64_t(a.z) * b.z;
}

// Scales v (any length up to 2^31 per component, not all zero) to a Q1.30 unit vector.
// Returns false for the zero vector.
bool normalize_q30(const Vec3i& v, Vec3i* out);

// One Newton step of renormalization for a Q1.14 vector that is already close to unit length
// (interpolated normals): x1 = x0 * (1.5 - 0.5 * |x0|^2), no square root. Converges quadratically:
// two steps take any length in [0.85, 1.15] to within 0.25% of 1, and [0.95, 1.05] to within
// rounding (a few Q1.14 units).
inline Vec3i newton_renormalize_q14(const Vec3i& n) {
  const int64_t len2 = dot64(n, n);                               // Q2.28
  const int64_t factor = (int64_t(3) << 27) - (len2 >> 1);        // Q2.28: 1.5 - 0.5 |n|^2
  return Vec3i{int32_t(mul_shift(n.x, factor, 28)), int32_t(mul_shift(n.y, factor, 28)),
               int32_t(mul_shift(n.z, factor, 28))};
}

// tan of an angle in degrees Q16.16, for angles in [0, 89] degrees (larger ones give tan 89); Q16.16.
// A Q24 table at whole degrees and the tan addition formula: error within one Q16 unit or 1e-5.
int32_t tan_deg_q16(int32_t degrees_q16);

}  // namespace ml

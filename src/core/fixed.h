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
constexpr int64_t kPlaneOffsetLimit = int64_t(1) << 50;   // |d| of a BSP plane
constexpr int kViewFractionBits = 4;     // view space keeps 4 bits below the world unit
constexpr int kViewLimitBits = 30;

// Screen-space guard band: after clipping, every vertex lies within ±kGuardBandPixels of the screen
// centre, so screen coordinates stay below 2^22 subpixels and edge functions below 2^47.
constexpr int32_t kGuardBandPixels = 1 << 13;
constexpr int32_t kMaxScreenDim = 4096;     // widest/tallest render (in samples) the pipeline supports

constexpr int kDepthBits = 30;
constexpr uint32_t kDepthNear = 1u << kDepthBits;

constexpr int kWeightBits = 16;
constexpr int32_t kWeightOne = 1 << kWeightBits;

constexpr int kTexcoordBits = 16;
constexpr int kAngleBits = 16;
constexpr int kFocalBits = 8;

// ---- integer helpers -------------------------------------------------------------------------

inline int64_t abs64(int64_t v) { return v < 0 ? -v : v; }
inline int32_t abs32(int32_t v) { return v < 0 ? -v : v; }
template <typename T> inline T min_of(T a, T b) { return a < b ? a : b; }
template <typename T> inline T max_of(T a, T b) { return a > b ? a : b; }
template <typename T> inline T clamp_to(T v, T lo, T hi) { return v < lo ? lo : (v > hi ? hi : v); }

// Arithmetic shift right that rounds to nearest (ties away from zero). s in [1, 62].
inline int64_t shift_round(int64_t v, int s) {
  const int64_t half = int64_t(1) << (s - 1);
  return v >= 0 ? (v + half) >> s : -((-v + half) >> s);
}

// v * 2^s for signed v (a left shift of a negative value is undefined in C++17). |v * 2^s| < 2^63.
inline int64_t shift_left(int64_t v, int s) { return v * (int64_t(1) << s); }

// (a * b) >> s rounded to nearest. Caller guarantees |a * b| < 2^63 (true for the formats above
// when one factor is Q1.30 or smaller and the other below 2^32).
inline int64_t mul_shift(int64_t a, int64_t b, int s) { return shift_round(a * b, s); }

// Q16.16 multiply: |result| must fit int32 (checked by callers through the documented ranges).
inline int32_t mul_q16(int32_t a, int32_t b) { return int32_t(mul_shift(a, b, 16)); }

// Division rounding to nearest, ties away from zero. d != 0.
inline int64_t div_round(int64_t n, int64_t d) {
  if (d < 0) { n = -n; d = -d; }
  return n >= 0 ? (n + d / 2) / d : -((-n + d / 2) / d);
}

// Floor division (rounds toward minus infinity). d > 0.
inline int64_t div_floor(int64_t n, int64_t d) {
  int64_t q = n / d;
  return (n % d != 0 && n < 0) ? q - 1 : q;
}

// Reciprocal 2^bits / d rounded, for d > 0, bits <= 62.
inline int64_t reciprocal(int64_t d, int bits) { return div_round(int64_t(1) << bits, d); }

// floor(sqrt(v)) for any uint64, bit by bit: no division, no float.
inline uint64_t isqrt64(uint64_t v) {
  uint64_t result = 0;
  uint64_t bit = uint64_t(1) << 62;
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

// Number of significant bits of v (0 for v == 0).
inline int bit_length(uint64_t v) { return v ? 64 - __builtin_clzll(v) : 0; }

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

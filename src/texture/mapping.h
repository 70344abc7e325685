// Perspective-correct texture mapping in integers, shared by both renderers so that they pick the
// same texel at every sample (docs/textures.md).
//
// For a sample whose view ray has direction d and a triangle with view-space vertices P0, P1, P2,
// the perspective-correct barycentric weight of vertex i is e_i / (e_0 + e_1 + e_2) with
// e_i = d . (P_j x P_k) (i, j, k cyclic). d = (sx - cx, sy - cy, focal) is linear in the sample's
// screen position, so each e_i is a plane over the renderer's sample lattice, evaluated exactly in
// int64 — the integer form of stepping u/w, v/w and 1/w. The planes come from the whole original
// triangle (never a clipped or BSP-split piece), so every piece of it, in either renderer, maps
// identically; triangles crossing the near plane need no special case.
//
// The division is not made at every sample. A row is cut into segments of kTextureSegment samples
// at fixed lattice columns (multiples of the length, whatever span a renderer draws, so both
// renderers interpolate between the same ends); the exact coordinates at a segment's two ends are
// divided out and the samples between interpolate them linearly (affine), unless the error bound
// says the segment is too curved: then it is cut in halves, quarters, ... down to single samples
// (every sample exact). The bound: along a segment u = N(t) / D(t) with N and D linear (D = the sum
// of the e_i), and interpolating between the ends errs by at most |du| |dD| / (4 min |D|); a part of
// 1/k of the segment errs by at most |du| |dD| max|D| / (4 k^2 min|D|^2) (du, dD: the changes over
// the whole segment). The longest part is kept whose bound, along both axes, is within
//   - 2^-kTextureAffineErrorBitsNearest texel (nearest) or 2^-kTextureAffineErrorBitsBilinear texel
//     (bilinear: a colour step between neighbouring texels moves by 2 levels at most), or
//   - 2^-kTextureAffineShiftBits of the segment's mean texel step per sample (the sample takes the
//     coordinates of a point at most 1/8 sample away along the row: minified textures, whose texels
//     are smaller than a sample, need no finer precision than that).
// Segments whose ends have D of different signs or zero, or saturated coordinates, are cut down to
// single samples. tests/texture/mapping_test.cpp checks the bound against the exact division and
// tests/oracle/texture_vs_oracle_test.cpp the images against the double-precision texturer.
//
// Small triangles take no segments (TexturePlanes::exact): a triangle the view does not clip whose
// lattice sample box is less than kTextureExactSide samples a side. Their rows are short, and the
// perspective of a real model's small faces (often seen at a slant) cuts their segments into pieces
// of a few samples anyway: deciding a segment (two exact ends and the bound) for such a row costs
// more than dividing each of its samples. Each sample's coordinates are the floored quotient of the
// sums above with the e_i scaled once for the whole box instead of at each sample
// (TexturePlanes::boxed, BoxSums): the sums are then planes over the box, stepped from sample to
// sample by additions, and a sample costs its two divisions. Rounding the planes' coefficients to
// the box's scale moves each e_i by at most 33.5 units of its 28 bits over the box, so the
// coordinates stay within one unit (2^-16) of exact_texture_uv's for the differences of texture
// coordinates a real model's small triangle spans (tests/texture/mapping_test.cpp). A box whose sum
// of e_i changes sign or reaches 0 (the plane seen edge-on) divides each sample as exact_texture_uv
// does.
#pragma once
#include <stdint.h>

#include "core/build.h"
#include "core/fixed.h"
#include "scene/scene.h"
#include "view/view.h"

namespace ml {

// Samples a segment spans (a power of two) and the affine error bounds above.
constexpr int kTextureSegmentBits = 5;
constexpr int32_t kTextureSegment = 1 << kTextureSegmentBits;
constexpr int kTextureAffineErrorBitsNearest = 5;
constexpr int kTextureAffineErrorBitsBilinear = 7;
constexpr int kTextureAffineShiftBits = 3;
constexpr int32_t kTextureExactSide = 32;  // small triangles: sample boxes narrower and lower than this

// Exact texture coordinates at one sample, and what deciding a segment needs about them.
struct ExactUv {
  int32_t uv[2];   // Q16.16, floored
  int64_t denom;   // sum of e_i, unshifted (its sign is the side of the plane the ray meets)
  bool clean;      // denom != 0 and neither coordinate saturated: the ends of an affine piece
};

// A segment: samples [x, x + kTextureSegment) of row y, cut in affine pieces of 2^bits samples.
struct TextureSegment {
  int32_t x, y, bits;  // y = -1: none
  ExactUv ends[2];     // exact at x and x + kTextureSegment
  // The last end of a shorter piece evaluated in it (at sample last_x of row y; -1: none): a block
  // of a few samples ends where the next block along the row starts.
  int32_t last_x;
  ExactUv last;
};

// An affine piece of a row: samples [x, x + 2^bits), uv(x + j) = uv + floor(step j / 2^bits).
struct TexturePiece {
  int32_t x, y, bits;
  int32_t uv[2];
  int64_t step[2];  // uv at x + 2^bits minus uv at x (0 when bits == 0: one exact sample)
};

// A small triangle's sums over its box (above): at lattice sample (X, Y) of the box, n_k = at[k] +
// dx[k] (X - x) + dy[k] (Y - y) for k = 0 (u), 1 (v), 2 (the sum of e_i, positive over the box), and
// the coordinates are floor(n_0 / n_2) and floor(n_1 / n_2), clamped to int32 (|n_0|, |n_1| < 2^61,
// n_2 < 2^30).
struct BoxSums {
  int32_t x, y;    // the box's first sample (the triangle's box and a sample more each side)
  int32_t w, h;    // its last sample: (x + w, y + h)
  int64_t at[3], dx[3], dy[3];
  // 64-bit hosts: 0 <= n_k < 2^31 n_2 (k = 0, 1) at every sample of the box, so that the coordinates
  // are the truncated quotients n_k / n_2 as they are (no floor step, no clamp). (Not set on the
  // boards, which do not read it.)
  bool plain;
};

struct TexturePlanes {
  int64_t a[3], b[3], k[3];   // e_i(X, Y) = a_i X + b_i Y + k_i, |e_i| < 2^61 on the lattice
  int32_t uv[3][2];           // the triangle's TEXCOORD_0, Q16.16
  int32_t size_bits[2];       // log2 of the texture's width and height: the error bound is in its texels
  int32_t error_bits;         // the affine error bound allowed: 2^-error_bits texel
  bool exact;                 // a small triangle: no segments, each sample's coordinates its own
  bool boxed;                 // a small triangle's sums scaled once for its box (`sums`), else divided
  uint8_t level;              // the mip level sampled (texture_level), whose texels the planes are for
  uint64_t whole_denom;       // texture_segment_whole's threshold on |sum e_i| (65 dd)
  // Caches, so that drawing costs about one exact division a segment: the segments decided (one,
  // or one per row of a few rows for a renderer that draws blocks, use_segment_rows), the piece
  // last used. A small triangle has no segments: its sums take their place.
  TextureSegment* rows;       // null: `one`
  uint32_t row_mask;
  union {
    TextureSegment one;       // !exact
    BoxSums sums;             // boxed
  };
  TexturePiece piece;
};

// Sample (X, Y) of the lattice lies at subpixel ((256 X + ox) / den, (256 Y + oy) / den): den = 1,
// ox = oy = 128 are pixel centres (the tiler and the 1x1 scanline renderer). width and height: of
// the texture the coordinates will index (powers of two), error_bits: its filter's affine error bits.
void make_texture_planes(const View& view, const Vec3i world[3], const int32_t uv[3][2], int32_t den,
                         int32_t ox, int32_t oy, uint32_t width, uint32_t height, int error_bits,
                         TexturePlanes* out);

// Segments of 2^count_bits rows kept at once (rows: that many, set aside by the caller): a renderer
// that draws a block row by row finds the segments again in the next block.
void use_segment_rows(TexturePlanes* planes, TextureSegment* rows, int count_bits);

// Nothing cached in the planes (no segment rows, no segment or piece: samples have y >= 0), as
// make_texture_planes leaves them.
inline void clear_texture_caches(TexturePlanes* planes) {
  planes->rows = nullptr;
  planes->row_mask = 0;
  if (!planes->boxed) planes->one.y = -1;  // (a small triangle's sums are no cache: they stay)
  planes->piece.y = -1;
}

// Makes the planes of a small triangle (exact) boxed, with their sums over the lattice box [x0, x1] x
// [y0, y1] of its samples (less than kTextureExactSide samples a side) and a sample more each side,
// unless the sum of e_i changes sign or reaches 0 there.
void make_box_sums(TexturePlanes* planes, int32_t x0, int32_t y0, int32_t x1, int32_t y1);

// The exact coordinates at lattice sample (X, Y) >= 0: sum uv_i e_i / sum e_i, floored (ExactSteps'
// division, below).
void exact_texture_uv(const TexturePlanes& p, int32_t x, int32_t y, ExactUv* out);
// The same division as a loop over the vertices and axes: exact_texture_uv on 32-bit boards, whose
// flash it spares (about 330 bytes on the Cortex-M0+ against ExactSteps written out). The same
// coordinates (TextureMapping.ExactDivisionIsTheFlooredQuotient checks both on the host).
void exact_texture_uv_looped(const TexturePlanes& p, int32_t x, int32_t y, ExactUv* out);

// exact_texture_uv's coordinates of samples x .. x + n - 1 of row y (x >= 0), into uv: the planes
// stepped along the row, one division a coordinate and sample.
void exact_texture_row(const TexturePlanes& p, int32_t x, int32_t y, int32_t n, int32_t (*uv)[2]);

// floor(n / d) for d > 0. On 64-bit hosts one signed division gives the truncated quotient and its
// remainder, and a negative remainder steps the quotient down: the same floor as div_floor without
// its branch on n's sign (boards: div_floor, whose 32-bit divisor takes udiv_64_32).
inline int64_t texture_floor_quotient(int64_t n, int64_t d) {
#if UINTPTR_MAX == 0xFFFFFFFFu
  return div_floor(n, d);
#else
  const int64_t q = n / d, r = n % d;
  return q - (r < 0 ? 1 : 0);
#endif
}

// uv = (qu, qv) clamped to int32; false when clamped. Both within int32 is the usual case, one test:
// q + 2^31 below 2^32 as unsigned.
__attribute__((always_inline)) inline bool clamped_coordinates(int64_t qu, int64_t qv, int32_t uv[2]) {
  if (((uint64_t(qu) + 0x80000000u) | (uint64_t(qv) + 0x80000000u)) >> 32 == 0) {
    uv[0] = int32_t(qu);
    uv[1] = int32_t(qv);
    return true;
  }
  uv[0] = int32_t(clamp_to<int64_t>(qu, INT32_MIN, INT32_MAX));
  uv[1] = int32_t(clamp_to<int64_t>(qv, INT32_MIN, INT32_MAX));
  return false;
}

// The exact coordinates of samples x, x + 1, ... of a row, one at a time (exact_texture_uv's, the
// planes stepped along the row): for a caller that uses each sample's coordinates at once.
// Each sample divides sum uv_i e_i by sum e_i with the e_i shifted to kTextureWeightBits bits first
// (one common shift: the divisor stays below 2^30), floored and clamped to int32. The sums are taken
// from vertex 0: floor(sum uv_i w_i / W) = uv_0 + floor((d_1 w_1 + d_2 w_2) / W) for W = sum w_i and
// d_i = uv_i - uv_0 (|d_i| < 2^32, |d_i w_i| < 2^60): two products a coordinate instead of three.
constexpr int kTextureWeightBits = 28;
class ExactSteps {
 public:
  __attribute__((always_inline)) explicit ExactSteps(const TexturePlanes& p)
      : u0_(p.uv[0][0]), v0_(p.uv[0][1]), du1_(int64_t(p.uv[1][0]) - u0_), du2_(int64_t(p.uv[2][0]) - u0_),
        dv1_(int64_t(p.uv[1][1]) - v0_), dv2_(int64_t(p.uv[2][1]) - v0_), a0_(p.a[0]), a1_(p.a[1]), a2_(p.a[2]) {}
  // The row's first sample: (x, y) of the lattice.
  __attribute__((always_inline)) void start(const TexturePlanes& p, int32_t x, int32_t y) {
    e0_ = p.a[0] * x + p.b[0] * y + p.k[0];
    e1_ = p.a[1] * x + p.b[1] * y + p.k[1];
    e2_ = p.a[2] * x + p.b[2] * y + p.k[2];
  }
  // sum e_i at the current sample, unshifted (|e_i| < 2^61: the sum fits).
  int64_t denom() const { return e0_ + e1_ + e2_; }
  // The current sample's coordinates, then the next sample along the row.
  __attribute__((always_inline)) void next(int32_t uv[2]) {
    divide(e0_, e1_, e2_, uv);
    e0_ += a0_, e1_ += a1_, e2_ += a2_;
  }
  // The current sample's coordinates. False when a quotient left int32 or the shifted sum is 0 (the
  // ray grazes the triangle's plane: any vertex will do, vertex 0's).
  bool here(int32_t uv[2]) const { return divide(e0_, e1_, e2_, uv); }

 private:
  __attribute__((always_inline)) bool divide(int64_t e0, int64_t e1, int64_t e2, int32_t uv[2]) const {
    const int shift = max_of(0, bit_length(magnitude(e0) | magnitude(e1) | magnitude(e2)) - kTextureWeightBits);
    const int64_t w1 = e1 >> shift, w2 = e2 >> shift;
    int64_t total = (e0 >> shift) + w1 + w2;
    int64_t nu = du1_ * w1 + du2_ * w2, nv = dv1_ * w1 + dv2_ * w2;
    if (total < 0) total = -total, nu = -nu, nv = -nv;  // (-n) / (-W): the same quotient
    if (total == 0) {
      uv[0] = int32_t(u0_);
      uv[1] = int32_t(v0_);
      return false;
    }
    return clamped_coordinates(u0_ + texture_floor_quotient(nu, total), v0_ + texture_floor_quotient(nv, total), uv);
  }

  int64_t u0_, v0_, du1_, du2_, dv1_, dv2_;
  int64_t a0_, a1_, a2_;
  int64_t e0_ = 0, e1_ = 0, e2_ = 0;
};

// ExactSteps' interface for a boxed small triangle: its sums stepped along the row, each sample's
// coordinates their two quotients. The loops over a small triangle's samples take either; this one
// for samples of the sums' box only (the renderers' samples of the triangle, box_uv below).
// Plain: the sums are BoxSums::plain (64-bit hosts), each quotient the truncated one as it is.
template <bool Plain = false>
class BoxSteps {
 public:
  __attribute__((always_inline)) explicit BoxSteps(const TexturePlanes& p) : s_(p.sums) {}
  __attribute__((always_inline)) void start(const TexturePlanes&, int32_t x, int32_t y) {
    const int64_t dx = x - s_.x, dy = y - s_.y;
    ML_HOST_UNROLL for (int k = 0; k < 3; ++k) n_[k] = s_.at[k] + s_.dx[k] * dx + s_.dy[k] * dy;
  }
  __attribute__((always_inline)) void next(int32_t uv[2]) {
    if (Plain) {
      uv[0] = int32_t(n_[0] / n_[2]);
      uv[1] = int32_t(n_[1] / n_[2]);
    } else {
      // (Clamped only outside the triangle: inside, the coordinates are means of its vertices'.)
      clamped_coordinates(texture_floor_quotient(n_[0], n_[2]), texture_floor_quotient(n_[1], n_[2]), uv);
    }
    ML_HOST_UNROLL for (int k = 0; k < 3; ++k) n_[k] += s_.dx[k];
  }

 private:
  const BoxSums& s_;
  int64_t n_[3] = {0, 0, 1};  // the sums at the current sample
};

// The coordinates of lattice sample (x, y) of a boxed small triangle, BoxSteps' one sample: a sample
// outside the sums' box takes those of the nearest sample in it. (The renderers' samples of the
// triangle lie in the triangle's box; the sums' box has a sample more each side for an oversampled
// tiler's pixel centres, whose pixels the triangle covers in part.)
inline void box_uv(const TexturePlanes& p, int32_t x, int32_t y, int32_t uv[2]) {
  BoxSteps<> steps(p);
  const BoxSums& s = p.sums;
  steps.start(p, clamp_to(x, s.x, s.x + s.w), clamp_to(y, s.y, s.y + s.h));
  steps.next(uv);
}

// The length bits of the affine pieces of the segment between exact ends s and e, kTextureSegmentBits
// down to 0: the error bound above, in 16-bit mantissas.
int texture_segment_bits(const TexturePlanes& p, const ExactUv& s, const ExactUv& e);

// A cheap test that the segment between exact ends s and e (kTextureSegment samples apart along a
// row) is one affine piece, so that the bound need not be evaluated: when it holds,
// texture_segment_bits gives kTextureSegmentBits. Along a row D = sum e_i changes by the same dd over
// every segment (kTextureSegment times the sum of the planes' X coefficients), and the bound's
// second test (1/8 of the mean step) holds at full length, whatever du, when both ends' |D| are at
// least 65 dd: then dd max|D| <= min|D|^2 66 / 65^2 = min|D|^2 / 64.015, within the test's 1/64 with
// room for its mantissas' rounding (relative 2^-15 each, (1 + 2^-15)^2 / (1 - 2^-15)^2 < 64.015 / 64).
// Mild perspective passes it everywhere: the banded scene's segments all do.
inline bool texture_segment_whole(const TexturePlanes& p, const ExactUv& s, const ExactUv& e) {
  return s.clean && e.clean && (s.denom < 0) == (e.denom < 0) &&
         min_of(magnitude(s.denom), magnitude(e.denom)) >= p.whole_denom;
}

// The affine piece holding lattice sample (x, y) >= 0 (the segment rules above; for a small
// triangle the sample alone, exact).
const TexturePiece& texture_piece(TexturePlanes& p, int32_t x, int32_t y);

// Texture coordinates (Q16.16) at lattice sample (X, Y) >= 0: exact at piece ends, affine between.
inline void texture_uv(TexturePlanes& p, int32_t x, int32_t y, int32_t uv[2]) {
  const TexturePiece& piece = texture_piece(p, x, y);
  const int64_t j = x - piece.x;
  uv[0] = int32_t(piece.uv[0] + ((piece.step[0] * j) >> piece.bits));
  uv[1] = int32_t(piece.uv[1] + ((piece.step[1] * j) >> piece.bits));
}

// The texture (index into the scene's textures) triangle `id` is drawn with, or kNone when its
// material has no texels. Only valid on a Scene from read_scene.
uint32_t triangle_texture(const Scene& scene, uint32_t id);

// triangle_texture for the renderers' loops. On 64-bit hosts by a triangle's batch, the last batch's
// answer kept: a mesh's triangles (and BSP pieces) come batch after batch. The boards look each
// triangle's up and keep nothing (flash, stack).
class BatchTextures {
 public:
#if UINTPTR_MAX > 0xFFFFFFFFu
  // (One scene's: the answer kept is for the scene last asked about.)
  uint32_t of(const Scene& scene, uint32_t batch) {
    if (batch != batch_) {
      batch_ = batch;
      const Material& m = batch_material(scene, batch);
      texture_ = material_texels(scene, m) ? m.texture : kNone;
    }
    return texture_;
  }
  uint32_t of_triangle(const Scene& scene, uint32_t id) { return of(scene, triangle_at(scene, id).batch); }

 private:
  uint32_t batch_ = kNone, texture_ = kNone;
#else
  uint32_t of_triangle(const Scene& scene, uint32_t id) { return triangle_texture(scene, id); }
#endif
};

// A texture's mip level as both renderers sample it: its texels (texture_level_texels; level 0: the
// scene's own) and its bytes within the texture's, the last (texture, level > 0) asked for kept: a
// frame's runs and blocks ask for a few, again and again. One scene's (the first asked about).
class TextureLevels {
 public:
  // Valid until another texture's or level's are asked for.
  const TextureTexels& texels(const Scene& scene, uint32_t texture, uint32_t level) {
    if (level == 0) return scene.texture_texels[texture];
    look_up(scene, texture, level);
    return texels_;
  }
  // The level's bytes, given the texture's (TexturePager::get's; null stays null).
  const uint8_t* bytes(const Scene& scene, uint32_t texture, uint32_t level, const uint8_t* texture_bytes) {
    if (level == 0 || !texture_bytes) return texture_bytes;
    look_up(scene, texture, level);
    return texture_bytes + offset_;
  }

 private:
  void look_up(const Scene& scene, uint32_t texture, uint32_t level);  // out of line: rare, and flash
  TextureTexels texels_{};
  uint32_t offset_ = 0, texture_ = kNone, level_ = 0;
};

// The mip level a triangle samples of texture t (0 when t has none, or when the view clips the
// triangle): the level whose texels come nearest one a sample, from the triangle's area in texels
// over its area in samples (ratio r): the greatest L <= t.levels with 4^L <= 2 r, that is L =
// floor(log2(r) / 2 + 1/2), in integers (docs/textures.md). Both renderers choose it from the same
// projected vertices, so they sample the same level.
uint32_t texture_level(const TextureTexels& t, const ViewTriangle& viewed, const int32_t uv[3][2], int32_t den);

// make_texture_planes for triangle `id` of the scene (its world positions and TEXCOORD_0), drawn with
// texture `texture` at its texture_level (TexturePlanes::level: the planes are for that level's
// texels, texture_level_texels), and whether it is small (exact: its sample box from its projected
// vertices, so that both renderers decide alike).
// viewed: the whole triangle's view_triangle when the caller has it (else it is made here).
void triangle_texture_planes(const Scene& scene, const View& view, uint32_t id, uint32_t texture, int32_t den,
                             int32_t ox, int32_t oy, TexturePlanes* out, const ViewTriangle* viewed = nullptr);
#if UINTPTR_MAX > 0xFFFFFFFFu && !defined(ML_TEXTURE_RUNS_GENERAL_ONLY)
// triangle_texture_planes from the triangle's view (view_triangle) and TEXCOORD_0, drawn with texture t.
// On 64-bit hosts a small triangle's planes and box sums are made in one (the same values as
// make_texture_planes and make_box_sums: tests/texture/mapping_test.cpp).
void view_texture_planes(const View& view, const ViewTriangle& viewed, const int32_t uv[3][2], const TextureTexels& t,
                         int32_t den, int32_t ox, int32_t oy, TexturePlanes* out);
#endif

}  // namespace ml

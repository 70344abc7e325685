#include "texture/mapping.h"

namespace ml {
namespace {

constexpr int kCrossBits = 28;   // the P_j x P_k keep this many bits (a common scale)
constexpr int kMantissaBits = 16;  // the error bound compares products of 16-bit mantissas

int log2_of(uint32_t v) { return bit_length(v) - 1; }

// v as m 2^e with m < 2^16 + 1 (e added to *e): m rounded up (an upper bound of v) or down.
uint64_t mantissa(uint64_t v, int* e, bool up) {
  const int s = max_of(0, bit_length(v) - kMantissaBits);
  *e += s;
  const uint64_t m = v >> s;
  return up && (m << s) != v ? m + 1 : m;
}

// l 2^el <= r 2^er, for l, r < 2^62.
bool scaled_le(uint64_t l, int el, uint64_t r, int er) {
  if (el >= er) {
    const int d = el - er;
    return d < 62 ? l <= (r >> d) : l == 0;
  }
  const int d = er - el;
  if (d >= 62) return l == 0 || r != 0;
  return ((l + ((uint64_t(1) << d) - 1)) >> d) <= r;  // ceil(l / 2^d) <= r
}

// texture_segment_bits: the longest part whose affine error bound (mapping.h) stays within
// 2^-error_bits texel on both axes, or within 2^-kTextureAffineShiftBits of the mean step.
__attribute__((always_inline)) inline int segment_bits(const TexturePlanes& p, const ExactUv& s, const ExactUv& e) {
  if (!s.clean || !e.clean || (s.denom < 0) != (e.denom < 0)) return 0;
  uint64_t du = 0;  // the larger change, in Q16 texels (< 2^42)
  for (int k = 0; k < 2; ++k)
    du = max_of(du, magnitude(int64_t(e.uv[k]) - s.uv[k]) << p.size_bits[k]);
  const uint64_t d0 = magnitude(s.denom), d1 = magnitude(e.denom);
  const uint64_t dd = d0 > d1 ? d0 - d1 : d1 - d0;
  // Within 2^-error_bits texel: du dd max(D) (len / L)^2 <= 4 min(D)^2 2^(16 - error_bits); or within
  // 2^-kTextureAffineShiftBits of the mean step du / L: dd max(D) (len / L)^2 <= min(D)^2 2^(2 - E - S),
  // in mantissas and exponents (L = 2^S samples in a segment).
  int ed = 0, em = 0;
  const uint64_t dm = mantissa(dd, &ed, true) * mantissa(max_of(d0, d1), &ed, true);
  int el = ed;
  const uint64_t l = mantissa(du, &el, true) * dm;
  const uint64_t m = mantissa(min_of(d0, d1), &em, false);
  const int er = 2 * em + 2 + 16 - p.error_bits;
  const int es = 2 * em + 2 - kTextureAffineShiftBits - kTextureSegmentBits;
  for (int bits = kTextureSegmentBits; bits > 0; --bits) {
    const int scale = 2 * (bits - kTextureSegmentBits);
    if (scaled_le(l, el + scale, m * m, er) || scaled_le(dm, ed + scale, m * m, es)) return bits;
  }
  return 0;
}

// The segment of row y starting at sample x, from the cache or decided now.
TextureSegment& segment_at(TexturePlanes& p, int32_t x, int32_t y) {
  TextureSegment& sg = p.rows ? p.rows[uint32_t(y) & p.row_mask] : p.one;
  if (sg.y == y && sg.x == x) return sg;
  // Stepping right along a row, the previous segment's end is this one's start.
  if (sg.y == y && sg.x + kTextureSegment == x) sg.ends[0] = sg.ends[1];
  else exact_texture_uv(p, x, y, &sg.ends[0]);
  exact_texture_uv(p, x + kTextureSegment, y, &sg.ends[1]);
  sg.x = x;
  sg.y = y;
  sg.last_x = -1;
  sg.bits = texture_segment_whole(p, sg.ends[0], sg.ends[1]) ? kTextureSegmentBits
                                                              : segment_bits(p, sg.ends[0], sg.ends[1]);
  return sg;
}

// The exact coordinates at sample x inside segment sg (of its row): its ends, the last one evaluated
// in it, or now.
ExactUv exact_in(const TexturePlanes& p, TextureSegment& sg, int32_t x) {
  if (x == sg.x) return sg.ends[0];
  if (x == sg.x + kTextureSegment) return sg.ends[1];
  if (x != sg.last_x) {
    exact_texture_uv(p, x, sg.y, &sg.last);
    sg.last_x = x;
  }
  return sg.last;
}

}  // namespace

int texture_segment_bits(const TexturePlanes& p, const ExactUv& s, const ExactUv& e) { return segment_bits(p, s, e); }

namespace {

// make_texture_planes from the triangle's view-space vertices (view_coordinate on right, down and
// forward of its world vertices).
void planes_from_view(const View& view, const Vec3i viewed[3], const int32_t uv[3][2], int32_t den, int32_t ox,
                      int32_t oy, uint32_t width, uint32_t height, int error_bits, TexturePlanes* out) {
  for (int i = 0; i < 3; ++i) {
    out->uv[i][0] = uv[i][0];
    out->uv[i][1] = uv[i][1];
  }
  // c_i = P_j x P_k (i, j, k cyclic), written out: |world - eye| < 2^25, so view coordinates stay
  // below 2^29 and each cross term below 2^58.
  const Vec3i &p0 = viewed[0], &p1 = viewed[1], &p2 = viewed[2];
  const auto cross = [](const Vec3i& q, const Vec3i& r, int64_t* c) {
    c[0] = int64_t(q.y) * r.z - int64_t(q.z) * r.y;
    c[1] = int64_t(q.z) * r.x - int64_t(q.x) * r.z;
    c[2] = int64_t(q.x) * r.y - int64_t(q.y) * r.x;
    return magnitude(c[0]) | magnitude(c[1]) | magnitude(c[2]);
  };
  int64_t c[3][3];
  const uint64_t largest = cross(p1, p2, c[0]) | cross(p2, p0, c[1]) | cross(p0, p1, c[2]);
  // One shift for all three keeps their ratios; below 2^28 the planes below cannot overflow.
  const int shift = max_of(0, bit_length(largest) - kCrossBits);
  // d = (256 X + ox - cx, 256 Y + oy - cy, focal), all scaled by den.
  const int64_t dx = ox - int64_t(view.center_x) * den, dy = oy - int64_t(view.center_y) * den;
  const int64_t fz = view.focal_q8 * den;  // < 2^30
  for (int i = 0; i < 3; ++i) {
    const int64_t x = c[i][0] >> shift, y = c[i][1] >> shift, z = c[i][2] >> shift;
    out->a[i] = x * kSubpixelOne;
    out->b[i] = y * kSubpixelOne;
    out->k[i] = x * dx + y * dy + z * fz;
  }
  out->size_bits[0] = log2_of(max_of(width, 1u));
  out->size_bits[1] = log2_of(max_of(height, 1u));
  out->error_bits = error_bits;
  // texture_segment_whole: dd = L |a_0 + a_1 + a_2| (|a_i| < 2^36: below 2^51 with the factor).
  static_assert(kTextureAffineShiftBits + kTextureSegmentBits == 8, "65 dd is for the test's 1/64 (mapping.h)");
  out->whole_denom = 65 * (magnitude(out->a[0] + out->a[1] + out->a[2]) << kTextureSegmentBits);
  out->exact = out->boxed = false;
  out->level = 0;
  clear_texture_caches(out);
}

}  // namespace

#if UINTPTR_MAX > 0xFFFFFFFFu && !defined(ML_TEXTURE_RUNS_GENERAL_ONLY)
namespace {
// BoxSums::plain for sums whose least n_2 over the box is least_w (> 0): each n_k is least and
// greatest at corners of the box (a plane), whose values are those of samples of the box (|n_k| <
// 2^61: no overflow).
ML_HOST_INLINE inline bool plain_quotients(const BoxSums& s, int64_t least_w) {
  const int64_t limit = least_w * (int64_t(1) << 31);  // < 2^62
  bool plain = true;
  ML_HOST_UNROLL for (int k = 0; k < 2; ++k) {
    const int64_t across = s.dx[k] * s.w, down = s.dy[k] * s.h;
    const int64_t least = s.at[k] + min_of(int64_t(0), across) + min_of(int64_t(0), down);
    const int64_t most = s.at[k] + max_of(int64_t(0), across) + max_of(int64_t(0), down);
    plain = plain && least >= 0 && most < limit;
  }
  return plain;
}
}  // namespace
#endif

// The e_i over the box, scaled once (mapping.h): |e_i| is at most its value at (x0, y0) plus the
// steps to the far corner; the scale keeps that below 2^kTextureWeightBits, and the coefficients,
// rounded, add at most (1 + 33 + 33) / 2 units (boxes of at most 33 samples a side, with the one
// more each side), so |w_i| < 2^28 + 34 (ExactSteps' sums: below 2^28) and |sum uv_i w_i| < 2^61.
void make_box_sums(TexturePlanes* p, int32_t x0, int32_t y0, int32_t x1, int32_t y1) {
  --x0, --y0;  // a sample more each side
  const int64_t w = int64_t(x1) + 1 - x0, h = int64_t(y1) + 1 - y0;
  int64_t e[3];
  uint64_t largest = 0;
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    e[i] = p->a[i] * x0 + p->b[i] * y0 + p->k[i];
    largest |= magnitude(e[i]) + magnitude(p->a[i]) * uint64_t(w) + magnitude(p->b[i]) * uint64_t(h);
  }
  const int s = max_of(0, bit_length(largest) - kTextureWeightBits);
  const int64_t half = s > 0 ? int64_t(1) << (s - 1) : 0;
  const int64_t* const from[3] = {e, p->a, p->b};  // the e_i at (x0, y0), their steps along X and Y
  int64_t scaled[3][3];
  ML_HOST_UNROLL for (int j = 0; j < 3; ++j)
    ML_HOST_UNROLL for (int i = 0; i < 3; ++i) scaled[j][i] = (from[j][i] + half) >> s;
  const int64_t sign = scaled[0][0] + scaled[0][1] + scaled[0][2] < 0 ? -1 : 1;  // the sum made positive
  // The sums (u, v, W) at (x0, y0) and their steps, written before the test below: a small triangle
  // left divided uses neither them nor the segment cache they share the union with. Each scaled
  // value is at most 2^kTextureWeightBits in magnitude: 32-bit targets take the products as 32 x 32
  // bits (one multiply-accumulate on a Cortex-M3, where 64 x 64 bits take three and a carry).
#if UINTPTR_MAX > 0xFFFFFFFFu
  using Weight = int64_t;
#else
  using Weight = int32_t;
  static_assert(kTextureWeightBits < 31, "scaled values in 32 bits");
#endif
  BoxSums& sums = p->sums;
  int64_t* const to[3] = {sums.at, sums.dx, sums.dy};
  const int32_t(*uv)[2] = p->uv;
  ML_HOST_UNROLL for (int j = 0; j < 3; ++j) {
    const Weight w0 = Weight(sign * scaled[j][0]), w1 = Weight(sign * scaled[j][1]), w2 = Weight(sign * scaled[j][2]);
    to[j][0] = int64_t(uv[0][0]) * w0 + int64_t(uv[1][0]) * w1 + int64_t(uv[2][0]) * w2;
    to[j][1] = int64_t(uv[0][1]) * w0 + int64_t(uv[1][1]) * w1 + int64_t(uv[2][1]) * w2;
    to[j][2] = int64_t(w0) + w1 + w2;
  }
  // The sum of e_i stays above 0 over the box: a plane, least at a corner.
  const int64_t least_w = sums.at[2] + min_of(int64_t(0), sums.dx[2] * w) + min_of(int64_t(0), sums.dy[2] * h);
  if (least_w <= 0) return;
  sums.x = x0, sums.y = y0, sums.w = int32_t(w), sums.h = int32_t(h);
#if UINTPTR_MAX > 0xFFFFFFFFu && !defined(ML_TEXTURE_RUNS_GENERAL_ONLY)
  sums.plain = plain_quotients(sums, least_w);
#endif
  p->boxed = true;
}

void make_texture_planes(const View& view, const Vec3i world[3], const int32_t uv[3][2], int32_t den,
                         int32_t ox, int32_t oy, uint32_t width, uint32_t height, int error_bits,
                         TexturePlanes* out) {
  Vec3i p[3];
  for (int i = 0; i < 3; ++i)
    p[i] = Vec3i{view_coordinate(view, view.right, world[i]), view_coordinate(view, view.down, world[i]),
                 view_coordinate(view, view.forward, world[i])};
  planes_from_view(view, p, uv, den, ox, oy, width, height, error_bits, out);
}

void use_segment_rows(TexturePlanes* p, TextureSegment* rows, int count_bits) {
  p->rows = rows;
  p->row_mask = (uint32_t(1) << count_bits) - 1;
  for (uint32_t i = 0; i <= p->row_mask; ++i) rows[i].y = -1;
}

void exact_texture_uv(const TexturePlanes& p, int32_t x, int32_t y, ExactUv* out) {
#if UINTPTR_MAX == 0xFFFFFFFFu
  exact_texture_uv_looped(p, x, y, out);  // the boards' flash
#else
  ExactSteps steps(p);
  steps.start(p, x, y);
  out->denom = steps.denom();
  out->clean = steps.here(out->uv) && out->denom != 0;
#endif
}

void exact_texture_uv_looped(const TexturePlanes& p, int32_t x, int32_t y, ExactUv* out) {
  int64_t e[3];
  uint64_t largest = 0;
  out->denom = 0;
  for (int i = 0; i < 3; ++i) {
    e[i] = p.a[i] * x + p.b[i] * y + p.k[i];
    out->denom += e[i];  // |e_i| < 2^61: the sum fits
    largest |= magnitude(e[i]);
  }
  const int shift = max_of(0, bit_length(largest) - kTextureWeightBits);
  int64_t total = 0;
  for (int i = 0; i < 3; ++i) {
    e[i] >>= shift;
    total += e[i];
  }
  if (total < 0) {
    total = -total;
    for (int i = 0; i < 3; ++i) e[i] = -e[i];
  }
  if (total == 0) {  // the ray grazes the triangle's plane: any vertex will do
    out->uv[0] = p.uv[0][0];
    out->uv[1] = p.uv[0][1];
    out->clean = false;
    return;
  }
  out->clean = out->denom != 0;
  for (int k = 0; k < 2; ++k) {
    // |uv| < 2^31 and |e| < 2^28: the sum stays below 2^61; total < 2^30 divides in 32 bits.
    const int64_t sum = p.uv[0][k] * e[0] + p.uv[1][k] * e[1] + p.uv[2][k] * e[2];
    const int64_t q = div_floor(sum, total);
    if (q < INT32_MIN || q > INT32_MAX) out->clean = false;
    out->uv[k] = int32_t(clamp_to<int64_t>(q, INT32_MIN, INT32_MAX));
  }
}

void exact_texture_row(const TexturePlanes& p, int32_t x, int32_t y, int32_t n, int32_t (*uv)[2]) {
  ExactSteps steps(p);
  steps.start(p, x, y);
  for (int32_t j = 0; j < n; ++j) steps.next(uv[j]);
}

const TexturePiece& texture_piece(TexturePlanes& p, int32_t x, int32_t y) {
  TexturePiece& piece = p.piece;
  if (y == piece.y && x >= piece.x && x - piece.x < (int32_t(1) << piece.bits)) return piece;
  if (p.exact) {  // a small triangle: the sample alone
    if (p.boxed) {
      int32_t uv[2];
      box_uv(p, x, y, uv);
      piece = TexturePiece{x, y, 0, {uv[0], uv[1]}, {0, 0}};
      return piece;
    }
    ExactUv e;
    exact_texture_uv(p, x, y, &e);
    piece = TexturePiece{x, y, 0, {e.uv[0], e.uv[1]}, {0, 0}};
    return piece;
  }
  TextureSegment& sg = segment_at(p, x & ~(kTextureSegment - 1), y);
  const int32_t bits = sg.bits;
  piece.y = y;
  piece.bits = bits;
  if (bits == kTextureSegmentBits) {  // the common case: the whole segment is one piece
    piece.x = sg.x;
    for (int k = 0; k < 2; ++k) {
      piece.uv[k] = sg.ends[0].uv[k];
      piece.step[k] = int64_t(sg.ends[1].uv[k]) - sg.ends[0].uv[k];
    }
    return piece;
  }
  const int32_t start = x & ~((int32_t(1) << bits) - 1);
  const ExactUv s = exact_in(p, sg, start);
  piece.x = start;
  piece.uv[0] = s.uv[0];
  piece.uv[1] = s.uv[1];
  piece.step[0] = piece.step[1] = 0;
  if (bits > 0) {
    const ExactUv e = exact_in(p, sg, start + (int32_t(1) << bits));
    for (int k = 0; k < 2; ++k) piece.step[k] = int64_t(e.uv[k]) - s.uv[k];
  }
  return piece;
}

uint32_t triangle_texture(const Scene& scene, uint32_t id) {
  const Material& m = triangle_material(scene, id);
  return material_texels(scene, m) ? m.texture : kNone;
}

#if UINTPTR_MAX > 0xFFFFFFFFu && !defined(ML_TEXTURE_RUNS_GENERAL_ONLY)
namespace {

// planes_from_view and make_box_sums for a small triangle, written as one (64-bit hosts: the boards
// keep the two for their flash): the same sums, box, size and error bits, and caches cleared as
// planes_from_view leaves them. What a boxed triangle no longer reads is not written: its planes (a,
// b, k), coordinates (uv) and whole_denom (as the tiler's PlaneCache keeps it). False, with nothing
// written, when the sum of e_i changes sign or reaches 0 over the box (planes_from_view and
// make_box_sums then leave the triangle divided).
ML_HOST_INLINE inline bool boxed_planes(const View& view, const Vec3i viewed[3], const int32_t uv[3][2], int32_t den, int32_t ox,
                  int32_t oy, uint32_t width, uint32_t height, int error_bits, int32_t x0, int32_t y0, int32_t x1,
                  int32_t y1, TexturePlanes* out) {
  const Vec3i &p0 = viewed[0], &p1 = viewed[1], &p2 = viewed[2];
  int64_t c[3][3];  // c_i = P_j x P_k, as planes_from_view
  c[0][0] = int64_t(p1.y) * p2.z - int64_t(p1.z) * p2.y;
  c[0][1] = int64_t(p1.z) * p2.x - int64_t(p1.x) * p2.z;
  c[0][2] = int64_t(p1.x) * p2.y - int64_t(p1.y) * p2.x;
  c[1][0] = int64_t(p2.y) * p0.z - int64_t(p2.z) * p0.y;
  c[1][1] = int64_t(p2.z) * p0.x - int64_t(p2.x) * p0.z;
  c[1][2] = int64_t(p2.x) * p0.y - int64_t(p2.y) * p0.x;
  c[2][0] = int64_t(p0.y) * p1.z - int64_t(p0.z) * p1.y;
  c[2][1] = int64_t(p0.z) * p1.x - int64_t(p0.x) * p1.z;
  c[2][2] = int64_t(p0.x) * p1.y - int64_t(p0.y) * p1.x;
  uint64_t largest = 0;
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) largest |= magnitude(c[i][0]) | magnitude(c[i][1]) | magnitude(c[i][2]);
  const int shift = max_of(0, bit_length(largest) - kCrossBits);
  const int64_t dx = ox - int64_t(view.center_x) * den, dy = oy - int64_t(view.center_y) * den;
  const int64_t fz = view.focal_q8 * den;
  // make_box_sums: the box and a sample more each side; e_i at its first sample, a_i and b_i.
  const int64_t bx = int64_t(x0) - 1, by = int64_t(y0) - 1;
  const int64_t w = int64_t(x1) + 1 - bx, h = int64_t(y1) + 1 - by;
  // e_i = a_i X + b_i Y + k_i at (bx, by), with a_i = 256 x, b_i = 256 y, k_i = x dx + y dy + z fz: the
  // same value as x (256 bx + dx) + y (256 by + dy) + z fz (int64 arithmetic is exact modulo 2^64, and
  // |e_i| < 2^61).
  const int64_t ex = bx * kSubpixelOne + dx, ey = by * kSubpixelOne + dy;
  const uint64_t sw = uint64_t(w) * kSubpixelOne, sh = uint64_t(h) * kSubpixelOne;
  int64_t e[3], a[3], b[3];
  uint64_t reach = 0;
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    const int64_t x = c[i][0] >> shift, y = c[i][1] >> shift, z = c[i][2] >> shift;
    a[i] = x * kSubpixelOne;
    b[i] = y * kSubpixelOne;
    e[i] = int64_t(uint64_t(x) * uint64_t(ex) + uint64_t(y) * uint64_t(ey) + uint64_t(z) * uint64_t(fz));
    reach |= magnitude(e[i]) + magnitude(x) * sw + magnitude(y) * sh;
  }
  const int s = max_of(0, bit_length(reach) - kTextureWeightBits);
  const int64_t half = s > 0 ? int64_t(1) << (s - 1) : 0;
  int64_t se[3], sa[3], sb[3];
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    se[i] = (e[i] + half) >> s;
    sa[i] = (a[i] + half) >> s;
    sb[i] = (b[i] + half) >> s;
  }
  int64_t total = se[0] + se[1] + se[2];
  int64_t tx = sa[0] + sa[1] + sa[2], ty = sb[0] + sb[1] + sb[2];
  const bool negative = total < 0;  // the sum made positive
  if (negative) total = -total, tx = -tx, ty = -ty;
  const int64_t least_w = total + min_of(int64_t(0), tx * w) + min_of(int64_t(0), ty * h);
  if (least_w <= 0) return false;
  BoxSums& sums = out->sums;
  ML_HOST_UNROLL for (int q = 0; q < 2; ++q) {
    const int64_t u0 = uv[0][q], u1 = uv[1][q], u2 = uv[2][q];
    const int64_t at = u0 * se[0] + u1 * se[1] + u2 * se[2];
    const int64_t sx = u0 * sa[0] + u1 * sa[1] + u2 * sa[2];
    const int64_t sy = u0 * sb[0] + u1 * sb[1] + u2 * sb[2];
    sums.at[q] = negative ? -at : at;
    sums.dx[q] = negative ? -sx : sx;
    sums.dy[q] = negative ? -sy : sy;
  }
  sums.at[2] = total, sums.dx[2] = tx, sums.dy[2] = ty;
  sums.x = int32_t(bx), sums.y = int32_t(by), sums.w = int32_t(w), sums.h = int32_t(h);
  sums.plain = plain_quotients(sums, least_w);
  // As planes_from_view. (Two adjacent __builtin_ctz stores here were miscompiled by GCC 12 at -O2
  // with -mgeneral-regs-only: its SLP vectorizer took them as one 64-bit count, so size_bits[1] was 0
  // and nearest small triangles sampled the wrong texel rows; the Makefile also turns that pass off.)
  out->size_bits[0] = log2_of(max_of(width, 1u));
  out->size_bits[1] = log2_of(max_of(height, 1u));
  out->error_bits = error_bits;
  out->exact = out->boxed = true;
  out->level = 0;
  out->rows = nullptr;
  out->row_mask = 0;
  out->piece.y = -1;
  return true;
}

}  // namespace
#endif

namespace {

// Whether an unclipped triangle is small (its lattice box narrower and lower than kTextureExactSide
// samples), its box's first and last samples into box: the lattice rows and columns of samples within
// the projected vertices' box (the positions unclipped_positions gives; sample X lies at subpixel
// (256 X + ox) / den).
ML_HOST_INLINE inline bool small_box(const View& view, const ViewTriangle& viewed, int32_t den, int32_t ox, int32_t oy,
                                     intptr_t& bx0, intptr_t& by0, intptr_t& bx1, intptr_t& by1) {
  int32_t sx[3], sy[3];  // unclipped_positions' (its loop unrolled on 64-bit hosts)
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    sx[i] = int32_t(view.center_x + viewed.ox[i]);
    sy[i] = int32_t(view.center_y + viewed.oy[i]);
  }
  const int64_t lo_x = min_of(sx[0], min_of(sx[1], sx[2])), hi_x = max_of(sx[0], max_of(sx[1], sx[2]));
  const int64_t lo_y = min_of(sy[0], min_of(sy[1], sy[2])), hi_y = max_of(sy[0], max_of(sy[1], sy[2]));
  const int64_t x0 = floor_shift(lo_x * den - ox + kSubpixelOne - 1, kSubpixelBits);
  const int64_t x1 = floor_shift(hi_x * den - ox, kSubpixelBits);
  const int64_t y0 = floor_shift(lo_y * den - oy + kSubpixelOne - 1, kSubpixelBits);
  const int64_t y1 = floor_shift(hi_y * den - oy, kSubpixelBits);
  bx0 = intptr_t(x0), by0 = intptr_t(y0), bx1 = intptr_t(x1), by1 = intptr_t(y1);  // (within int32)
  return x1 - x0 < kTextureExactSide && y1 - y0 < kTextureExactSide;
}

// triangle_texture_planes once the triangle's view and coordinates are at hand, for texels of these
// sides (a texture's or one of its mip levels': the caller picks the level) and filter.
ML_HOST_INLINE inline void planes_of_view(const View& view, const ViewTriangle& viewed, const int32_t uv[3][2],
                                          uint32_t width, uint32_t height, uint8_t filter, int32_t den, int32_t ox,
                                          int32_t oy, TexturePlanes* out) {
  const int error_bits = filter == uint8_t(TextureFilter::Bilinear) ? kTextureAffineErrorBitsBilinear
                                                                    : kTextureAffineErrorBitsNearest;
  intptr_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
#if UINTPTR_MAX > 0xFFFFFFFFu && !defined(ML_TEXTURE_RUNS_GENERAL_ONLY)
  // The box first: a small triangle's planes and sums in one.
  const bool exact = viewed.unclipped && small_box(view, viewed, den, ox, oy, x0, y0, x1, y1);
  if (exact && boxed_planes(view, viewed.p, uv, den, ox, oy, width, height, error_bits, int32_t(x0), int32_t(y0),
                            int32_t(x1), int32_t(y1), out))
    return;
  planes_from_view(view, viewed.p, uv, den, ox, oy, width, height, error_bits, out);
  out->exact = exact;
#else
  planes_from_view(view, viewed.p, uv, den, ox, oy, width, height, error_bits, out);
  if (!viewed.unclipped) return;
  out->exact = small_box(view, viewed, den, ox, oy, x0, y0, x1, y1);
#endif
  if (out->exact) make_box_sums(out, int32_t(x0), int32_t(y0), int32_t(x1), int32_t(y1));
}

}  // namespace

#if UINTPTR_MAX > 0xFFFFFFFFu && !defined(ML_TEXTURE_RUNS_GENERAL_ONLY)
void view_texture_planes(const View& view, const ViewTriangle& viewed, const int32_t uv[3][2], const TextureTexels& t,
                         int32_t den, int32_t ox, int32_t oy, TexturePlanes* out) {
  planes_of_view(view, viewed, uv, t.width, t.height, t.filter, den, ox, oy, out);
}
#endif

namespace {
// Shifts the four differences right by the same s >= 0 until each is at most 2^13 in magnitude (the
// cross product of two such pairs then fits an int32) and returns s.
ML_HOST_INLINE inline int fit_14_bits(int32_t d[4]) {
  const auto size = [](int32_t v) { return v < 0 ? ~uint32_t(v) : uint32_t(v); };  // below 2^b when |v| < 2^b
  const uint32_t bits = size(d[0]) | size(d[1]) | size(d[2]) | size(d[3]);
  const int s = max_of(0, bits ? 32 - __builtin_clz(bits) - 13 : 0);
  d[0] >>= s, d[1] >>= s, d[2] >>= s, d[3] >>= s;
  return s;
}
}  // namespace

uint32_t texture_level(const TextureTexels& t, const ViewTriangle& viewed, const int32_t uv[3][2], int32_t den) {
  if (t.levels == 0 || !viewed.unclipped) return 0;
  // Twice the area in texture coordinates (Q15 squared: halved, the differences fit an int32) and in
  // samples (subpixels times den, squared), each from its differences scaled to 14 bits (by 2^su and
  // 2^ss). Screen offsets lie within the guard band (2^22 x den < 2^31).
  int32_t d[4] = {(uv[1][0] >> 1) - (uv[0][0] >> 1), (uv[1][1] >> 1) - (uv[0][1] >> 1),
                  (uv[2][0] >> 1) - (uv[0][0] >> 1), (uv[2][1] >> 1) - (uv[0][1] >> 1)};
  int32_t p[4] = {int32_t(viewed.ox[1] - viewed.ox[0]) * den, int32_t(viewed.oy[1] - viewed.oy[0]) * den,
                  int32_t(viewed.ox[2] - viewed.ox[0]) * den, int32_t(viewed.oy[2] - viewed.oy[0]) * den};
  const int su = fit_14_bits(d), ss = fit_14_bits(p);
  const int32_t texels_signed = d[0] * d[3] - d[2] * d[1], samples_signed = p[0] * p[3] - p[2] * p[1];
  const uint32_t texels = texels_signed < 0 ? uint32_t(-texels_signed) : uint32_t(texels_signed);
  const uint32_t samples = samples_signed < 0 ? uint32_t(-samples_signed) : uint32_t(samples_signed);
  if (texels == 0) return 0;
  if (samples == 0) return t.levels;
  // r = texels 4^su width height 2^-30 / (samples 4^ss 2^-16), and 4^L <= 2 r when 2 L <= f =
  // floor(log2(texels 2^e / samples)): the bit lengths' difference, less one when texels' leading bits
  // (both shifted to bit 31) are below samples'.
  const int tz = __builtin_clz(texels), sz = __builtin_clz(samples);
  const int e = 2 * (su - ss) + log2_of(t.width) + log2_of(t.height) - 14 + 1;
  const int f = e + sz - tz - ((texels << tz) < (samples << sz) ? 1 : 0);
  return f < 0 ? 0 : min_of(uint32_t(f) / 2, uint32_t(t.levels));
}

void triangle_texture_planes(const Scene& scene, const View& view, uint32_t id, uint32_t texture, int32_t den,
                             int32_t ox, int32_t oy, TexturePlanes* out, const ViewTriangle* viewed) {
  ViewTriangle own;
  if (!viewed) {
    Vec3i world[3];
    triangle_world(scene, id, world);
    view_triangle(view, world, &own);
    viewed = &own;
  }
  const Triangle tri = triangle_at(scene, id);
  int32_t uv[3][2] = {};  // a scene without coordinates: all 0, as vertex_uv gives
  if (scene.uvs) ML_HOST_UNROLL for (int i = 0; i < 3; ++i) vertex_uv(scene, tri.v[i], uv[i]);  // (one test of them)
  const TextureTexels& t = scene.texture_texels[texture];
  uint32_t level = 0, width = t.width, height = t.height;  // the sides of the level's texels: all the planes read
  if (t.levels) {
    level = texture_level(t, *viewed, uv, den);
    width = level_side(width, level), height = level_side(height, level);
  }
  planes_of_view(view, *viewed, uv, width, height, t.filter, den, ox, oy, out);
  out->level = uint8_t(level);
}

void TextureLevels::look_up(const Scene& scene, uint32_t texture, uint32_t level) {
  if (texture == texture_ && level == level_) return;
  texels_ = texture_level_texels(scene.texture_texels[texture], level, &offset_);
  texture_ = texture, level_ = level;
}

}  // namespace ml

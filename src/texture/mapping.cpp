#include "texture/mapping.h"

namespace ml {
namespace {

constexpr int kCrossBits = 28;   // the P_j x P_k keep this many bits (a common scale)
constexpr int kWeightKeep = 28;  // e_i keep this many bits per sample before the division
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

void make_texture_planes(const View& view, const Vec3i world[3], const int32_t uv[3][2], int32_t den,
                         int32_t ox, int32_t oy, uint32_t width, uint32_t height, int error_bits,
                         TexturePlanes* out) {
  int64_t p[3][3];
  for (int i = 0; i < 3; ++i) {
    // |world - eye| < 2^25, so view coordinates stay below 2^29 and each cross term below 2^58.
    p[i][0] = view_coordinate(view, view.right, world[i]);
    p[i][1] = view_coordinate(view, view.down, world[i]);
    p[i][2] = view_coordinate(view, view.forward, world[i]);
    out->uv[i][0] = uv[i][0];
    out->uv[i][1] = uv[i][1];
  }
  int64_t c[3][3];
  uint64_t largest = 0;
  for (int i = 0; i < 3; ++i) {
    const int64_t* q = p[i == 2 ? 0 : i + 1];
    const int64_t* r = p[i == 0 ? 2 : i - 1];
    c[i][0] = q[1] * r[2] - q[2] * r[1];
    c[i][1] = q[2] * r[0] - q[0] * r[2];
    c[i][2] = q[0] * r[1] - q[1] * r[0];
    for (int a = 0; a < 3; ++a) largest |= magnitude(c[i][a]);
  }
  // One shift for all three keeps their ratios; below 2^28 the planes below cannot overflow.
  const int shift = max_of(0, bit_length(largest) - kCrossBits);
  const int64_t cx = int64_t(view.center_x) * den, cy = int64_t(view.center_y) * den;
  const int64_t fz = view.focal_q8 * den;  // < 2^30
  for (int i = 0; i < 3; ++i) {
    const int64_t x = c[i][0] >> shift, y = c[i][1] >> shift, z = c[i][2] >> shift;
    // d = (256 X + ox - cx, 256 Y + oy - cy, focal), all scaled by den.
    out->a[i] = x * kSubpixelOne;
    out->b[i] = y * kSubpixelOne;
    out->k[i] = x * (ox - cx) + y * (oy - cy) + z * fz;
  }
  out->size_bits[0] = log2_of(max_of(width, 1u));
  out->size_bits[1] = log2_of(max_of(height, 1u));
  out->error_bits = error_bits;
  // texture_segment_whole: dd = L |a_0 + a_1 + a_2| (|a_i| < 2^36: below 2^51 with the factor).
  static_assert(kTextureAffineShiftBits + kTextureSegmentBits == 8, "65 dd is for the test's 1/64 (mapping.h)");
  out->whole_denom = 65 * (magnitude(out->a[0] + out->a[1] + out->a[2]) << kTextureSegmentBits);
  // Nothing cached yet (samples have y >= 0).
  out->rows = nullptr;
  out->row_mask = 0;
  out->one.y = -1;
  out->piece.y = -1;
  out->exact = false;
}

void use_segment_rows(TexturePlanes* p, TextureSegment* rows, int count_bits) {
  p->rows = rows;
  p->row_mask = (uint32_t(1) << count_bits) - 1;
  for (uint32_t i = 0; i <= p->row_mask; ++i) rows[i].y = -1;
}

void exact_texture_uv(const TexturePlanes& p, int32_t x, int32_t y, ExactUv* out) {
  int64_t e[3];
  uint64_t largest = 0;
  out->denom = 0;
  for (int i = 0; i < 3; ++i) {
    e[i] = p.a[i] * x + p.b[i] * y + p.k[i];
    out->denom += e[i];  // |e_i| < 2^61: the sum fits
    largest |= magnitude(e[i]);
  }
  const int shift = max_of(0, bit_length(largest) - kWeightKeep);
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
  // exact_texture_uv's steps, the planes stepped along the row in locals (no denominator or flags kept).
  int64_t e0 = p.a[0] * x + p.b[0] * y + p.k[0], e1 = p.a[1] * x + p.b[1] * y + p.k[1];
  int64_t e2 = p.a[2] * x + p.b[2] * y + p.k[2];
  const int64_t a0 = p.a[0], a1 = p.a[1], a2 = p.a[2];
  const int64_t u0 = p.uv[0][0], u1 = p.uv[1][0], u2 = p.uv[2][0];
  const int64_t v0 = p.uv[0][1], v1 = p.uv[1][1], v2 = p.uv[2][1];
  for (int32_t j = 0; j < n; ++j, e0 += a0, e1 += a1, e2 += a2) {
    const int shift = max_of(0, bit_length(magnitude(e0) | magnitude(e1) | magnitude(e2)) - kWeightKeep);
    int64_t w0 = e0 >> shift, w1 = e1 >> shift, w2 = e2 >> shift;
    int64_t total = w0 + w1 + w2;
    if (total < 0) total = -total, w0 = -w0, w1 = -w1, w2 = -w2;
    if (total == 0) {
      uv[j][0] = p.uv[0][0];
      uv[j][1] = p.uv[0][1];
      continue;
    }
    uv[j][0] = int32_t(clamp_to<int64_t>(div_floor(u0 * w0 + u1 * w1 + u2 * w2, total), INT32_MIN, INT32_MAX));
    uv[j][1] = int32_t(clamp_to<int64_t>(div_floor(v0 * w0 + v1 * w1 + v2 * w2, total), INT32_MIN, INT32_MAX));
  }
}

const TexturePiece& texture_piece(TexturePlanes& p, int32_t x, int32_t y) {
  TexturePiece& piece = p.piece;
  if (y == piece.y && x >= piece.x && x - piece.x < (int32_t(1) << piece.bits)) return piece;
  if (p.exact) {  // a small triangle: the sample alone
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
  const Material& m = scene.materials[scene.batches[triangle_at(scene, id).batch].material];
  return material_texels(scene, m) ? m.texture : kNone;
}

void triangle_texture_planes(const Scene& scene, const View& view, uint32_t id, uint32_t texture, int32_t den,
                             int32_t ox, int32_t oy, TexturePlanes* out) {
  Vec3i world[3];
  triangle_world(scene, id, world);
  const Triangle tri = triangle_at(scene, id);
  int32_t uv[3][2];
  for (int i = 0; i < 3; ++i) vertex_uv(scene, tri.v[i], uv[i]);
  const TextureTexels& t = scene.texture_texels[texture];
  const int error_bits = t.filter == uint8_t(TextureFilter::Bilinear) ? kTextureAffineErrorBitsBilinear
                                                                      : kTextureAffineErrorBitsNearest;
  make_texture_planes(view, world, uv, den, ox, oy, t.width, t.height, error_bits, out);
  int32_t sx[3], sy[3];
  if (!project_unclipped_positions(view, world, sx, sy)) return;
  // The lattice rows and columns of samples within the vertices' box: sample X lies at subpixel
  // (256 X + ox) / den.
  const int64_t lo_x = min_of(sx[0], min_of(sx[1], sx[2])), hi_x = max_of(sx[0], max_of(sx[1], sx[2]));
  const int64_t lo_y = min_of(sy[0], min_of(sy[1], sy[2])), hi_y = max_of(sy[0], max_of(sy[1], sy[2]));
  const int64_t x0 = floor_shift(lo_x * den - ox + kSubpixelOne - 1, kSubpixelBits);
  const int64_t x1 = floor_shift(hi_x * den - ox, kSubpixelBits);
  const int64_t y0 = floor_shift(lo_y * den - oy + kSubpixelOne - 1, kSubpixelBits);
  const int64_t y1 = floor_shift(hi_y * den - oy, kSubpixelBits);
  out->exact = x1 - x0 < kTextureExactSide && y1 - y0 < kTextureExactSide;
}

}  // namespace ml

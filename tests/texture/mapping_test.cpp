// The affine texture mapping (texture/mapping.h) against the exact division at every sample: random
// triangles seen from random angles, every sample of rows across the screen, in any order; and the
// row function both renderers draw with (texture/sampler.h texture_row) against the sample-by-sample
// colours, for every format, wrap mode, filter and texel table.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "texture/mapping.h"
#include "texture/sampler.h"
#include "view/view.h"

namespace {

struct Case {
  ml::View view;
  ml::Vec3i world[3];
  int32_t uv[3][2];
  uint32_t width, height;
  int error_bits;
};

Case random_case(std::mt19937& rng) {
  std::uniform_int_distribution<int> coord(-3000, 3000), far(-30000, -2000), uvd(-8 * 65536, 8 * 65536);
  Case c{};
  ml::Camera cam;
  cam.eye = ml::Vec3i{0, 0, 0};
  cam.target = ml::Vec3i{coord(rng) / 10, coord(rng) / 10, -1000};
  cam.width = 320;
  cam.height = 240;
  cam.near = 16;
  EXPECT_TRUE(ml::make_view(cam, &c.view).ok());
  for (int i = 0; i < 3; ++i) {
    // Some triangles nearly edge-on (strong perspective), some facing the eye.
    c.world[i] = ml::Vec3i{coord(rng) * 3, coord(rng) * 2, far(rng)};
    c.uv[i][0] = uvd(rng);
    c.uv[i][1] = uvd(rng);
  }
  c.width = 1u << std::uniform_int_distribution<int>(0, 10)(rng);
  c.height = 1u << std::uniform_int_distribution<int>(0, 10)(rng);
  c.error_bits = rng() % 2 ? ml::kTextureAffineErrorBitsNearest : ml::kTextureAffineErrorBitsBilinear;
  return c;
}

TEST(TextureMapping, AffinePiecesStayWithinTheStatedBound) {
  std::mt19937 rng(20261130);
  size_t samples = 0, affine = 0;
  for (int n = 0; n < 300; ++n) {
    const Case c = random_case(rng);
    ml::TexturePlanes p;
    ml::make_texture_planes(c.view, c.world, c.uv, 1, ml::kSubpixelHalf, ml::kSubpixelHalf, c.width, c.height,
                            c.error_bits, &p);
    for (int32_t y = 0; y < 240; y += 37) {
      // Left to right, then right to left: the result may not depend on the order.
      for (int pass = 0; pass < 2; ++pass)
        for (int32_t i = 0; i < 320; ++i) {
          const int32_t x = pass == 0 ? i : 319 - i;
          int32_t got[2];
          ml::texture_uv(p, x, y, got);
          ml::ExactUv exact, a, b;
          ml::exact_texture_uv(p, x, y, &exact);
          const int32_t x0 = x & ~(ml::kTextureSegment - 1);
          ml::exact_texture_uv(p, x0, y, &a);
          ml::exact_texture_uv(p, x0 + ml::kTextureSegment, y, &b);
          ++samples;
          if (got[0] != exact.uv[0] || got[1] != exact.uv[1]) ++affine;
          const double size[2] = {double(c.width), double(c.height)};
          double step = 0;
          for (int k = 0; k < 2; ++k)
            step = std::max(step, std::fabs(double(b.uv[k]) - a.uv[k]) * size[k] / 65536 / ml::kTextureSegment);
          const double bound = std::max(std::ldexp(1.0, -c.error_bits), std::ldexp(step, -ml::kTextureAffineShiftBits));
          for (int k = 0; k < 2; ++k) {
            // In texels; the floors of the ends and of the interpolation add at most 2 units of 2^-16.
            const double err = std::fabs(double(got[k]) - exact.uv[k]) * size[k] / 65536;
            ASSERT_LE(err, bound + 3 * size[k] / 65536)
                << "case " << n << " sample " << x << "," << y << " axis " << k << " step " << step;
          }
        }
    }
  }
  EXPECT_GT(affine, samples / 4);  // most samples are interpolated, not divided
}

// texture_segment_whole (the cheap test that a segment is one affine piece) against the bound it
// stands for: whenever it holds, texture_segment_bits gives a whole segment. Segments of random
// triangles along rows, and ends whose |D| lies just above and below the test's 65 dd (both signs,
// random triangles put the threshold at 37 to 48 bits, so that the bound's mantissas round).
TEST(TextureMapping, WholeSegmentTestImpliesTheBound) {
  std::mt19937 rng(20261201);
  int whole = 0, near_whole = 0, cut_near = 0;
  for (int n = 0; n < 300; ++n) {
    const Case c = random_case(rng);
    ml::TexturePlanes p;
    ml::make_texture_planes(c.view, c.world, c.uv, 1, ml::kSubpixelHalf, ml::kSubpixelHalf, c.width, c.height,
                            c.error_bits, &p);
    for (int32_t y = 0; y < 240; y += 23)
      for (int32_t x = 0; x < 320; x += ml::kTextureSegment) {
        ml::ExactUv s, e;
        ml::exact_texture_uv(p, x, y, &s);
        ml::exact_texture_uv(p, x + ml::kTextureSegment, y, &e);
        if (!ml::texture_segment_whole(p, s, e)) continue;
        ++whole;
        ASSERT_EQ(ml::texture_segment_bits(p, s, e), ml::kTextureSegmentBits) << "case " << n << " at " << x << "," << y;
      }
    // Ends with |D| around the threshold: D changes by dd = whole_denom / 65 from one to the other.
    const uint64_t dd = p.whole_denom / 65;
    if (dd == 0) continue;
    for (int k = 0; k < 200; ++k) {
      ml::ExactUv a{}, b{};
      a.clean = b.clean = true;
      for (int i = 0; i < 2; ++i) {
        a.uv[i] = int32_t(rng());
        b.uv[i] = int32_t(rng());
      }
      const uint64_t slack = dd < 4 ? 4 : dd / 4;
      const uint64_t m = p.whole_denom - slack + std::uniform_int_distribution<uint64_t>(0, 2 * slack)(rng);
      const int64_t sign = rng() % 2 ? 1 : -1;
      a.denom = sign * int64_t(m);
      b.denom = sign * int64_t(m + dd);
      if (rng() % 2) std::swap(a, b);
      const int bits = ml::texture_segment_bits(p, a, b);
      if (ml::texture_segment_whole(p, a, b)) {
        ++near_whole;
        ASSERT_EQ(bits, ml::kTextureSegmentBits) << "case " << n << " |D| " << m << " dd " << dd;
      } else if (bits < ml::kTextureSegmentBits) {
        ++cut_near;
      }
    }
  }
  EXPECT_GT(whole, 1000);
  EXPECT_GT(near_whole, 10000);
  EXPECT_GT(cut_near, 10000);  // just under the threshold the bound does cut segments: the test is tight
}

// exact_texture_uv's coordinates as mapping.h states them, written plainly: the e_i shifted by one
// common shift to kTextureWeightBits bits, sum uv_i e_i / sum e_i floored (div_floor, the divisor
// made positive), clamped to int32; vertex 0's coordinates when the shifted sum is 0. clean: as
// ExactUv's.
void reference_uv(const ml::TexturePlanes& p, int32_t x, int32_t y, int32_t out[2], bool* clean) {
  int64_t e[3], denom = 0;
  uint64_t largest = 0;
  for (int i = 0; i < 3; ++i) {
    e[i] = p.a[i] * x + p.b[i] * y + p.k[i];
    denom += e[i];
    largest |= ml::magnitude(e[i]);
  }
  const int shift = std::max(0, ml::bit_length(largest) - ml::kTextureWeightBits);
  int64_t total = 0;
  for (int64_t& w : e) total += (w >>= shift);
  if (total == 0) {
    out[0] = p.uv[0][0];
    out[1] = p.uv[0][1];
    *clean = false;
    return;
  }
  const int64_t sign = total < 0 ? -1 : 1;
  *clean = denom != 0;
  for (int k = 0; k < 2; ++k) {
    int64_t sum = 0;
    for (int i = 0; i < 3; ++i) sum += int64_t(p.uv[i][k]) * (sign * e[i]);
    const int64_t q = ml::div_floor(sum, sign * total);
    if (q < INT32_MIN || q > INT32_MAX) *clean = false;
    out[k] = int32_t(std::clamp<int64_t>(q, INT32_MIN, INT32_MAX));
  }
}

// The per-sample division (exact_texture_uv, the boards' exact_texture_uv_looped, and
// exact_texture_row stepping the planes) gives the floored quotient of both coordinates, over random
// planes of every magnitude up to the 2^61 the lattice allows and their edge cases: plane values at
// powers of two (the shift's steps), sums of either sign and zero, quotients past int32 (clamped),
// coordinates at int32's ends.
TEST(TextureMapping, ExactDivisionIsTheFlooredQuotient) {
  std::mt19937_64 rng(20261201);
  const auto any = [&](int bits) {  // uniform in (-2^bits, 2^bits)
    const int64_t m = int64_t(rng() >> (64 - bits - 1)) - (int64_t(1) << bits);
    return bits == 0 ? 0 : m;
  };
  const int32_t extremes[] = {INT32_MIN, INT32_MIN + 1, -1, 0, 1, INT32_MAX - 1, INT32_MAX};
  size_t samples = 0, clamped = 0, grazing = 0, negative = 0;
  for (int n = 0; n < 200000; ++n) {
    ml::TexturePlanes p{};
    const int kind = n % 4;
    for (int i = 0; i < 3; ++i) {
      if (kind == 0) {  // a power of two, or one below it, in k alone: every shift step
        const int64_t v = (int64_t(1) << (rng() % 60)) - int64_t(rng() % 2);
        p.a[i] = p.b[i] = 0;
        p.k[i] = rng() % 2 ? v : -v;
      } else {
        p.a[i] = any(int(rng() % 46));
        p.b[i] = any(int(rng() % 46));
        p.k[i] = any(int(rng() % 60));
      }
      for (int k = 0; k < 2; ++k)
        p.uv[i][k] = rng() % 4 == 0 ? extremes[rng() % 7] : int32_t(uint32_t(rng()) >> (rng() % 32));
    }
    if (kind == 3) p.k[2] = -(p.k[0] + p.k[1]) + any(int(rng() % 8));  // sums near zero: huge quotients
    if (kind == 2) {                                                     // in range of one another
      p.a[2] = -(p.a[0] + p.a[1]);
      p.b[2] = -(p.b[0] + p.b[1]);
    }
    const int32_t x = int32_t(rng() % 2048), y = int32_t(rng() % 2048), len = 1 + int32_t(rng() % 16);
    int32_t row[16][2];
    ml::exact_texture_row(p, x, y, len, row);
    for (int32_t j = 0; j < len; ++j) {
      int32_t want[2];
      bool clean;
      reference_uv(p, x + j, y, want, &clean);
      ml::ExactUv got, looped;
      ml::exact_texture_uv(p, x + j, y, &got);
      ml::exact_texture_uv_looped(p, x + j, y, &looped);
      ASSERT_EQ(got.uv[0], want[0]) << "case " << n << " sample " << j;
      ASSERT_EQ(got.uv[1], want[1]) << "case " << n << " sample " << j;
      ASSERT_EQ(got.clean, clean) << "case " << n << " sample " << j;
      ASSERT_EQ(looped.uv[0], want[0]) << "case " << n << " sample " << j;
      ASSERT_EQ(looped.uv[1], want[1]) << "case " << n << " sample " << j;
      ASSERT_EQ(looped.clean, clean) << "case " << n << " sample " << j;
      ASSERT_EQ(looped.denom, got.denom) << "case " << n << " sample " << j;
      ASSERT_EQ(row[j][0], want[0]) << "case " << n << " sample " << j;
      ASSERT_EQ(row[j][1], want[1]) << "case " << n << " sample " << j;
      const int64_t denom = p.a[0] * (x + j) + p.b[0] * y + p.k[0] + p.a[1] * (x + j) + p.b[1] * y + p.k[1] +
                            p.a[2] * (x + j) + p.b[2] * y + p.k[2];
      clamped += !clean && denom != 0;
      grazing += want[0] == p.uv[0][0] && want[1] == p.uv[0][1] && !clean;
      negative += denom < 0;
      ++samples;
    }
  }
  EXPECT_GT(samples, 1000000u);
  EXPECT_GT(clamped, 10000u);
  EXPECT_GT(grazing, 100u);
  EXPECT_GT(negative, samples / 4);
}

// Small triangles left divided (TexturePlanes::exact, not boxed) take the exact coordinates at every
// sample, and the row function steps the planes to the same values as dividing each sample on its own.
TEST(TextureMapping, SmallTrianglesAreExactAtEverySample) {
  std::mt19937 rng(20261201);
  size_t samples = 0;
  for (int n = 0; n < 200; ++n) {
    const Case c = random_case(rng);
    ml::TexturePlanes p;
    ml::make_texture_planes(c.view, c.world, c.uv, 1, ml::kSubpixelHalf, ml::kSubpixelHalf, c.width, c.height,
                            c.error_bits, &p);
    p.exact = true;
    for (int32_t y = 1; y < 240; y += 29) {
      const int32_t x = int32_t(rng() % 300), len = 1 + int32_t(rng() % 20);
      std::vector<int32_t> row(size_t(2 * len));
      ml::exact_texture_row(p, x, y, len, reinterpret_cast<int32_t(*)[2]>(row.data()));
      for (int32_t i = 0; i < len; ++i) {
        ml::ExactUv exact;
        ml::exact_texture_uv(p, x + i, y, &exact);
        int32_t got[2];
        ml::texture_uv(p, x + i, y, got);
        ASSERT_EQ(got[0], exact.uv[0]) << "case " << n << " sample " << x + i << "," << y;
        ASSERT_EQ(got[1], exact.uv[1]) << "case " << n << " sample " << x + i << "," << y;
        ASSERT_EQ(row[size_t(2 * i)], exact.uv[0]) << "case " << n << " sample " << x + i << "," << y;
        ASSERT_EQ(row[size_t(2 * i + 1)], exact.uv[1]) << "case " << n << " sample " << x + i << "," << y;
        ++samples;
      }
    }
  }
  EXPECT_GT(samples, 10000u);
}

// A small triangle of case c's view: its vertices pulled towards their centroid until it projects to
// a box of fewer than kTextureExactSide samples a side (false: it does not, or the view clips it),
// with coordinates spanning at most `span` (Q16.16) around a random base; *box: its lattice box at
// pixel centres, as triangle_texture_planes finds it.
bool shrink_to_small(Case* c, std::mt19937& rng, int32_t span, int32_t box[4]) {
  double centre[3] = {0, 0, 0};
  for (const ml::Vec3i& v : c->world) centre[0] += v.x / 3.0, centre[1] += v.y / 3.0, centre[2] += v.z / 3.0;
  const double f = std::uniform_real_distribution<double>(0.001, 0.03)(rng);
  for (ml::Vec3i& v : c->world)
    v = ml::Vec3i{int32_t(std::lround(centre[0] + (v.x - centre[0]) * f)),
                  int32_t(std::lround(centre[1] + (v.y - centre[1]) * f)),
                  int32_t(std::lround(centre[2] + (v.z - centre[2]) * f))};
  std::uniform_int_distribution<int32_t> base(-30000 * 65536, 30000 * 65536), near(-span, span);
  for (int k = 0; k < 2; ++k) {
    const int32_t b = base(rng);
    for (auto& uv : c->uv) uv[k] = b + near(rng);
  }
  ml::ViewTriangle t;
  ml::view_triangle(c->view, c->world, &t);
  if (!t.unclipped) return false;
  int32_t sx[3], sy[3];
  ml::unclipped_positions(c->view, t, sx, sy);
  box[0] = int32_t((int64_t(*std::min_element(sx, sx + 3)) - 128 + 255) >> 8);
  box[1] = int32_t((int64_t(*std::min_element(sy, sy + 3)) - 128 + 255) >> 8);
  box[2] = int32_t((int64_t(*std::max_element(sx, sx + 3)) - 128) >> 8);
  box[3] = int32_t((int64_t(*std::max_element(sy, sy + 3)) - 128) >> 8);
  return box[2] - box[0] < ml::kTextureExactSide && box[3] - box[1] < ml::kTextureExactSide && box[0] <= box[2] &&
         box[1] <= box[3];
}

// Small triangles' coordinates from their box's sums (make_box_sums, BoxSteps): within one unit of
// the exact division at every sample of the triangle (coordinates spanning up to two textures about
// any base), BoxSteps along each row the same as box_uv sample by sample, and the sum of e_i positive
// over the box and a sample beyond it (what make_box_sums promises).
TEST(TextureMapping, SmallTrianglesBoxSumsStayWithinAUnitOfTheExactDivision) {
  std::mt19937 rng(20261202);
  size_t samples = 0, boxed = 0, triangles = 0, off_by_one = 0;
  for (int n = 0; n < 12000; ++n) {
    Case c = random_case(rng);
    int32_t box[4];
    if (!shrink_to_small(&c, rng, 2 * 65536, box)) continue;
    ++triangles;
    ml::TexturePlanes p;
    ml::make_texture_planes(c.view, c.world, c.uv, 1, ml::kSubpixelHalf, ml::kSubpixelHalf, c.width, c.height,
                            c.error_bits, &p);
    p.exact = true;
    const ml::TexturePlanes divided = p;
    ml::make_box_sums(&p, box[0], box[1], box[2], box[3]);
    if (!p.boxed) continue;
    ++boxed;
    const ml::BoxSums& s = p.sums;
    for (int32_t y = box[1] - 1; y <= box[3] + 1; ++y) {
      ml::BoxSteps steps(p);
      steps.start(p, box[0] - 1, y);
      for (int32_t x = box[0] - 1; x <= box[2] + 1; ++x) {
        ASSERT_GT(s.at[2] + s.dx[2] * (x - s.x) + s.dy[2] * (y - s.y), 0) << "case " << n;
        int32_t stepped[2], one[2];
        steps.next(stepped);
        ml::box_uv(p, x, y, one);
        ASSERT_EQ(stepped[0], one[0]) << "case " << n << " sample " << x << "," << y;
        ASSERT_EQ(stepped[1], one[1]) << "case " << n << " sample " << x << "," << y;
        // Inside the triangle: every e_i of the sum's sign.
        int64_t e[3], d = 0;
        for (int i = 0; i < 3; ++i) d += e[i] = p.a[i] * x + p.b[i] * y + p.k[i];
        if (!((e[0] >= 0) == (d > 0) && (e[1] >= 0) == (d > 0) && (e[2] >= 0) == (d > 0))) continue;
        ml::ExactUv exact;
        ml::exact_texture_uv(divided, x, y, &exact);
        for (int k = 0; k < 2; ++k) {
          ASSERT_LE(std::abs(int64_t(one[k]) - exact.uv[k]), 1) << "case " << n << " sample " << x << "," << y;
          off_by_one += one[k] != exact.uv[k];
        }
        ++samples;
      }
    }
  }
  EXPECT_GT(triangles, 1000u);
  EXPECT_GT(boxed, triangles * 9 / 10);
  EXPECT_GT(samples, 20000u);
  EXPECT_LT(off_by_one, samples / 20);  // mostly the same floor as the exact division
}

// view_texture_planes (triangle_texture_planes) makes a small triangle's planes and box sums in one
// on 64-bit hosts: the same sums, box and fields a boxed triangle reads as make_texture_planes and
// make_box_sums give, and the same planes for the other triangles (larger, clipped, or left divided),
// on the renderers' lattices (pixel centres, and the supersampled scanline renderer's), for random
// small and larger triangles near and far from the eye.
#if UINTPTR_MAX > 0xFFFFFFFFu
TEST(TextureMapping, SmallTrianglesSetUpInOneGiveTheSumsOfThePlanes) {
  std::mt19937 rng(20261204);
  struct Lat {
    int32_t den, ox, oy;
  };
  const Lat lattices[] = {{1, ml::kSubpixelHalf, ml::kSubpixelHalf}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {7, 0, 0}};
  size_t boxed = 0, divided = 0, large = 0, plain = 0;
  for (int n = 0; n < 20000; ++n) {
    Case c = random_case(rng);
    // Coordinates of every magnitude the views take (|world - eye| < 2^25).
    const int scale = int(rng() % 10);
    for (ml::Vec3i& v : c.world) v = ml::Vec3i{v.x * (1 << scale), v.y * (1 << scale), v.z * (1 << scale)};
    int32_t box[4];
    if (n % 4 != 0) shrink_to_small(&c, rng, int32_t(1 + rng() % (4 * 65536)), box);
    const Lat& lat = lattices[n % 5];
    ml::TextureTexels t{};
    t.width = uint16_t(c.width);
    t.height = uint16_t(c.height);
    t.filter = uint8_t(c.error_bits == ml::kTextureAffineErrorBitsBilinear ? ml::TextureFilter::Bilinear
                                                                           : ml::TextureFilter::Nearest);
    ml::ViewTriangle viewed;
    ml::view_triangle(c.view, c.world, &viewed);
    ml::TexturePlanes got, want;
    ml::view_texture_planes(c.view, viewed, c.uv, t, lat.den, lat.ox, lat.oy, &got);
    ml::make_texture_planes(c.view, c.world, c.uv, lat.den, lat.ox, lat.oy, c.width, c.height, c.error_bits, &want);
    if (viewed.unclipped) {
      int32_t sx[3], sy[3];
      ml::unclipped_positions(c.view, viewed, sx, sy);
      const int64_t lo_x = *std::min_element(sx, sx + 3), hi_x = *std::max_element(sx, sx + 3);
      const int64_t lo_y = *std::min_element(sy, sy + 3), hi_y = *std::max_element(sy, sy + 3);
      const int64_t x0 = (lo_x * lat.den - lat.ox + 255) >> 8, x1 = (hi_x * lat.den - lat.ox) >> 8;
      const int64_t y0 = (lo_y * lat.den - lat.oy + 255) >> 8, y1 = (hi_y * lat.den - lat.oy) >> 8;
      want.exact = x1 - x0 < ml::kTextureExactSide && y1 - y0 < ml::kTextureExactSide;
      if (want.exact) ml::make_box_sums(&want, int32_t(x0), int32_t(y0), int32_t(x1), int32_t(y1));
    }
    ASSERT_EQ(got.exact, want.exact) << "case " << n;
    ASSERT_EQ(got.boxed, want.boxed) << "case " << n;
    ASSERT_EQ(got.size_bits[0], want.size_bits[0]) << "case " << n;
    ASSERT_EQ(got.size_bits[1], want.size_bits[1]) << "case " << n;
    ASSERT_EQ(got.error_bits, want.error_bits) << "case " << n;
    ASSERT_EQ(got.rows, nullptr) << "case " << n;
    ASSERT_EQ(got.row_mask, 0u) << "case " << n;
    ASSERT_EQ(got.piece.y, -1) << "case " << n;
    if (got.boxed) {
      ++boxed;
      const ml::BoxSums &g = got.sums, &w = want.sums;
      ASSERT_EQ(g.x, w.x) << "case " << n;
      ASSERT_EQ(g.y, w.y) << "case " << n;
      ASSERT_EQ(g.w, w.w) << "case " << n;
      ASSERT_EQ(g.h, w.h) << "case " << n;
      ASSERT_EQ(g.plain, w.plain) << "case " << n;
      plain += g.plain;
      for (int k = 0; k < 3; ++k) {
        ASSERT_EQ(g.at[k], w.at[k]) << "case " << n << " sum " << k;
        ASSERT_EQ(g.dx[k], w.dx[k]) << "case " << n << " sum " << k;
        ASSERT_EQ(g.dy[k], w.dy[k]) << "case " << n << " sum " << k;
      }
      continue;
    }
    (got.exact ? divided : large) += 1;
    ASSERT_EQ(got.whole_denom, want.whole_denom) << "case " << n;
    for (int i = 0; i < 3; ++i) {
      ASSERT_EQ(got.a[i], want.a[i]) << "case " << n;
      ASSERT_EQ(got.b[i], want.b[i]) << "case " << n;
      ASSERT_EQ(got.k[i], want.k[i]) << "case " << n;
      ASSERT_EQ(got.uv[i][0], want.uv[i][0]) << "case " << n;
      ASSERT_EQ(got.uv[i][1], want.uv[i][1]) << "case " << n;
    }
    if (!got.exact) {
      ASSERT_EQ(got.one.y, -1) << "case " << n;
    }
  }
  EXPECT_GT(boxed, 5000u);
  EXPECT_GT(large, 2000u);
  EXPECT_GT(divided, 10u);
  EXPECT_GT(plain, 100u);
}
#endif

// make_box_sums over random planes of every magnitude (as ExactDivisionIsTheFlooredQuotient's) and
// random boxes: when it boxes them, the sum of e_i is positive over the box and BoxSteps gives the
// floored quotients of the sums, clamped to int32, at every sample (no overflow: the sanitizers); on
// 64-bit hosts, sums it finds plain (BoxSums::plain) have 0 <= n_k < 2^31 n_2 at every sample, and
// BoxSteps<true>'s truncated quotients are the same.
TEST(TextureMapping, BoxSumsOfAnyPlanesStayPositiveAndInRange) {
  std::mt19937_64 rng(20261203);
  const auto any = [&](int bits) {
    return bits == 0 ? 0 : int64_t(rng() >> (64 - bits - 1)) - (int64_t(1) << bits);
  };
  size_t boxed = 0, samples = 0, plain = 0;
  for (int n = 0; n < 20000; ++n) {
    ml::TexturePlanes p{};
    for (int i = 0; i < 3; ++i) {
      p.a[i] = any(int(rng() % 46));
      p.b[i] = any(int(rng() % 46));
      p.k[i] = any(int(rng() % 60));
      // Coordinates of any sign, or (one case in two) of one sign: sums that may be plain.
      for (int k = 0; k < 2; ++k) p.uv[i][k] = int32_t(uint32_t(rng()) >> (n % 2));
    }
    p.exact = true;
    const int32_t x0 = int32_t(rng() % 2048), y0 = int32_t(rng() % 2048);
    const int32_t x1 = x0 + int32_t(rng() % ml::kTextureExactSide), y1 = y0 + int32_t(rng() % ml::kTextureExactSide);
    ml::make_box_sums(&p, x0, y0, x1, y1);
    if (!p.boxed) continue;
    ++boxed;
    const ml::BoxSums& s = p.sums;
#if UINTPTR_MAX > 0xFFFFFFFFu
    plain += s.plain;
#endif
    for (int32_t y = y0 - 1; y <= y1 + 1; ++y) {
      ml::BoxSteps steps(p);
      steps.start(p, x0 - 1, y);
#if UINTPTR_MAX > 0xFFFFFFFFu
      ml::BoxSteps<true> plain_steps(p);
      plain_steps.start(p, x0 - 1, y);
#endif
      for (int32_t x = x0 - 1; x <= x1 + 1; ++x, ++samples) {
        const int64_t w = s.at[2] + s.dx[2] * (x - s.x) + s.dy[2] * (y - s.y);
        ASSERT_GT(w, 0) << "case " << n;
        ASSERT_LT(w, int64_t(1) << 30) << "case " << n;
        int32_t uv[2];
        steps.next(uv);
        for (int k = 0; k < 2; ++k) {
          const int64_t sum = s.at[k] + s.dx[k] * (x - s.x) + s.dy[k] * (y - s.y);
          ASSERT_EQ(uv[k], int32_t(std::clamp<int64_t>(ml::div_floor(sum, w), INT32_MIN, INT32_MAX))) << "case " << n;
#if UINTPTR_MAX > 0xFFFFFFFFu
          if (s.plain) {
            ASSERT_GE(sum, 0) << "case " << n;
            ASSERT_LT(ml::div_floor(sum, w), int64_t(1) << 31) << "case " << n;
          }
#endif
        }
#if UINTPTR_MAX > 0xFFFFFFFFu
        int32_t truncated[2];
        plain_steps.next(truncated);
        if (s.plain) {
          ASSERT_EQ(truncated[0], uv[0]) << "case " << n;
          ASSERT_EQ(truncated[1], uv[1]) << "case " << n;
        }
#endif
      }
    }
  }
  EXPECT_GT(boxed, 5000u);
  EXPECT_GT(samples, 100000u);
#if UINTPTR_MAX > 0xFFFFFFFFu
  EXPECT_GT(plain, 500u);
#endif
}

// A texture of random bytes in format f (any bytes are valid: palette indices past the palette read
// its last colour).
struct RandomTexture {
  ml::TextureTexels t{};
  std::vector<uint8_t> bytes;
  RandomTexture(std::mt19937& rng, ml::TexelFormat f, uint32_t width, uint32_t height) {
    t.width = uint16_t(width);
    t.height = uint16_t(height);
    t.format = uint8_t(f);
    t.palette_size = f == ml::TexelFormat::Palette8 ? uint16_t(1 + rng() % 256) : 0;
    t.bytes = ml::texture_bytes(f, width, height, t.palette_size);
    t.wrap_s = uint8_t(rng() % 3);
    t.wrap_t = uint8_t(rng() % 3);
    t.filter = uint8_t(rng() % 2 ? ml::TextureFilter::Bilinear : ml::TextureFilter::Nearest);
    bytes.resize(t.bytes);
    for (uint8_t& b : bytes) b = uint8_t(rng());
  }
};

// The planes both renderers map case c with, at the segment bound of the texture's filter.
ml::TexturePlanes planes_for(const Case& c, const ml::TextureTexels& t) {
  const int error_bits = t.filter == uint8_t(ml::TextureFilter::Bilinear) ? ml::kTextureAffineErrorBitsBilinear
                                                                          : ml::kTextureAffineErrorBitsNearest;
  ml::TexturePlanes planes;
  ml::make_texture_planes(c.view, c.world, c.uv, 1, ml::kSubpixelHalf, ml::kSubpixelHalf, c.width, c.height,
                          error_bits, &planes);
  return planes;
}

// Makes small planes boxed over the whole 320x240 lattice the sampler tests draw (make_box_sums;
// unless the triangle's plane is seen edge-on there): their steps are the box sums', and these tests
// compare the loops with sample_texture at box_uv's coordinates. True when boxed.
bool box_over_screen(ml::TexturePlanes* planes) {
  ml::make_box_sums(planes, 0, 0, 319, 239);
  return planes->boxed;
}

// One random case of the sampler tests: a triangle, a random texture of format formats[n % 3] at its
// size, a colour (white one case in four) and the planes of the triangle, small when `small` (every
// sample divided, or with `boxed` from sums over the screen when the plane allows).
struct SamplerCase {
  Case c;
  RandomTexture tex;
  ml::Pixel colour;
  ml::TexturePlanes planes;
};
SamplerCase sampler_case(std::mt19937& rng, int n, bool small, bool boxed = false) {
  const ml::TexelFormat formats[] = {ml::TexelFormat::Rgb565, ml::TexelFormat::Palette8, ml::TexelFormat::Grey4};
  const Case c = random_case(rng);
  RandomTexture tex(rng, formats[n % 3], c.width, c.height);
  const ml::Pixel colour = n % 4 == 0 ? 0xFFFFFF : ml::Pixel(rng() & 0xFFFFFF);
  ml::TexturePlanes planes = planes_for(c, tex.t);
  planes.exact = small;
  if (small && boxed) box_over_screen(&planes);
  return SamplerCase{c, std::move(tex), colour, planes};
}

TEST(TextureMapping, RowsGiveTheColoursSampleBySample) {
  std::mt19937 rng(7);
  size_t compared = 0, boxed = 0;
  for (int n = 0; n < 120; ++n) {
    // Some small triangles' rows: every sample divided, or from the box's sums.
    const SamplerCase sc = sampler_case(rng, n, n % 5 == 1, n % 10 == 1);
    boxed += sc.planes.boxed;
    const RandomTexture& tex = sc.tex;
    const ml::Pixel colour = sc.colour;
    ml::TexturePlanes rows = sc.planes;
    ml::TexturePlanes one = rows;
    std::vector<ml::Pixel> tinted(ml::kTexelLutEntries), white(ml::kTexelLutEntries);
    ml::make_texel_lut(tex.t, tex.bytes.data(), colour, tinted.data());
    ml::make_texel_lut(tex.t, tex.bytes.data(), 0xFFFFFF, white.data());
    for (int32_t y = 3; y < 240; y += 41) {
      // Spans of random lengths and starts, as the renderers' blocks and runs come.
      for (int32_t x = 0; x < 320;) {
        const int32_t len = std::min<int32_t>(320 - x, 1 + int32_t(rng() % 70));
        const int table = int(rng() % 3);  // none, the colour's, white (the colour applied per sample)
        const ml::Pixel* lut = table == 0 ? nullptr : (table == 1 ? tinted.data() : white.data());
        const ml::Pixel lut_colour = table == 2 ? 0xFFFFFF : colour;
        std::vector<ml::Pixel> got(size_t(len), 0);
        ml::texture_row(rows, tex.t, tex.bytes.data(), lut, lut_colour, colour, x, y, len, got.data());
        for (int32_t i = 0; i < len; ++i) {
          int32_t uv[2];
          ml::texture_uv(one, x + i, y, uv);
          const ml::Pixel want = ml::sample_texture(tex.t, tex.bytes.data(), uv, colour, one.exact);
          ASSERT_EQ(got[size_t(i)], want) << "case " << n << " sample " << x + i << "," << y << " table " << table
                                          << " format " << int(tex.t.format) << " filter " << int(tex.t.filter);
          if (lut) {
            ASSERT_EQ(ml::sample_texture(tex.t, tex.bytes.data(), lut, lut_colour, uv, colour, one.exact), want);
          }
          ++compared;
        }
        x += len;
      }
    }
  }
  EXPECT_GT(compared, 100000u);
  EXPECT_GT(boxed, 3u);
}

// texture_runs as the tiler calls it for a small triangle's block: runs of a few samples on a few
// rows, in one call, give the colours sample by sample (small triangles and larger ones, every format,
// filter and wrap, the table of the colour or the white one).
TEST(TextureMapping, RunsOfABlockGiveTheColoursSampleBySample) {
  std::mt19937 rng(17);
  size_t compared = 0, boxed = 0;
  for (int n = 0; n < 90; ++n) {
    const SamplerCase sc = sampler_case(rng, n, n % 3 != 2, n % 3 == 0);
    boxed += sc.planes.boxed;
    const RandomTexture& tex = sc.tex;
    const ml::Pixel colour = sc.colour;
    ml::TexturePlanes planes = sc.planes;
    const ml::TexturePlanes one = planes;
    const ml::Pixel lut_colour = n % 2 ? 0xFFFFFF : colour;
    std::vector<ml::Pixel> lut(ml::kTexelLutEntries);
    ml::make_texel_lut(tex.t, tex.bytes.data(), lut_colour, lut.data());
    for (int k = 0; k < 40; ++k) {
      // An 8x8 block's runs: up to 4 a row, left to right.
      const int32_t bx = int32_t(rng() % 312), by = int32_t(rng() % 232);
      std::vector<ml::SampleRun> runs;
      for (int32_t row = 0; row < 8; ++row)
        for (int32_t at = int32_t(rng() % 3); at < 8; at += 2 + int32_t(rng() % 3)) {
          const int32_t len = std::min<int32_t>(8 - at, 1 + int32_t(rng() % 3));
          runs.push_back(ml::SampleRun{bx + at, by + row, len});
          at += len - 1;
        }
      size_t total = 0;
      for (const ml::SampleRun& r : runs) total += size_t(r.n);
      std::vector<ml::Pixel> got(total, 0);
      ml::texture_runs(planes, tex.t, tex.bytes.data(), lut.data(), lut_colour, colour, runs.data(),
                       int32_t(runs.size()), got.data());
      size_t i = 0;
      for (const ml::SampleRun& r : runs)
        for (int32_t j = 0; j < r.n; ++j, ++i) {
          int32_t uv[2];
          ml::TexturePlanes at = one;
          ml::texture_uv(at, r.x + j, r.y, uv);
          ASSERT_EQ(got[i], ml::sample_texture(tex.t, tex.bytes.data(), uv, colour, one.exact))
              << "case " << n << " sample " << r.x + j << "," << r.y << " format " << int(tex.t.format)
              << " filter " << int(tex.t.filter);
          ++compared;
        }
    }
  }
  EXPECT_GT(compared, 30000u);
  EXPECT_GT(boxed, 5u);
}

// Nearest runs whose texel indices cross the texture's edges a few times (coordinates over a few
// periods, long runs), for every pair of wrap modes and both directions along the row: the runs cut
// at the wrap's cells give the colours sample by sample.
TEST(TextureMapping, NearestRunsAcrossTextureEdgesGiveTheColoursSampleBySample) {
  std::mt19937 rng(13);
  const ml::TexelFormat formats[] = {ml::TexelFormat::Rgb565, ml::TexelFormat::Palette8, ml::TexelFormat::Grey4};
  size_t compared = 0;
  for (int n = 0; n < 162; ++n) {
    Case c = random_case(rng);
    std::uniform_int_distribution<int32_t> uv(-2 * 65536, 3 * 65536);
    for (auto& v : c.uv) v[0] = uv(rng), v[1] = uv(rng);
    c.width = 1u << (2 + rng() % 5);
    c.height = 1u << (2 + rng() % 5);
    RandomTexture tex(rng, formats[n % 3], c.width, c.height);
    tex.t.filter = uint8_t(ml::TextureFilter::Nearest);
    tex.t.wrap_s = uint8_t(n / 3 % 3);
    tex.t.wrap_t = uint8_t(n / 9 % 3);
    const ml::Pixel colour = n % 2 ? 0xFFFFFF : ml::Pixel(rng() & 0xFFFFFF);
    ml::TexturePlanes rows = planes_for(c, tex.t), one = rows;
    std::vector<ml::Pixel> lut(ml::kTexelLutEntries);
    ml::make_texel_lut(tex.t, tex.bytes.data(), colour, lut.data());
    for (int32_t y = 5; y < 240; y += 29)
      for (int32_t x = 0; x < 320;) {
        const int32_t len = std::min<int32_t>(320 - x, 16 + int32_t(rng() % 120));
        std::vector<ml::Pixel> got(size_t(len), 0);
        ml::texture_row(rows, tex.t, tex.bytes.data(), lut.data(), colour, colour, x, y, len, got.data());
        for (int32_t i = 0; i < len; ++i) {
          int32_t at[2];
          ml::texture_uv(one, x + i, y, at);
          ASSERT_EQ(got[size_t(i)], ml::sample_texture(tex.t, tex.bytes.data(), at, colour, false))
              << "case " << n << " sample " << x + i << "," << y << " wraps " << int(tex.t.wrap_s)
              << int(tex.t.wrap_t) << " size " << c.width << "x" << c.height;
          ++compared;
        }
        x += len;
      }
  }
  EXPECT_GT(compared, 300000u);
}

// texture_rows as the tiler calls it: blocks of a few rows (segments kept per row), sample by sample
// the same colours, for every format, wrap mode and filter, with coordinates across many texture
// periods and within one (runs that need no wrapping).
TEST(TextureMapping, BlocksOfRowsGiveTheColoursSampleBySample) {
  std::mt19937 rng(11);
  const ml::TexelFormat formats[] = {ml::TexelFormat::Rgb565, ml::TexelFormat::Palette8, ml::TexelFormat::Grey4};
  size_t compared = 0, boxed = 0;
  for (int n = 0; n < 90; ++n) {
    Case c = random_case(rng);
    if (n % 2)
      for (auto& uv : c.uv) uv[0] = int32_t(rng() % 65536), uv[1] = int32_t(rng() % 65536);
    const RandomTexture tex(rng, formats[n % 3], c.width, c.height);
    const ml::Pixel colour = n % 4 == 0 ? 0xFFFFFF : ml::Pixel(rng() & 0xFFFFFF);
    ml::TexturePlanes blocks = planes_for(c, tex.t);
    blocks.exact = n % 5 == 1;  // a small triangle's blocks: every sample divided, or from its box's sums
    if (n % 10 == 1) boxed += box_over_screen(&blocks);
    ml::TexturePlanes one = blocks;
    std::vector<ml::TextureSegment> segment_rows(16);
    ml::use_segment_rows(&blocks, segment_rows.data(), 4);
    std::vector<ml::Pixel> lut(ml::kTexelLutEntries);
    ml::make_texel_lut(tex.t, tex.bytes.data(), colour, lut.data());
    for (int k = 0; k < 40; ++k) {
      const int32_t w = 1 + int32_t(rng() % 16), h = 1 + int32_t(rng() % 8);
      const int32_t x = int32_t(rng() % uint32_t(320 - w)), y = int32_t(rng() % uint32_t(240 - h));
      std::vector<ml::Pixel> got(size_t(w * h), 0);
      ml::texture_rows(blocks, tex.t, tex.bytes.data(), lut.data(), colour, colour, x, y, w, h, got.data());
      for (int32_t r = 0; r < h; ++r)
        for (int32_t i = 0; i < w; ++i) {
          int32_t uv[2];
          ml::texture_uv(one, x + i, y + r, uv);
          ASSERT_EQ(got[size_t(r * w + i)], ml::sample_texture(tex.t, tex.bytes.data(), uv, colour, one.exact))
              << "case " << n << " sample " << x + i << "," << y + r << " format " << int(tex.t.format)
              << " filter " << int(tex.t.filter) << " wraps " << int(tex.t.wrap_s) << int(tex.t.wrap_t);
          ++compared;
        }
    }
  }
  EXPECT_GT(compared, 100000u);
  EXPECT_GT(boxed, 2u);
}

// A row's spans of small triangles sampled in one call (sample_spans, the scanline renderer's row of
// small triangles: each span with its own planes and colour) give the colours sample by sample: every
// format and wrap, both filters, boxed and divided triangles, grey colours (white, black, any grey:
// one product for the three channels) and others, through the white table (and its lanes on 64-bit
// hosts, as the renderer takes them).
TEST(TextureMapping, SpansOfSmallTrianglesGiveTheColoursSampleBySample) {
  std::mt19937 rng(19);
  const ml::TexelFormat formats[] = {ml::TexelFormat::Rgb565, ml::TexelFormat::Palette8, ml::TexelFormat::Grey4};
  size_t compared = 0, boxed = 0, grey = 0;
  for (int n = 0; n < 120; ++n) {
    const Case base = random_case(rng);
    RandomTexture tex(rng, formats[n % 3], base.width, base.height);
    if (n % 2) tex.t.wrap_s = tex.t.wrap_t = uint8_t(ml::TextureWrap::Repeat);
    tex.t.filter = uint8_t(n % 5 == 4 ? ml::TextureFilter::Nearest : ml::TextureFilter::Bilinear);
    std::vector<ml::Pixel> white(ml::kTexelLutEntries);
    ml::make_texel_lut(tex.t, tex.bytes.data(), 0xFFFFFF, white.data());
    std::vector<uint64_t> lanes(ml::kTexelLutEntries);
    ml::spread_texel_lut(tex.t, white.data(), lanes.data());
    // Triangles of this texture, each small (divided, or boxed over the screen), with its colour.
    std::vector<ml::TexturePlanes> planes(6);
    std::vector<ml::Pixel> colours(planes.size());
    for (size_t i = 0; i < planes.size(); ++i) {
      Case c = random_case(rng);
      c.width = base.width, c.height = base.height;
      planes[i] = planes_for(c, tex.t);
      planes[i].exact = true;
      if (rng() % 4 != 0) boxed += box_over_screen(&planes[i]);
      const uint32_t g = rng() % 256;
      const int kind = int(rng() % 4);
      colours[i] = kind == 0 ? 0xFFFFFF : kind == 1 ? 0 : kind == 2 ? g * 0x010101u : ml::Pixel(rng() & 0xFFFFFF);
      grey += kind != 3;
    }
    for (int k = 0; k < 30; ++k) {
      const int32_t y = int32_t(rng() % 240);
      std::vector<ml::SmallSpan> spans;
      for (int32_t x = int32_t(rng() % 8); x < 320; x += 1 + int32_t(rng() % 6)) {
        const int32_t len = std::min<int32_t>(320 - x, 1 + int32_t(rng() % 6));
        const size_t i = rng() % planes.size();
        spans.push_back(ml::SmallSpan{&planes[i], colours[i], x, len});
        x += len;
      }
      std::vector<ml::Pixel> row(320, 0x12345678u);
      const ml::TextureSampling sampling =
          ml::texture_sampling(*spans[0].planes, tex.t, tex.bytes.data(), white.data(), 0xFFFFFF, spans[0].colour,
                               lanes.data());
      ml::sample_spans(sampling, spans.data(), uint32_t(spans.size()), y, row.data());
      for (const ml::SmallSpan& sp : spans)
        for (int32_t j = 0; j < sp.n; ++j) {
          int32_t uv[2];
          ml::TexturePlanes one = *sp.planes;
          ml::texture_uv(one, sp.x + j, y, uv);
          ASSERT_EQ(row[size_t(sp.x + j)], ml::sample_texture(tex.t, tex.bytes.data(), uv, sp.colour, true))
              << "case " << n << " sample " << sp.x + j << "," << y << " format " << int(tex.t.format) << " filter "
              << int(tex.t.filter) << " wraps " << int(tex.t.wrap_s) << int(tex.t.wrap_t) << " colour " << std::hex
              << sp.colour << (sp.planes->boxed ? " boxed" : " divided");
          ++compared;
        }
    }
  }
  EXPECT_GT(compared, 100000u);
  EXPECT_GT(boxed, 100u);
  EXPECT_GT(grey, 300u);
}

}  // namespace

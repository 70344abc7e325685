// The affine texture mapping (texture/mapping.h) against the exact division at every sample: random
// triangles seen from random angles, every sample of rows across the screen, in any order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "texture/mapping.h"
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

}  // namespace

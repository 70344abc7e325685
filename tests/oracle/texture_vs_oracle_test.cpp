// Both renderers' unlit colours of textured scenes against the oracle's double-precision texturer
// (tests/oracle/texturer.h): exact for nearest filtering wherever the sample is clear of triangle
// edges (1/16 pixel) and of texel edges (1/20 texel); within 3 per channel for bilinear filtering,
// whose weights the renderers keep to 8 bits.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/oracle/oracle.h"
#include "tests/oracle/scene_triangles.h"
#include "tests/oracle/texturer.h"
#include "tests/texture/texture_test_util.h"
#include "texture/mapping.h"

namespace {

// The affine mapping's stated error bound (texture/mapping.h).
oracle::CoordinateError affine_error() {
  oracle::CoordinateError e;
  e.texel_nearest = std::ldexp(1.0, -ml::kTextureAffineErrorBitsNearest);
  e.texel_bilinear = std::ldexp(1.0, -ml::kTextureAffineErrorBitsBilinear);
  e.shift = std::ldexp(1.0, -ml::kTextureAffineShiftBits);
  e.segment = ml::kTextureSegment;
  return e;
}

struct Check {
  size_t compared = 0, mismatches = 0;
  std::string first;
};

Check compare(const std::string& path, double turn, ml::RendererKind renderer) {
  Check c;
  const mlhost::LoadedScene& s = textest::load(path);
  const ml::Camera cam = textest::camera_for(s, 160, 120, turn);
  const textest::Frame f = textest::render(s.scene, cam, textest::options(renderer));
  if (!f.status.ok()) {
    c.first = std::string("render failed: ") + f.status.message;
    c.mismatches = 1;
    return c;
  }
  const std::vector<oracle::Triangle> tris = oracle::scene_triangles(s.scene);
  const oracle::Camera ocam = oracle::to_oracle_camera(cam);
  const oracle::Result visible = oracle::rasterize(tris, ocam);
  const std::vector<oracle::Texture> textures = oracle::scene_textures(s.scene);
  const std::vector<oracle::Surface> surfaces = oracle::scene_surfaces(s.scene);
  const auto expected = oracle::texture_image(tris, surfaces, textures, ocam, visible, 0.05, 1.0 / 16.0, affine_error());
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const size_t i = visible.index(x, y);
      if (!expected[i].known) continue;
      const bool bilinear = textures[size_t(surfaces[size_t(visible.id[i])].texture)].bilinear;
      const ml::Pixel got = f.pixels[i];
      ++c.compared;
      for (int k = 0; k < 3; ++k) {
        const double want = expected[i].rgb[k];
        const double have = double((got >> (16 - 8 * k)) & 0xFF);
        if (std::fabs(have - want) > (bilinear ? 3.0 + expected[i].slack[k] : 0.5 + 1e-9)) {
          if (c.mismatches++ == 0)
            c.first = "pixel " + std::to_string(x) + "," + std::to_string(y) + " channel " + std::to_string(k) +
                      ": " + std::to_string(have) + " vs " + std::to_string(want) + " bilinear " + std::to_string(bilinear) + " slack " + std::to_string(expected[i].slack[k]);
          break;
        }
      }
    }
  return c;
}

TEST(TextureOracle, BothRenderersAgreeWithTheReferenceTexturer) {
  size_t total = 0;
  for (const std::string& path : textest::textured_scenes()) {
    for (double turn : {0.0, 30.0, -55.0}) {  // -55: the flat textureTransform panels seen nearly edge-on
      for (ml::RendererKind r : {ml::RendererKind::Tiler, ml::RendererKind::Scanline}) {
        const Check c = compare(path, turn, r);
        EXPECT_GT(c.compared, 100u) << path << " turn " << turn;
        EXPECT_EQ(c.mismatches, 0u) << path << " turn " << turn << " renderer " << int(r) << ": " << c.first;
        total += c.compared;
      }
    }
  }
  EXPECT_GT(total, 100000u);
}

}  // namespace

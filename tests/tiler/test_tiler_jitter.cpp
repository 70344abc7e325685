// Jittered sample patterns (--samples jittered, core/jitter.h): the tiler's samples against the oracle's
// rays and the scanline renderer's samples at the same jittered positions (each drawn one pattern
// sample at a time through Camera::sample_shift), band invariance, the regular grid untouched, and
// the error against the 16 x 16 reference.
#include <gtest/gtest.h>

#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "core/jitter.h"
#include "tests/tiler/aa_test_util.h"

namespace {

using namespace aatest;

ml::RenderOptions jittered_options(int aa, ml::ShadingMode shading = ml::ShadingMode::Unlit, int band_rows = 16) {
  ml::RenderOptions o;
  o.aa = aa;
  o.shading = shading;
  o.samples = ml::SamplePattern::Jittered;
  o.background = kBackground;
  o.output.band_rows = band_rows;
  o.seed = 7;
  return o;
}

// Per pixel and sample, where the jittered pattern puts it: the shift of a one-sample-a-pixel camera
// that samples it (subpixels from the pixel centre).
struct Shift {
  int32_t x, y;
};
Shift sample_shift(uint32_t pattern, int sx, int sy, int f) {
  const int32_t pitch = 256 / f;
  int32_t jx, jy;
  ml::jitter_offset(pattern, sx, sy, pitch, &jx, &jy);
  return Shift{sx * pitch + jx - 128, sy * pitch + jy - 128};
}

// The colours of every pixel's f x f jittered samples, as seen by `sample` (one image of ids a
// pattern sample, all pixels of that pattern read from it): [pixel][sy * f + sx].
template <typename Sample>
std::vector<std::vector<int64_t>> jittered_ids(const ml::Camera& camera, int f, uint32_t seed, Sample sample) {
  std::vector<std::vector<int64_t>> ids(size_t(camera.width) * size_t(camera.height), std::vector<int64_t>(size_t(f * f)));
  for (uint32_t k = 0; k < ml::kJitterPatterns; ++k)
    for (int sy = 0; sy < f; ++sy)
      for (int sx = 0; sx < f; ++sx) {
        ml::Camera shifted = camera;
        const Shift s = sample_shift(k, sx, sy, f);
        shifted.sample_shift_x = s.x;
        shifted.sample_shift_y = s.y;
        const std::vector<int64_t> image = sample(shifted);
        for (int py = 0; py < camera.height; ++py)
          for (int px = 0; px < camera.width; ++px)
            if (ml::jitter_pattern(px, py, seed) == k) {
              const size_t i = size_t(py) * size_t(camera.width) + size_t(px);
              ids[i][size_t(sy * f + sx)] = image[i];
            }
      }
  return ids;
}

// The scanline renderer's ids (triangle id, -1 for the background) at one sample a pixel.
std::vector<int64_t> scanline_ids(const ml::Scene& scene, const ml::Camera& camera) {
  ml::RenderOptions o;
  o.renderer = ml::RendererKind::Scanline;
  o.shading = ml::ShadingMode::Ids;
  const Image img = testrender::render_checked(scene, camera, o);
  EXPECT_TRUE(img.ok) << img.error;
  std::vector<int64_t> ids(img.pixels.size(), -1);
  for (size_t i = 0; i < img.pixels.size() && img.ok; ++i) ids[i] = int64_t(img.pixels[i]) - 1;
  return ids;
}

// Box-filtered unlit colour of a pixel's sample ids, rounded as the tiler rounds.
ml::Pixel box_of(const ml::Scene& scene, const std::vector<int64_t>& ids, int bits) {
  uint32_t sum[3] = {0, 0, 0};
  for (int64_t id : ids) {
    const ml::Pixel c = oracle::base_colour(scene, id, kBackground);
    for (int k = 0; k < 3; ++k) sum[k] += uint32_t(channel(c, k));
  }
  const uint32_t half = (1u << bits) >> 1;
  return ml::rgb((sum[0] + half) >> bits, (sum[1] + half) >> bits, (sum[2] + half) >> bits);
}

// Tiler and scanline agree where they use the same pattern: the scanline renderer's exact edge
// functions at each jittered position (one sample a frame, Camera::sample_shift) give the tiler's
// jittered box-filtered image exactly; the oracle's rays there agree wherever they are decisive.
TEST(TilerJitter, TilerScanlineAndOracleAgreeAtTheJitteredSamples) {
  for (uint32_t seed = 1; seed <= 2; ++seed) {
    mlhost::LoadedScene s;
    random_scene(seed, 14, &s);
    const ml::Camera camera = framing(s.scene, 40, 30);
    for (int f : {2, 4}) {
      SCOPED_TRACE("seed " + std::to_string(seed) + ", aa " + std::to_string(f));
      ml::RenderOptions o = jittered_options(f);
      const Image tiler = testrender::render_checked(s.scene, camera, o);
      ASSERT_TRUE(tiler.ok) << tiler.error;
      const int bits = f == 4 ? 4 : 2;
      const auto scan = jittered_ids(camera, f, o.seed, [&](const ml::Camera& c) { return scanline_ids(s.scene, c); });
      std::vector<const oracle::Result*> unused;
      std::vector<std::vector<bool>> decisive(scan.size(), std::vector<bool>(size_t(f * f)));
      const auto rays = jittered_ids(camera, f, o.seed, [&](const ml::Camera& c) {
        const oracle::Result r = oracle::rasterize(oracle::scene_triangles(s.scene), oracle::to_oracle_camera(c));
        std::vector<int64_t> ids(r.id.begin(), r.id.end());
        for (size_t i = 0; i < ids.size(); ++i)  // a ray within 1/16 sample of an edge, or a tie: undecided
          if (!r.decisive(int(i % size_t(c.width)), int(i / size_t(c.width)), 1.0 / (16.0 * f))) ids[i] = -2;
        return ids;
      });
      int mismatches = 0, checked = 0, blended = 0;
      std::string first;
      for (size_t i = 0; i < tiler.pixels.size(); ++i) {
        const ml::Pixel want = box_of(s.scene, scan[i], bits);
        if (tiler.pixels[i] != want && mismatches++ == 0) first = "pixel " + std::to_string(i) + " scanline";
        bool sure = true, mixed = false;
        for (size_t k = 0; k < rays[i].size(); ++k) {
          sure = sure && rays[i][k] != -2;
          mixed = mixed || rays[i][k] != rays[i][0];
        }
        if (!sure) continue;
        ++checked;
        blended += mixed;
        if (box_of(s.scene, rays[i], bits) != tiler.pixels[i] && mismatches++ == 0) first = "pixel " + std::to_string(i) + " oracle";
      }
      EXPECT_EQ(mismatches, 0) << first;
      EXPECT_GE(checked, int(tiler.pixels.size()) / 2);
      EXPECT_GE(blended, 10) << "too few pixels with more than one colour checked";
    }
  }
}

// The jittered samples are not the regular grid's, every pattern is used, the seed moves them; the
// regular grid stays the default.
TEST(TilerJitter, PatternsVaryByPixelAndSeed) {
  std::set<uint32_t> used;
  for (int py = 0; py < 30; ++py)
    for (int px = 0; px < 40; ++px) used.insert(ml::jitter_pattern(px, py, 1));
  EXPECT_EQ(used.size(), size_t(ml::kJitterPatterns));
  int off_centre = 0;
  for (uint32_t k = 0; k < ml::kJitterPatterns; ++k)
    for (int s = 0; s < 64; ++s) {
      int32_t jx, jy;
      ml::jitter_offset(k, s % 8, s / 8, 32, &jx, &jy);
      EXPECT_GE(jx, 1);
      EXPECT_LE(jx, 31);
      EXPECT_GE(jy, 1);
      EXPECT_LE(jy, 31);
      off_centre += jx != 16 || jy != 16;
    }
  EXPECT_GT(off_centre, 900);
  const auto& s = default_scene();
  const ml::Camera camera = framing(s.scene, 64, 48);
  ml::RenderOptions o = jittered_options(4, ml::ShadingMode::Flat);
  const Image a = testrender::render_checked(s.scene, camera, o);
  o.seed = 8;
  const Image b = testrender::render_checked(s.scene, camera, o);
  const Image regular = render_colour(s.scene, camera, ml::RendererKind::Tiler, 4, ml::ShadingMode::Flat);
  ml::RenderOptions defaults;
  EXPECT_EQ(defaults.samples, ml::SamplePattern::Regular);
  ASSERT_TRUE(a.ok && b.ok && regular.ok) << a.error << b.error << regular.error;
  EXPECT_NE(a.pixels, b.pixels);
  EXPECT_NE(a.pixels, regular.pixels);
}

// Any band height (with and without the band plan) gives the one-band image, box and cosine filters.
TEST(TilerJitter, BandHeightsGiveTheSameImage) {
  const auto& s = default_scene();
  const ml::Camera camera = framing(s.scene, 64, 48);
  for (ml::FilterKind filter : {ml::FilterKind::Box, ml::FilterKind::Cosine})
    for (int f : {2, 8}) {
      SCOPED_TRACE(std::string(filter == ml::FilterKind::Box ? "box" : "cosine") + " aa " + std::to_string(f));
      ml::RenderOptions o = jittered_options(f, ml::ShadingMode::Gouraud, 0);
      o.filter = filter;
      const Image whole = testrender::render_checked(s.scene, camera, o);
      ASSERT_TRUE(whole.ok) << whole.error;
      for (int rows : {1, 3, 16})
        for (bool plan : {false, true}) {
          o.output.band_rows = rows;
          const Image banded = testrender::render_checked(s.scene, camera, o, plan);
          ASSERT_TRUE(banded.ok) << banded.error;
          EXPECT_EQ(banded.pixels, whole.pixels) << rows << "-row bands";
        }
    }
}

// Jittered 8 x 8 stays within a quarter of the point-sampled error against the 16 x 16 reference, and
// more samples give less error.
TEST(TilerJitter, ErrorFallsAsSamplesGrow) {
  for (uint32_t seed = 5; seed <= 7; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    mlhost::LoadedScene s;
    random_scene(seed, 24, &s);
    const ml::Camera camera = framing(s.scene, 48, 36);
    const std::vector<double> reference = oracle::box_filtered_unlit(s.scene, camera, 16, kBackground);
    auto error = [&](int aa) {
      const Image img = aa == 1 ? render_colour(s.scene, camera, ml::RendererKind::Tiler, 1)
                                : testrender::render_checked(s.scene, camera, jittered_options(aa));
      EXPECT_TRUE(img.ok) << img.error;
      return img.ok ? rms_against(img.pixels, reference) : 1e9;
    };
    const double e[4] = {error(1), error(2), error(4), error(8)};
    printf("[ info ] seed %u, jittered, RMS against 16x16: 1x1 %.2f, 2x2 %.2f, 4x4 %.2f, 8x8 %.2f\n", seed, e[0], e[1],
           e[2], e[3]);
    for (int i = 1; i < 4; ++i) EXPECT_LT(e[i], e[i - 1]);
    EXPECT_LE(e[3], e[0] / 4);
  }
}

TEST(TilerJitter, NeedsSamplesAndTheTiler) {
  const auto& s = default_scene();
  const ml::Camera camera = framing(s.scene, 32, 24);
  EXPECT_FALSE(testrender::render_checked(s.scene, camera, jittered_options(1)).ok);
  ml::RenderOptions o = jittered_options(4);
  o.renderer = ml::RendererKind::Scanline;
  EXPECT_FALSE(testrender::render_checked(s.scene, camera, o).ok);
  ml::Camera far = camera;
  far.sample_shift_x = 256;  // a whole pixel is not a sample shift
  EXPECT_FALSE(render_colour(s.scene, far, ml::RendererKind::Tiler, 1).ok);
}

}  // namespace

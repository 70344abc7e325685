// The tiler's cosine-hump filter (--filter cosine): the generated tables, the image against the
// oracle's samples filtered with the same integer weights, band invariance with the once-per-pixel
// sink contract, and convergence towards the oracle's 16 x 16 cosine-filtered reference.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "tables/filter_tables.h"
#include "tests/tiler/aa_test_util.h"
#include "tools/maskgen/filter_gen.h"

namespace {

using namespace aatest;

Image render_cosine(const ml::Scene& scene, const ml::Camera& camera, int aa,
                    ml::ShadingMode shading = ml::ShadingMode::Unlit, int band_rows = 16,
                    ml::PixelFormat format = ml::PixelFormat::Xrgb8888) {
  return render_colour(scene, camera, ml::RendererKind::Tiler, aa, shading, band_rows, format,
                       ml::FilterKind::Cosine);
}

TEST(CosineTable, CompiledTablesAreTheGeneratorsAndSumToOne) {
  const std::vector<uint32_t> w = filtergen::sample_weights();
  const std::vector<uint64_t> table = filtergen::byte_table(w);
  ASSERT_EQ(table.size() * 8, sizeof ml::kCosineByteWeights);
  EXPECT_EQ(std::memcmp(table.data(), ml::kCosineByteWeights, sizeof ml::kCosineByteWeights), 0)
      << "tables/filter_tables_data.cpp differs from the generator: run `make tables`";
  EXPECT_EQ(filtergen::table_crc(table), ml::kCosineTableCrc32);
  uint32_t sum = 0;
  for (int d = 0; d < 9; ++d) {
    uint32_t total = 0;
    for (int s = 0; s < 64; ++s) total += w[size_t(d * 64 + s)];
    EXPECT_EQ(total, ml::kCosineTotals[d]) << "neighbour " << d;
    sum += ml::kCosineTotals[d];
  }
  EXPECT_EQ(sum, ml::kFilterWeightOne);  // a pixel's weights are exactly one
  // Samples at or beyond one pixel from the destination's centre weigh nothing; the centre most.
  for (int d = 0; d < 9; ++d)
    for (int s = 0; s < 64; ++s) {
      const double x = (d % 3 - 1) + ((s & 7) + 0.5) / 8 - 0.5, y = (d / 3 - 1) + ((s >> 3) + 0.5) / 8 - 0.5;
      if (x * x + y * y >= 1) {
        EXPECT_EQ(w[size_t(d * 64 + s)], 0u) << d << " " << s;
      }
      EXPECT_LE(w[size_t(d * 64 + s)], w[4 * 64 + 27]);
    }
  // Mirror images weigh the same, and an entry's lanes are the summed weights of the byte's bits for
  // the three destinations on its row (table 0: dy = 0, table 1: dy = 1; rows 0..3).
  for (int i = 0; i < 9 * 64; ++i) {
    EXPECT_EQ(w[size_t(i)], w[size_t(filtergen::mirror_x(i))]) << i;
    EXPECT_EQ(w[size_t(i)], w[size_t(filtergen::mirror_y(i))]) << i;
  }
  for (int t = 0; t < 2; ++t)
    for (int row = 0; row < 8; ++row)
      for (int dx = -1; dx <= 1; ++dx)
        for (int b = 1; b < 256; ++b) {
          uint32_t bits = 0;
          for (int col = 0; col < 8; ++col)
            if (b >> col & 1) bits += w[size_t(((t + 1) * 3 + dx + 1) * 64 + row * 8 + col)];
          if (row >= 4) {  // not stored: mirrored rows (t = 0), or beyond the kernel (t = 1)
            const uint32_t mirrored = uint32_t(ml::kCosineByteWeights[0][7 - row][b] >> (16 * (dx + 1))) & 0xFFFFu;
            ASSERT_EQ(bits, t == 0 ? mirrored : 0u) << t << " " << row << " " << dx << " " << b;
            continue;
          }
          ASSERT_EQ(uint32_t(ml::kCosineByteWeights[t][row][b] >> (16 * (dx + 1))) & 0xFFFFu, bits)
              << t << " " << row << " " << dx << " " << b;
        }
}

// Integer weight of sample (sx, sy) of an f x f grid of neighbour d: the table samples in its area.
uint32_t coarse_weight(const std::vector<uint32_t>& w, int d, int f, int sx, int sy) {
  const int k = 8 / f;
  uint32_t sum = 0;
  for (int y = sy * k; y < sy * k + k; ++y)
    for (int x = sx * k; x < sx * k + k; ++x) sum += w[size_t(d * 64 + y * 8 + x)];
  return sum;
}

// Tiler pixels against the oracle's samples (one ray each) filtered with the same integer weights and
// rounding. A pixel none of whose weighted samples is undecided (within 1/16 sample of an edge, or a
// depth tie) must match exactly; otherwise each channel may differ by the weight of its undecided
// samples.
void check_cosine_with_oracle(const ml::Scene& scene, const ml::Camera& camera, int f) {
  SCOPED_TRACE("aa " + std::to_string(f));
  const Image img = render_cosine(scene, camera, f);
  ASSERT_TRUE(img.ok) << img.error;
  const oracle::Result ref = oracle_samples(scene, camera, f);
  const std::vector<uint32_t> w = filtergen::sample_weights();
  int failures = 0, exact = 0, blended = 0;
  std::string first;
  for (int py = 0; py < camera.height; ++py)
    for (int px = 0; px < camera.width; ++px) {
      uint64_t sum[3] = {0, 0, 0}, full = 0, unsure = 0;
      bool mixed = false;
      ml::Pixel seen = 0;
      for (int d = 0; d < 9; ++d) {
        const int qx = px + d % 3 - 1, qy = py + d / 3 - 1;
        if (qx < 0 || qy < 0 || qx >= camera.width || qy >= camera.height) continue;
        for (int sy = 0; sy < f; ++sy)
          for (int sx = 0; sx < f; ++sx) {
            const uint32_t weight = coarse_weight(w, d, f, sx, sy);
            if (weight == 0) continue;
            const int x = qx * f + sx, y = qy * f + sy;
            const ml::Pixel c = oracle::base_colour(scene, ref.id[ref.index(x, y)], kBackground);
            if (full == 0) seen = c;
            mixed = mixed || c != seen;
            full += weight;
            for (int k = 0; k < 3; ++k) sum[k] += uint64_t(channel(c, k)) * weight;
            if (!ref.decisive(x, y, 1.0 / 16.0)) unsure += weight;
          }
      }
      const int tolerance = unsure == 0 ? 0 : int((unsure * 255 + full - 1) / full) + 1;
      if (unsure == 0) ++exact;
      if (mixed && unsure * 64 <= full) ++blended;  // a blend checked to within 5 of 255
      const ml::Pixel got = img.pixels[size_t(py) * size_t(camera.width) + size_t(px)];
      for (int k = 0; k < 3; ++k) {
        const int want = int((sum[k] + full / 2) / full);
        if (std::abs(channel(got, k) - want) > tolerance && failures++ == 0)
          first = "pixel (" + std::to_string(px) + "," + std::to_string(py) + ") channel " + std::to_string(k) +
                  ": got " + std::to_string(channel(got, k)) + ", oracle " + std::to_string(want);
      }
    }
  EXPECT_EQ(failures, 0) << first;
  EXPECT_GE(exact, camera.width * camera.height / 3);
  EXPECT_GE(blended, 20) << "too few blended pixels checked closely";
}

TEST(TilerCosine, RandomScenesMatchTheOracleSamplesFiltered) {
  for (uint32_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    mlhost::LoadedScene s;
    random_scene(seed, 10 + int(seed) * 4, &s);
    for (int f : {2, 4, 8}) check_cosine_with_oracle(s.scene, framing(s.scene, 48, 36), f);
  }
  check_cosine_with_oracle(default_scene().scene, framing(default_scene().scene, 32, 24), 8);
}

// A pixel's colour needs its neighbours' samples: each band is tiled with a row of its neighbours
// around it, so any band height gives the one-band image, every pixel written once.
TEST(TilerCosine, BandHeightsGiveTheSameImage) {
  const auto& s = default_scene();
  const ml::Camera camera = framing(s.scene, 64, 48);
  for (int f : {2, 4, 8})
    for (ml::ShadingMode shading : {ml::ShadingMode::Flat, ml::ShadingMode::Gouraud}) {
      SCOPED_TRACE("aa " + std::to_string(f) + (shading == ml::ShadingMode::Flat ? " flat" : " gouraud"));
      const Image whole = render_cosine(s.scene, camera, f, shading, 0);
      ASSERT_TRUE(whole.ok) << whole.error;
      for (int rows : {1, 2, 3, 16})
        for (bool plan : {false, true}) {  // with the band plan too (the halo's rows are planned)
          ml::RenderOptions o;
          o.shading = shading;
          o.aa = f;
          o.filter = ml::FilterKind::Cosine;
          o.background = kBackground;
          o.output.band_rows = rows;
          const Image banded = testrender::render_checked(s.scene, camera, o, plan);
          ASSERT_TRUE(banded.ok) << banded.error;
          EXPECT_EQ(banded.pixels, whole.pixels) << rows << "-row bands" << (plan ? ", planned" : "");
        }
      const Image packed = render_cosine(s.scene, camera, f, shading, 5, ml::PixelFormat::Rgb565Be);
      EXPECT_TRUE(packed.ok) << packed.error;
      const Image box = render_colour(s.scene, camera, ml::RendererKind::Tiler, f, shading, 0);
      EXPECT_NE(box.pixels, whole.pixels) << "the filter changes nothing";
    }
}

// Against the oracle's 16 x 16 rays a pixel filtered by the continuous kernel: the error falls as the
// samples grow, 8 x 8 is within a quarter of the point-sampled error and closer than the box filter.
TEST(TilerCosine, ErrorFallsAsSamplesGrow) {
  for (uint32_t seed = 5; seed <= 7; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    mlhost::LoadedScene s;
    random_scene(seed, 24, &s);
    const ml::Camera camera = framing(s.scene, 48, 36);
    const std::vector<double> reference = oracle::cosine_filtered_unlit(s.scene, camera, 16, kBackground);
    auto error = [&](int aa, ml::FilterKind filter) {
      const Image img =
          render_colour(s.scene, camera, ml::RendererKind::Tiler, aa, ml::ShadingMode::Unlit, 16,
                        ml::PixelFormat::Xrgb8888, filter);
      EXPECT_TRUE(img.ok) << img.error;
      return img.ok ? rms_against(img.pixels, reference) : 1e9;
    };
    const double point = error(1, ml::FilterKind::Box), box = error(8, ml::FilterKind::Box);
    const double cosine[3] = {error(2, ml::FilterKind::Cosine), error(4, ml::FilterKind::Cosine),
                              error(8, ml::FilterKind::Cosine)};
    printf("[ info ] seed %u, RMS against the 16x16 cosine reference: tiler 1x1 %.2f, box 8x8 %.2f, cosine 2x2 "
           "%.2f, 4x4 %.2f, 8x8 %.2f\n", seed, point, box, cosine[0], cosine[1], cosine[2]);
    EXPECT_LT(cosine[1], cosine[0]);
    EXPECT_LT(cosine[2], cosine[1]);
    EXPECT_LE(cosine[2], point / 4);
    EXPECT_LT(cosine[2], box);
  }
}

TEST(TilerCosine, NeedsSamplesAndTheTiler) {
  const auto& s = default_scene();
  const ml::Camera camera = framing(s.scene, 32, 24);
  EXPECT_FALSE(render_cosine(s.scene, camera, 1).ok);
  EXPECT_FALSE(render_colour(s.scene, camera, ml::RendererKind::Scanline, 4, ml::ShadingMode::Unlit, 16,
                             ml::PixelFormat::Xrgb8888, ml::FilterKind::Cosine)
                   .ok);
  // Ids stay point-sampled whatever the filter.
  const Image ids = render_cosine(s.scene, camera, 8, ml::ShadingMode::Ids);
  const Image point = render_colour(s.scene, camera, ml::RendererKind::Tiler, 1, ml::ShadingMode::Ids);
  ASSERT_TRUE(ids.ok && point.ok) << ids.error << point.error;
  EXPECT_EQ(ids.pixels, point.pixels);
}

}  // namespace

// Coverage pyramid: layout, memory formula (P3), start state, invariants P1, P2, P4 under tiling.
#include <gtest/gtest.h>

#include <random>

#include "tests/tiler/tiler_test_util.h"
#include "tiler/pyramid.h"
#include "tiler/tile.h"

namespace {

using tiler_test::OwnedPyramid;

// P3: bits per sample of a full power-of-8 square = 1 + (2/63)(1 - 64^-(n-1)), checked exactly:
// bytes * 8 * 63 * 64^(n-1) == samples * (63 * 64^(n-1) + 2 * (64^(n-1) - 1)).
TEST(Pyramid, MemoryFollowsFormulaOnPowerOfEightSquares) {
  for (int side : {64, 512, 4096}) {
    ml::PyramidLayout l;
    ASSERT_TRUE(ml::make_pyramid_layout(side, side, &l));
    const int n = l.levels;
    const uint64_t p = uint64_t(1) << (6 * (n - 1));  // 64^(n-1)
    const uint64_t samples = uint64_t(side) * side;
    EXPECT_EQ(uint64_t(l.bytes()) * 8 * 63 * p, samples * (63 * p + 2 * (p - 1))) << side;
    // And inside [1 1/32, 1 2/63).
    EXPECT_GE(uint64_t(l.bytes()) * 8 * 32, samples * 33);
    EXPECT_LT(uint64_t(l.bytes()) * 8 * 63, samples * 65);
  }
  ml::PyramidLayout l;
  ASSERT_TRUE(ml::make_pyramid_layout(512, 512, &l));
  EXPECT_EQ(l.levels, 3);
  EXPECT_EQ(l.bytes(), 33808u);  // 16 + 1,024 + 32,768 (the digest's §3.2)
  ASSERT_TRUE(ml::make_pyramid_layout(4096, 4096, &l));
  EXPECT_EQ(l.bytes(), 2163728u);
}

// Other sizes store only the masks that overlap the screen: never more than the padded square's
// formula, and exactly the sum over the stored masks.
TEST(Pyramid, OtherSizesStoreOnlyUsedMasks) {
  ml::PyramidLayout l;
  ASSERT_TRUE(ml::make_pyramid_layout(320, 240, &l));
  EXPECT_EQ(l.levels, 3);
  EXPECT_EQ(l.bytes(), 16u + 20u * 16u + 1200u * 8u);  // 9,936 bytes
  std::mt19937 rng(3);
  for (int i = 0; i < 200; ++i) {
    const int w = 1 + int(rng() % 4096), h = 1 + int(rng() % 4096);
    ASSERT_TRUE(ml::make_pyramid_layout(w, h, &l));
    const uint64_t side = uint64_t(1) << (3 * l.levels);
    ASSERT_GE(side, uint64_t(std::max(w, h)));
    ASSERT_TRUE(l.levels == 2 || (side >> 3) < uint64_t(std::max(w, h)));
    const uint64_t p = uint64_t(1) << (6 * (l.levels - 1));
    EXPECT_LE(uint64_t(l.bytes()) * 8 * 63 * p, side * side * (63 * p + 2 * (p - 1)));
    // Every finest block holds at least one on-screen sample.
    EXPECT_EQ(uint64_t(l.block_count), uint64_t((w + 7) / 8) * uint64_t((h + 7) / 8));
  }
  // Up to kMaxSampleDim samples a side (4096 pixels at 8 x 8 samples): five levels.
  ASSERT_TRUE(ml::make_pyramid_layout(ml::kMaxSampleDim, 10, &l));
  EXPECT_EQ(l.levels, 5);
  EXPECT_FALSE(ml::make_pyramid_layout(ml::kMaxSampleDim + 1, 10, &l));
  EXPECT_FALSE(ml::make_pyramid_layout(10, 0, &l));
}

TEST(Pyramid, OffScreenStartsCoveredOnScreenVacant) {
  for (auto [w, h] : {std::pair<int, int>{320, 240}, {61, 7}, {1, 1}, {512, 100}, {1000, 999}}) {
    OwnedPyramid op(w, h);
    const auto cov = tiler_test::covered_samples(op.pyramid);
    for (uint8_t c : cov) ASSERT_EQ(c, 0) << w << "x" << h;
    EXPECT_EQ(tiler_test::check_pyramid(op.pyramid), "");
    // The padding is covered: the root has exactly the off-screen subcells covered.
    const ml::PyramidLayout& l = op.pyramid.layout;
    const int sub = l.shift(0) - 3;
    for (int bit = 0; bit < 64; ++bit) {
      const bool off = ((bit & 7) << sub) >= w || ((bit >> 3) << sub) >= h;
      EXPECT_EQ((op.pyramid.mask(0, 0, 0).c >> bit & 1) != 0, off);
    }
  }
}

// P1, P2, P4 after every polygon on random scenes.
TEST(Pyramid, InvariantsHoldAfterEveryPolygon) {
  std::mt19937 rng(21);
  for (auto [w, h] : {std::pair<int, int>{320, 240}, {100, 70}, {64, 64}, {530, 20}}) {
    OwnedPyramid op(w, h);
    ml::HierTiler tiler;
    tiler.init(&op.pyramid, 256, nullptr);
    tiler_test::RecordingWriter rec(w, h);
    size_t covered_before = 0;
    for (int i = 0; i < 150; ++i) {
      ml::ScreenTriangle t;
      if (!tiler_test::random_triangle(rng, w, h, i % 3 == 0 ? w : 20, &t)) continue;
      ml::TriangleSetup s;
      ml::setup_triangle(t, w, h, &s);
      ml::ConvexPoly poly;
      ml::poly_from_setup(s, &poly);
      tiler.tile(poly, rec);
      ASSERT_EQ(tiler_test::check_pyramid(op.pyramid), "") << "after polygon " << i;
      const auto cov = tiler_test::covered_samples(op.pyramid);
      size_t covered = 0;
      for (size_t p = 0; p < cov.size(); ++p) {
        covered += cov[p];
        // The pyramid says covered exactly where something was written.
        ASSERT_EQ(cov[p] != 0, rec.count[p] != 0) << "pixel " << p << " after polygon " << i;
      }
      ASSERT_GE(covered, covered_before);  // P4
      covered_before = covered;
    }
  }
}

}  // namespace

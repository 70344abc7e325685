// Tests of the shared shading helpers (src/shade): screen-space planes against double math, Lambert
// terms, colour modulation.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "shade/shade.h"

namespace {

using ml::ScreenTriangle;
using ml::Vec3i;

ScreenTriangle random_triangle(std::mt19937_64& rng, int32_t span) {
  ScreenTriangle t{};
  std::uniform_int_distribution<int32_t> c(-span, span);
  do {
    for (auto& v : t.v) { v.x = 8192 + c(rng); v.y = 8192 + c(rng); }
    t.area2 = (int64_t(t.v[1].x) - t.v[0].x) * (t.v[2].y - t.v[0].y) -
              (int64_t(t.v[2].x) - t.v[0].x) * (t.v[1].y - t.v[0].y);
  } while (t.area2 == 0);
  if (t.area2 < 0) { std::swap(t.v[1], t.v[2]); t.area2 = -t.area2; }
  return t;
}

TEST(ShadePlane, MatchesDoubleInterpolationInsideTheTriangle) {
  std::mt19937_64 rng(17);
  int checked = 0;
  for (int iter = 0; iter < 3000; ++iter) {
    const int32_t span = iter % 3 == 0 ? 600 : iter % 3 == 1 ? 6000 : 60000;
    const ScreenTriangle t = random_triangle(rng, span);
    int32_t values[3];
    for (auto& v : values) v = int32_t(rng() % 65536) - 32768;
    const ml::LinearPlane p = ml::make_plane(t, values);
    // Slivers steeper than the documented bound (2^20 per pixel) are clamped by design.
    const double gx = 256.0 * ((values[1] - values[0]) * double(t.v[2].y - t.v[0].y) -
                               (values[2] - values[0]) * double(t.v[1].y - t.v[0].y)) / double(t.area2);
    const double gy = 256.0 * ((values[2] - values[0]) * double(t.v[1].x - t.v[0].x) -
                               (values[1] - values[0]) * double(t.v[2].x - t.v[0].x)) / double(t.area2);
    if (std::fabs(gx) >= (1 << 20) || std::fabs(gy) >= (1 << 20)) continue;
    // Double interpolation at a few pixel centres inside the triangle.
    for (int k = 0; k < 20; ++k) {
      const double w1 = double(rng() % 1000) / 1000, w2 = double(rng() % 1000) / 1000 * (1 - w1);
      const double x = t.v[0].x + w1 * (t.v[1].x - t.v[0].x) + w2 * (t.v[2].x - t.v[0].x);
      const double y = t.v[0].y + w1 * (t.v[1].y - t.v[0].y) + w2 * (t.v[2].y - t.v[0].y);
      const int px = int(std::floor((x - 128) / 256 + 0.5)), py = int(std::floor((y - 128) / 256 + 0.5));
      const double cx = px * 256.0 + 128, cy = py * 256.0 + 128;
      // Barycentric weights of the pixel centre (it may lie slightly outside; planes extrapolate).
      const double d = double(t.area2);
      const double b1 = ((cx - t.v[0].x) * (t.v[2].y - t.v[0].y) - (cx - t.v[0].x) * 0 -
                         (cy - t.v[0].y) * (t.v[2].x - t.v[0].x)) / d;
      const double b2 = ((t.v[1].x - t.v[0].x) * (cy - t.v[0].y) - (t.v[1].y - t.v[0].y) * (cx - t.v[0].x)) / d;
      if (b1 < 0 || b2 < 0 || b1 + b2 > 1) continue;  // only centres inside
      const double expect = values[0] + b1 * (values[1] - values[0]) + b2 * (values[2] - values[0]);
      EXPECT_NEAR(p.at(px, py), expect, 1.01) << "iter " << iter;
      ++checked;
    }
  }
  EXPECT_GT(checked, 10000);
}

TEST(ShadeLight, LambertIsAmbientPlusClampedDiffuse) {
  ml::Light light;
  ml::normalize_q30(Vec3i{0, 0, 1}, &light.to_light);
  light.ambient_q8 = 50;
  light.diffuse_q8 = 200;
  Vec3i facing, away, sideways, half;
  ml::normalize_q30(Vec3i{0, 0, 5}, &facing);
  ml::normalize_q30(Vec3i{0, 0, -5}, &away);
  ml::normalize_q30(Vec3i{3, 0, 0}, &sideways);
  ml::normalize_q30(Vec3i{0, 1000, 1000}, &half);
  EXPECT_EQ(ml::lambert_q8(light, facing), 250);
  EXPECT_EQ(ml::lambert_q8(light, away), 50);
  EXPECT_EQ(ml::lambert_q8(light, sideways), 50);
  EXPECT_NEAR(ml::lambert_q8(light, half), 50 + 200 * std::sqrt(0.5), 1);
  const uint8_t base[4] = {200, 100, 10, 255};
  EXPECT_EQ(ml::modulate(base, 256), ml::rgb(200, 100, 10));
  EXPECT_EQ(ml::modulate(base, 512), ml::rgb(255, 200, 20));
  EXPECT_EQ(ml::modulate(base, 128), ml::rgb(100, 50, 5));
}

TEST(ShadeLight, FaceNormalFollowsCounterClockwiseWinding) {
  const Vec3i tri[3] = {Vec3i{0, 0, 0}, Vec3i{1000, 0, 0}, Vec3i{0, 1000, 0}};
  const Vec3i n = ml::face_normal(tri);
  EXPECT_EQ(n.x, 0);
  EXPECT_EQ(n.y, 0);
  EXPECT_NEAR(n.z, ml::kUnitOne, 1);
  const Vec3i huge[3] = {Vec3i{-(1 << 23), -(1 << 23), 5}, Vec3i{1 << 23, -(1 << 23), 5}, Vec3i{0, 1 << 23, -7}};
  const Vec3i m = ml::face_normal(huge);
  EXPECT_NEAR(std::sqrt(double(ml::dot64(m, m))) / ml::kUnitOne, 1.0, 1e-6);
  const Vec3i flat[3] = {Vec3i{0, 0, 0}, Vec3i{10, 10, 10}, Vec3i{20, 20, 20}};
  const Vec3i z = ml::face_normal(flat);
  EXPECT_EQ(z.x | z.y | z.z, 0);
}

// Flat shading's light from the face's cross product (face_lambert_q8, one division) against the exact
// value and against lambert_q8 of the unit normal (face_normal, three divisions): triangles from a
// few world units to the world's range, random lights, both sides. Where the two differ (rounding at
// a half), by one step, and the face's own is the nearer the exact value: no frame gets a colour
// further from the light than before.
TEST(ShadeLight, FaceLightIsTheExactCosineRounded) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int32_t> direction(-1000, 1000);
  std::uniform_int_distribution<int> bits(0, 23);
  long cases = 0, differ = 0;
  for (int l = 0; l < 40; ++l) {
    ml::Light light;
    if (!ml::normalize_q30(Vec3i{direction(rng), direction(rng), direction(rng)}, &light.to_light)) continue;
    light.ambient_q8 = 72;
    light.diffuse_q8 = 200;
    const double to[3] = {light.to_light.x / double(ml::kUnitOne), light.to_light.y / double(ml::kUnitOne),
                          light.to_light.z / double(ml::kUnitOne)};
    for (int t = 0; t < 5000; ++t) {
      const int32_t span = int32_t(1) << bits(rng);
      std::uniform_int_distribution<int32_t> at(-span, span);
      Vec3i w[3];
      for (Vec3i& v : w) v = Vec3i{at(rng), at(rng), at(rng)};
      const double a[3] = {double(w[1].x) - w[0].x, double(w[1].y) - w[0].y, double(w[1].z) - w[0].z};
      const double b[3] = {double(w[2].x) - w[0].x, double(w[2].y) - w[0].y, double(w[2].z) - w[0].z};
      const double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
      const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (const bool front : {true, false}) {
        Vec3i unit = ml::face_normal(w);
        if (!front) unit = Vec3i{-unit.x, -unit.y, -unit.z};
        const int32_t face = ml::face_lambert_q8(light, w, front), normal = ml::lambert_q8(light, unit);
        const double cosine = length > 0 ? (front ? 1 : -1) * (n[0] * to[0] + n[1] * to[1] + n[2] * to[2]) / length : 0;
        const double exact = light.ambient_q8 + light.diffuse_q8 * std::max(0.0, cosine);
        ++cases;
        ASSERT_LE(std::abs(face - exact), 0.5 + 1e-6) << "triangle " << t << " light " << l;
        if (face == normal) continue;
        ++differ;
        EXPECT_EQ(std::abs(face - normal), 1);
        EXPECT_LT(std::abs(face - exact), std::abs(normal - exact));
      }
    }
  }
  EXPECT_EQ(cases, 400000);
  EXPECT_LT(differ, cases / 10000) << differ << " of " << cases;  // 90 in 8,000,000 when measured
}

}  // namespace

// Checks of the oracle itself against hand-computed geometry, so that comparisons with the renderers
// rest on something verified.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/oracle/oracle.h"

namespace {

using oracle::Triangle;
using oracle::Vec3;

// Camera at the origin looking down -z, y up: a point (X, Y, Z) lands at
// (cx + f X / -Z, cy - f Y / -Z) with f = (h / 2) / tan(fov / 2).
oracle::Camera simple_camera(int w, int h) {
  oracle::Camera c;
  c.eye = {0, 0, 0};
  c.target = {0, 0, -1};
  c.up = {0, 1, 0};
  c.vfov_deg = 90;
  c.width = w;
  c.height = h;
  c.near = 1;
  return c;
}

// Screen point (sx, sy) at depth d as a world point, for the simple camera.
Vec3 at_screen(const oracle::Camera& c, double sx, double sy, double d) {
  const double f = (c.height / 2.0) / std::tan(c.vfov_deg * M_PI / 360.0);
  return {(sx - c.width / 2.0) * d / f, -(sy - c.height / 2.0) * d / f, -d};
}

// Counter-clockwise seen from the eye in world space = clockwise on the y-down screen.
Triangle screen_triangle(const oracle::Camera& c, double ax, double ay, double bx, double by, double qx, double qy,
                         double depth) {
  Triangle t;
  t.v[0] = at_screen(c, ax, ay, depth);
  t.v[1] = at_screen(c, bx, by, depth);
  t.v[2] = at_screen(c, qx, qy, depth);
  return t;
}

bool inside_2d(double px, double py, double ax, double ay, double bx, double by, double cx, double cy) {
  const double e0 = (bx - ax) * (py - ay) - (by - ay) * (px - ax);
  const double e1 = (cx - bx) * (py - by) - (cy - by) * (px - bx);
  const double e2 = (ax - cx) * (py - cy) - (ay - cy) * (px - cx);
  return (e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0);
}

TEST(OracleSelf, SingleTriangleCoverageMatchesScreenGeometry) {
  const auto cam = simple_camera(40, 30);
  // Screen-space corners; world order chosen counter-clockwise as seen from the eye (y up).
  const double ax = 3.3, ay = 2.7, bx = 5.1, by = 27.2, qx = 36.6, qy = 14.9;
  Triangle t = screen_triangle(cam, ax, ay, bx, by, qx, qy, 7.0);
  auto r = oracle::rasterize({t}, cam);
  int covered = 0, checked = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      if (!r.decisive(x, y, 1e-3)) continue;
      ++checked;
      const bool in = inside_2d(x + 0.5, y + 0.5, ax, ay, bx, by, qx, qy);
      EXPECT_EQ(r.id[r.index(x, y)], in ? 0 : -1) << x << "," << y;
      covered += in;
    }
  EXPECT_GT(covered, 200);
  EXPECT_GT(checked, 1000);
}

TEST(OracleSelf, BackFacesCulledUnlessDoubleSided) {
  const auto cam = simple_camera(20, 20);
  Triangle front = screen_triangle(cam, 2, 2, 2, 18, 18, 10, 5);
  Triangle back = front;
  std::swap(back.v[1], back.v[2]);
  const auto rf = oracle::rasterize({front}, cam);
  const auto rb = oracle::rasterize({back}, cam);
  back.double_sided = true;
  const auto rd = oracle::rasterize({back}, cam);
  int front_hits = 0;
  for (size_t i = 0; i < rf.id.size(); ++i) {
    front_hits += rf.id[i] == 0;
    EXPECT_EQ(rb.id[i], -1);
    EXPECT_EQ(rd.id[i], rf.id[i]);
  }
  EXPECT_GT(front_hits, 50);
}

TEST(OracleSelf, NearestWinsInAnyOrderAndTiesAreFlagged) {
  const auto cam = simple_camera(32, 32);
  Triangle far_t = screen_triangle(cam, 0, 0, 0, 64, 64, 0, 20);
  Triangle near_t = screen_triangle(cam, 8, 8, 8, 40, 40, 8, 10);
  const auto r1 = oracle::rasterize({far_t, near_t}, cam);
  const auto r2 = oracle::rasterize({near_t, far_t}, cam);
  int nears = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const size_t i = r1.index(x, y);
      if (!r1.decisive(x, y, 0.01)) continue;
      const bool in_near = inside_2d(x + 0.5, y + 0.5, 8, 8, 8, 40, 40, 8);
      EXPECT_EQ(r1.id[i], in_near ? 1 : 0);
      EXPECT_EQ(r2.id[i], in_near ? 0 : 1);
      nears += in_near;
    }
  EXPECT_GT(nears, 100);
  // The same triangle twice: every covered pixel is a tie.
  const auto rt = oracle::rasterize({near_t, near_t}, cam);
  for (size_t i = 0; i < rt.id.size(); ++i) EXPECT_EQ(rt.ambiguous[i], rt.id[i] >= 0 ? 1 : 0);
}

TEST(OracleSelf, ContactWithANearlyCoveringTriangleIsATieButASharedEdgeIsNot) {
  const auto cam = simple_camera(32, 32);
  const Triangle wall = screen_triangle(cam, -20, -20, -20, 100, 100, -20, 10);
  // A fin standing on the wall: its left edge lies in the wall's plane at x = 10.5001, so the centre
  // of pixel column 10 misses it by 0.0001 pixel where the two surfaces meet.
  Triangle fin;
  fin.v[0] = at_screen(cam, 10.5001, 5, 10);
  fin.v[1] = at_screen(cam, 10.5001, 25, 10);
  fin.v[2] = at_screen(cam, 20, 15, 5);
  fin.double_sided = true;
  const auto r = oracle::rasterize({wall, fin}, cam);
  EXPECT_EQ(r.id[r.index(10, 15)], 0);
  EXPECT_EQ(r.ambiguous[r.index(10, 15)], 1);
  EXPECT_EQ(r.id[r.index(12, 15)], 1);
  EXPECT_EQ(r.ambiguous[r.index(12, 15)], 0);
  EXPECT_EQ(r.ambiguous[r.index(5, 15)], 0);
  // Two halves of one flat quad sharing the edge at x = 10.5001: never a tie.
  Triangle left = screen_triangle(cam, 10.5001, 0, 0, 16, 10.5001, 32, 10);
  Triangle right = screen_triangle(cam, 10.5001, 0, 10.5001, 32, 30, 16, 10);
  left.double_sided = right.double_sided = true;
  const auto q = oracle::rasterize({left, right}, cam);
  EXPECT_EQ(q.id[q.index(10, 15)], 0);
  EXPECT_EQ(q.ambiguous[q.index(10, 15)], 0);
}

TEST(OracleSelf, HitsInFrontOfTheNearPlaneAreRejected) {
  auto cam = simple_camera(32, 32);
  cam.near = 4;
  // A floor below the eye reaching from behind it to far away: rows near the bottom of the screen
  // see it closer than the near plane.
  Triangle floor;
  floor.v[0] = {-100, -2, 10};
  floor.v[1] = {100, -2, 10};
  floor.v[2] = {0, -2, -200};
  const auto r = oracle::rasterize({floor}, cam);
  const double f = 16.0;  // (32 / 2) / tan(45 degrees)
  int hits = 0, rejected = 0;
  for (int y = 17; y < 32; ++y) {
    // The row's ray hits y = -2 at depth d = 2 f / (y + 0.5 - 16).
    const double d = 2 * f / (y + 0.5 - 16);
    const int x = 16;
    if (std::fabs(d - cam.near) < 0.05) continue;
    if (d >= cam.near) {
      EXPECT_EQ(r.id[r.index(x, y)], 0) << y;
      ++hits;
    } else {
      EXPECT_EQ(r.id[r.index(x, y)], -1) << y;
      ++rejected;
    }
  }
  EXPECT_GT(hits, 2);
  EXPECT_GT(rejected, 2);
}

TEST(OracleSelf, EdgeDistanceIsPixelDistanceToTheOutline) {
  const auto cam = simple_camera(30, 30);
  // A vertical edge at x = 10.25 from y = 0 to y = 30, the triangle to its right.
  Triangle t = screen_triangle(cam, 10.25, -5, 10.25, 40, 60, 15, 3);
  const auto r = oracle::rasterize({t}, cam);
  for (int y = 5; y < 25; ++y) {
    EXPECT_NEAR(r.edge_distance[r.index(10, y)], 0.25, 1e-9);
    EXPECT_NEAR(r.edge_distance[r.index(9, y)], 0.75, 1e-9);
    EXPECT_EQ(r.edge_distance[r.index(5, y)], oracle::kFar);
    EXPECT_EQ(r.id[r.index(9, y)], -1);
    EXPECT_EQ(r.id[r.index(10, y)], 0);
  }
}

}  // namespace

// Property tests of the view pipeline (src/view): coverage against a double-precision reference,
// watertightness on closed meshes, extreme triangles without overflow (UBSan checks), validation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "view/view.h"

namespace {

using ml::Camera;
using ml::ScreenTriangle;
using ml::TriangleSetup;
using ml::Vec3i;
using ml::View;

struct D3 { double x, y, z; };

// The double-precision reference: same camera basis and focal length as the fixed-point View (so it
// tests clipping, projection and rasterization, not the accuracy of tan()), everything else in double.
struct Reference {
  D3 eye, right, down, forward;
  double focal, cx, cy, near;

  explicit Reference(const View& v) {
    const double one = double(ml::kUnitOne);
    eye = {double(v.eye.x), double(v.eye.y), double(v.eye.z)};
    right = {v.right.x / one, v.right.y / one, v.right.z / one};
    down = {v.down.x / one, v.down.y / one, v.down.z / one};
    forward = {v.forward.x / one, v.forward.y / one, v.forward.z / one};
    focal = double(v.focal_q8);  // subpixels per unit of x/z
    cx = v.center_x;
    cy = v.center_y;
    near = double(v.near) / (1 << ml::kViewFractionBits);
  }
  D3 to_view(const Vec3i& p) const {
    const D3 d{p.x - eye.x, p.y - eye.y, p.z - eye.z};
    auto dot = [&](const D3& a) { return a.x * d.x + a.y * d.y + a.z * d.z; };
    return {dot(right), dot(down), dot(forward)};
  }
  // Clips against the near plane, projects to subpixels. Returns the polygon (may be empty).
  std::vector<std::pair<double, double>> project(const Vec3i w[3]) const {
    std::vector<D3> in = {to_view(w[0]), to_view(w[1]), to_view(w[2])}, out;
    for (size_t i = 0; i < in.size(); ++i) {
      const D3 a = in[i], b = in[(i + 1) % in.size()];
      const double da = a.z - near, db = b.z - near;
      if (da >= 0) out.push_back(a);
      if ((da >= 0) != (db >= 0)) {
        const double t = da / (da - db);
        out.push_back({a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, near});
      }
    }
    std::vector<std::pair<double, double>> s;
    for (const D3& p : out) s.push_back({cx + focal * p.x / p.z, cy + focal * p.y / p.z});
    return s;
  }
};

// Inside test of a convex polygon (either orientation) and the distance to its nearest edge line.
struct Hit { bool inside; double edge_distance; };
Hit classify(const std::vector<std::pair<double, double>>& poly, double x, double y) {
  if (poly.size() < 3) return {false, 1e300};
  double area = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const auto& a = poly[i]; const auto& b = poly[(i + 1) % poly.size()];
    area += a.first * b.second - b.first * a.second;
  }
  if (area == 0) return {false, 1e300};
  bool inside = true;
  double nearest = 1e300;
  for (size_t i = 0; i < poly.size(); ++i) {
    const auto& a = poly[i]; const auto& b = poly[(i + 1) % poly.size()];
    const double ex = b.first - a.first, ey = b.second - a.second;
    const double len = std::hypot(ex, ey);
    if (len == 0) continue;
    const double side = (ex * (y - a.second) - ey * (x - a.first)) * (area > 0 ? 1 : -1);
    if (side < 0) inside = false;
    nearest = std::min(nearest, std::fabs(side) / len);
  }
  return {inside, nearest};
}

// Pixel centres covered by the fixed-point pipeline (all pieces, both facings).
std::vector<int> coverage(const View& view, const Vec3i w[3]) {
  std::vector<int> count(size_t(view.width) * view.height, 0);
  ScreenTriangle pieces[ml::kMaxClipTriangles];
  const int n = ml::project_triangle(view, w, pieces);
  for (int i = 0; i < n; ++i) {
    EXPECT_GT(pieces[i].area2, 0);
    TriangleSetup s;
    ml::setup_triangle(pieces[i], view.width, view.height, &s);
    for (int py = 0; py < view.height; ++py)
      for (int px = 0; px < view.width; ++px) {
        const bool in = ml::covers_pixel(s, px, py);
        if (in) {
          EXPECT_TRUE(px >= s.min_x && px <= s.max_x && py >= s.min_y && py <= s.max_y) << "bbox misses a covered pixel";
          ++count[size_t(py) * view.width + px];
        }
      }
  }
  return count;
}

View make(const Camera& c) {
  View v;
  const ml::Status st = ml::make_view(c, &v);
  EXPECT_TRUE(st.ok()) << st.message;
  return v;
}

Camera random_camera(std::mt19937_64& rng, int w, int h) {
  std::uniform_int_distribution<int32_t> pos(-70000, 70000);
  Camera c;
  c.width = w; c.height = h;
  c.eye = Vec3i{pos(rng), pos(rng), pos(rng)};
  do { c.target = Vec3i{pos(rng), pos(rng), pos(rng)}; } while (c.target.x == c.eye.x);
  c.up = Vec3i{0, 1, 0};
  c.fov_deg_q16 = int32_t((20 + rng() % 100) << 16);
  c.near = int32_t(1 + rng() % 2000);
  return c;
}

Vec3i random_point_near_view(std::mt19937_64& rng, const Camera& c, int kind) {
  // Points scattered around the line of sight at scales from tiny to huge.
  const int scale_bits = kind == 0 ? 4 : kind == 1 ? 12 : kind == 2 ? 17 : 22;
  std::uniform_int_distribution<int32_t> off(-(1 << scale_bits), 1 << scale_bits);
  std::uniform_real_distribution<double> along(-0.3, 2.0);
  const double t = along(rng);
  auto lerp = [&](int32_t a, int32_t b) { return int32_t(std::llround(a + (b - a) * t)); };
  Vec3i p{lerp(c.eye.x, c.target.x) + off(rng), lerp(c.eye.y, c.target.y) + off(rng),
          lerp(c.eye.z, c.target.z) + off(rng)};
  const int32_t lim = ml::kWorldLimit - 1;
  p.x = std::clamp(p.x, -lim, lim); p.y = std::clamp(p.y, -lim, lim); p.z = std::clamp(p.z, -lim, lim);
  return p;
}

TEST(ViewCoverage, MatchesDoubleReferenceAwayFromEdges) {
  std::mt19937_64 rng(2024);
  int compared = 0, covered = 0;
  for (int iter = 0; iter < 600; ++iter) {
    const Camera cam = random_camera(rng, 48, 36);
    const View view = make(cam);
    const Reference ref(view);
    Vec3i w[3];
    const int kind = iter % 4;
    for (auto& p : w) p = random_point_near_view(rng, cam, kind);
    if (iter % 50 == 0) w[2] = w[1];                 // degenerate
    if (iter % 50 == 1) w[2] = Vec3i{(w[0].x + w[1].x) / 2, (w[0].y + w[1].y) / 2, (w[0].z + w[1].z) / 2};
    const std::vector<int> cov = coverage(view, w);
    const auto poly = ref.project(w);
    for (int py = 0; py < view.height; ++py)
      for (int px = 0; px < view.width; ++px) {
        const Hit h = classify(poly, px * 256.0 + 128, py * 256.0 + 128);
        const int got = cov[size_t(py) * view.width + px];
        ASSERT_LE(got, 1) << "pieces of one triangle overlap at " << px << "," << py;
        if (h.edge_distance <= 1.0) continue;  // within one subpixel of an edge: either answer is right
        ++compared;
        covered += h.inside;
        ASSERT_EQ(got, h.inside ? 1 : 0) << "iter " << iter << " pixel " << px << "," << py << " dist "
                                         << h.edge_distance;
      }
  }
  EXPECT_GT(compared, 500000);
  EXPECT_GT(covered, 20000);
}

// A closed box around the eye: every ray from the eye leaves it exactly once, so the union of all
// (clipped, projected) triangles must cover every pixel centre exactly once — no cracks along shared
// edges, no double coverage, near-plane and guard-band clipping included.
TEST(ViewCoverage, ClosedMeshAroundEyeCoversEverySampleExactlyOnce) {
  std::mt19937_64 rng(99);
  for (int iter = 0; iter < 12; ++iter) {
    const int32_t half = 20000 + int32_t(rng() % 30000);
    const int n = 6 + int(rng() % 6);  // grid cells per face side
    // Shared jittered grid per face: vertices on face edges are shared exactly between faces.
    auto grid_point = [&](int face, int i, int j) -> Vec3i {
      auto coord = [&](int k) {
        if (k == 0) return -half;
        if (k == n) return half;
        // deterministic jitter from (face-independent) position so shared border vertices agree
        const uint32_t h = uint32_t(k * 2654435761u) ^ uint32_t(iter * 40503u);
        return -half + int32_t(int64_t(2 * half) * k / n) + int32_t(h % 997) - 498;
      };
      const int32_t a = coord(i), b = coord(j);
      switch (face) {
        case 0: return Vec3i{half, a, b};
        case 1: return Vec3i{-half, a, b};
        case 2: return Vec3i{a, half, b};
        case 3: return Vec3i{a, -half, b};
        case 4: return Vec3i{a, b, half};
        default: return Vec3i{a, b, -half};
      }
    };
    Camera cam;
    cam.width = 64; cam.height = 48;
    std::uniform_int_distribution<int32_t> inside(-half / 2, half / 2);
    cam.eye = Vec3i{inside(rng), inside(rng), inside(rng)};
    cam.target = Vec3i{inside(rng), inside(rng), inside(rng)};
    if (cam.target.x == cam.eye.x && cam.target.z == cam.eye.z) cam.target.x += 100;
    cam.up = Vec3i{int32_t(rng() % 5) - 2, 10, int32_t(rng() % 5) - 2};
    cam.fov_deg_q16 = int32_t((40 + rng() % 50) << 16);
    cam.near = 50;  // far below half / 2 * cos(diagonal half angle)
    const View view = make(cam);
    std::vector<int> total(size_t(cam.width) * cam.height, 0);
    for (int face = 0; face < 6; ++face)
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const Vec3i a = grid_point(face, i, j), b = grid_point(face, i + 1, j);
          const Vec3i c = grid_point(face, i + 1, j + 1), d = grid_point(face, i, j + 1);
          const bool flip = (i + j + face) % 2;  // mix both diagonal directions
          const Vec3i t1[3] = {a, b, flip ? d : c};
          const Vec3i t2[3] = {flip ? b : a, c, d};
          const auto c1 = coverage(view, t1), c2 = coverage(view, t2);
          for (size_t k = 0; k < total.size(); ++k) total[k] += c1[k] + c2[k];
        }
    for (size_t k = 0; k < total.size(); ++k)
      ASSERT_EQ(total[k], 1) << "iter " << iter << " pixel " << k % cam.width << "," << k / cam.width;
  }
}

TEST(ViewCoverage, SharedEdgesOfRandomFansAreWatertight) {
  // Fans of triangles around a centre point on screen, with random rims partly behind the eye and
  // far outside the screen: the fan's interior samples are covered exactly once.
  std::mt19937_64 rng(7);
  for (int iter = 0; iter < 200; ++iter) {
    const Camera cam = random_camera(rng, 40, 30);
    const View view = make(cam);
    const int kind = 1 + iter % 3;
    const Vec3i centre = random_point_near_view(rng, cam, 0);
    const int spokes = 3 + int(rng() % 8);
    std::vector<Vec3i> rim;
    for (int i = 0; i < spokes; ++i) rim.push_back(random_point_near_view(rng, cam, kind));
    std::vector<int> total(size_t(cam.width) * cam.height, 0);
    for (int i = 0; i < spokes; ++i) {
      const Vec3i t[3] = {centre, rim[i], rim[(i + 1) % spokes]};
      const auto c = coverage(view, t);
      for (size_t k = 0; k < total.size(); ++k) total[k] += c[k];
    }
    // Where two neighbouring triangles overlap in projection (a non-convex fan folds over) counts
    // of 2 are legitimate; what must never happen is a sample on a shared edge counted by both or
    // by neither. Check the shared-edge property directly: for each spoke, samples on its line
    // segment near the centre are covered by exactly one of its two triangles when both lie on
    // opposite sides of the spoke.
    for (int i = 0; i < spokes; ++i) {
      const Vec3i left[3] = {centre, rim[(i + spokes - 1) % spokes], rim[i]};
      const Vec3i right[3] = {centre, rim[i], rim[(i + 1) % spokes]};
      ScreenTriangle pl[ml::kMaxClipTriangles], pr[ml::kMaxClipTriangles];
      const int nl = ml::project_triangle(view, left, pl), nr = ml::project_triangle(view, right, pr);
      if (nl == 0 || nr == 0) continue;
      // Same facing means they lie on opposite sides of the shared spoke.
      if (pl[0].front_facing != pr[0].front_facing) continue;
      const auto cl = coverage(view, left), cr = coverage(view, right);
      for (size_t k = 0; k < cl.size(); ++k) ASSERT_LE(cl[k] + cr[k], 1) << "double coverage on a shared edge";
    }
  }
}

TEST(ViewExtremes, HugeTinyAndBehindTrianglesStayInRange) {
  // UBSan (the test build) reports any signed overflow; also checks that every output is in range.
  std::mt19937_64 rng(1);
  const int32_t lim = ml::kWorldLimit - 1;
  for (int iter = 0; iter < 20000; ++iter) {
    Camera cam;
    cam.width = 1 + int(rng() % ml::kMaxScreenDim);
    cam.height = 1 + int(rng() % ml::kMaxScreenDim);
    std::uniform_int_distribution<int32_t> any(-lim, lim);
    cam.eye = Vec3i{any(rng), any(rng), any(rng)};
    cam.target = Vec3i{any(rng), any(rng), any(rng)};
    cam.fov_deg_q16 = int32_t((1 + rng() % 170) << 16);
    cam.near = int32_t(1 + rng() % ((1 << 26) - 1));
    if (iter % 3 == 0) cam.near = 1;
    View view;
    if (!ml::make_view(cam, &view).ok()) continue;
    Vec3i w[3];
    for (auto& p : w) p = Vec3i{any(rng), any(rng), any(rng)};
    if (iter % 4 == 1) for (auto& p : w) p = Vec3i{cam.eye.x + int32_t(rng() % 5) - 2, cam.eye.y + int32_t(rng() % 5) - 2, cam.eye.z + int32_t(rng() % 5) - 2};
    if (iter % 4 == 2) w[0] = cam.eye;
    for (auto& p : w) { p.x = std::clamp(p.x, -lim, lim); p.y = std::clamp(p.y, -lim, lim); p.z = std::clamp(p.z, -lim, lim); }
    ScreenTriangle out[ml::kMaxClipTriangles];
    const int n = ml::project_triangle(view, w, out);
    ASSERT_LE(n, ml::kMaxClipTriangles);
    for (int i = 0; i < n; ++i) {
      TriangleSetup s;
      ml::setup_triangle(out[i], view.width, view.height, &s);
      for (const auto& v : out[i].v) {
        ASSERT_LT(std::abs(v.x), 1 << 22);
        ASSERT_LT(std::abs(v.y), 1 << 22);
        ASSERT_GE(v.z, view.near);
        ASSERT_LE(v.depth, ml::kDepthNear);
        ASSERT_GT(v.depth, 0u);
        ASSERT_GE(v.weight[0] + v.weight[1] + v.weight[2], ml::kWeightOne - 4);
        ASSERT_LE(v.weight[0] + v.weight[1] + v.weight[2], ml::kWeightOne + 4);
      }
      // Edge functions at every corner of the screen stay far from overflow.
      for (int64_t x : {int64_t(0), int64_t(view.width) * 256}) for (int64_t y : {int64_t(0), int64_t(view.height) * 256})
        for (const auto& e : s.edge) ASSERT_LT(std::llabs(e.at(x, y)), int64_t(1) << 47);
    }
  }
}

TEST(ViewFacing, ExactSignOfTheTripleProduct) {
  std::mt19937_64 rng(12);
  const int32_t lim = ml::kWorldLimit - 1;
  int front = 0, back = 0, zero = 0;
  for (int iter = 0; iter < 200000; ++iter) {
    Camera cam;
    cam.width = 32; cam.height = 32;
    const int bits = 1 + int(rng() % 24);
    std::uniform_int_distribution<int32_t> any(-(1 << bits) + 1, (1 << bits) - 1);
    cam.eye = Vec3i{any(rng), any(rng), any(rng)};
    cam.target = Vec3i{cam.eye.x + 1000, cam.eye.y + 7, cam.eye.z - 3};
    if (std::abs(cam.target.x) >= ml::kWorldLimit) cam.target.x = cam.eye.x - 1000;
    View v;
    ASSERT_TRUE(ml::make_view(cam, &v).ok());
    Vec3i w[3];
    for (auto& p : w) p = Vec3i{any(rng), any(rng), any(rng)};
    if (iter % 7 == 0) w[2] = Vec3i{w[0].x + (w[1].x - w[0].x) / 2, w[0].y + (w[1].y - w[0].y) / 2, w[0].z + (w[1].z - w[0].z) / 2};
    if (iter % 11 == 0) w[0] = cam.eye;  // eye in the plane
    if (iter % 5 == 0) { w[0].x = lim; w[1].y = -lim; }
    const __int128 e1[3] = {(__int128)w[1].x - w[0].x, (__int128)w[1].y - w[0].y, (__int128)w[1].z - w[0].z};
    const __int128 e2[3] = {(__int128)w[2].x - w[0].x, (__int128)w[2].y - w[0].y, (__int128)w[2].z - w[0].z};
    const __int128 r[3] = {(__int128)cam.eye.x - w[0].x, (__int128)cam.eye.y - w[0].y, (__int128)cam.eye.z - w[0].z};
    const __int128 det = (e1[1] * e2[2] - e1[2] * e2[1]) * r[0] + (e1[2] * e2[0] - e1[0] * e2[2]) * r[1] +
                         (e1[0] * e2[1] - e1[1] * e2[0]) * r[2];
    const int expect = det > 0 ? 1 : det < 0 ? -1 : 0;
    ASSERT_EQ(ml::triangle_facing(v, w), expect) << iter;
    front += expect > 0; back += expect < 0; zero += expect == 0;
  }
  EXPECT_GT(front, 50000); EXPECT_GT(back, 50000); EXPECT_GT(zero, 1000);
}

TEST(ViewFacing, AgreesWithScreenOrientationOfLargeTriangles) {
  std::mt19937_64 rng(13);
  int checked = 0;
  for (int iter = 0; iter < 3000; ++iter) {
    const Camera cam = random_camera(rng, 64, 48);
    const View view = make(cam);
    Vec3i w[3];
    for (auto& p : w) p = random_point_near_view(rng, cam, 2);
    ScreenTriangle out[ml::kMaxClipTriangles];
    const int n = ml::project_triangle(view, w, out);
    const int facing = ml::triangle_facing(view, w);
    for (int i = 0; i < n; ++i) {
      EXPECT_EQ(out[i].front_facing, facing > 0);
      if (n != 1 || out[i].area2 < (int64_t(1) << 24)) continue;  // clipped, or a sliver snapping may flip
      // Unclipped: each vertex's weights name its original vertex. An odd permutation means orient()
      // swapped the order, i.e. the original order was counter-clockwise as seen by the viewer.
      int perm[3] = {-1, -1, -1};
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j)
          if (out[i].v[k].weight[j] == ml::kWeightOne) perm[k] = j;
      if (perm[0] < 0 || perm[1] < 0 || perm[2] < 0) continue;  // one piece left by clipping
      const bool odd = !((perm[0] == 0 && perm[1] == 1) || (perm[0] == 1 && perm[1] == 2) || (perm[0] == 2 && perm[1] == 0));
      EXPECT_EQ(odd, facing > 0) << iter;
      ++checked;
    }
  }
  EXPECT_GT(checked, 500);
}

// triangle_row_span is triangle_outside_rows worked out once: for every row range the two agree, on
// triangles at every scale (behind the near plane too) and row ranges on and far off the screen; and
// both give the same from the triangle's view-space points (view_row_span, view_outside_rows).
TEST(ViewRows, RowSpanAgreesWithTheBandTest) {
  std::mt19937_64 rng(29);
  int spans = 0, outside = 0, inside = 0;
  for (int iter = 0; iter < 4000; ++iter) {
    const Camera cam = random_camera(rng, 64, 48);
    const View view = make(cam);
    Vec3i w[3];
    const int kind = int(rng() % 4);
    for (auto& p : w) p = random_point_near_view(rng, cam, kind);
    int64_t first = 0, last = 0;
    const bool known = ml::triangle_row_span(view, w, &first, &last);
    spans += known;
    // The same answers from the triangle's view-space points (what the tiler's vertex cache holds).
    ml::ViewTriangle t;
    ml::view_triangle(view, w, &t);
    int64_t view_first = 0, view_last = 0;
    ASSERT_EQ(ml::view_row_span(view, t.p, &view_first, &view_last), known) << iter;
    if (known) {
      EXPECT_EQ(view_first, first) << iter;
      EXPECT_EQ(view_last, last) << iter;
    }
    for (int k = 0; k < 12; ++k) {
      const int32_t row0 = int32_t(rng() % 90) - 20, row1 = row0 + int32_t(rng() % 20);
      const bool out = ml::triangle_outside_rows(view, w, row0, row1);
      EXPECT_EQ(out, known && (row1 < first || row0 > last)) << iter << " rows " << row0 << ".." << row1;
      EXPECT_EQ(ml::view_outside_rows(view, t.p, row0, row1), out) << iter;
      (out ? outside : inside)++;
    }
    // The span's edges are tight: its first and last rows are kept.
    const int64_t lim = int64_t(1) << 28;
    if (known && first <= last && first > -lim && last < lim) {
      EXPECT_FALSE(ml::triangle_outside_rows(view, w, int32_t(first), int32_t(first))) << iter;
      EXPECT_FALSE(ml::triangle_outside_rows(view, w, int32_t(last), int32_t(last))) << iter;
    }
  }
  EXPECT_GT(spans, 1500);
  EXPECT_GT(outside, 5000);
  EXPECT_GT(inside, 5000);
}

TEST(ViewCamera, RejectsBadCameras) {
  View v;
  Camera c;
  c.width = 64; c.height = 48; c.eye = Vec3i{0, 0, 10}; c.target = Vec3i{0, 0, 0};
  EXPECT_TRUE(ml::make_view(c, &v).ok());
  Camera bad = c; bad.width = 0;
  EXPECT_EQ(ml::make_view(bad, &v).code, ml::StatusCode::InvalidArgument);
  bad = c; bad.height = ml::kMaxScreenDim + 1;
  EXPECT_FALSE(ml::make_view(bad, &v).ok());
  bad = c; bad.target = bad.eye;
  EXPECT_FALSE(ml::make_view(bad, &v).ok());
  bad = c; bad.up = Vec3i{0, 0, 5};  // parallel to the view direction
  EXPECT_FALSE(ml::make_view(bad, &v).ok());
  bad = c; bad.fov_deg_q16 = 171 << 16;
  EXPECT_FALSE(ml::make_view(bad, &v).ok());
  bad = c; bad.near = 0;
  EXPECT_FALSE(ml::make_view(bad, &v).ok());
  bad = c; bad.eye.x = ml::kWorldLimit;
  EXPECT_FALSE(ml::make_view(bad, &v).ok());
}

TEST(ViewCamera, BasisIsOrthonormalRightHandedYDown) {
  Camera c;
  c.width = 100; c.height = 50; c.eye = Vec3i{0, 0, 1000}; c.target = Vec3i{0, 0, 0};
  View v;
  ASSERT_TRUE(ml::make_view(c, &v).ok());
  const int32_t one = ml::kUnitOne;
  EXPECT_NEAR(v.right.x, one, 2); EXPECT_NEAR(v.down.y, -one, 2); EXPECT_NEAR(v.forward.z, -one, 2);
  // A point up and to the right of the target projects up (smaller y) and right of the centre.
  const Vec3i tri[3] = {Vec3i{100, 100, 0}, Vec3i{110, 100, 0}, Vec3i{100, 110, 0}};
  ScreenTriangle out[ml::kMaxClipTriangles];
  ASSERT_EQ(ml::project_triangle(v, tri, out), 1);
  for (const auto& p : out[0].v) { EXPECT_GT(p.x, v.center_x); EXPECT_LT(p.y, v.center_y); }
  EXPECT_TRUE(out[0].front_facing);  // counter-clockwise seen from +z
  const Vec3i back[3] = {tri[0], tri[2], tri[1]};
  ASSERT_EQ(ml::project_triangle(v, back, out), 1);
  EXPECT_FALSE(out[0].front_facing);
  // Focal length: 45 degrees vertical on 50 pixels is 25 / tan(22.5) = 60.355 pixels.
  EXPECT_NEAR(double(v.focal_q8) / 256, 60.355, 0.02);
}

TEST(ViewCamera, FrameSphereKeepsTheSphereOnScreen) {
  std::mt19937_64 rng(4);
  for (int iter = 0; iter < 200; ++iter) {
    const Vec3i centre{int32_t(rng() % 20000) - 10000, int32_t(rng() % 20000) - 10000, int32_t(rng() % 20000) - 10000};
    const int32_t radius = 100 + int32_t(rng() % 120000);
    const int w = 16 + int(rng() % 600), h = 16 + int(rng() % 600);
    const Camera c = ml::frame_sphere(centre, radius, w, h, int32_t((30 + rng() % 60) << 16));
    View v;
    ASSERT_TRUE(ml::make_view(c, &v).ok());
    // Six extreme points of the sphere project inside the screen and in front of the near plane.
    for (int axis = 0; axis < 3; ++axis)
      for (int sign : {-1, 1}) {
        Vec3i p = centre;
        (axis == 0 ? p.x : axis == 1 ? p.y : p.z) += sign * radius;
        const Vec3i tri[3] = {p, Vec3i{p.x + 1, p.y, p.z}, Vec3i{p.x, p.y + 1, p.z + 1}};
        const Reference ref(v);
        const D3 q = ref.to_view(p);
        ASSERT_GT(q.z, ref.near);
        const double sx = ref.cx + ref.focal * q.x / q.z, sy = ref.cy + ref.focal * q.y / q.z;
        EXPECT_GE(sx, 0); EXPECT_LE(sx, w * 256.0); EXPECT_GE(sy, 0); EXPECT_LE(sy, h * 256.0);
        (void)tri;
      }
  }
}

TEST(ViewCamera, FrameSphereWorksForEverySize) {
  // The compiler's largest sphere (radius sqrt(3) * 2^16) at the origin and off it: very narrow or
  // very short images used to put the eye outside the world range.
  const std::vector<int> sides = {1, 2, 3, 7, 45, 89, 90, 100, 240, 1000, 2047, 4095, 4096};
  // Also the extremes read_scene accepts (centre below 2^18, radius below 2^20).
  for (const Vec3i centre : {Vec3i{0, 0, 0}, Vec3i{65536, -65536, 65536}, Vec3i{ml::kSceneLimit - 1, 1 - ml::kSceneLimit, 0}})
    for (int32_t radius : {1, 1000, 113512, ml::kRadiusLimit - 1})
      for (int fov : {1, 45, 170})
        for (int w : sides)
          for (int h : sides) {
            const Camera c = ml::frame_sphere(centre, radius, w, h, int32_t(fov << 16));
            View v;
            const ml::Status s = ml::make_view(c, &v);
            ASSERT_TRUE(s.ok()) << w << "x" << h << " radius " << radius << " fov " << fov << ": " << s.message;
          }
}

}  // namespace

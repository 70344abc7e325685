// Reference rasterizer: see oracle.h. Deliberately simple: per triangle, clip against the near plane
// only to find the screen bounding box and the projected edges, then cast a ray through every pixel
// centre in that box (Moller-Trumbore) and keep the two nearest hits per pixel.
#include "tests/oracle/oracle.h"
#include "tests/oracle/vec3_math.h"

#include <algorithm>
#include <cmath>

namespace oracle {
namespace {

struct Point2 {
  double x, y;
};

double segment_distance(const Point2& p, const Point2& a, const Point2& b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double ex = a.x + t * dx - p.x, ey = a.y + t * dy - p.y;
  return std::sqrt(ex * ex + ey * ey);
}

}  // namespace

Result rasterize(const std::vector<Triangle>& triangles, const Camera& cam, const Options& options) {
  Result r;
  r.width = cam.width;
  r.height = cam.height;
  const size_t n = size_t(cam.width) * size_t(cam.height);
  r.id.assign(n, -1);
  r.edge_distance.assign(n, kFar);
  r.ambiguous.assign(n, 0);
  r.depth_gap.assign(n, kFar);
  r.second_id.assign(n, -1);
  std::vector<double> z1(n, INFINITY), z2(n, INFINITY);
  struct NearCover {
    size_t pixel;
    size_t triangle;
    double depth;
  };
  std::vector<NearCover> near_covers;

  const Vec3 forward = normalized(sub(cam.target, cam.eye));
  const Vec3 right = normalized(cross(forward, cam.up));
  const Vec3 down = cross(forward, right);
  const double focal = (cam.height / 2.0) / std::tan(cam.vfov_deg * M_PI / 360.0);
  const double cx = cam.width / 2.0 - cam.shift_x, cy = cam.height / 2.0 - cam.shift_y;

  for (size_t t = 0; t < triangles.size(); ++t) {
    const Triangle& tri = triangles[t];
    // View space: x right, y down, z forward.
    Vec3 view[3];
    for (int i = 0; i < 3; ++i) {
      const Vec3 d = sub(tri.v[i], cam.eye);
      view[i] = {dot(d, right), dot(d, down), dot(d, forward)};
    }
    // Clip against z >= near (Sutherland-Hodgman).
    Vec3 poly[4];
    int count = 0;
    for (int i = 0; i < 3; ++i) {
      const Vec3& a = view[i];
      const Vec3& b = view[(i + 1) % 3];
      const bool a_in = a.z >= cam.near, b_in = b.z >= cam.near;
      if (a_in) poly[count++] = a;
      if (a_in != b_in) {
        const double s = (cam.near - a.z) / (b.z - a.z);
        poly[count++] = add(a, scale(sub(b, a), s));
      }
    }
    if (count < 3) continue;
    Point2 screen[4];
    double min_x = INFINITY, max_x = -INFINITY, min_y = INFINITY, max_y = -INFINITY;
    for (int i = 0; i < count; ++i) {
      screen[i] = {cx + focal * poly[i].x / poly[i].z, cy + focal * poly[i].y / poly[i].z};
      min_x = std::min(min_x, screen[i].x);
      max_x = std::max(max_x, screen[i].x);
      min_y = std::min(min_y, screen[i].y);
      max_y = std::max(max_y, screen[i].y);
    }
    const double m = options.edge_margin;
    if (max_x < -m || max_y < -m || min_x > cam.width + m || min_y > cam.height + m) continue;
    const int x0 = std::max(0, int(std::floor(std::max(min_x, -1.0) - m)));
    const int x1 = std::min(cam.width - 1, int(std::ceil(std::min(max_x, cam.width + 1.0) + m)));
    const int y0 = std::max(0, int(std::floor(std::max(min_y, -1.0) - m)));
    const int y1 = std::min(cam.height - 1, int(std::ceil(std::min(max_y, cam.height + 1.0) + m)));

    const Vec3 e1 = sub(tri.v[1], tri.v[0]);
    const Vec3 e2 = sub(tri.v[2], tri.v[0]);
    const Vec3 normal = cross(e1, e2);
    for (int py = y0; py <= y1; ++py) {
      for (int px = x0; px <= x1; ++px) {
        const size_t i = r.index(px, py);
        const Point2 c{px + 0.5, py + 0.5};
        // Distance to the projected (near-clipped) outline.
        double outline = kFar;
        for (int k = 0; k < count; ++k) {
          const double d = segment_distance(c, screen[k], screen[(k + 1) % count]);
          outline = std::min(outline, d);
          if (d <= m && d < r.edge_distance[i]) r.edge_distance[i] = d;
        }
        // Ray through the pixel centre, scaled so that its forward component is 1: t = view depth.
        const Vec3 dir = add(forward, add(scale(right, (c.x - cx) / focal), scale(down, (c.y - cy) / focal)));
        const double facing = dot(normal, dir);  // < 0: the counter-clockwise side faces the eye
        if (!(facing < 0) && !tri.double_sided) continue;
        const Vec3 p = cross(dir, e2);
        const double det = dot(e1, p);
        if (det == 0 || !std::isfinite(det)) continue;
        const double inv = 1.0 / det;
        const Vec3 s = sub(cam.eye, tri.v[0]);
        const double u = dot(s, p) * inv;
        const Vec3 q = cross(s, e1);
        const double v = dot(dir, q) * inv;
        const double z = dot(e2, q) * inv;  // depth of the triangle's plane along the ray
        if (u < 0 || u > 1 || v < 0 || u + v > 1) {
          if (outline <= options.near_cover && z >= cam.near) near_covers.push_back({i, t, z});
          continue;
        }
        if (!(z >= cam.near)) continue;
        if (z < z1[i]) {
          z2[i] = z1[i];
          r.second_id[i] = r.id[i];
          z1[i] = z;
          r.id[i] = int64_t(t);
        } else if (z < z2[i]) {
          z2[i] = z;
          r.second_id[i] = int64_t(t);
        }
      }
    }
  }
  // Ties with nearly covering triangles; two triangles sharing an edge never both cover a sample
  // (the fill rule), so they cannot tie.
  auto share_edge = [&](size_t a, size_t b) {
    int same = 0;
    for (const Vec3& va : triangles[a].v)
      for (const Vec3& vb : triangles[b].v) same += va.x == vb.x && va.y == vb.y && va.z == vb.z;
    return same >= 2;
  };
  for (const NearCover& nc : near_covers) {
    const size_t i = nc.pixel;
    if (r.id[i] < 0 || size_t(r.id[i]) == nc.triangle) continue;
    if (std::fabs(nc.depth - z1[i]) <= options.depth_tie * z1[i] && !share_edge(size_t(r.id[i]), nc.triangle))
      r.ambiguous[i] = 1;
  }
  for (size_t i = 0; i < n; ++i) {
    if (r.id[i] < 0 || !std::isfinite(z2[i])) continue;
    r.depth_gap[i] = (z2[i] - z1[i]) / z1[i];
    if (z2[i] - z1[i] <= options.depth_tie * z1[i]) r.ambiguous[i] = 1;
  }
  return r;
}

}  // namespace oracle

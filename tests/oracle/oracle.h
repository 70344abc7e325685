// An independent double-precision reference rasterizer, used only as a test oracle. It shares no
// code with src/: it casts one ray per pixel centre against world-space triangles and keeps the
// nearest hit. Conventions it must agree with (written in src/view/view.h): pixel (x, y) covers
// [x, x+1) x [y, y+1), y down, samples at centres; the camera looks from eye to target with
// right = forward x up, down = forward x right; focal length (height / 2) / tan(vfov / 2); glTF
// front faces are counter-clockwise seen from the front; hits nearer than `near` (view depth) are
// rejected, as near-plane clipping does.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include <vector>

namespace oracle {

struct Vec3 {
  double x, y, z;
};

struct Triangle {
  Vec3 v[3];
  bool double_sided = false;
};

struct Camera {
  Vec3 eye{0, 0, 0}, target{0, 0, -1}, up{0, 1, 0};
  double vfov_deg = 45;
  int width = 0, height = 0;
  double near = 1;
  // Pixel (x, y) casts its ray through (x + 0.5 + shift_x, y + 0.5 + shift_y) of the unshifted picture
  // (src/view's Camera::sample_shift, in pixels).
  double shift_x = 0, shift_y = 0;
};

struct Options {
  // Two hits tie when their view depths differ by at most this fraction of the nearer one.
  double depth_tie = 1e-4;
  // Edge distances are exact up to this many pixels; farther ones are reported as `kFar`.
  double edge_margin = 1.0;
  // A triangle whose outline passes within this many pixels of a centre it does not contain may still
  // cover that sample in fixed point; if its plane is then at the front triangle's depth (a contact,
  // not a shared edge) the pixel is a tie too.
  double near_cover = 1.0 / 16.0;
};

constexpr double kFar = 1e30;

struct Result {
  int width = 0, height = 0;
  std::vector<int64_t> id;             // per pixel: nearest covering triangle's index, -1 = background
  std::vector<double> edge_distance;   // per pixel: pixels from the centre to the nearest projected edge
  std::vector<uint8_t> ambiguous;      // per pixel: the front surface is a depth tie (between two hits,
                                       // or with a nearly covering triangle that shares no edge with it)
  std::vector<double> depth_gap;       // per pixel: (second depth - first) / first, kFar if < 2 hits
  std::vector<int64_t> second_id;      // per pixel: the second-nearest hit's triangle, -1 if none

  size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
  // Whether the pixel's answer is well defined: away from every edge and no depth tie.
  bool decisive(int x, int y, double min_edge_distance) const {
    const size_t i = index(x, y);
    return edge_distance[i] > min_edge_distance && !ambiguous[i];
  }
};

Result rasterize(const std::vector<Triangle>& triangles, const Camera& camera, const Options& options = Options{});

}  // namespace oracle

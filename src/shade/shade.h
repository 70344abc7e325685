// Shading shared by both renderers, so that the same triangle gets the same colour from either.
// Intensities are Q8 (256 = 1.0). One directional light plus ambient, integer Lambert.
#pragma once
#include <stdint.h>

#include "core/fixed.h"
#include "core/options.h"
#include "core/sink.h"
#include "scene/scene.h"
#include "view/view.h"

namespace ml {


struct Light {
  Vec3i to_light;      // Q1.30 unit vector, world space, pointing towards the light
  int32_t ambient_q8;  // added to every surface
  int32_t diffuse_q8;  // scaled by max(0, N.L)
};

// A light over the viewer's left shoulder, so the default view shows three distinct face tones.
Light make_light(const View& view);

// Q1.30 unit normal of a world-space triangle (counter-clockwise front); zero vector if degenerate.
Vec3i face_normal(const Vec3i world[3]);

// The face's Lambert term (lambert_q8 of its normal, negated when !front_facing: a double-sided
// triangle seen from behind) as N.L / |N| from the cross product itself: one square root and one
// division, where the unit normal takes a square root and three. Flat shading's colour, and Gouraud's
// for vertices without normals. Within half a step of the exact value; lambert_q8(face_normal) gives
// the same value but for about 1 in 100,000 faces, one step further from it (tests/shade).
int32_t face_lambert_q8(const Light& light, const Vec3i world[3], bool front_facing);

// Ambient + diffuse * max(0, N.L), Q8, for a Q1.30 normal.
int32_t lambert_q8(const Light& light, const Vec3i& normal_q30);

// base * intensity, per channel, saturated.
Pixel modulate(const uint8_t base_rgba[4], int32_t intensity_q8);

// Colours of one triangle for a shading mode. `smooth` is true when the vertex colours differ and
// must be interpolated (Gouraud); otherwise every pixel gets `flat`.
struct TriangleColors {
  Pixel flat;
  Pixel vertex[3];
  bool smooth;
};
// world: the triangle's world vertices (triangle_world) when the caller has them, else read here.
void shade_triangle(const Scene& scene, const Light& light, ShadingMode mode, uint32_t triangle_id,
                    bool front_facing, TriangleColors* out, const Vec3i* world = nullptr);

// A quantity linear in screen space, evaluated at pixel centres:
//   value(px, py) = (origin + step_x * px + step_y * py) >> kPlaneBits
// Ranges: inputs |v| < 2^16; slopes are bounded by 2^20 per pixel (exact for anything wider than
// 1/16 pixel); inside the guard band every term stays below 2^62. kPlaneBits: core/fixed.h.
struct LinearPlane {
  int64_t origin, step_x, step_y;
  int32_t at(int32_t px, int32_t py) const {
    return int32_t((origin + step_x * px + step_y * py) >> kPlaneBits);
  }
};
// The plane through (v[i].x, v[i].y, values[i]) of a projected triangle.
LinearPlane make_plane(const ScreenTriangle& tri, const int32_t values[3]);

// c[0] w[0] + c[1] w[1] + c[2] w[2] per channel, weights Q16 summing to 65536, rounded and saturated.
Pixel blend_colors(const Pixel c[3], const int32_t w[3]);
// blend_colors inline, for a loop of samples (the scanline renderer's Gouraud runs; blend_colors is
// its one out-of-line copy), its channels unrolled on 64-bit hosts.
inline Pixel blend_colors_inline(const Pixel c[3], const int32_t w[3]) {
  uint32_t out = 0;
  ML_HOST_UNROLL for (int shift = 16; shift >= 0; shift -= 8) {
    int64_t sum = 0;
    ML_HOST_UNROLL for (int k = 0; k < 3; ++k) sum += int64_t((c[k] >> shift) & 0xFF) * w[k];
    out |= uint32_t(clamp_to<int64_t>(shift_round(sum, kWeightBits), 0, 255)) << shift;
  }
  return out;
}

// The colour of piece vertex i of a projected triangle, from the original triangle's vertex colours
// and the piece vertex's barycentric weights.
Pixel blend_vertex_color(const TriangleColors& colors, const ScreenVertex& v);

// Red, green and blue planes of a smooth triangle piece (the renderer evaluates them per pixel).
struct ColorPlanes {
  LinearPlane channel[3];
  Pixel at(int32_t px, int32_t py) const;
};
void make_color_planes(const ScreenTriangle& piece, const TriangleColors& colors, ColorPlanes* out);

// ColorPlanes::at stepped along a row from pixel (x, y): the same sums, shifts and clamp, one addition
// a channel a pixel.
class ColorPlanesRow {
 public:
  ColorPlanesRow(const ColorPlanes& planes, int64_t x, int64_t y) : planes_(planes) {
    ML_HOST_UNROLL for (int c = 0; c < 3; ++c) {
      const LinearPlane& p = planes.channel[c];
      acc_[c] = p.origin + p.step_x * x + p.step_y * y;
    }
  }
  // The current pixel's colour.
  Pixel colour() const {
    uint32_t ch[3];
    ML_HOST_UNROLL for (int c = 0; c < 3; ++c) ch[c] = uint32_t(clamp_to(int32_t(acc_[c] >> kPlaneBits), 0, 255));
    return rgb(ch[0], ch[1], ch[2]);
  }
  // On to the next pixel of the row.
  void step() {
    ML_HOST_UNROLL for (int c = 0; c < 3; ++c) acc_[c] += planes_.channel[c].step_x;
  }

 private:
  const ColorPlanes& planes_;
  int64_t acc_[3];
};

}  // namespace ml

#include "shade/shade.h"

#include "core/build.h"

namespace ml {
namespace {

Vec3i negate(const Vec3i& v) { return Vec3i{-v.x, -v.y, -v.z}; }

// Adds weighted unit vectors (weights are small integers) into a direction.
Vec3i combine(const Vec3i& a, int wa, const Vec3i& b, int wb, const Vec3i& c, int wc) {
  return Vec3i{int32_t((int64_t(a.x) * wa + int64_t(b.x) * wb + int64_t(c.x) * wc) / 16),
               int32_t((int64_t(a.y) * wa + int64_t(b.y) * wb + int64_t(c.y) * wc) / 16),
               int32_t((int64_t(a.z) * wa + int64_t(b.z) * wb + int64_t(c.z) * wc) / 16)};
}

}  // namespace

Light make_light(const View& view) {
  Light light;
  // Towards the light: up (-down), to the left (-right) and back towards the viewer (-forward).
  const Vec3i dir = combine(negate(view.down), 10, negate(view.right), 6, negate(view.forward), 7);
  if (!normalize_q30(dir, &light.to_light)) light.to_light = negate(view.forward);
  light.ambient_q8 = 72;
  light.diffuse_q8 = 200;
  return light;
}

namespace {

// Ambient + diffuse * cosine, Q8, for a Q1.30 cosine >= 0 (lambert_q8 and face_lambert_q8).
int32_t lambert_of_cosine(const Light& light, int64_t cosine_q30) {
  return int32_t(light.ambient_q8 + mul_shift(light.diffuse_q8, cosine_q30, kUnitBits));
}

// The face's cross product (counter-clockwise front) scaled by a power of two so that its largest
// component has 30 bits (|N| >= 2^29: its square root loses at most 2^-29 of it); false when the
// triangle is degenerate. normalize_q30 gives the same unit vector for it as for the unscaled product
// (it keeps 21 bits, taken here by the same floors).
bool face_cross(const Vec3i world[3], Vec3i* out) {
  // World points lie within ±2^24: differences within ±2^25, products within ±2^50 (32 x 32 bits).
  const int32_t ax = world[1].x - world[0].x, ay = world[1].y - world[0].y, az = world[1].z - world[0].z;
  const int32_t bx = world[2].x - world[0].x, by = world[2].y - world[0].y, bz = world[2].z - world[0].z;
  const auto product = [](int32_t a, int32_t b) { return int64_t(a) * b; };
  const int64_t n[3] = {product(ay, bz) - product(az, by), product(az, bx) - product(ax, bz),
                        product(ax, by) - product(ay, bx)};
  const uint64_t largest = max_of(magnitude(n[0]), max_of(magnitude(n[1]), magnitude(n[2])));
  if (largest == 0) return false;
  // floor(c 2^(30 - b)) for b = bit_length(largest) <= 52, up or down, as the high word of
  // c 2^(62 - b) (below 2^62 in magnitude): one shift, no branch.
  const int up = 62 - bit_length(largest);
  const auto scaled = [up](int64_t c) { return int32_t(int64_t(uint64_t(c) << up) >> 32); };
  *out = Vec3i{scaled(n[0]), scaled(n[1]), scaled(n[2])};
  return true;
}

}  // namespace

Vec3i face_normal(const Vec3i world[3]) {
  Vec3i n, out{0, 0, 0};
  if (face_cross(world, &n)) normalize_q30(n, &out);
  return out;
}

int32_t face_lambert_q8(const Light& light, const Vec3i world[3], bool front_facing) {
  Vec3i n;
  if (!face_cross(world, &n)) return light.ambient_q8;  // as lambert_q8 of the zero normal
  const int64_t dot = dot64(n, light.to_light);  // |N| 2^30 cos: |N| < 2^31, so below 2^61
  const int64_t lit = front_facing ? dot : -dot;  // the side seen
  if (lit <= 0) return light.ambient_q8;
  const uint64_t length = isqrt64(uint64_t(dot64(n, n)));  // 2^29 .. 2^31
  return lambert_of_cosine(light, div_round(lit, int64_t(length)));  // Q1.30
}

int32_t lambert_q8(const Light& light, const Vec3i& normal_q30) {
  const int64_t cosine = shift_round(dot64(normal_q30, light.to_light), kUnitBits);  // Q1.30
  return lambert_of_cosine(light, max_of<int64_t>(0, cosine));
}

Pixel modulate(const uint8_t base[4], int32_t intensity_q8) {
  const uint32_t r = uint32_t(min_of<int32_t>(255, (base[0] * intensity_q8 + 128) >> 8));
  const uint32_t g = uint32_t(min_of<int32_t>(255, (base[1] * intensity_q8 + 128) >> 8));
  const uint32_t b = uint32_t(min_of<int32_t>(255, (base[2] * intensity_q8 + 128) >> 8));
  return rgb(r, g, b);
}

void shade_triangle(const Scene& scene, const Light& light, ShadingMode mode, uint32_t triangle_id,
                    bool front_facing, TriangleColors* out, const Vec3i* world) {
  const Triangle tri = triangle_at(scene, triangle_id);
  const Batch& batch = scene.batches[tri.batch];
  const Material& material = scene.materials[batch.material];
  out->smooth = false;
  if (mode == ShadingMode::Ids) {
    out->flat = triangle_id + 1;
  } else if (mode == ShadingMode::Unlit || mode == ShadingMode::Lines) {
    out->flat = rgb(material.base_color[0], material.base_color[1], material.base_color[2]);
  } else {
    Vec3i read[3];
    if (!world) {
      triangle_world(scene, triangle_id, read);
      world = read;
    }
    out->flat = modulate(material.base_color, face_lambert_q8(light, world, front_facing));
    if (mode == ShadingMode::Gouraud) {
      for (int i = 0; i < 3; ++i) {
        const int16_t* n = vertex_normal(scene, tri.v[i]);
        constexpr int up = kUnitBits - kNormalBits;
        Vec3i vn{int32_t(shift_left(n[0], up)), int32_t(shift_left(n[1], up)), int32_t(shift_left(n[2], up))};
        if (vn.x == 0 && vn.y == 0 && vn.z == 0) {  // mesh without normals: the face's colour
          out->vertex[i] = out->flat;
          continue;
        }
        if (!front_facing) vn = negate(vn);  // a double-sided triangle seen from behind
        out->vertex[i] = modulate(material.base_color, lambert_q8(light, vn));
      }
      out->smooth = out->vertex[0] != out->vertex[1] || out->vertex[0] != out->vertex[2];
    }
  }
  if (!out->smooth) out->vertex[0] = out->vertex[1] = out->vertex[2] = out->flat;
}

LinearPlane make_plane(const ScreenTriangle& tri, const int32_t values[3]) {
  const ScreenVertex* v = tri.v;
  const int64_t dv1 = int64_t(values[1]) - values[0], dv2 = int64_t(values[2]) - values[0];
  const int64_t dx1 = int64_t(v[1].x) - v[0].x, dx2 = int64_t(v[2].x) - v[0].x;
  const int64_t dy1 = int64_t(v[1].y) - v[0].y, dy2 = int64_t(v[2].y) - v[0].y;
  // Gradients per subpixel: (dv1 dy2 - dv2 dy1) / area2 and (dv2 dx1 - dv1 dx2) / area2. Numerators
  // are below 2^41. Per pixel and in Q20 that is numerator * 2^28 / area2: shift numerator and area
  // together until it fits (the area keeps >= 26 bits whenever the slope is below the bound), then
  // bound the slope to 2^40 (2^20 value units per pixel, so origin below stays under 2^62; only
  // slivers thinner than 1/16 pixel across a 2^16 value range reach it).
  const int64_t limit = int64_t(1) << 40;
  int64_t steps[2];
  const int64_t numerators[2] = {dv1 * dy2 - dv2 * dy1, dv2 * dx1 - dv1 * dx2};
  for (int k = 0; k < 2; ++k) {
    int64_t num = numerators[k], den = tri.area2;
    const int s = max_of(0, bit_length(uint64_t(abs64(num))) - 34);
    num >>= s;
    den >>= s;
    steps[k] = den == 0 ? (num >= 0 ? limit : -limit)
                        : clamp_to<int64_t>(div_round(shift_left(num, kPlaneBits + kSubpixelBits), den), -limit, limit);
  }
  LinearPlane p;
  p.step_x = steps[0];
  p.step_y = steps[1];
  // Value at the centre of pixel (0, 0): extrapolate from vertex 0 (offsets below 2^23 subpixels).
  p.origin = shift_left(values[0], kPlaneBits) + (int64_t(1) << (kPlaneBits - 1)) -
             div_round(p.step_x * (int64_t(v[0].x) - kSubpixelHalf), kSubpixelOne) -
             div_round(p.step_y * (int64_t(v[0].y) - kSubpixelHalf), kSubpixelOne);
  return p;
}

Pixel blend_colors(const Pixel c[3], const int32_t w[3]) { return blend_colors_inline(c, w); }

Pixel blend_vertex_color(const TriangleColors& colors, const ScreenVertex& v) {
  return blend_colors(colors.vertex, v.weight);
}

void make_color_planes(const ScreenTriangle& piece, const TriangleColors& colors, ColorPlanes* out) {
  Pixel corner[3];
  for (int i = 0; i < 3; ++i) corner[i] = blend_vertex_color(colors, piece.v[i]);
  for (int c = 0; c < 3; ++c) {
    const int shift = 16 - 8 * c;
    const int32_t values[3] = {int32_t((corner[0] >> shift) & 0xFF), int32_t((corner[1] >> shift) & 0xFF),
                               int32_t((corner[2] >> shift) & 0xFF)};
    out->channel[c] = make_plane(piece, values);
  }
}

Pixel ColorPlanes::at(int32_t px, int32_t py) const {
  return rgb(uint32_t(clamp_to(channel[0].at(px, py), 0, 255)), uint32_t(clamp_to(channel[1].at(px, py), 0, 255)),
             uint32_t(clamp_to(channel[2].at(px, py), 0, 255)));
}

}  // namespace ml

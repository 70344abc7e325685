#include "texture/mapping.h"

namespace ml {
namespace {

constexpr int kCrossBits = 28;   // the P_j x P_k keep this many bits (a common scale)
constexpr int kWeightKeep = 28;  // e_i keep this many bits per sample before the division

}  // namespace

void make_texture_planes(const View& view, const Vec3i world[3], const int32_t uv[3][2], int32_t den,
                         int32_t ox, int32_t oy, TexturePlanes* out) {
  int64_t p[3][3];
  for (int i = 0; i < 3; ++i) {
    // |world - eye| < 2^25, so view coordinates stay below 2^29 and each cross term below 2^58.
    p[i][0] = view_coordinate(view, view.right, world[i]);
    p[i][1] = view_coordinate(view, view.down, world[i]);
    p[i][2] = view_coordinate(view, view.forward, world[i]);
    out->uv[i][0] = uv[i][0];
    out->uv[i][1] = uv[i][1];
  }
  int64_t c[3][3];
  uint64_t largest = 0;
  for (int i = 0; i < 3; ++i) {
    const int64_t* q = p[i == 2 ? 0 : i + 1];
    const int64_t* r = p[i == 0 ? 2 : i - 1];
    c[i][0] = q[1] * r[2] - q[2] * r[1];
    c[i][1] = q[2] * r[0] - q[0] * r[2];
    c[i][2] = q[0] * r[1] - q[1] * r[0];
    for (int a = 0; a < 3; ++a) largest |= magnitude(c[i][a]);
  }
  // One shift for all three keeps their ratios; below 2^28 the planes below cannot overflow.
  const int shift = max_of(0, bit_length(largest) - kCrossBits);
  const int64_t cx = int64_t(view.center_x) * den, cy = int64_t(view.center_y) * den;
  const int64_t fz = view.focal_q8 * den;  // < 2^30
  for (int i = 0; i < 3; ++i) {
    const int64_t x = c[i][0] >> shift, y = c[i][1] >> shift, z = c[i][2] >> shift;
    // d = (256 X + ox - cx, 256 Y + oy - cy, focal), all scaled by den.
    out->a[i] = x * kSubpixelOne;
    out->b[i] = y * kSubpixelOne;
    out->k[i] = x * (ox - cx) + y * (oy - cy) + z * fz;
  }
  out->ey = -1;  // no sample evaluated yet (samples have y >= 0)
  out->ex = 0;
}

void texture_uv(TexturePlanes& p, int32_t x, int32_t y, int32_t uv[2]) {
  const bool step = y == p.ey && x == p.ex + 1;
  int64_t e[3];
  uint64_t largest = 0;
  for (int i = 0; i < 3; ++i) {
    p.e[i] = step ? p.e[i] + p.a[i] : p.a[i] * x + p.b[i] * y + p.k[i];
    e[i] = p.e[i];
    largest |= magnitude(e[i]);
  }
  p.ex = x;
  p.ey = y;
  const int shift = max_of(0, bit_length(largest) - kWeightKeep);
  int64_t total = 0;
  for (int i = 0; i < 3; ++i) {
    e[i] >>= shift;
    total += e[i];
  }
  if (total < 0) {
    total = -total;
    for (int i = 0; i < 3; ++i) e[i] = -e[i];
  }
  if (total == 0) {  // the ray grazes the triangle's plane: any vertex will do
    uv[0] = p.uv[0][0];
    uv[1] = p.uv[0][1];
    return;
  }
  for (int k = 0; k < 2; ++k) {
    // |uv| < 2^31 and |e| < 2^28: the sum stays below 2^61; total < 2^30 divides in 32 bits.
    const int64_t sum = p.uv[0][k] * e[0] + p.uv[1][k] * e[1] + p.uv[2][k] * e[2];
    uv[k] = int32_t(clamp_to<int64_t>(div_floor(sum, total), INT32_MIN, INT32_MAX));
  }
}

uint32_t triangle_texture(const Scene& scene, uint32_t id) {
  const Material& m = scene.materials[scene.batches[scene.triangles[id].batch].material];
  return material_texels(scene, m) ? m.texture : kNone;
}

void triangle_texture_planes(const Scene& scene, const View& view, uint32_t id, int32_t den, int32_t ox,
                             int32_t oy, TexturePlanes* out) {
  Vec3i world[3];
  triangle_world(scene, id, world);
  int32_t uv[3][2];
  for (int i = 0; i < 3; ++i) vertex_uv(scene, scene.triangles[id].v[i], uv[i]);
  make_texture_planes(view, world, uv, den, ox, oy, out);
}

}  // namespace ml

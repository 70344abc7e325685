// Normal cones of BSP subtrees (blob_format.h PackedBspCone): for each subtree whose triangles all face
// about one way, a cone of their normals, which the tiler tests against the eye on entering the node to
// skip the subtree when every triangle in it is a back face (Greene's thesis, ch. 4: culling in groups,
// before any piece is touched).
//
// Computed from a packed scene, with the renderer's own decoders (triangle_world, bsp_piece,
// bsp_node_box), so that the proof in blob_format.h holds for exactly the vertices the renderer reads:
//   - each triangle's unit normal n (double, from exact integer edge vectors; relative error ~1e-16);
//   - the stored axis A (int8, rounded) and c = the smallest n . A / |A| over the subtree; then
//     |n - A / |A|| <= sqrt(2 - 2 c), and spread = ceil(2 |A| sqrt(2 - 2 c)) plus a margin;
//   - every piece vertex within kConeMarginWorld of its triangle's plane (split points are snapped to
//     the quantized grid), so its projection onto the plane lies in the box grown by the margin.
// Degenerate triangles (zero normal) are culled by the renderer's facing test anyway and are left out.
#include <algorithm>
#include <cmath>

#include "scene/scene.h"
#include "tools/scenec/internal.h"

namespace ml {
namespace scenec_detail {
namespace {

// Subtrees smaller than this get no cone: walking a piece or two costs about what the test does.
constexpr uint32_t kConeMinPieces = 4;

struct TriangleNormal {
  double n[3] = {0, 0, 0};
  Vec3i v0{0, 0, 0};
  bool degenerate = true, double_sided = false;
};

std::vector<TriangleNormal> triangle_normals(const Scene& scene) {
  std::vector<TriangleNormal> out(scene.triangle_count);
  for (uint32_t t = 0; t < scene.triangle_count; ++t) {
    Vec3i w[3];
    triangle_world(scene, t, w);
    const Triangle tri = triangle_at(scene, t);
    TriangleNormal& o = out[t];
    o.v0 = w[0];
    o.double_sided = batch_material(scene, tri.batch).double_sided != 0;
    const double e1[3] = {double(w[1].x) - w[0].x, double(w[1].y) - w[0].y, double(w[1].z) - w[0].z};
    const double e2[3] = {double(w[2].x) - w[0].x, double(w[2].y) - w[0].y, double(w[2].z) - w[0].z};
    const double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double len = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    if (len == 0) continue;
    for (int k = 0; k < 3; ++k) o.n[k] = c[k] / len;
    o.degenerate = false;
  }
  return out;
}

// Largest distance (world units) of a piece's vertices from its triangle's plane.
double piece_offset(const Scene& scene, const BspPiece& piece, const TriangleNormal& t) {
  const uint32_t batch = triangle_at(scene, piece.triangle).batch;
  double worst = 0;
  for (int k = 0; k < 3; ++k) {
    const Vec3i p = vertex_world(scene, batch, piece.v[k]);
    const double d = t.n[0] * (double(p.x) - t.v0.x) + t.n[1] * (double(p.y) - t.v0.y) + t.n[2] * (double(p.z) - t.v0.z);
    worst = std::max(worst, std::fabs(d));
  }
  return worst;
}

// What a subtree's pieces contribute, summed bottom-up.
struct SubtreeSum {
  double normal_sum[3] = {0, 0, 0};
  double offset = 0;  // largest piece_offset
  bool double_sided = false, any = false;
};

// The stored axis for a sum of normals: the largest component at +-127 (the finest int8 direction).
bool quantize_axis_of(const double sum[3], int8_t axis[3]) {
  const double m = std::max({std::fabs(sum[0]), std::fabs(sum[1]), std::fabs(sum[2])});
  if (!(m > 0)) return false;
  for (int k = 0; k < 3; ++k) axis[k] = int8_t(std::lround(127.0 * sum[k] / m));
  return true;
}

}  // namespace

std::vector<PackedBspCone> bsp_cones(const Scene& scene) {
  const uint32_t count = scene.bsp_node_count;
  std::vector<PackedBspCone> cones(count, PackedBspCone{{0, 0, 0}, kNoCone});
  const std::vector<TriangleNormal> normals = triangle_normals(scene);
  std::vector<BspNode> nodes(count);
  for (uint32_t i = 0; i < count; ++i) {
    nodes[i] = bsp_node(scene, i);
  }
  // Bottom-up sums: children follow their parent (breadth-first), so a reverse pass sees them first.
  std::vector<SubtreeSum> sums(count);
  for (uint32_t i = count; i-- > 0;) {
    SubtreeSum& s = sums[i];
    const BspNode& n = nodes[i];
    for (uint32_t p = n.first_piece; p < n.first_piece + n.piece_count; ++p) {
      const BspPiece piece = bsp_piece(scene, p);
      const TriangleNormal& t = normals[piece.triangle];
      s.double_sided |= t.double_sided;
      if (t.degenerate) continue;
      for (int k = 0; k < 3; ++k) s.normal_sum[k] += t.n[k];
      s.offset = std::max(s.offset, piece_offset(scene, piece, t));
      s.any = true;
    }
    for (uint32_t c : {n.front, n.back}) {
      if (c == kNone) continue;
      for (int k = 0; k < 3; ++k) s.normal_sum[k] += sums[c].normal_sum[k];
      s.offset = std::max(s.offset, sums[c].offset);
      s.double_sided |= sums[c].double_sided;
      s.any |= sums[c].any;
    }
  }
  std::vector<uint32_t> stack;
  for (uint32_t i = 0; i < count; ++i) {
    const SubtreeSum& s = sums[i];
    int8_t axis[3];
    if (nodes[i].subtree_pieces < kConeMinPieces || !s.any || s.double_sided || s.offset > kConeMarginWorld - 1e-3 ||
        !quantize_axis_of(s.normal_sum, axis))
      continue;
    const double len = std::sqrt(double(axis[0]) * axis[0] + double(axis[1]) * axis[1] + double(axis[2]) * axis[2]);
    // The smallest cosine between the axis and a normal of the subtree (stop once no cone can pay).
    double min_cos = 1;
    stack.assign(1, i);
    while (!stack.empty() && min_cos > 0) {
      const BspNode& n = nodes[stack.back()];
      stack.pop_back();
      for (uint32_t p = n.first_piece; p < n.first_piece + n.piece_count; ++p) {
        const TriangleNormal& t = normals[bsp_piece(scene, p).triangle];
        if (!t.degenerate) min_cos = std::min(min_cos, (t.n[0] * axis[0] + t.n[1] * axis[1] + t.n[2] * axis[2]) / len);
      }
      if (n.front != kNone) stack.push_back(n.front);
      if (n.back != kNone) stack.push_back(n.back);
    }
    if (min_cos <= 0) continue;
    // Margins: 1e-9 on the bound for the normals' rounding, one unit on spread for the axis length's.
    const double spread = std::ceil(2 * len * (std::sqrt(std::max(0.0, 2 - 2 * min_cos)) + 1e-9)) + 1;
    if (spread >= kNoCone) continue;
    cones[i] = PackedBspCone{{axis[0], axis[1], axis[2]}, uint8_t(spread)};
  }
  return cones;
}

}  // namespace scenec_detail
}  // namespace ml

// Internal pieces of the scene compiler shared between its .cpp files (not a public API).
#pragma once
#include <string>
#include <vector>

#include "core/fixed.h"
#include "scene/blob_format.h"
#include "tools/scenec/scenec.h"

namespace ml {
struct Scene;
namespace scenec_detail {

// The renderer's dequantization (scene/reader.cpp vertex_world), on blob structs.
inline Vec3i dequantize(const Batch& b, const int16_t q[3]) {
  return Vec3i{int32_t(b.offset[0] + ((int64_t(q[0]) * b.scale[0]) >> 16)),
               int32_t(b.offset[1] + ((int64_t(q[1]) * b.scale[1]) >> 16)),
               int32_t(b.offset[2] + ((int64_t(q[2]) * b.scale[2]) >> 16))};
}

// The int16 value whose dequantized position along axis `axis` of batch b is nearest to world w.
int16_t quantize_axis(const Batch& b, int axis, double w);

// Q1.14 unit normal from a direction (zero vector -> zero).
void quantize_normal(const double n[3], int16_t out[3]);

struct BspResult {
  std::vector<BspNode> nodes;     // breadth-first order, node 0 is the root
  std::vector<BspPiece> pieces;   // node by node, in node order
  uint32_t depth = 0;             // nodes on the longest root-to-leaf path
  uint32_t split_vertices = 0;    // vertices appended to *vertices
};

// Builds a BSP over every triangle (see bsp.cpp). Split vertices are appended to *vertices, each
// quantized with the batch of the triangle it splits. False with a one-line *error on failure.
bool build_bsp(const std::vector<Material>& materials, const std::vector<Batch>& batches,
               const std::vector<Triangle>& triangles, std::vector<Vertex>* vertices,
               const CompileOptions& options, BspResult* out, std::string* error);

// Fills every node's subtree_pieces and bounds_min/max (blob_format.h) from its pieces' vertices as
// the renderer dequantizes them; one reverse pass (children follow their parent breadth-first).
void fill_subtree_bounds(const std::vector<Batch>& batches, const std::vector<Triangle>& triangles,
                         const std::vector<Vertex>& vertices, BspResult* bsp);

// Normal cones of a packed scene's BSP subtrees, one per node (kNoCone where none pays or holds); see
// cones.cpp and blob_format.h PackedBspCone.
std::vector<PackedBspCone> bsp_cones(const Scene& scene);

}  // namespace scenec_detail
}  // namespace ml

// The validating reader of the scene blob (format: scene/blob_format.h, docs/scene-blob.md).
// read_scene checks everything a renderer will rely on — header, CRC, section bounds and alignment,
// every count, offset and index — and only then fills a Scene of typed pointers into the blob.
// After an Ok status no accessor below can read outside the blob.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "core/build.h"
#include "core/crc32.h"
#include "core/fixed.h"
#include "core/status.h"
#include "scene/blob_format.h"

namespace ml {

// Deepest BSP the renderers accept (their traversal stack is sized by SceneInfo::bsp_depth).
constexpr uint32_t kMaxBspDepth = 4096;

// Decoded records: what the accessors below return, whatever the blob's packing (blob_format.h).
// The scene compiler builds its tables in these shapes too.
struct Vertex {
  int16_t position[3];         // quantized with a batch
  int16_t normal[3];           // Q1.14, (0,0,0) when the mesh had none
  int32_t uv[2];               // Q16.16
};

struct Triangle {
  uint32_t v[3];               // indices into Vertices
  uint32_t batch;              // index into Batches
};

struct BspPiece {
  uint32_t v[3];               // indices into Vertices
  uint32_t triangle;           // the triangle it is (part of)
};

struct BspNode {
  int32_t normal[3];           // Q1.30 (the blob's Q1.14 value shifted up)
  int64_t d;                   // world units * 2^30: plane value dot(normal, p) - d
  uint32_t front, back;        // child indices or kNone
  uint32_t first_piece, piece_count, subtree_pieces;
  int32_t bounds_min[3];       // world units, inclusive (the cells' outer edges)
  int32_t bounds_max[3];
};

struct Scene {
  const uint8_t* base = nullptr;
  uint32_t size = 0;
  const SceneInfo* info = nullptr;
  const Material* materials = nullptr;       uint32_t material_count = 0;
  const Batch* batches = nullptr;            uint32_t batch_count = 0;
  const PackedVertex* vertices = nullptr;    uint32_t vertex_count = 0;
  const int32_t* uvs = nullptr;              // 2 per vertex, or null (all zero)
  const void* triangles = nullptr;           uint32_t triangle_count = 0;
  const Node* nodes = nullptr;               uint32_t node_count = 0;
  const void* bsp_nodes = nullptr;           uint32_t bsp_node_count = 0;
  const void* bsp_pieces = nullptr;          uint32_t bsp_piece_count = 0;
  const void* bsp_splits = nullptr;          uint32_t bsp_split_count = 0;
  const PackedBspCone* bsp_cones = nullptr;  // one per BSP node, or null (no subtree cone tests)
  const TextureRef* textures = nullptr;      uint32_t texture_count = 0;
  bool wide = false;                         // 32-bit index fields (SceneInfo kWideIndices)
  int bounds_shift = 0;                      // log2 of a BSP bounds cell
  // Optional: absent in scenes without texels (then every material draws its base colour).
  const TextureTexels* texture_texels = nullptr;  uint32_t texture_texels_count = 0;  // == texture_count
  const uint8_t* texels = nullptr;           uint32_t texel_bytes = 0;
};

enum class CrcCheck { Skip, Check };

// Validates `blob` (size bytes, 8-byte aligned) and fills *out. On error *out is left empty and the
// status message names the failed check (e.g. "triangle vertex index out of range"). The CRC over the
// whole blob is checked only with CrcCheck::Check (it reads every byte: 5.5 M instructions for a
// 450 KB blob on a Cortex-M3); every structural check runs either way.
Status read_scene(const void* blob, size_t size, Scene* out, CrcCheck crc = CrcCheck::Check);

// ---- accessors (only valid on a Scene from read_scene; indices in range) ----------------------------

namespace scene_detail {
template <typename Index>
inline Triangle triangle(const void* table, uint32_t id) {
  const PackedTriangle<Index>& t = static_cast<const PackedTriangle<Index>*>(table)[id];
  return Triangle{{t.v[0], t.v[1], t.v[2]}, t.batch};
}
template <typename Index>
inline BspPiece piece(const Scene& s, uint32_t p) {
  const uint32_t ref = static_cast<const Index*>(s.bsp_pieces)[p];
  if (ref < s.triangle_count) {
    const Triangle t = triangle<Index>(s.triangles, ref);
    return BspPiece{{t.v[0], t.v[1], t.v[2]}, ref};
  }
  const PackedSplitPiece<Index>& sp = static_cast<const PackedSplitPiece<Index>*>(s.bsp_splits)[ref - s.triangle_count];
  return BspPiece{{sp.v[0], sp.v[1], sp.v[2]}, sp.triangle};
}
template <typename Index>
inline BspNode node(const Scene& s, uint32_t i) {
  const PackedBspNode<Index>* nodes = static_cast<const PackedBspNode<Index>*>(s.bsp_nodes);
  const PackedBspNode<Index>& n = nodes[i];
  BspNode out;
  ML_HOST_UNROLL for (int a = 0; a < 3; ++a) out.normal[a] = int32_t(n.normal[a]) * 65536;  // Q1.14 -> Q1.30
  out.d = int64_t(n.d) * (int64_t(1) << 18);                                  // Q12 -> Q30
  const uint32_t second = n.first_child + ((n.children & kFrontChild) ? 1u : 0u);
  out.front = (n.children & kFrontChild) ? uint32_t(n.first_child) : kNone;
  out.back = (n.children & kBackChild) ? second : kNone;
  out.first_piece = n.first_piece;
  const uint32_t end = i + 1 < s.bsp_node_count ? uint32_t(nodes[i + 1].first_piece) : s.bsp_piece_count;
  out.piece_count = end - n.first_piece;
  out.subtree_pieces = n.subtree_pieces;
  return out;
}
template <typename Index>
inline void node_box(const Scene& s, uint32_t i, BspNode* out) {
  const PackedBspNode<Index>& n = static_cast<const PackedBspNode<Index>*>(s.bsp_nodes)[i];
  const int cell = s.bounds_shift;
  ML_HOST_UNROLL for (int a = 0; a < 3; ++a) {
    out->bounds_min[a] = s.info->bounds_min[a] + int32_t(uint32_t(n.cells[a]) << cell);
    out->bounds_max[a] = s.info->bounds_min[a] + int32_t((uint32_t(n.cells[3 + a]) + 1) << cell) - 1;
  }
}
}  // namespace scene_detail

// Triangle `id` (its vertex indices and batch).
inline Triangle triangle_at(const Scene& s, uint32_t id) {
  return s.wide ? scene_detail::triangle<uint32_t>(s.triangles, id) : scene_detail::triangle<uint16_t>(s.triangles, id);
}

// BSP piece p: the whole triangle or a split part, with the triangle's id.
inline BspPiece bsp_piece(const Scene& s, uint32_t p) {
  return s.wide ? scene_detail::piece<uint32_t>(s, p) : scene_detail::piece<uint16_t>(s, p);
}

// BSP node i without its box: plane in Q1.30, children, piece range (bounds_min/max left unset). What
// a walk reads at every node; bsp_node_box adds the box where it is needed. (Out of line: one copy of
// each decoder for every caller, in flash.)
BspNode bsp_node_unboxed(const Scene& s, uint32_t i);

// Fills node->bounds_min/max with node i's subtree box in world units.
void bsp_node_box(const Scene& s, uint32_t i, BspNode* node);

// True when node i has a normal cone (blob_format.h PackedBspCone) proving that every triangle with a
// piece in its subtree faces away from `eye` (world units, |.| < 2^24), so the subtree can be skipped
// whole. False without cones, without a cone for the node, or when the cone does not prove it.
bool bsp_subtree_faces_away(const Scene& s, uint32_t i, const Vec3i& eye);

// BSP node i, decoded: plane in Q1.30, children, piece range, subtree box in world units.
inline BspNode bsp_node(const Scene& s, uint32_t i) {
  BspNode n = bsp_node_unboxed(s, i);
  bsp_node_box(s, i, &n);
  return n;
}

// Vertex normal, Q1.14 ((0,0,0) when the mesh had none).
inline const int16_t* vertex_normal(const Scene& s, uint32_t v) { return s.vertices[v].normal; }

// TEXCOORD_0 of a vertex, Q16.16 (0 when the blob carries no UVs). The one way to read UVs.
inline void vertex_uv(const Scene& s, uint32_t v, int32_t out[2]) {
  out[0] = s.uvs ? s.uvs[2 * v] : 0;
  out[1] = s.uvs ? s.uvs[2 * v + 1] : 0;
}

// World position of a vertex quantized with `batch`. Only valid on a Scene from read_scene.
Vec3i vertex_world(const Scene& scene, uint32_t batch, uint32_t vertex);

// The texels of a material's base-colour texture, or null when it has none (no texture, no texels
// section, or a texture the compiler stored as TexelFormat::None).
const TextureTexels* material_texels(const Scene& scene, const Material& material);

// The material batch `batch` draws with, and triangle `id`'s.
inline const Material& batch_material(const Scene& s, uint32_t batch) { return s.materials[s.batches[batch].material]; }
inline const Material& triangle_material(const Scene& s, uint32_t id) { return batch_material(s, triangle_at(s, id).batch); }

// Whether a material's triangles are invisible, so that both renderers leave them out in every mode:
// a MASK whose base-colour alpha is below its cutoff, or a BLEND of alpha 0 (texel alpha is not read:
// the base colour's alpha holds over the whole triangle). A BLEND of alpha 0 adds nothing to the
// scanline renderer's compositing, and the tiler, which draws other MASK and BLEND materials opaque,
// would draw it over what lies behind. One test for the opaque materials, the common case.
inline bool material_hidden(const Material& m) {
  return m.alpha_mode != uint8_t(AlphaMode::Opaque) &&
         (m.alpha_mode == uint8_t(AlphaMode::Mask) ? m.base_color[3] < m.alpha_cutoff
                                                   : m.alpha_mode == uint8_t(AlphaMode::Blend) && m.base_color[3] == 0);
}

// Whether any of the scene's materials is hidden (a frame's one look).
inline bool has_hidden_material(const Scene& s) {
  for (uint32_t m = 0; m < s.material_count; ++m)
    if (material_hidden(s.materials[m])) return true;
  return false;
}

// World positions of three vertices quantized with `batch` (a triangle's, a BSP piece's).
void vertices_world(const Scene& scene, uint32_t batch, const uint32_t v[3], Vec3i out[3]);

// World positions of triangle `id`'s three vertices.
void triangle_world(const Scene& scene, uint32_t id, Vec3i out[3]);

}  // namespace ml

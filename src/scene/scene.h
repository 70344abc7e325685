// The validating reader of the scene blob (format: scene/blob_format.h, docs/scene-blob.md).
// read_scene checks everything a renderer will rely on — header, CRC, section bounds and alignment,
// every count, offset and index — and only then fills a Scene of typed pointers into the blob.
// After an Ok status no accessor below can read outside the blob.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "core/fixed.h"
#include "core/status.h"
#include "scene/blob_format.h"

namespace ml {

// Deepest BSP the renderers accept (their traversal stack is sized by SceneInfo::bsp_depth).
constexpr uint32_t kMaxBspDepth = 4096;

struct Scene {
  const uint8_t* base = nullptr;
  uint32_t size = 0;
  const SceneInfo* info = nullptr;
  const Material* materials = nullptr;   uint32_t material_count = 0;
  const Batch* batches = nullptr;        uint32_t batch_count = 0;
  const Vertex* vertices = nullptr;      uint32_t vertex_count = 0;
  const Triangle* triangles = nullptr;   uint32_t triangle_count = 0;
  const Node* nodes = nullptr;           uint32_t node_count = 0;
  const BspNode* bsp_nodes = nullptr;    uint32_t bsp_node_count = 0;
  const BspPiece* bsp_pieces = nullptr;  uint32_t bsp_piece_count = 0;
  const TextureRef* textures = nullptr;  uint32_t texture_count = 0;
  // Optional: absent in scenes without texels (then every material draws its base colour).
  const TextureTexels* texture_texels = nullptr;  uint32_t texture_texels_count = 0;  // == texture_count
  const uint8_t* texels = nullptr;       uint32_t texel_bytes = 0;
};

// CRC-32 (IEEE 802.3, reflected, as zlib's crc32). Pass the previous value to continue a running CRC.
uint32_t crc32(const void* data, size_t size, uint32_t previous = 0);

// Validates `blob` (size bytes, 8-byte aligned) and fills *out. On error *out is left empty and the
// status message names the failed check (e.g. "triangle vertex index out of range").
Status read_scene(const void* blob, size_t size, Scene* out);

// World position of a vertex quantized with `batch`. Only valid on a Scene from read_scene.
Vec3i vertex_world(const Scene& scene, uint32_t batch, uint32_t vertex);

// TEXCOORD_0 of a vertex, Q16.16 (the one place that reads Vertex::uv).
void vertex_uv(const Scene& scene, uint32_t vertex, int32_t out[2]);

// The texels of a material's base-colour texture, or null when it has none (no texture, no texels
// section, or a texture the compiler stored as TexelFormat::None).
const TextureTexels* material_texels(const Scene& scene, const Material& material);

// World positions of triangle `id`'s three vertices.
void triangle_world(const Scene& scene, uint32_t id, Vec3i out[3]);

}  // namespace ml

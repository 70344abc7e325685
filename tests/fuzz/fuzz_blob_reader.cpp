// libFuzzer target for the scene-blob reader (make fuzz; a short smoke run is part of make test).
// Each input is read twice: as given (almost always stopped by the CRC), and with its CRC patched to
// match so the structural checks behind it get fuzzed too. Whatever read_scene accepts is then walked
// completely: every triangle's and every BSP piece's vertices, every node — ASan and UBSan watch.
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"

namespace {

volatile int64_t g_sink;

void walk(const ml::Scene& s) {
  int64_t sum = 0;
  for (uint32_t t = 0; t < s.triangle_count; ++t) {
    ml::Vec3i w[3];
    ml::triangle_world(s, t, w);
    sum += int64_t(w[0].x) + w[1].y + w[2].z;
  }
  for (uint32_t i = 0; i < s.bsp_node_count; ++i) {
    const ml::BspNode& n = s.bsp_nodes[i];
    for (uint32_t p = n.first_piece; p < n.first_piece + n.piece_count; ++p) {
      const ml::BspPiece& piece = s.bsp_pieces[p];
      const uint32_t batch = s.triangles[piece.triangle].batch;
      for (uint32_t v : piece.v) sum += ml::vertex_world(s, batch, v).x;
    }
    if (n.front != ml::kNone) sum += s.bsp_nodes[n.front].piece_count;
    if (n.back != ml::kNone) sum += s.bsp_nodes[n.back].piece_count;
    sum += int64_t(n.bounds_min[0]) + n.bounds_max[2] + n.subtree_pieces;
  }
  for (uint32_t i = 0; i < s.node_count; ++i) {
    for (uint32_t b = s.nodes[i].first_batch; b < s.nodes[i].first_batch + s.nodes[i].batch_count; ++b) {
      sum += s.batches[b].material;
    }
  }
  for (uint32_t b = 0; b < s.batch_count; ++b) sum += s.materials[s.batches[b].material].base_color[0];
  for (uint32_t m = 0; m < s.material_count; ++m) {
    if (s.materials[m].texture != ml::kNone) sum += s.textures[s.materials[m].texture].image;
  }
  for (uint32_t t = 0; t < s.texture_texels_count; ++t) {  // every texel byte a texture claims
    const ml::TextureTexels& tex = s.texture_texels[t];
    for (uint32_t b = 0; b < tex.bytes; ++b) sum += s.texels[tex.offset + b];
  }
  sum += s.info->sphere_radius;
  g_sink = sum;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // An exactly-sized copy (malloc is at least 8-aligned), so ASan catches a read even one byte past
  // the end.
  uint8_t* buffer = static_cast<uint8_t*>(malloc(size ? size : 1));
  if (buffer == nullptr || (reinterpret_cast<uintptr_t>(buffer) & 7u) != 0) abort();
  if (size) memcpy(buffer, data, size);
  ml::Scene scene;
  if (ml::read_scene(buffer, size, &scene).ok()) walk(scene);
  if (size >= 24) {
    const uint32_t crc = ml::crc32(buffer + 16, size - 16);
    memcpy(buffer + 12, &crc, 4);
    if (ml::read_scene(buffer, size, &scene).ok()) walk(scene);
  }
  free(buffer);
  return 0;
}

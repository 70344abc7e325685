// libFuzzer target for the scene-blob reader (make fuzz; a short smoke run is part of make test).
// Each input is read twice: as given with the CRC checked (almost always stopped by it), and without
// the CRC check so the structural checks behind it get fuzzed too. Whatever read_scene accepts is then
// walked completely through the accessors: every triangle's and every BSP piece's vertices, normals
// and UVs, every node; what is accepted without the CRC check is then rendered small by both
// renderers (render_small) — ASan and UBSan watch.
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "render/render.h"
#include "scene/scene.h"
#include "tests/fuzz/checked_render.h"

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
    const ml::BspNode& n = ml::bsp_node(s, i);
    for (uint32_t p = n.first_piece; p < n.first_piece + n.piece_count; ++p) {
      const ml::BspPiece& piece = ml::bsp_piece(s, p);
      const uint32_t batch = ml::triangle_at(s, piece.triangle).batch;
      for (uint32_t v : piece.v) sum += ml::vertex_world(s, batch, v).x;
    }
    if (n.front != ml::kNone) sum += ml::bsp_node(s, n.front).piece_count;
    if (n.back != ml::kNone) sum += ml::bsp_node(s, n.back).piece_count;
    sum += int64_t(n.bounds_min[0]) + n.bounds_max[2] + n.subtree_pieces;
  }
  for (uint32_t v = 0; v < s.vertex_count; ++v) {
    int32_t uv[2];
    ml::vertex_uv(s, v, uv);
    sum += uv[0] + uv[1] + ml::vertex_normal(s, v)[2];
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

// What read_scene accepts is rendered, both renderers small with the default framing (their spare
// bytes too: the tiler's band plan and vertex cache, the scanline renderer's vertex cache). A render
// may refuse the scene with a status; one that succeeds must keep the band contract and write every
// pixel (CheckingSink), and none may read or write out of bounds.
void render_small(const ml::Scene& s) {
  const ml::Camera camera = fuzz::small_camera(s);
  ml::RenderOptions options[2];
  options[0].renderer = ml::RendererKind::Tiler;
  options[1].renderer = ml::RendererKind::Scanline;
  constexpr size_t kMaxArenaBytes = size_t(64) << 20;  // (within -rss_limit_mb)
  for (const ml::RenderOptions& o : options) (void)fuzz::render_checked(s, camera, o, true, kMaxArenaBytes);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // An exactly-sized copy (malloc is at least 8-aligned), so ASan catches a read even one byte past
  // the end.
  uint8_t* buffer = static_cast<uint8_t*>(malloc(size ? size : 1));
  if (buffer == nullptr || (reinterpret_cast<uintptr_t>(buffer) & 7u) != 0) abort();
  if (size) memcpy(buffer, data, size);
  ml::Scene scene;
  if (ml::read_scene(buffer, size, &scene, ml::CrcCheck::Check).ok()) walk(scene);
  if (ml::read_scene(buffer, size, &scene, ml::CrcCheck::Skip).ok()) {
    walk(scene);
    render_small(scene);
  }
  free(buffer);
  return 0;
}

// libFuzzer target for the glTF side (make fuzz; a short smoke run is part of make test). Each input
// goes to the importer from memory (.glb when it starts with "glTF", else .gltf; no external file is
// read), and its JSON once more in the other container. Whatever compiles is read back with
// read_scene; every refusal must be one line. What compiles is rendered small with both renderers into
// a sink that checks every pixel is written exactly once.
// ASan and UBSan watch all of it; a crash, a hang (-timeout) or a big allocation (-rss_limit_mb,
// -malloc_limit_mb) is a finding.
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <algorithm>

#include <vector>

#include "render/render.h"
#include "scene/scene.h"
#include "tests/fuzz/checked_render.h"
#include "tools/scenec/scenec.h"
#include "view/view.h"

namespace {

// The render step, in one place (the render and sink API are the part most likely to change): both
// renderers at a small size with the default framing; scanline also with 2x2 samples and Gouraud; the
// tiler also with its spare bytes (band plan, kept node rectangles and cone answers, vertex cache) in
// 4-row bands rendered one at a time, Gouraud.
void render_small(const ml::Scene& scene) {
  const ml::Camera camera = fuzz::small_camera(scene);
  ml::View view;
  if (!ml::make_view(camera, &view).ok()) abort();   // the default framing must work for any valid scene
  ml::RenderOptions options[4];
  options[0].renderer = ml::RendererKind::Tiler;
  options[1].renderer = ml::RendererKind::Scanline;
  options[2].renderer = ml::RendererKind::Scanline;
  options[2].aa = 2;
  options[2].shading = ml::ShadingMode::Gouraud;
  options[3].renderer = ml::RendererKind::Tiler;
  options[3].shading = ml::ShadingMode::Gouraud;
  options[3].output.band_rows = 4;
  options[3].output.render_rows = 4;
  constexpr int kWithSpare = 3;  // the option rendered with render_spare_bytes as well
  for (int i = 0; i < 4; ++i)
    if (!fuzz::render_checked(scene, camera, options[i], i == kWithSpare).ok()) abort();
}

}  // namespace

namespace {

// The other container for the same JSON: a .glb's JSON chunk alone (as .gltf), or JSON text wrapped
// as a .glb without a BIN chunk. Empty when the input has no JSON chunk.
std::vector<uint8_t> other_container(const uint8_t* data, size_t size) {
  std::vector<uint8_t> out;
  if (size >= 4 && memcmp(data, "glTF", 4) == 0) {
    if (size < 20) return out;
    uint32_t length;
    memcpy(&length, data + 12, 4);
    out.assign(data + 20, data + 20 + std::min<size_t>(length, size - 20));
    return out;
  }
  const size_t padded = (size + 3) & ~size_t(3);
  out.resize(20 + padded, ' ');
  const uint32_t header[5] = {0x46546C67u, 2, uint32_t(20 + padded), uint32_t(padded), 0x4E4F534Au};
  memcpy(out.data(), header, sizeof header);
  if (size) memcpy(out.data() + 20, data, size);
  return out;
}

// Compiles one input; what compiles is read back and, once per fuzz input, rendered.
void compile_read_render(const uint8_t* data, size_t size, bool* rendered) {
  // A cheaper BSP plane search than the default (same code paths, fewer candidates): big seeds
  // otherwise take seconds per execution.
  ml::CompileOptions options;
  options.bsp_triangle_candidates = 2;
  options.bsp_axis_positions = 1;
  options.bsp_sample_size = 16;
  ml::CompileResult r = ml::compile_gltf_memory(data, size, options);
  if (!r.ok) {
    if (r.error.empty() || r.error.find('\n') != std::string::npos) abort();   // one line, always
    return;
  }
  ml::Scene scene;
  if (!ml::read_scene(r.blob.data(), r.blob.size, &scene).ok()) abort();   // the compiler's output is valid
  if (!*rendered) render_small(scene);
  *rendered = true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  bool rendered = false;
  compile_read_render(data, size, &rendered);
  // Both parsers see every mutation: the same JSON in the other container (small inputs only).
  if (size <= 65536) {
    const std::vector<uint8_t> other = other_container(data, size);
    if (!other.empty()) compile_read_render(other.data(), other.size(), &rendered);
  }
  return 0;
}

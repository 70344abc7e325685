// One frame into the once-per-pixel image sink (platform/host/image_sink.h) with an arena of exactly
// render_arena_bytes, the render's status and the sink's contract checked: the helper of the image
// tests (ids against the oracle, the tiler's antialiasing tests).
#pragma once
#include <stdint.h>

#include <string>
#include <vector>

#include "core/arena.h"
#include "platform/host/image_sink.h"
#include "render/render.h"

namespace testrender {

struct Image {
  bool ok = false;
  std::string error;               // why not ok: the render failed or the sink's contract broke
  std::vector<ml::Pixel> pixels;   // row-major; in Ids shading id + 1 (0 = background)
};

// spare: the arena holds render_spare_bytes more (the tiler then renders its bands at once on a 64-bit
// host, with the facing bits and the vertex cache).
inline Image render_checked(const ml::Scene& scene, const ml::Camera& camera, const ml::RenderOptions& o,
                            bool spare = false) {
  Image out;
  const size_t bytes = ml::render_arena_bytes(scene, camera, o) + (spare ? ml::render_spare_bytes(scene, camera, o) : 0);
  std::vector<uint64_t> storage(bytes / 8 + 1);
  ml::Arena arena(storage.data(), bytes);
  mlhost::ImageSink sink;
  const ml::Status s = ml::render(scene, camera, o, arena, sink, nullptr);
  if (!s.ok()) {
    out.error = std::string("render failed: ") + s.message;
    return out;
  }
  if (!sink.contract_ok()) {
    out.error = "sink contract: " + sink.contract_error();
    return out;
  }
  out.ok = true;
  out.pixels = sink.pixels();
  return out;
}

}  // namespace testrender

// The fuzzers' render step: a small frame of the scene at its default framing, rendered into a
// poisoned arena and a sink that checks the band contract (core/sink.h) on XRGB8888 frames — bands
// top to bottom, full width, each once — and that no pixel is left unwritten. Unwritten pixels show
// as poison: the arena starts filled with kPoison, every band is poisoned again after it is read, and
// a written pixel's top byte is 0. Any breach aborts (a finding).
#pragma once
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <algorithm>
#include <vector>

#include "core/sink.h"
#include "render/render.h"
#include "scene/scene.h"
#include "view/view.h"

namespace fuzz {

constexpr uint8_t kPoison = 0xA5;

class CheckingSink : public ml::Sink {
 public:
  bool begin_frame(const ml::FrameInfo& frame) override {
    if (frame.format != ml::PixelFormat::Xrgb8888 || frame.band_rows < 1) abort();
    frame_ = frame;
    next_row_ = 0;
    return true;
  }
  bool flush(const ml::Flush& band) override {
    const int rows = std::min(frame_.band_rows, frame_.height - next_row_);
    if (band.x != 0 || band.y != next_row_ || band.width != frame_.width || band.height != rows) abort();
    for (int r = 0; r < band.height; ++r)
      for (int x = 0; x < band.width; ++x)
        if (band.bytes[size_t(r) * band.stride + size_t(x) * 4 + 3] != 0) abort();  // never written
    memset(const_cast<uint8_t*>(band.bytes), kPoison, size_t(band.stride) * size_t(band.height));
    next_row_ += rows;
    flush_ready(band.buffer);
    return true;
  }
  bool end_frame() override {
    if (next_row_ != frame_.height) abort();
    return true;
  }

 private:
  ml::FrameInfo frame_;
  int next_row_ = 0;
};

// The scene's default framing (as the CLI frames it) at 24x16.
inline ml::Camera small_camera(const ml::Scene& scene) {
  const ml::SceneInfo& info = *scene.info;
  const ml::Vec3i centre{info.sphere_center[0], info.sphere_center[1], info.sphere_center[2]};
  return ml::frame_sphere(centre, info.sphere_radius, 24, 16, 45 << 16);
}

// One frame into CheckingSink, the arena render_arena_bytes and, with_spare, render_spare_bytes too;
// skipped (Ok) when that is more than max_bytes.
inline ml::Status render_checked(const ml::Scene& scene, const ml::Camera& camera, const ml::RenderOptions& options,
                                 bool with_spare, size_t max_bytes = SIZE_MAX) {
  const size_t spare = with_spare ? ml::render_spare_bytes(scene, camera, options) : 0;
  const size_t bytes = ml::render_arena_bytes(scene, camera, options) + spare;
  if (bytes > max_bytes) return ml::Status{};
  std::vector<uint8_t> storage(bytes, kPoison);
  ml::Arena arena(storage.data(), bytes);
  CheckingSink sink;
  ml::Stats stats;
  return ml::render(scene, camera, options, arena, sink, &stats);
}

}  // namespace fuzz

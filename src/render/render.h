// One entry point for both renderers: the host CLI, tests and firmware call render().
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "core/arena.h"
#include "core/sink.h"
#include "core/stats.h"
#include "core/status.h"
#include "scene/scene.h"
#include "shade/shade.h"
#include "view/view.h"

namespace ml {

enum class RendererKind : uint8_t { Tiler, Scanline };

// Optional per-pixel work counter (Greene's work image): the tiler adds, for every pyramid cell it
// visits, 1 / (pixels the cell covers) to each of those pixels, in Q16 units. Host-owned buffer of
// width * height entries; null when not wanted.
struct WorkImage {
  uint32_t* q16 = nullptr;
  int width = 0, height = 0;
};

struct RenderOptions {
  RendererKind renderer = RendererKind::Tiler;
  ShadingMode shading = ShadingMode::Flat;
  int aa = 1;                         // samples per pixel per axis (scanline: 1..8; tiler: 1)
  Pixel background = 0x202830;        // 0x00RRGGBB; ignored (0) in Ids mode
  uint32_t seed = 1;                  // for stochastic choices (adaptive shading, jitter)
  WorkImage* work = nullptr;
};

// Arena bytes a render needs (the render fails with ArenaTooSmall naming this number if given less).
size_t render_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options);

Status render(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
              Sink& sink, Stats* stats);

}  // namespace ml

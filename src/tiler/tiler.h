// Greene's hierarchical polygon tiler: BSP front-to-back order, triage coverage masks from ROM tables
// (tables/), a coverage pyramid, every visible pixel written exactly once. See docs/tiler.md.
#pragma once
#include "render/render.h"

namespace ml {

size_t tiler_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options);
Status tiler_render(const Scene& scene, const Camera& camera, const RenderOptions& options,
                    Arena& arena, Sink& sink, Stats* stats);

}  // namespace ml

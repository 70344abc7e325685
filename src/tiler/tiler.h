// Greene's hierarchical polygon tiler: BSP front-to-back order, triage coverage masks from ROM tables
// (tables/), a coverage pyramid, every visible pixel written exactly once. See docs/tiler.md.
#pragma once
#include <stddef.h>

#include "core/arena.h"
#include "core/options.h"
#include "core/sink.h"
#include "core/stats.h"
#include "core/status.h"
#include "scene/scene.h"
#include "view/view.h"

namespace ml {

size_t tiler_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options);
Status tiler_render(const Scene& scene, const Camera& camera, const RenderOptions& options,
                    Arena& arena, Sink& sink, Stats* stats);

}  // namespace ml

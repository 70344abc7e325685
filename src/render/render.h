// One entry point for both renderers: the host CLI, tests and firmware call render().
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "core/arena.h"
#include "core/options.h"
#include "core/sink.h"
#include "core/stats.h"
#include "core/status.h"
#include "scene/scene.h"
#include "shade/shade.h"
#include "view/view.h"

namespace ml {

// Arena bytes a render needs (the render fails with ArenaTooSmall naming this number if given less).
size_t render_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options);

// Arena bytes beyond render_arena_bytes that make a frame faster when the arena has them free (the
// tiler's band plan, tiler_plan_bytes, for frames of several bands; 0 otherwise). Same image either way.
size_t render_spare_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options);

Status render(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
              Sink& sink, Stats* stats);

}  // namespace ml

// What every renderer entry of render.h does around the renderer itself (render/entry.cpp): the
// options as a renderer sees them, the checks and the counters filled in after the frame.
#pragma once
#include "render/render.h"

namespace ml {

// A renderer's own entry (tiler_render, scanline_render).
using RendererEntry = Status (*)(const Scene&, const Camera&, const RenderOptions&, Arena&, Sink&, Stats*);

// Id mode always leaves as Id32 (32-bit ids, whatever format was asked for).
RenderOptions effective_options(const RenderOptions& options);

// Renders with `entry`: stats cleared (a local set when stats is null), Id32 refused outside ids
// shading, the sink's counters copied into the stats afterwards.
Status render_with(RendererEntry entry, const Scene& scene, const Camera& camera, const RenderOptions& given,
                   Arena& arena, Sink& sink, Stats* stats);

}  // namespace ml

// Woo and Chall's scanline renderer: sorted triangle arrays, active lists, supersampling with one
// shading call per pixel, rows streamed to the sink top to bottom. See docs/scanline.md.
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

size_t scanline_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options);
Status scanline_render(const Scene& scene, const Camera& camera, const RenderOptions& options,
                       Arena& arena, Sink& sink, Stats* stats);

}  // namespace ml

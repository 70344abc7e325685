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
// Arena bytes beyond scanline_arena_bytes that make a frame faster when the arena has them free: a
// vertex cache (view/vertex_cache.h, 40 bytes a vertex up to 1,024) for the view transforms of the
// ySortList pass and of activation; 0 in a build without it (ML_VERTEX_CACHE=0, the Cortex-M0+ image).
// Same image either way. With fewer, the cache the free bytes hold serves the ySortList pass while the
// list leaves it room.
size_t scanline_spare_bytes(const Scene& scene);
Status scanline_render(const Scene& scene, const Camera& camera, const RenderOptions& options,
                       Arena& arena, Sink& sink, Stats* stats);

}  // namespace ml

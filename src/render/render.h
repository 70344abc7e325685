// One entry point for both renderers: the host CLI, tests and firmware call render(). An image that
// uses one renderer only calls that renderer's entry (render_tiler, render_scanline), which links
// nothing of the other (each entry is a translation unit of its own; render() references both).
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
// tiler's bands rendered at once, tiler_render_rows_bytes: the most OutputOptions::render_rows allows,
// an upper bound for a frame whose textures keep it to fewer; the plan of the bands that leaves, its
// BSP subtrees' screen rectangles and textured triangles' planes, tiler_plan_bytes; for a frame of
// one band the plan's facing bits and, when the BSP split textured triangles, their planes alone,
// which 32-bit boards do not keep: 0 there; and its vertex cache, tiler_cache_bytes; the scanline
// renderer's vertex cache, scanline_spare_bytes; both caches 0 in a build without them,
// ML_VERTEX_CACHE=0: the Cortex-M0+ image). Same image either way.
size_t render_spare_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options);

Status render(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
              Sink& sink, Stats* stats);

// render_arena_bytes and render with options.renderer taken as the tiler (render/render_tiler.cpp) or
// the scanline renderer (render/render_scanline.cpp), whatever it says.
size_t render_tiler_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options);
size_t render_tiler_spare_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options);
Status render_tiler(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
                    Sink& sink, Stats* stats);
// The tiler without its cosine-hump filter (options.filter = cosine is Unsupported): an image that
// never asks for it calls this and links none of the filter's code and tables (about 18 KB of flash).
Status render_tiler_box(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
                        Sink& sink, Stats* stats);
size_t render_scanline_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options);
size_t render_scanline_spare_bytes(const Scene& scene);
Status render_scanline(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
                       Sink& sink, Stats* stats);

}  // namespace ml

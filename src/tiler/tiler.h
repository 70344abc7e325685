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

class SampleFilter;  // tiler/filter.h

// The least arena the tiler needs (render() checks it).
size_t tiler_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options);
// Arena bytes beyond tiler_arena_bytes with which a frame of `bands` bands plans them once (one entry
// a BSP piece, a byte up to 16 bands and two beyond: each piece's facing test and band range are worked
// out once, not once per band; and two bits a triangle: its facing, tested once for all the pieces the
// BSP split it into; on 32-bit targets a byte a piece alone; a frame of one band keeps the facing bits
// alone, none on 32-bit targets), and eight bytes a BSP node with several bands: the screen rectangle of
// its subtree's box, worked out in the first band that tests it, not in every band; with texels in
// the scene and several bands, or a BSP that split triangles, 256 textured triangles' texture planes
// kept for their next piece or band (32 KB; none on 32-bit targets).
// The tiler uses them when the arena has them free (the pieces' entries first, the rectangles, then the
// planes when they fit as well); the image is the same either way.
size_t tiler_plan_bytes(const Scene& scene, int bands);
// Arena bytes beyond those with which each vertex is decoded and transformed about once a frame (the
// vertex cache, view/vertex_cache.h: 40 bytes a vertex up to 1,024; none in a build without it,
// ML_VERTEX_CACHE=0). Taken, as many as fit, from what the arena has free after the plan; the image
// is the same either way.
size_t tiler_cache_bytes(const Scene& scene);
// Arena bytes beyond tiler_arena_bytes with which the frame is rendered `render_rows` rows at a time
// (render_rows_for: whole bands; core/band.h's render bands, on 64-bit hosts, 0 elsewhere): one band
// buffer of those rows in place of the band buffers, and a pyramid (and antialiasing sums) that tall.
// The walk of the BSP and its per-band tests then run once for all those bands. Taken before the plan
// and the vertex cache: as many bands at once as the arena has free (the image is the same either
// way), and in a frame with paged textures no more than keep the textures the pager plans to hold at
// once to a band at a time's (the pager frees a texture after the last band that uses it: the banded
// scene's four textures at 320x240 in 16-row bands peak at half their bytes, in one band at all).
size_t tiler_render_rows_bytes(const Camera& camera, const RenderOptions& options, int render_rows);
// cosine: the cosine-hump filter to use when options.filter asks for it (a CosineFilter); null leaves
// it out of the image (such a render is Unsupported).
Status tiler_render(const Scene& scene, const Camera& camera, const RenderOptions& options,
                    Arena& arena, Sink& sink, Stats* stats, SampleFilter* cosine);

}  // namespace ml

// The tiler's entries alone: an image that calls only these links no scanline code, and one that
// calls only render_tiler_box links no cosine-hump filter.
#include "core/band.h"
#include "render/entry.h"
#include "texture/pager.h"
#include "tiler/filter.h"
#include "tiler/tiler.h"

namespace ml {

namespace {

Status tiler_with_filters(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
                          Sink& sink, Stats* stats) {
  CosineFilter cosine;
  return tiler_render(scene, camera, options, arena, sink, stats, &cosine);
}

Status tiler_box_only(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
                      Sink& sink, Stats* stats) {
  return tiler_render(scene, camera, options, arena, sink, stats, nullptr);
}

}  // namespace

size_t render_tiler_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  return tiler_arena_bytes(scene, camera, effective_options(options));
}

size_t render_tiler_spare_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  // The most rows at once the options allow, and the plan of the bands that leaves; with textures the
  // frame may keep to a band at a time (tiler_render_rows_bytes): then the plan of every band.
  const RenderOptions o = effective_options(options);
  const int most = render_rows_allowed(o.output, camera.height);
  const size_t at_once = tiler_render_rows_bytes(camera, o, most);
  const bool paged = o.shading != ShadingMode::Ids && texture_pool_needs(scene).desired > 0;
  const int rows = at_once > 0 && !paged ? render_rows_for(o.output, camera.height, most) : band_rows_for(o.output, camera.height);
  return at_once + tiler_plan_bytes(scene, (camera.height + rows - 1) / rows) + tiler_cache_bytes(scene);
}

Status render_tiler(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
                    Sink& sink, Stats* stats) {
  return render_with(tiler_with_filters, scene, camera, options, arena, sink, stats);
}

Status render_tiler_box(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
                        Sink& sink, Stats* stats) {
  return render_with(tiler_box_only, scene, camera, options, arena, sink, stats);
}

}  // namespace ml

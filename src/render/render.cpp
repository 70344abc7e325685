#include "render/render.h"

namespace ml {

size_t render_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  return options.renderer == RendererKind::Tiler ? render_tiler_arena_bytes(scene, camera, options)
                                                 : render_scanline_arena_bytes(scene, camera, options);
}

size_t render_spare_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  return options.renderer == RendererKind::Tiler ? render_tiler_spare_bytes(scene, camera, options)
                                                 : render_scanline_spare_bytes(scene);
}

Status render(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
              Sink& sink, Stats* stats) {
  return options.renderer == RendererKind::Tiler ? render_tiler(scene, camera, options, arena, sink, stats)
                                                 : render_scanline(scene, camera, options, arena, sink, stats);
}

}  // namespace ml

#include "render/render.h"

#include "scanline/scanline.h"
#include "tiler/tiler.h"

namespace ml {

size_t render_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  return options.renderer == RendererKind::Tiler ? tiler_arena_bytes(scene, camera, options)
                                                 : scanline_arena_bytes(scene, camera, options);
}

Status render(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
              Sink& sink, Stats* stats) {
  Stats local;
  Stats* out = stats ? stats : &local;
  *out = Stats{};
  return options.renderer == RendererKind::Tiler
             ? tiler_render(scene, camera, options, arena, sink, out)
             : scanline_render(scene, camera, options, arena, sink, out);
}

}  // namespace ml

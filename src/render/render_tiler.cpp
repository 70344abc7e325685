// The tiler's entry alone: an image that calls only this links no scanline code.
#include "render/entry.h"
#include "tiler/tiler.h"

namespace ml {

size_t render_tiler_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  return tiler_arena_bytes(scene, camera, effective_options(options));
}

Status render_tiler(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
                    Sink& sink, Stats* stats) {
  return render_with(tiler_render, scene, camera, options, arena, sink, stats);
}

}  // namespace ml

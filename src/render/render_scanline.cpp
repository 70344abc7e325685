// The scanline renderer's entry alone: an image that calls only this links no tiler code.
#include "render/entry.h"
#include "scanline/scanline.h"

namespace ml {

size_t render_scanline_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  return scanline_arena_bytes(scene, camera, effective_options(options));
}

size_t render_scanline_spare_bytes(const Scene& scene) { return scanline_spare_bytes(scene); }

Status render_scanline(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
                       Sink& sink, Stats* stats) {
  // The scanline renderer filters with its own box over corner samples (docs/scanline.md).
  if (options.filter != FilterKind::Box)
    return error(StatusCode::Unsupported, "the filter option is the tiler's (the scanline renderer has its own)");
  if (options.samples != SamplePattern::Regular)
    return error(StatusCode::Unsupported,
                 "the scanline renderer supersamples its corner lattice (jittered samples: Camera::sample_shift)");
  return render_with(scanline_render, scene, camera, options, arena, sink, stats);
}

}  // namespace ml

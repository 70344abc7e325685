#include "render/render.h"

#include "scanline/scanline.h"
#include "tiler/tiler.h"

namespace ml {

namespace {

// Id mode always leaves as Id32 (32-bit ids, whatever format was asked for).
RenderOptions effective(const RenderOptions& options) {
  RenderOptions o = options;
  if (o.shading == ShadingMode::Ids) o.output.format = PixelFormat::Id32;
  return o;
}

}  // namespace

size_t render_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& given) {
  const RenderOptions options = effective(given);
  return options.renderer == RendererKind::Tiler ? tiler_arena_bytes(scene, camera, options)
                                                 : scanline_arena_bytes(scene, camera, options);
}

Status render(const Scene& scene, const Camera& camera, const RenderOptions& given, Arena& arena,
              Sink& sink, Stats* stats) {
  const RenderOptions options = effective(given);
  Stats local;
  Stats* out = stats ? stats : &local;
  *out = Stats{};
  if (options.shading != ShadingMode::Ids && options.output.format == PixelFormat::Id32)
    return error(StatusCode::InvalidArgument, "the Id32 output format is for ids shading only");
  if (options.renderer == RendererKind::Scanline && options.filter != FilterKind::Box)
    return error(StatusCode::Unsupported, "the scanline renderer filters with its own box (filter is the tiler's)");
  const Status s = options.renderer == RendererKind::Tiler
                       ? tiler_render(scene, camera, options, arena, sink, out)
                       : scanline_render(scene, camera, options, arena, sink, out);
  out->sink_calls = out->bands;  // one flush a band
  out->display_bytes = sink.counters.bytes;
  out->display_windows = sink.counters.windows;
  return s;
}

}  // namespace ml

#include "render/entry.h"

namespace ml {

RenderOptions effective_options(const RenderOptions& options) {
  RenderOptions o = options;
  if (o.shading == ShadingMode::Ids) o.output.format = PixelFormat::Id32;
  return o;
}

Status render_with(RendererEntry entry, const Scene& scene, const Camera& camera, const RenderOptions& given,
                   Arena& arena, Sink& sink, Stats* stats) {
  const RenderOptions options = effective_options(given);
  Stats local;
  Stats* out = stats ? stats : &local;
  *out = Stats{};
  if (options.shading != ShadingMode::Ids && options.output.format == PixelFormat::Id32)
    return error(StatusCode::InvalidArgument, "the Id32 output format is for ids shading only");
  const Status s = entry(scene, camera, options, arena, sink, out);
  out->sink_calls = out->bands;  // one flush a band
  out->display_bytes = sink.counters.bytes;
  out->display_windows = sink.counters.windows;
  return s;
}

}  // namespace ml

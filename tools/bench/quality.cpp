// bench quality: how close each renderer's antialiased picture comes to a reference. The reference
// is the double-precision oracle (tests/oracle) casting 16 x 16 rays a pixel, box-filtered, or
// filtered with the tiler's cosine-hump kernel for the cosine rows; renders use unlit base colours,
// so only coverage (visibility and filtering) makes the difference. Prints one line a renderer,
// sample count and filter: RMS and largest error per channel (0..255).
#include <stdio.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/arena.h"
#include "platform/host/image_sink.h"
#include "platform/host/scene_load.h"
#include "render/render.h"
#include "tests/oracle/oracle.h"
#include "tests/oracle/scene_triangles.h"
#include "tools/bench/bench.h"

namespace {

constexpr int kReferenceSamples = 16;  // rays a pixel per axis
constexpr ml::Pixel kBackground = 0x202830;

int channel(uint32_t p, int c) { return int(p >> (16 - 8 * c)) & 0xFF; }

bool render_unlit(const ml::Scene& scene, const ml::Camera& camera, ml::RendererKind renderer, int aa,
                  ml::FilterKind filter, ml::SamplePattern samples, std::vector<ml::Pixel>* pixels) {
  ml::RenderOptions o;
  o.renderer = renderer;
  o.shading = ml::ShadingMode::Unlit;
  o.aa = aa;
  o.filter = filter;
  o.samples = samples;
  o.background = kBackground;
  const size_t bytes = ml::render_arena_bytes(scene, camera, o);
  std::vector<uint64_t> storage(bytes / 8 + 1);
  ml::Arena arena(storage.data(), bytes);
  mlhost::ImageSink sink;
  const ml::Status s = ml::render(scene, camera, o, arena, sink, nullptr);
  if (!s.ok() || !sink.contract_ok()) {
    fprintf(stderr, "bench quality: render failed: %s\n", s.ok() ? sink.contract_error().c_str() : s.message);
    return false;
  }
  *pixels = sink.pixels();
  return true;
}

}  // namespace

int quality(const std::string& path, const std::string& size) {
  int w = 0, h = 0;
  if (sscanf(size.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1 || w > 1024 || h > 1024) {
    fprintf(stderr, "bench quality: size must be WxH, 1..1024 each\n");
    return 2;
  }
  mlhost::LoadedScene loaded;
  std::string error;
  if (!mlhost::load_scene(path, &loaded, &error)) {
    fprintf(stderr, "bench quality: %s\n", error.c_str());
    return 1;
  }
  const ml::Scene& scene = loaded.scene;
  const ml::Camera camera = bench_camera(path, scene, w, h);
  const std::vector<double> box_ref = oracle::box_filtered_unlit(scene, camera, kReferenceSamples, kBackground);
  const std::vector<double> cosine_ref = oracle::cosine_filtered_unlit(scene, camera, kReferenceSamples, kBackground);
  constexpr ml::FilterKind kBox = ml::FilterKind::Box, kCosine = ml::FilterKind::Cosine;
  constexpr bool kJit = true;
  const ml::RendererKind kTiler = ml::RendererKind::Tiler, kScan = ml::RendererKind::Scanline;
  const struct {
    ml::RendererKind kind;
    int aa;
    ml::FilterKind filter;
    bool jittered, cosine_reference;
  } runs[] = {{kTiler, 1, kBox, false, false},  {kTiler, 2, kBox, false, false},   {kTiler, 4, kBox, false, false},
              {kTiler, 8, kBox, false, false},  {kTiler, 4, kBox, kJit, false},    {kTiler, 8, kBox, kJit, false},
              {kScan, 1, kBox, false, false},   {kScan, 3, kBox, false, false},    {kScan, 4, kBox, false, false},
              {kTiler, 1, kBox, false, true},   {kTiler, 8, kBox, false, true},    {kTiler, 4, kCosine, false, true},
              {kTiler, 8, kCosine, false, true}, {kTiler, 8, kCosine, kJit, true}};
  for (const auto& run : runs) {
    std::vector<ml::Pixel> pixels;
    const ml::SamplePattern samples = run.jittered ? ml::SamplePattern::Jittered : ml::SamplePattern::Regular;
    if (!render_unlit(scene, camera, run.kind, run.aa, run.filter, samples, &pixels)) return 1;
    const std::vector<double>& ref = run.cosine_reference ? cosine_ref : box_ref;
    double sum = 0, worst = 0;
    for (size_t i = 0; i < pixels.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const double d = std::fabs(channel(pixels[i], k) - ref[i * 3 + size_t(k)]);
        sum += d * d;
        worst = std::max(worst, d);
      }
    printf("renderer=%s aa=%d samples=%s filter=%s reference=%s size=%dx%d rms=%.3f max=%.1f\n",
           run.kind == kTiler ? "tiler" : "scanline", run.aa, run.jittered ? "jittered" : "regular",
           run.filter == kCosine ? "cosine" : "box", run.cosine_reference ? "cosine" : "box", w, h,
           std::sqrt(sum / double(pixels.size() * 3)), worst);
  }
  return 0;
}

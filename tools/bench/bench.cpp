// Benchmark driver: renders one frame of a scene with the tiler, the scanline renderer or a plain
// z-buffer baseline into a sink that discards pixels. Only the frame runs between
// CALLGRIND_START_INSTRUMENTATION and CALLGRIND_STOP_INSTRUMENTATION, so
//   valgrind --tool=callgrind --instr-atstart=no build/bench ...
// counts the instructions of exactly one frame (tools/bench/run.sh does this and builds the table).
//
//   bench prepare default|office[:LAYERS]|tessellated[:TRIANGLES]|FILE OUT.mls
//       compile a scene (natively, before measuring) to a blob; writes OUT.mls.camera when the scene
//       has a suggested camera (the office scene looks down its rows)
//   bench frame SCENE.mls tiler|scanline|zbuffer WxH AA [flat|gouraud] [BAND_ROWS [FORMAT]]
//       one frame (flat shading unless told; 16-row XRGB8888 bands unless told, 0 = the whole frame
//       as one band); prints "key=value ..." statistics on stdout
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <valgrind/callgrind.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "core/arena.h"
#include "platform/host/format_names.h"
#include "platform/host/scene_load.h"
#include "render/render.h"
#include "shade/shade.h"
#include "tools/scenec/scenec.h"
#include "view/view.h"

namespace {

// Counts what arrives and keeps nothing, like a display that is not there.
class DiscardSink : public ml::Sink {
 public:
  bool flush(const ml::Flush& band) override {
    pixels_ += uint64_t(band.width) * uint64_t(band.height);
    checksum_ += band.bytes[0];
    flush_ready(band.buffer);
    return true;
  }
  uint64_t pixels_ = 0;
  uint64_t checksum_ = 0;
};

// The baseline: a plain z-buffer scan converter. Same camera, same project_triangle/setup_triangle
// setup and the same flat shading as the renderers, but its own full-screen colour and depth buffers
// and bounding-box + edge-function scan conversion of every triangle in scene order.
struct ZBufferStats {
  uint64_t pixels_tested = 0, pixels_written = 0;
  uint32_t triangles_drawn = 0;
  size_t buffer_bytes = 0;
};

ml::Status zbuffer_render(const ml::Scene& scene, const ml::Camera& camera, ml::Pixel background, ml::Sink& sink,
                          ZBufferStats* st) {
  ml::View view;
  ml::Status s = ml::make_view(camera, &view);
  if (!s.ok()) return s;
  const ml::Light light = ml::make_light(view);
  const int w = camera.width, h = camera.height;
  std::vector<ml::Pixel> colour(size_t(w) * size_t(h), background);
  std::vector<uint32_t> depth(size_t(w) * size_t(h), 0);  // larger = nearer; 0 = empty
  st->buffer_bytes = colour.size() * sizeof(ml::Pixel) + depth.size() * sizeof(uint32_t);
  ml::ScreenTriangle pieces[ml::kMaxClipTriangles];
  for (uint32_t id = 0; id < scene.triangle_count; ++id) {
    ml::Vec3i world[3];
    ml::triangle_world(scene, id, world);
    const int count = ml::project_triangle(view, world, pieces);
    if (count == 0) continue;
    const bool double_sided = scene.materials[scene.batches[scene.triangles[id].batch].material].double_sided != 0;
    bool drawn = false;
    for (int p = 0; p < count; ++p) {
      const ml::ScreenTriangle& tri = pieces[p];
      if (!tri.front_facing && !double_sided) continue;
      ml::TriangleSetup setup;
      ml::setup_triangle(tri, w, h, &setup);
      if (setup.min_x > setup.max_x || setup.min_y > setup.max_y) continue;
      ml::TriangleColors colors;
      ml::shade_triangle(scene, light, ml::ShadingMode::Flat, id, tri.front_facing, &colors);
      // Depth (linear in screen space) as a Q16 plane over pixel indices: edge i (v[i] -> v[i+1]) is
      // proportional to the weight of the opposite vertex v[i+2].
      const int64_t cx0 = int64_t(setup.min_x) * ml::kSubpixelOne + ml::kSubpixelHalf;
      const int64_t cy0 = int64_t(setup.min_y) * ml::kSubpixelOne + ml::kSubpixelHalf;
      __int128 origin = 0, step_x = 0, step_y = 0;
      for (int i = 0; i < 3; ++i) {
        const ml::EdgeFunction& e = setup.edge[i];
        const int64_t d = tri.v[(i + 2) % 3].depth;
        origin += __int128(e.a * cx0 + e.b * cy0 + e.c) * d;
        step_x += __int128(e.a) * ml::kSubpixelOne * d;
        step_y += __int128(e.b) * ml::kSubpixelOne * d;
      }
      const __int128 area2 = tri.area2;
      const int64_t z_origin = int64_t((origin << 16) / area2);
      const int64_t z_dx = int64_t((step_x << 16) / area2);
      const int64_t z_dy = int64_t((step_y << 16) / area2);
      int64_t e_row[3];
      int64_t e_dx[3], e_dy[3];
      for (int i = 0; i < 3; ++i) {
        e_row[i] = setup.edge[i].at(cx0, cy0);
        e_dx[i] = setup.edge[i].a * ml::kSubpixelOne;
        e_dy[i] = setup.edge[i].b * ml::kSubpixelOne;
      }
      int64_t z_row = z_origin;
      for (int y = setup.min_y; y <= setup.max_y; ++y) {
        int64_t e0 = e_row[0], e1 = e_row[1], e2 = e_row[2], z = z_row;
        ml::Pixel* crow = colour.data() + size_t(y) * size_t(w);
        uint32_t* zrow = depth.data() + size_t(y) * size_t(w);
        for (int x = setup.min_x; x <= setup.max_x; ++x) {
          ++st->pixels_tested;
          if ((e0 | e1 | e2) >= 0) {
            const uint32_t zz = uint32_t(z >> 16);
            if (zz > zrow[x]) {
              zrow[x] = zz;
              crow[x] = colors.flat;
              ++st->pixels_written;
              drawn = true;
            }
          }
          e0 += e_dx[0];
          e1 += e_dx[1];
          e2 += e_dx[2];
          z += z_dx;
        }
        for (int i = 0; i < 3; ++i) e_row[i] += e_dy[i];
        z_row += z_dy;
      }
    }
    st->triangles_drawn += drawn;
  }
  // The colour buffer is XRGB8888 already: the frame leaves as one band.
  ml::FrameInfo frame;
  frame.width = w;
  frame.height = h;
  frame.band_rows = h;
  ml::Flush all;
  all.width = w;
  all.height = h;
  all.stride = uint32_t(w) * 4;
  all.bytes = reinterpret_cast<const uint8_t*>(colour.data());
  if (!sink.begin_frame(frame) || !sink.flush(all) || !sink.end_frame())
    return ml::error(ml::StatusCode::SinkFailed, "sink refused the frame");
  return ml::ok_status();
}

int usage() {
  fprintf(stderr,
          "usage: bench prepare default|office[:LAYERS]|tessellated[:TRIANGLES]|banded|banded-plain|FILE|plain:FILE OUT.mls\n"
          "       bench frame SCENE.mls tiler|scanline|zbuffer WxH AA [flat|gouraud] [BAND_ROWS [FORMAT]]\n");
  return 2;
}

// The same scene without texels (every texture draws its material colour): the untextured baseline of
// a textured frame. An empty path is the banded scene.
ml::CompileResult compile_untextured(const std::string& path) {
  ml::SceneMesh mesh;
  if (path.empty()) {
    mesh = ml::make_banded_scene();
  } else {
    std::vector<std::string> warnings;
    ml::CompileResult failed;
    if (!ml::import_gltf_file(path, &mesh, &warnings, &failed.error)) return failed;
  }
  mesh.images.clear();
  return ml::compile_mesh(mesh);
}

int prepare(const std::string& what, const std::string& out) {
  ml::CompileResult result;
  const size_t colon = what.find(':');
  const std::string kind = what.substr(0, colon);
  const std::string arg = colon == std::string::npos ? "" : what.substr(colon + 1);
  if (kind == "default") result = ml::build_default_scene();
  else if (kind == "office") result = ml::build_office_scene(arg.empty() ? 8 : atoi(arg.c_str()));
  else if (kind == "tessellated") result = ml::build_tessellated_scene(arg.empty() ? 100000u : uint32_t(atol(arg.c_str())));
  else if (kind == "banded") result = ml::build_banded_scene();
  else if (kind == "banded-plain" || kind == "plain") result = compile_untextured(kind == "plain" ? arg : "");
  else result = ml::compile_gltf_file(what);
  if (!result.ok) {
    fprintf(stderr, "bench: %s\n", result.error.c_str());
    return 1;
  }
  std::string error;
  if (!ml::save_blob_file(out, result.blob, &error)) {
    fprintf(stderr, "bench: %s\n", error.c_str());
    return 1;
  }
  const std::string cam_path = out + ".camera";
  remove(cam_path.c_str());
  if (result.camera.valid) {
    std::ofstream f(cam_path);
    for (const double* v : {result.camera.eye, result.camera.target})
      f << std::llround(v[0]) << " " << std::llround(v[1]) << " " << std::llround(v[2]) << "\n";
    const double* u = result.camera.up;  // a direction: keep 20 fractional bits
    f << std::llround(u[0] * 1048576) << " " << std::llround(u[1] * 1048576) << " " << std::llround(u[2] * 1048576) << "\n";
  }
  printf("%s: %u triangles, %zu bytes, bsp split ratio %.4f\n", out.c_str(), result.report.triangles, result.blob.size,
         result.report.split_ratio);
  return 0;
}

int frame(const std::string& path, const std::string& renderer, const std::string& size, int aa,
          ml::ShadingMode shading, const ml::OutputOptions& output) {
  int w = 0, h = 0;
  if (sscanf(size.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1 || w > ml::kMaxScreenDim ||
      h > ml::kMaxScreenDim)
    return usage();
  mlhost::LoadedScene loaded;
  std::string error;
  if (!mlhost::load_scene(path, &loaded, &error)) {
    fprintf(stderr, "bench: %s\n", error.c_str());
    return 1;
  }
  const ml::Scene& scene = loaded.scene;
  const ml::SceneInfo& info = *scene.info;
  ml::Camera camera = ml::frame_sphere(ml::Vec3i{info.sphere_center[0], info.sphere_center[1], info.sphere_center[2]},
                                       info.sphere_radius, w, h, 45 << 16);
  std::ifstream cam_file(path + ".camera");
  long long e[9];
  if (cam_file && (cam_file >> e[0] >> e[1] >> e[2] >> e[3] >> e[4] >> e[5] >> e[6] >> e[7] >> e[8])) {
    camera.eye = ml::Vec3i{int32_t(e[0]), int32_t(e[1]), int32_t(e[2])};
    camera.target = ml::Vec3i{int32_t(e[3]), int32_t(e[4]), int32_t(e[5])};
    camera.up = ml::Vec3i{int32_t(e[6]), int32_t(e[7]), int32_t(e[8])};
    if (camera.up.x == 0 && camera.up.y == 0 && camera.up.z == 0) camera.up = ml::Vec3i{0, 1, 0};
    camera.near = std::max(16, info.sphere_radius / 1024);
  }
  DiscardSink sink;
  ml::Stats stats;
  ml::Status s;
  const double pixels = double(w) * h;
  if (renderer == "zbuffer") {
    ZBufferStats z;
    CALLGRIND_START_INSTRUMENTATION;
    s = zbuffer_render(scene, camera, 0x202830, sink, &z);
    CALLGRIND_STOP_INSTRUMENTATION;
    if (!s.ok()) {
      fprintf(stderr, "bench: %s\n", s.message);
      return 1;
    }
    printf("renderer=zbuffer size=%dx%d aa=1 triangles=%u drawn=%u pixels_tested=%llu pixels_written=%llu "
           "buffer_bytes=%zu sink_pixels=%llu\n",
           w, h, scene.triangle_count, z.triangles_drawn, (unsigned long long)z.pixels_tested,
           (unsigned long long)z.pixels_written, z.buffer_bytes, (unsigned long long)sink.pixels_);
    return 0;
  }
  ml::RenderOptions o;
  if (renderer == "tiler") o.renderer = ml::RendererKind::Tiler;
  else if (renderer == "scanline") o.renderer = ml::RendererKind::Scanline;
  else return usage();
  o.shading = shading;
  o.aa = aa;
  o.output = output;
  const size_t bytes = ml::render_arena_bytes(scene, camera, o);
  std::vector<uint64_t> storage(bytes / 8 + 1);
  ml::Arena arena(storage.data(), bytes);
  CALLGRIND_START_INSTRUMENTATION;
  s = ml::render(scene, camera, o, arena, sink, &stats);
  CALLGRIND_STOP_INSTRUMENTATION;
  if (!s.ok()) {
    fprintf(stderr, "bench: render failed: %s (%llu)\n", s.message, (unsigned long long)s.value);
    return 1;
  }
  printf("renderer=%s size=%dx%d aa=%d triangles=%u drawn=%u culled=%u cells_visited=%llu cells_per_pixel=%.4f "
         "peak_arena_bytes=%u arena_bytes=%zu pyramid_bytes=%u shading_calls=%llu geometry_samples=%llu m_max=%u n=%u "
         "pixel_writes=%llu sink_pixels=%llu bands=%u\n",
         renderer.c_str(), w, h, aa, scene.triangle_count, stats.triangles_drawn, stats.triangles_culled,
         (unsigned long long)stats.cells_visited, double(stats.cells_visited) / pixels, stats.peak_arena_bytes, bytes,
         stats.pyramid_bytes, (unsigned long long)stats.shading_calls, (unsigned long long)stats.geometry_samples,
         stats.m_max, stats.n, (unsigned long long)stats.pixel_writes, (unsigned long long)sink.pixels_, stats.bands);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && strcmp(argv[1], "prepare") == 0) return prepare(argv[2], argv[3]);
  if (argc >= 6 && argc <= 9 && strcmp(argv[1], "frame") == 0) {
    const int aa = atoi(argv[5]);
    if (aa < 1 || aa > 8) return usage();
    ml::ShadingMode shading = ml::ShadingMode::Flat;
    if (argc >= 7 && strcmp(argv[6], "gouraud") == 0) shading = ml::ShadingMode::Gouraud;
    else if (argc >= 7 && strcmp(argv[6], "flat") != 0) return usage();
    ml::OutputOptions output;
    if (argc >= 8) output.band_rows = atoi(argv[7]);
    if (argc >= 9 && !mlhost::parse_format(argv[8], &output.format)) return usage();
    if (output.band_rows < 0) return usage();
    return frame(argv[2], argv[3], argv[4], aa, shading, output);
  }
  return usage();
}

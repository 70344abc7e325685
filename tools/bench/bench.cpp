// Benchmark driver: renders one frame of a scene with the tiler, the scanline renderer or an integer
// z-buffer baseline into a sink that discards pixels. Only the frame runs between
// CALLGRIND_START_INSTRUMENTATION and CALLGRIND_STOP_INSTRUMENTATION, so
//   valgrind --tool=callgrind --instr-atstart=no build/bench ...
// counts the instructions of exactly one frame (tools/bench/run.sh does this and builds the table).
//
//   bench prepare default|office[:LAYERS]|tessellated[:TRIANGLES]|FILE OUT.mls
//       compile a scene (natively, before measuring) to a blob; writes OUT.mls.camera when the scene
//       has a suggested camera (the office scene looks down its rows)
//   bench frame SCENE.mls tiler|scanline|zbuffer WxH AA [flat|gouraud] [BAND_ROWS[:RENDER_ROWS] [FORMAT]]
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
#include "tools/bench/bench.h"
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

// The baseline: what a good integer z-buffer renderer does (TinyGL, small3dlib): every vertex
// transformed and projected once per frame (not once per triangle), back faces culled from the
// projected winding, one flat colour per triangle, incremental edge functions along each row of the
// triangle's box (leaving the row once the span is passed), a 32-bit integer depth buffer and a colour
// buffer, and one write of the finished image to the sink. Triangles with a vertex behind the near
// plane or outside the guard band go through project_triangle's clipping (rare). The vertex cache and
// the two buffers are the baseline's own memory, counted in buffer_bytes.
struct ZBufferStats {
  uint64_t pixels_tested = 0, pixels_written = 0;
  uint32_t triangles_drawn = 0;
  size_t buffer_bytes = 0;
};

struct ProjectedVertex {
  int32_t x, y;     // subpixels
  uint32_t depth;   // near * 2^30 / z, larger = nearer
  bool ok;          // in front of the near plane and inside the guard band
};

ProjectedVertex project_vertex(const ml::View& view, const ml::Vec3i& world) {
  const int32_t vx = ml::view_coordinate(view, view.right, world);
  const int32_t vy = ml::view_coordinate(view, view.down, world);
  const int32_t vz = ml::view_coordinate(view, view.forward, world);
  ProjectedVertex p{0, 0, 0, false};
  if (vz < view.near) return p;
  const int64_t ox = ml::div_round(view.focal_q8 * vx, vz), oy = ml::div_round(view.focal_q8 * vy, vz);
  const int64_t guard = int64_t(ml::kGuardBandPixels) << ml::kSubpixelBits;
  if (ox < -guard || ox > guard || oy < -guard || oy > guard) return p;
  p.x = int32_t(view.center_x + ox);
  p.y = int32_t(view.center_y + oy);
  p.depth = uint32_t((uint64_t(view.near) << ml::kDepthBits) / uint64_t(vz));
  p.ok = true;
  return p;
}

class ZBuffer {
 public:
  ZBuffer(int w, int h, ml::Pixel background)
      : w_(w), h_(h), colour_(size_t(w) * size_t(h), background), depth_(size_t(w) * size_t(h), 0) {}

  // Draws a triangle whose vertices are in area2 > 0 order (all edge functions >= 0 inside).
  bool draw(const ml::ScreenVertex& v0, const ml::ScreenVertex& v1, const ml::ScreenVertex& v2, ml::Pixel colour,
            ZBufferStats* st) {
    ml::ScreenTriangle tri;
    tri.v[0] = v0;
    tri.v[1] = v1;
    tri.v[2] = v2;
    ml::TriangleSetup setup;
    ml::setup_triangle(tri, w_, h_, &setup);
    if (setup.min_x > setup.max_x || setup.min_y > setup.max_y) return false;
    const int64_t area2 = (int64_t(v1.x) - v0.x) * (int64_t(v2.y) - v0.y) - (int64_t(v1.y) - v0.y) * (int64_t(v2.x) - v0.x);
    // Depth as a Q16 plane over pixel centres: edge i is proportional to the weight of vertex i + 2.
    const int64_t cx0 = int64_t(setup.min_x) * ml::kSubpixelOne + ml::kSubpixelHalf;
    const int64_t cy0 = int64_t(setup.min_y) * ml::kSubpixelOne + ml::kSubpixelHalf;
    const uint32_t d[3] = {v2.depth, v0.depth, v1.depth};
    __int128 origin = 0, step_x = 0, step_y = 0;
    int64_t e_row[3], e_dx[3], e_dy[3];
    for (int i = 0; i < 3; ++i) {
      const ml::EdgeFunction& e = setup.edge[i];
      origin += __int128(e.a * cx0 + e.b * cy0 + e.c) * d[i];
      step_x += __int128(e.a) * ml::kSubpixelOne * d[i];
      step_y += __int128(e.b) * ml::kSubpixelOne * d[i];
      e_row[i] = e.at(cx0, cy0);
      e_dx[i] = e.a * ml::kSubpixelOne;
      e_dy[i] = e.b * ml::kSubpixelOne;
    }
    const int64_t z_dx = int64_t((step_x << 16) / area2), z_dy = int64_t((step_y << 16) / area2);
    int64_t z_row = int64_t((origin << 16) / area2);
    bool drawn = false;
    for (int y = setup.min_y; y <= setup.max_y; ++y) {
      int64_t e0 = e_row[0], e1 = e_row[1], e2 = e_row[2], z = z_row;
      ml::Pixel* crow = colour_.data() + size_t(y) * size_t(w_);
      uint32_t* zrow = depth_.data() + size_t(y) * size_t(w_);
      bool inside = false;
      for (int x = setup.min_x; x <= setup.max_x; ++x) {
        ++st->pixels_tested;
        if ((e0 | e1 | e2) >= 0) {
          inside = true;
          const uint32_t zz = uint32_t(z >> 16);
          if (zz > zrow[x]) {
            zrow[x] = zz;
            crow[x] = colour;
            ++st->pixels_written;
            drawn = true;
          }
        } else if (inside) {
          break;  // a row of a triangle is one span: past it, nothing more to cover
        }
        e0 += e_dx[0];
        e1 += e_dx[1];
        e2 += e_dx[2];
        z += z_dx;
      }
      for (int i = 0; i < 3; ++i) e_row[i] += e_dy[i];
      z_row += z_dy;
    }
    return drawn;
  }

  bool send(ml::Sink& sink) const {
    // The colour buffer is XRGB8888 already: the frame leaves as one band.
    ml::FrameInfo frame;
    frame.width = w_;
    frame.height = h_;
    frame.band_rows = h_;
    ml::Flush all;
    all.width = w_;
    all.height = h_;
    all.stride = uint32_t(w_) * 4;
    all.bytes = reinterpret_cast<const uint8_t*>(colour_.data());
    return sink.begin_frame(frame) && sink.flush(all) && sink.end_frame();
  }
  size_t bytes() const { return colour_.size() * sizeof(ml::Pixel) + depth_.size() * sizeof(uint32_t); }

 private:
  int w_, h_;
  std::vector<ml::Pixel> colour_;
  std::vector<uint32_t> depth_;
};

ml::ScreenVertex screen_vertex(const ProjectedVertex& p) {
  ml::ScreenVertex v{};
  v.x = p.x;
  v.y = p.y;
  v.depth = p.depth;
  return v;
}

ml::Status zbuffer_render(const ml::Scene& scene, const ml::Camera& camera, ml::Pixel background, ml::Sink& sink,
                          ZBufferStats* st) {
  ml::View view;
  ml::Status s = ml::make_view(camera, &view);
  if (!s.ok()) return s;
  const ml::Light light = ml::make_light(view);
  ZBuffer zb(camera.width, camera.height, background);
  // The vertex cache: each vertex projected the first time a triangle uses it.
  std::vector<ProjectedVertex> cache(scene.vertex_count);
  std::vector<uint8_t> done(scene.vertex_count, 0);
  st->buffer_bytes = zb.bytes() + cache.size() * sizeof(ProjectedVertex) + done.size();
  for (uint32_t id = 0; id < scene.triangle_count; ++id) {
    const ml::Triangle t = ml::triangle_at(scene, id);
    const bool double_sided = ml::batch_material(scene, t.batch).double_sided != 0;
    ProjectedVertex p[3];
    bool all_ok = true;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = t.v[k];
      if (!done[v]) {
        cache[v] = project_vertex(view, ml::vertex_world(scene, t.batch, v));
        done[v] = 1;
      }
      p[k] = cache[v];
      all_ok = all_ok && p[k].ok;
    }
    bool drawn = false;
    if (all_ok) {
      // Counter-clockwise in glTF is clockwise on a y-down screen: area2 < 0 faces the eye.
      const int64_t area2 = (int64_t(p[1].x) - p[0].x) * (int64_t(p[2].y) - p[0].y) -
                            (int64_t(p[1].y) - p[0].y) * (int64_t(p[2].x) - p[0].x);
      if (area2 == 0 || (area2 > 0 && !double_sided)) continue;
      ml::TriangleColors colors;
      ml::shade_triangle(scene, light, ml::ShadingMode::Flat, id, area2 < 0, &colors);
      const int a = area2 < 0 ? 2 : 1, b = area2 < 0 ? 1 : 2;
      drawn = zb.draw(screen_vertex(p[0]), screen_vertex(p[a]), screen_vertex(p[b]), colors.flat, st);
    } else {
      ml::Vec3i world[3];
      ml::triangle_world(scene, id, world);
      ml::ScreenTriangle pieces[ml::kMaxClipTriangles];
      const int count = ml::project_triangle(view, world, pieces);
      for (int k = 0; k < count; ++k) {
        if (!pieces[k].front_facing && !double_sided) continue;
        ml::TriangleColors colors;
        ml::shade_triangle(scene, light, ml::ShadingMode::Flat, id, pieces[k].front_facing, &colors);
        drawn |= zb.draw(pieces[k].v[0], pieces[k].v[1], pieces[k].v[2], colors.flat, st);
      }
    }
    st->triangles_drawn += drawn;
  }
  if (!zb.send(sink)) return ml::error(ml::StatusCode::SinkFailed, "sink refused the frame");
  return ml::ok_status();
}

int usage() {
  fprintf(stderr,
          "usage: bench prepare default|office[:LAYERS]|tessellated[:TRIANGLES]|banded[-plain|-nearest|-bilinear]|FILE|\n"
          "                     plain:FILE|nearest:FILE|bilinear:FILE|mips:FILE OUT.mls\n"
          "       bench frame SCENE.mls tiler|scanline|zbuffer WxH AA[,cosine][,jittered] [flat|gouraud]\n"
          "                   [BAND_ROWS[:RENDER_ROWS] [FORMAT]]\n"
          "       bench quality SCENE.mls WxH\n");
  return 2;
}

// A textured scene compiled in a variant: `plain` without texels (every texture draws its material
// colour: the untextured baseline of a textured frame), `nearest` or `bilinear` with every texture
// sampled so (maskline compile --texture-filter), `mips` with every texture's mip levels. An empty path
// is the banded scene.
ml::CompileResult compile_variant(const std::string& variant, const std::string& path) {
  ml::SceneMesh mesh;
  if (path.empty()) {
    mesh = ml::make_banded_scene();
  } else {
    std::vector<std::string> warnings;
    ml::CompileResult failed;
    if (!ml::import_gltf_file(path, &mesh, &warnings, &failed.error)) return failed;
  }
  ml::CompileOptions options;
  if (variant == "nearest") options.texture_filter = ml::TextureFilterChoice::Nearest;
  if (variant == "bilinear") options.texture_filter = ml::TextureFilterChoice::Bilinear;
  if (variant == "plain") options.texture_format = ml::TextureFormatChoice::None;
  if (variant == "mips") options.texture_mips = ml::TextureMipChoice::On;
  return ml::compile_mesh(mesh, options);
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
  else if (kind == "banded-plain") result = compile_variant("plain", "");
  else if (kind == "banded-nearest") result = compile_variant("nearest", "");
  else if (kind == "banded-bilinear") result = compile_variant("bilinear", "");
  else if (kind == "plain" || kind == "nearest" || kind == "bilinear" || kind == "mips")
    result = compile_variant(kind, arg);
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
          ml::FilterKind filter, ml::SamplePattern samples, ml::ShadingMode shading, const ml::OutputOptions& output) {
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
  const ml::Camera camera = bench_camera(path, scene, w, h);
  DiscardSink sink;
  ml::Stats stats;
  ml::Status s;
  const double pixels = double(w) * h;
  // BSP pieces per scene triangle (the scene compiler splits triangles the BSP planes cut).
  const double split = scene.triangle_count ? double(scene.bsp_piece_count) / scene.triangle_count : 0.0;
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
           "buffer_bytes=%zu sink_pixels=%llu split_ratio=%.4f\n",
           w, h, scene.triangle_count, z.triangles_drawn, (unsigned long long)z.pixels_tested,
           (unsigned long long)z.pixels_written, z.buffer_bytes, (unsigned long long)sink.pixels_, split);
    return 0;
  }
  ml::RenderOptions o;
  if (renderer == "tiler") o.renderer = ml::RendererKind::Tiler;
  else if (renderer == "scanline") o.renderer = ml::RendererKind::Scanline;
  else return usage();
  o.shading = shading;
  o.aa = aa;
  o.filter = filter;
  o.samples = samples;
  o.output = output;
  // The least arena plus what makes the frame faster, as a board with RAM to spare gives it.
  const size_t bytes = ml::render_arena_bytes(scene, camera, o);
  const size_t given = bytes + ml::render_spare_bytes(scene, camera, o);
  std::vector<uint64_t> storage(given / 8 + 1);
  ml::Arena arena(storage.data(), given);
  CALLGRIND_START_INSTRUMENTATION;
  s = ml::render(scene, camera, o, arena, sink, &stats);
  CALLGRIND_STOP_INSTRUMENTATION;
  if (!s.ok()) {
    fprintf(stderr, "bench: render failed: %s (%llu)\n", s.message, (unsigned long long)s.value);
    return 1;
  }
  printf("renderer=%s size=%dx%d aa=%d filter=%s samples=%s triangles=%u drawn=%u culled=%u cells_visited=%llu cells_per_pixel=%.4f "
         "peak_arena_bytes=%u arena_bytes=%zu pyramid_bytes=%u shading_calls=%llu geometry_samples=%llu m_max=%u n=%u "
         "pixel_writes=%llu sink_pixels=%llu bands=%u render_bands=%u triangles_tiled=%u split_ratio=%.4f texture_bytes_loaded=%u "
         "texture_bytes_peak=%u texture_loads=%u subtrees_culled=%u subtrees_back_facing=%u planes_reused=%u\n",
         renderer.c_str(), w, h, aa, filter == ml::FilterKind::Cosine ? "cosine" : "box",
         samples == ml::SamplePattern::Jittered ? "jittered" : "regular", scene.triangle_count, stats.triangles_drawn, stats.triangles_culled,
         (unsigned long long)stats.cells_visited, double(stats.cells_visited) / pixels, stats.peak_arena_bytes, bytes,
         stats.pyramid_bytes, (unsigned long long)stats.shading_calls, (unsigned long long)stats.geometry_samples,
         stats.m_max, stats.n, (unsigned long long)stats.pixel_writes, (unsigned long long)sink.pixels_, stats.bands, stats.render_bands,
         stats.triangles_tiled, split, stats.texture_bytes_loaded, stats.texture_bytes_peak, stats.texture_loads,
         stats.bsp_subtrees_culled, stats.bsp_subtrees_back_facing, stats.texture_planes_reused);
  return 0;
}

}  // namespace

// The bench's camera for a compiled scene: the CLI's default framing of the bounding sphere, or the
// eye, target and up that `prepare` saved beside the blob (SCENE.mls.camera) for a glTF camera.
ml::Camera bench_camera(const std::string& path, const ml::Scene& scene, int w, int h) {
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
  return camera;
}

int main(int argc, char** argv) {
  if (argc == 4 && strcmp(argv[1], "quality") == 0) return quality(argv[2], argv[3]);
  if (argc == 4 && strcmp(argv[1], "prepare") == 0) return prepare(argv[2], argv[3]);
  if (argc >= 6 && argc <= 9 && strcmp(argv[1], "frame") == 0) {
    // AA[,cosine][,jittered]: samples a pixel per axis, the tiler's filter and sample pattern.
    const int aa = atoi(argv[5]);
    if (aa < 1 || aa > 8) return usage();
    ml::FilterKind filter = ml::FilterKind::Box;
    ml::SamplePattern samples = ml::SamplePattern::Regular;
    for (const char* c = strchr(argv[5], ','); c; c = strchr(c + 1, ',')) {
      if (strncmp(c + 1, "cosine", 6) == 0) filter = ml::FilterKind::Cosine;
      else if (strncmp(c + 1, "jittered", 8) == 0) samples = ml::SamplePattern::Jittered;
      else return usage();
    }
    ml::ShadingMode shading = ml::ShadingMode::Flat;
    if (argc >= 7 && strcmp(argv[6], "gouraud") == 0) shading = ml::ShadingMode::Gouraud;
    else if (argc >= 7 && strcmp(argv[6], "flat") != 0) return usage();
    ml::OutputOptions output;
    // BAND_ROWS[:RENDER_ROWS]: the sink's bands, and the rows the tiler may render at once (OutputOptions).
    if (argc >= 8 && sscanf(argv[7], "%d:%d", &output.band_rows, &output.render_rows) < 1) return usage();
    if (argc >= 9 && !mlhost::parse_format(argv[8], &output.format)) return usage();
    if (output.band_rows < 0 || output.render_rows < 0) return usage();
    return frame(argv[2], argv[3], argv[4], aa, filter, samples, shading, output);
  }
  return usage();
}

// Measurement driver for the scanline renderer (not part of the test binary: .cc is not globbed).
//   scan_driver sphere N W H AA MODE [out.ppm]      a smooth sphere of about N triangles
//   scan_driver file SCENE.glb|.mls W H AA MODE [out.ppm] [tiler]
// MODE: flat | gouraud | ids | lines | unlit. Prints the frame's stats. Used under
// valgrind --tool=callgrind for docs/scanline.md.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/arena.h"
#include "render/render.h"
#include "tests/scanline/blob_builder.h"
#ifdef WITH_SCENEC
#include "tools/scenec/scenec.h"
#endif

namespace {
struct MemSink : ml::Sink {
  int w = 0, h = 0;
  std::vector<ml::Pixel> img;
  bool begin_frame(int W, int H) override { w = W; h = H; img.assign(size_t(W) * H, 0); return true; }
  bool write_block(int x, int y, int bw, int bh, const ml::Pixel* p, int stride) override {
    for (int j = 0; j < bh; ++j)
      for (int i = 0; i < bw; ++i) img[size_t(y + j) * w + x + i] = p[j * stride + i];
    return true;
  }
  bool fill_block(int x, int y, int bw, int bh, ml::Pixel v) override {
    for (int j = 0; j < bh; ++j)
      for (int i = 0; i < bw; ++i) img[size_t(y + j) * w + x + i] = v;
    return true;
  }
};

scantest::Prim sphere(int32_t r, int stacks, int slices) {
  scantest::Prim p;
  for (int i = 0; i <= stacks; ++i) {
    const double th = M_PI * i / stacks;
    for (int j = 0; j <= slices; ++j) {
      const double ph = 2 * M_PI * j / slices;
      const double n[3] = {std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)};
      p.pos.push_back({int32_t(std::lround(r * n[0])), int32_t(std::lround(r * n[1])), int32_t(std::lround(r * n[2]))});
      p.normal.push_back({n[0], n[1], n[2]});
    }
  }
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      const uint32_t a = uint32_t(i * (slices + 1) + j), b = a + uint32_t(slices + 1);
      if (i != 0) p.tris.push_back({a, a + 1, b});
      if (i != stacks - 1) p.tris.push_back({a + 1, b + 1, b});
    }
  return p;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 7) { std::fprintf(stderr, "usage: see source\n"); return 2; }
  const std::string kind = argv[1];
  const int W = std::atoi(argv[3]), H = std::atoi(argv[4]), aa = std::atoi(argv[5]);
  const std::string mode = argv[6];
  const char* out = argc > 7 ? argv[7] : nullptr;
  const bool tiler = argc > 8 && std::string(argv[8]) == "tiler";
  scantest::BuiltScene built;
  std::vector<uint64_t> file_words;
  ml::Scene scene;
  if (kind == "sphere") {
    const int n = std::atoi(argv[2]);
    const int stacks = std::max(4, int(std::sqrt(n / 4.0)));
    scantest::build({scantest::Material{}}, {sphere(30000, stacks, 2 * stacks)}, &built);
    if (!built.status.ok()) { std::fprintf(stderr, "%s\n", built.status.message); return 1; }
    scene = built.scene;
  } else {
#ifdef WITH_SCENEC
    ml::CompileOptions co;
    co.build_bsp = tiler;
    ml::CompileResult r = std::string(argv[2]) == "default" ? ml::build_default_scene(co)
                                                            : ml::compile_gltf_file(argv[2], co);
    if (!r.ok) { std::fprintf(stderr, "%s\n", r.error.c_str()); return 1; }
    file_words = r.blob.words;
    ml::Status st = ml::read_scene(file_words.data(), r.blob.size, &scene);
    if (!st.ok()) { std::fprintf(stderr, "%s\n", st.message); return 1; }
#else
    return 2;
#endif
  }
  ml::Camera cam = ml::frame_sphere(ml::Vec3i{scene.info->sphere_center[0], scene.info->sphere_center[1],
                                              scene.info->sphere_center[2]},
                                    scene.info->sphere_radius, W, H, 45 << 16);
  ml::RenderOptions o;
  o.renderer = tiler ? ml::RendererKind::Tiler : ml::RendererKind::Scanline;
  o.aa = aa;
  o.shading = mode == "flat" ? ml::ShadingMode::Flat : mode == "gouraud" ? ml::ShadingMode::Gouraud
            : mode == "ids" ? ml::ShadingMode::Ids : mode == "lines" ? ml::ShadingMode::Lines : ml::ShadingMode::Unlit;
  const size_t bytes = ml::render_arena_bytes(scene, cam, o);
  std::vector<uint64_t> storage(bytes / 8 + 1);
  ml::Arena arena(storage.data(), bytes);
  MemSink sink;
  ml::Stats s;
  const ml::Status st = ml::render(scene, cam, o, arena, sink, &s);
  if (!st.ok()) { std::fprintf(stderr, "render: %s (%llu)\n", st.message, (unsigned long long)st.value); return 1; }
  std::printf("triangles_in=%u culled=%u drawn=%u n=%u m_max=%u geometry_samples=%llu shading_calls=%llu "
              "sort_work=%llu peak_arena=%u arena_bytes=%zu target=%llu\n",
              s.triangles_in, s.triangles_culled, s.triangles_drawn, s.n, s.m_max,
              (unsigned long long)s.geometry_samples, (unsigned long long)s.shading_calls,
              (unsigned long long)s.sort_instructions, s.peak_arena_bytes, bytes,
              (unsigned long long)(16ull * s.n + 64ull * s.m_max + 16ull * W));
  if (out) {
    FILE* f = std::fopen(out, "wb");
    std::fprintf(f, "P6\n%d %d\n255\n", W, H);
    for (ml::Pixel p : sink.img) {
      if (o.shading == ml::ShadingMode::Ids) p = p ? (p * 2654435761u) >> 8 : 0;
      const unsigned char c[3] = {uint8_t(p >> 16), uint8_t(p >> 8), uint8_t(p)};
      std::fwrite(c, 1, 3, f);
    }
    std::fclose(f);
  }
  return 0;
}

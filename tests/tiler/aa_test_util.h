// Shared by the tiler's antialiasing tests (test_tiler_aa.cpp, test_tiler_filter.cpp): renders into the
// once-per-pixel image sink, random slab scenes, the oracle's samples and the RMS against a reference.
#pragma once
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "platform/host/scene_load.h"
#include "render/render.h"
#include "tests/common/mesh_builder.h"
#include "tests/common/checked_render.h"
#include "tests/oracle/oracle.h"
#include "tests/oracle/scene_triangles.h"
#include "tools/scenec/scenec.h"
#include "view/view.h"

namespace aatest {

constexpr ml::Pixel kBackground = 0x202830;

using Image = testrender::Image;

inline Image render_colour(const ml::Scene& scene, const ml::Camera& camera, ml::RendererKind renderer, int aa,
                    ml::ShadingMode shading = ml::ShadingMode::Unlit, int band_rows = 16,
                    ml::PixelFormat format = ml::PixelFormat::Xrgb8888,
                    ml::FilterKind filter = ml::FilterKind::Box) {
  ml::RenderOptions o;
  o.renderer = renderer;
  o.shading = shading;
  o.aa = aa;
  o.filter = filter;
  o.background = kBackground;
  o.output.band_rows = band_rows;
  o.output.format = format;
  return testrender::render_checked(scene, camera, o);
}

inline ml::Camera framing(const ml::Scene& scene, int w, int h) {
  const ml::SceneInfo& i = *scene.info;
  return ml::frame_sphere(ml::Vec3i{i.sphere_center[0], i.sphere_center[1], i.sphere_center[2]}, i.sphere_radius, w, h,
                          45 << 16);
}

// Random triangles in separate depth slabs (no crossings, so no depth ties), random winding, a third
// double-sided, each material its own colour.
inline void random_scene(uint32_t seed, int count, mlhost::LoadedScene* out) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> xy(-4, 4), in_slab(0, 0.8), unit(0, 1);
  std::vector<ml::MeshMaterial> materials(6);
  for (uint32_t m = 0; m < 6; ++m) {
    for (int c = 0; c < 3; ++c) materials[m].base_color[c] = unit(rng);
    materials[m].double_sided = m % 3 == 0;
  }
  ml::SceneMesh mesh = meshtest::one_node_mesh(std::move(materials), "random");
  for (int t = 0; t < count; ++t) {
    ml::MeshVertex v[3];
    for (ml::MeshVertex& vertex : v) {
      vertex.position[0] = xy(rng);
      vertex.position[1] = xy(rng);
      vertex.position[2] = -(t + in_slab(rng));
    }
    meshtest::add_triangle(&mesh, size_t(t) % 6, v);
  }
  std::string error;
  const ml::CompileResult c = ml::compile_mesh(mesh);
  ASSERT_TRUE(c.ok) << c.error;
  ASSERT_TRUE(mlhost::adopt_compiled(c, "random", out, &error)) << error;
}


// The oracle's samples: one ray per sample of an f x f grid a pixel (a camera f times larger).
inline oracle::Result oracle_samples(const ml::Scene& scene, const ml::Camera& camera, int f) {
  oracle::Camera c = oracle::to_oracle_camera(camera);
  c.width *= f;
  c.height *= f;
  return oracle::rasterize(oracle::scene_triangles(scene), c);
}

inline int channel(ml::Pixel p, int c) { return int(p >> (16 - 8 * c)) & 0xFF; }

inline const mlhost::LoadedScene& default_scene() {
  static mlhost::LoadedScene scene = [] {
    mlhost::LoadedScene s;
    std::string error;
    if (!mlhost::load_scene("", &s, &error)) ADD_FAILURE() << error;
    return s;
  }();
  return scene;
}

// RMS error (per channel, 0..255) of an image against the 16 x 16 box-filtered oracle.
inline double rms_against(const std::vector<ml::Pixel>& img, const std::vector<double>& reference) {
  double sum = 0;
  for (size_t i = 0; i < img.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double d = channel(img[i], k) - reference[i * 3 + size_t(k)];
      sum += d * d;
    }
  return std::sqrt(sum / double(img.size() * 3));
}

}  // namespace aatest

// Materials whose triangles are invisible (scene.h material_hidden: a MASK below its cutoff, a BLEND
// of alpha 0) are left out by both renderers in every mode: a scene with such triangles in front
// renders exactly as the same scene without them.
#include <gtest/gtest.h>

#include <initializer_list>
#include <random>
#include <string>
#include <vector>

#include "platform/host/image_sink.h"
#include "platform/host/scene_load.h"
#include "render/render.h"
#include "scene/scene.h"
#include "tests/common/checked_render.h"
#include "tests/common/mesh_builder.h"
#include "tools/scenec/scenec.h"

namespace {

ml::Material material(ml::AlphaMode mode, uint8_t alpha, uint8_t cutoff) {
  ml::Material m{};
  m.base_color[3] = alpha;
  m.alpha_mode = uint8_t(mode);
  m.alpha_cutoff = cutoff;
  return m;
}

TEST(HiddenMaterials, OnlyMasksBelowTheirCutoffAndBlendsOfAlphaZero) {
  EXPECT_FALSE(ml::material_hidden(material(ml::AlphaMode::Opaque, 0, 128)));
  EXPECT_TRUE(ml::material_hidden(material(ml::AlphaMode::Mask, 127, 128)));
  EXPECT_FALSE(ml::material_hidden(material(ml::AlphaMode::Mask, 128, 128)));  // at the cutoff: drawn
  EXPECT_FALSE(ml::material_hidden(material(ml::AlphaMode::Mask, 0, 0)));
  EXPECT_TRUE(ml::material_hidden(material(ml::AlphaMode::Blend, 0, 128)));
  EXPECT_FALSE(ml::material_hidden(material(ml::AlphaMode::Blend, 1, 128)));   // composited (scanline)
}

// Random opaque triangles in depth slabs (primitives 0 and 1, one double-sided) and, but for None,
// random triangles in front of them (primitives 2 and 3): Hidden, a MASK below its cutoff and a BLEND
// of alpha 0; Shown, the same triangles opaque. Those come last, so the others keep their ids, and lie
// inside the others' box, so the world mapping is the same.
enum class Front { None, Hidden, Shown };
ml::CompileResult scene_with(Front front) {
  std::vector<ml::MeshMaterial> materials(front == Front::None ? 2 : 4);
  materials[1].double_sided = true;
  for (size_t m = 2; m < materials.size(); ++m) {  // in a colour of their own, seen from both sides
    materials[m].base_color[1] = 0.1;
    materials[m].double_sided = true;
  }
  for (size_t m = 2; m < materials.size(); ++m) materials[m].texture = 0;  // textured: their texels unread
  if (front == Front::Hidden) {
    materials[2].alpha_mode = ml::AlphaMode::Mask;
    materials[2].base_color[3] = 0.3;
    materials[3].alpha_mode = ml::AlphaMode::Blend;
    materials[3].base_color[3] = 0;
  }
  const bool textured = materials.size() > 2;
  ml::SceneMesh mesh = meshtest::one_node_mesh(std::move(materials), "hidden");
  if (textured) {  // a 4x4 checker of red and blue
    ml::MeshImage checker;
    checker.width = checker.height = 4;
    for (int i = 0; i < 16; ++i)
      checker.rgba.insert(checker.rgba.end(), ((i ^ (i >> 2)) & 1) ? std::initializer_list<uint8_t>{230, 40, 40, 255}
                                                                  : std::initializer_list<uint8_t>{40, 40, 230, 255});
    mesh.images.push_back(checker);
    mesh.texture_images.push_back(0);
    mesh.texture_samplers.push_back(ml::MeshSampler{});
  }
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> xy(-4, 4), in_slab(0, 0.8), unit(0, 1);
  const auto add = [&](size_t primitive, double z) {
    ml::MeshVertex v[3];
    for (ml::MeshVertex& vertex : v) {
      vertex.position[0] = xy(rng);
      vertex.position[1] = xy(rng);
      vertex.position[2] = z + in_slab(rng) * 0.03;
    }
    for (int i = 0; i < 3; ++i) {  // the checker twice across each triangle (the front ones' texture)
      v[i].uv[0] = i == 1 ? 2 : 0;
      v[i].uv[1] = i == 2 ? 2 : 0;
    }
    meshtest::add_triangle(&mesh, primitive, v);
  };
  const auto corner = [&](size_t primitive, double x, double y, double z) {  // the box's corners, in both
    ml::MeshVertex v[3];
    for (int i = 0; i < 3; ++i) {
      v[i].position[0] = x + (i == 1 ? 0.2 : 0);
      v[i].position[1] = y + (i == 2 ? 0.2 : 0);
      v[i].position[2] = z;
    }
    meshtest::add_triangle(&mesh, primitive, v);
  };
  corner(0, -5, -5, -10);
  corner(0, 5, 5, 0);
  for (int t = 0; t < 150; ++t) add(unit(rng) < 0.3 ? 1 : 0, -(5 + 0.03 * t));
  if (front != Front::None)
    for (int t = 0; t < 40; ++t) add(2 + size_t(t % 2), -(1 + 0.1 * t));
  return ml::compile_mesh(mesh);
}

bool load(Front front, mlhost::LoadedScene* s) {
  std::string error;
  const ml::CompileResult c = scene_with(front);
  if (c.ok && mlhost::adopt_compiled(c, "hidden", s, &error)) return true;
  ADD_FAILURE() << (c.ok ? error : c.error);
  return false;
}

TEST(HiddenMaterials, TheCompilerWarnsOncePerMaterial) {
  const ml::CompileResult hidden = scene_with(Front::Hidden);
  ASSERT_TRUE(hidden.ok) << hidden.error;
  ASSERT_EQ(hidden.warnings.size(), 2u);
  EXPECT_EQ(hidden.warnings[0],
            "material 2: alphaMode MASK with base colour alpha below its alphaCutoff: its 20 triangles are invisible "
            "and not drawn");
  EXPECT_EQ(hidden.warnings[1],
            "material 3: alphaMode BLEND with base colour alpha 0: its 20 triangles are invisible and not drawn");
  for (Front front : {Front::None, Front::Shown}) {
    const ml::CompileResult c = scene_with(front);
    ASSERT_TRUE(c.ok) << c.error;
    EXPECT_TRUE(c.warnings.empty()) << c.warnings[0];
  }
}

// The texture only the invisible triangles use is never loaded (both renderers' texture plans and
// pagers leave them out); drawn opaque, the same triangles load it.
TEST(HiddenMaterials, TheirTextureIsNeverRead) {
  mlhost::LoadedScene with, shown;
  ASSERT_TRUE(load(Front::Hidden, &with));
  ASSERT_TRUE(load(Front::Shown, &shown));
  ASSERT_EQ(with.scene.texture_texels_count, 1u);
  ASSERT_NE(with.scene.texture_texels[0].format, uint8_t(ml::TexelFormat::None));
  const ml::SceneInfo& a = *with.scene.info;
  ml::Camera cam = ml::frame_sphere(ml::Vec3i{a.sphere_center[0], a.sphere_center[1], a.sphere_center[2]},
                                    a.sphere_radius, 96, 72, 45 << 16);
  for (ml::RendererKind renderer : {ml::RendererKind::Tiler, ml::RendererKind::Scanline})
    for (int rows : {0, 8}) {  // render_rows: the whole frame at once (with the spare arena), a band at a time
      ml::RenderOptions o;
      o.renderer = renderer;
      o.output.band_rows = 8;
      o.output.render_rows = rows;
      for (const mlhost::LoadedScene* s : {&with, &shown}) {
        const size_t bytes = ml::render_arena_bytes(s->scene, cam, o) + ml::render_spare_bytes(s->scene, cam, o);
        std::vector<uint64_t> storage(bytes / 8 + 1);
        ml::Arena arena(storage.data(), bytes);
        mlhost::ImageSink sink;
        ml::Stats stats;
        ASSERT_TRUE(ml::render(s->scene, cam, o, arena, sink, &stats).ok());
        const std::string what = std::string(renderer == ml::RendererKind::Tiler ? "tiler" : "scanline") +
                                 " rows " + std::to_string(rows) + (s == &with ? " hidden" : " shown");
        if (s == &with) {
          EXPECT_EQ(stats.texture_loads, 0u) << what;
          EXPECT_EQ(stats.texture_bytes_loaded, 0u) << what;
        } else {
          EXPECT_GE(stats.texture_loads, 1u) << what;  // not vacuous: drawn, the texture is read
        }
      }
    }
}

TEST(HiddenMaterials, BothRenderersLeaveThemOutInEveryMode) {
  mlhost::LoadedScene with, without, shown;
  ASSERT_TRUE(load(Front::Hidden, &with));
  ASSERT_TRUE(load(Front::None, &without));
  ASSERT_TRUE(load(Front::Shown, &shown));
  const ml::SceneInfo &a = *with.scene.info, &b = *without.scene.info;
  ASSERT_EQ(a.sphere_radius, b.sphere_radius);  // the same world mapping: the same camera and pixels
  for (int k = 0; k < 3; ++k) ASSERT_EQ(a.sphere_center[k], b.sphere_center[k]);
  ml::Camera cam;  // in front (+z), near enough for the visible triangles to fill the view
  cam.width = 96;
  cam.height = 72;
  cam.fov_deg_q16 = 45 << 16;
  cam.target = ml::Vec3i{a.sphere_center[0], a.sphere_center[1], a.sphere_center[2]};
  cam.eye = ml::Vec3i{cam.target.x + a.sphere_radius / 8, cam.target.y + a.sphere_radius / 8,
                      cam.target.z + a.sphere_radius * 6 / 5};
  cam.near = a.sphere_radius / 64;
  const ml::ShadingMode modes[] = {ml::ShadingMode::Flat, ml::ShadingMode::Unlit, ml::ShadingMode::Gouraud,
                                   ml::ShadingMode::Ids, ml::ShadingMode::Lines};
  for (ml::RendererKind renderer : {ml::RendererKind::Tiler, ml::RendererKind::Scanline})
    for (ml::ShadingMode mode : modes)
      for (int aa : {1, 2})
        for (bool spare : {false, true}) {  // spare: with render_rows 8, the tiler's band plan
          if (renderer == ml::RendererKind::Tiler && mode == ml::ShadingMode::Lines) continue;  // (scanline only)
          ml::RenderOptions o;
          o.renderer = renderer;
          o.shading = mode;
          o.aa = aa;
          o.output.band_rows = 8;  // 9 bands
          if (spare) o.output.render_rows = 8;
          const testrender::Image x = testrender::render_checked(with.scene, cam, o, spare);
          const testrender::Image y = testrender::render_checked(without.scene, cam, o, spare);
          const testrender::Image z = testrender::render_checked(shown.scene, cam, o, spare);
          ASSERT_TRUE(x.ok && y.ok && z.ok) << x.error << y.error << z.error;
          size_t differ = 0, in_front = 0;
          for (size_t p = 0; p < x.pixels.size(); ++p) {
            differ += x.pixels[p] != y.pixels[p];
            in_front += z.pixels[p] != y.pixels[p];
          }
          const std::string what = std::string(renderer == ml::RendererKind::Tiler ? "tiler" : "scanline") + " mode " +
                                   std::to_string(int(mode)) + " aa " + std::to_string(aa) +
                                   (spare ? " spare" : "");
          EXPECT_EQ(differ, 0u) << what;
          // Not vacuous: drawn opaque, the front triangles change much of the picture.
          EXPECT_GT(in_front, x.pixels.size() / 5) << what;
        }
}

}  // namespace

// The tiler on a real model (assimp-testmodels' 2CylinderEngine.glb, compiled by tools/scenec):
// every pixel written exactly once, the stats consistent, the working memory within budget.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "core/arena.h"
#include "core/band.h"
#include "render/render.h"
#include "platform/host/image_sink.h"
#include "platform/host/scene_load.h"
#include "tests/common/engine_scene.h"
#include "tests/tiler/tiler_test_util.h"
#include "tiler/tiler.h"

namespace {

const mlhost::LoadedScene* engine() { return testfiles::engine_scene(); }

TEST(TilerEngine, EveryPixelOnceAt320x240AndOthers) {
  const mlhost::LoadedScene* s = engine();
  if (!s) GTEST_SKIP() << "assimp-testmodels not installed";
  const ml::SceneInfo& info = *s->scene.info;
  const ml::Vec3i centre{info.sphere_center[0], info.sphere_center[1], info.sphere_center[2]};
  for (auto [w, h] : {std::pair<int, int>{320, 240}, {160, 120}, {203, 311}}) {
    for (ml::ShadingMode mode : {ml::ShadingMode::Flat, ml::ShadingMode::Gouraud, ml::ShadingMode::Ids}) {
      const ml::Camera cam = ml::frame_sphere(centre, info.sphere_radius, w, h, 45 << 16);
      ml::RenderOptions o;
      o.shading = mode;
      const size_t need = ml::render_arena_bytes(s->scene, cam, o);
      std::vector<uint64_t> mem(need / 8 + 1);
      ml::Arena arena(mem.data(), need);
      tiler_test::CountingSink sink;
      ml::Stats st;
      const ml::Status r = ml::render(s->scene, cam, o, arena, sink, &st);
      ASSERT_TRUE(r.ok()) << r.message;
      ASSERT_FALSE(sink.out_of_bounds);
      for (int c : sink.count) ASSERT_EQ(c, 1);
      EXPECT_EQ(st.pixel_writes, uint64_t(w) * uint64_t(h));
      EXPECT_EQ(st.triangles_drawn + st.triangles_culled, uint64_t(st.bsp_pieces) * st.render_bands);
      EXPECT_GT(st.triangles_drawn, 100u);
      EXPECT_LE(st.peak_arena_bytes, need);
      if (w == 320 && mode == ml::ShadingMode::Flat) {
        EXPECT_LE(need - ml::BandOutput::arena_bytes(o.output, w, h), 12u * 1024u) << "tiler memory at 320x240";
        ml::RenderOptions panel = o;
        panel.output.format = ml::PixelFormat::Rgb565Be;
        EXPECT_LE(ml::render_arena_bytes(s->scene, cam, panel), 24u * 1024u)
            << "320x240 RGB565 with 16-row bands: tiler and band buffer";
        std::printf("[ info ] 2CylinderEngine 320x240: cells_visited %llu (%.3f per pixel), pieces %u, "
                    "drawn %u, arena %zu bytes\n",
                    static_cast<unsigned long long>(st.cells_visited), double(st.cells_visited) / (w * h),
                    st.bsp_pieces, st.triangles_drawn, need);
      }
    }
  }
}

// The normal cones skip only back faces: the same image and the same pieces drawn as without them, from
// eyes all around the model, whole-frame and a band at a time, while they skip subtrees.
TEST(TilerEngine, NormalConesChangeNoImage) {
  const mlhost::LoadedScene* s = engine();
  if (!s) GTEST_SKIP() << "assimp-testmodels not installed";
  ASSERT_NE(s->scene.bsp_cones, nullptr);
  ml::Scene without = s->scene;
  without.bsp_cones = nullptr;
  const ml::SceneInfo& info = *s->scene.info;
  const int32_t r = info.sphere_radius * 5 / 2;
  uint32_t skipped = 0;
  const int32_t eyes[][3] = {{r, r / 3, r / 2}, {-r, r / 2, 0}, {0, -r, r / 4}, {r / 3, 0, -r}, {-r / 2, r, -r / 2}};
  for (const auto& e : eyes) {
    ml::Camera cam = ml::frame_sphere(ml::Vec3i{info.sphere_center[0], info.sphere_center[1], info.sphere_center[2]},
                                      info.sphere_radius, 160, 120, 45 << 16);
    cam.eye = ml::Vec3i{info.sphere_center[0] + e[0], info.sphere_center[1] + e[1], info.sphere_center[2] + e[2]};
    for (bool spare : {true, false}) {
      ml::RenderOptions o;
      o.shading = ml::ShadingMode::Ids;
      ml::Stats with_stats, without_stats;
      auto draw = [&](const ml::Scene& scene, ml::Stats* st) {
        const size_t bytes = ml::render_arena_bytes(scene, cam, o) + (spare ? ml::render_spare_bytes(scene, cam, o) : 0);
        std::vector<uint64_t> mem(bytes / 8 + 1);
        ml::Arena arena(mem.data(), bytes);
        mlhost::ImageSink sink;
        const ml::Status status = ml::render(scene, cam, o, arena, sink, st);
        EXPECT_TRUE(status.ok()) << status.message;
        EXPECT_TRUE(sink.contract_ok()) << sink.contract_error();
        return sink.pixels();
      };
      EXPECT_EQ(draw(s->scene, &with_stats), draw(without, &without_stats)) << "eye " << e[0] << "," << e[1] << "," << e[2];
      EXPECT_EQ(with_stats.triangles_drawn, without_stats.triangles_drawn);
      EXPECT_EQ(without_stats.bsp_subtrees_back_facing, 0u);
      skipped += with_stats.bsp_subtrees_back_facing;
    }
  }
  EXPECT_GT(skipped, 100u);
}

}  // namespace

// The vertex cache (view/vertex_cache.h): its lookups are vertices_world and view_triangle exactly,
// whatever its size and the order of lookups; it keeps a vertex until another takes its entry; it takes
// what the arena has free or the end of a block; and both renderers' frames are the same byte for byte
// with a cache of any size or none.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "core/arena.h"
#include "render/render.h"
#include "scanline/scanline.h"
#include "texture/pager.h"
#include "tests/texture/texture_test_util.h"
#include "tests/tiler/tiler_test_util.h"
#include "tiler/tiler.h"
#include "tools/scenec/scenec.h"
#include "view/vertex_cache.h"

namespace {

using ml::VertexCache;

ml::View make(const ml::Camera& cam) {
  ml::View v;
  EXPECT_TRUE(ml::make_view(cam, &v).ok());
  return v;
}

// A camera anywhere in or around the test scene (its triangles lie in planes from z = -200 to 220),
// looking anywhere near it, with a near plane that may cut triangles, and vertices far off to the side
// (outside the guard band): every case of view_triangle.
ml::Camera random_camera(std::mt19937& rng) {
  std::uniform_int_distribution<int> far(-1500, 1500), depth(-300, 1500), mid(-400, 400);
  ml::Camera c = tiler_test::test_camera(int(rng() % 300) + 16, int(rng() % 200) + 16);
  c.eye = ml::Vec3i{far(rng), far(rng), depth(rng)};
  c.target = ml::Vec3i{mid(rng), mid(rng), mid(rng)};
  if (c.target.x == c.eye.x && c.target.y == c.eye.y) c.target.z = c.eye.z + 1;
  c.near = int32_t(rng() % 4 == 0 ? 1 + rng() % 600 : 1);
  c.fov_deg_q16 = int32_t((20 + rng() % 140) << 16);
  return c;
}

// The test scene with its two batches made different (scale and offset), so that one vertex index read
// with each batch is two points.
struct TwoBatchScene {
  tiler_test::TestScene ts;
  std::vector<ml::Batch> batches;
  ml::Scene scene;
  explicit TwoBatchScene(uint32_t seed, int triangles) {
    std::mt19937 rng(seed);
    ts.build(tiler_test::random_scene(rng, triangles, 160));
    scene = ts.scene;
    batches.assign(scene.batches, scene.batches + scene.batch_count);
    batches[1].scale[0] = 70000;
    batches[1].offset[2] = -37;
    scene.batches = batches.data();
  }
};

void expect_same_view(const ml::ViewTriangle& got, const ml::ViewTriangle& want, const std::string& where) {
  ASSERT_EQ(got.unclipped, want.unclipped) << where;
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(got.p[i].x, want.p[i].x) << where;
    EXPECT_EQ(got.p[i].y, want.p[i].y) << where;
    EXPECT_EQ(got.p[i].z, want.p[i].z) << where;
    if (!want.unclipped) continue;  // offsets are read only when unclipped
    EXPECT_EQ(got.ox[i], want.ox[i]) << where;
    EXPECT_EQ(got.oy[i], want.oy[i]) << where;
  }
}

// Random lookups of random triangles (each read with its own batch or the other), world positions or
// view-space ones, from caches of the least size, a middling one and one holding every vertex, under
// random cameras: every answer is vertices_world's and view_triangle's.
TEST(VertexCache, LookupsAreTheDecodedAndTransformedVertices) {
  TwoBatchScene s(5, 300);
  ASSERT_EQ(s.scene.batch_count, 2u);
  std::mt19937 rng(17);
  int unclipped = 0, clipped = 0;
  for (int camera = 0; camera < 40; ++camera) {
    const ml::Camera cam = random_camera(rng);
    const ml::View view = make(cam);
    for (uint32_t entries : {VertexCache::kMinEntries, 128u, VertexCache::kMaxEntries}) {
      std::vector<uint8_t> mem(VertexCache::arena_bytes(entries));
      ml::Arena arena(mem.data(), mem.size());
      VertexCache cache;
      cache.init(arena, s.scene, view, entries, 0);
      ASSERT_EQ(cache.entries(), entries);
      for (int k = 0; k < 600; ++k) {
        const ml::Triangle tri = ml::triangle_at(s.scene, uint32_t(rng() % s.scene.triangle_count));
        const uint32_t batch = rng() % 3 == 0 ? 1 - tri.batch : tri.batch;
        ml::Vec3i want_world[3];
        ml::vertices_world(s.scene, batch, tri.v, want_world);
        const std::string where = "camera " + std::to_string(camera) + " entries " + std::to_string(entries) +
                                  " lookup " + std::to_string(k);
        if (rng() % 2 == 0) {
          ml::Vec3i got[3];
          cache.world(batch, tri.v, got);
          for (int i = 0; i < 3; ++i) {
            EXPECT_EQ(got[i].x, want_world[i].x) << where;
            EXPECT_EQ(got[i].y, want_world[i].y) << where;
            EXPECT_EQ(got[i].z, want_world[i].z) << where;
          }
        } else {
          ml::ViewTriangle got, want;
          cache.view(batch, tri.v, &got);
          ml::view_triangle(view, want_world, &want);
          expect_same_view(got, want, where);
          (want.unclipped ? unclipped : clipped)++;
        }
      }
    }
  }
  // Both kinds of triangle were asked for many times.
  EXPECT_GT(unclipped, 3000);
  EXPECT_GT(clipped, 1500);
}

// A vertex is decoded and transformed once while its entry holds it; a vertex whose index takes the
// same entry, or the same index read with another batch, replaces it; world lookups do not transform.
TEST(VertexCache, KeepsAVertexUntilAnotherTakesItsEntry) {
  TwoBatchScene s(9, 300);
  ASSERT_GT(s.scene.vertex_count, 2 * VertexCache::kMinEntries + 3);
  const ml::View view = make(tiler_test::test_camera(160, 120));
  const uint32_t n = VertexCache::kMinEntries;
  std::vector<uint8_t> mem(VertexCache::arena_bytes(n));
  ml::Arena arena(mem.data(), mem.size());
  VertexCache cache;
  cache.init(arena, s.scene, view, n, 0);
  ASSERT_EQ(cache.entries(), n);
  const uint32_t a[3] = {0, 1, 2}, same_entries[3] = {n, n + 1, n + 2}, other_entries[3] = {3, 4, 5};
  ml::Vec3i world[3];
  ml::ViewTriangle tri;
  cache.world(0, a, world);
  EXPECT_EQ(cache.decoded(), 3u);
  EXPECT_EQ(cache.transformed(), 0u);
  cache.view(0, a, &tri);  // the same vertices: transformed now, not decoded again
  cache.view(0, a, &tri);
  cache.world(0, a, world);
  EXPECT_EQ(cache.decoded(), 3u);
  EXPECT_EQ(cache.transformed(), 3u);
  cache.view(0, other_entries, &tri);  // other entries: a stays
  cache.view(0, a, &tri);
  EXPECT_EQ(cache.decoded(), 6u);
  EXPECT_EQ(cache.transformed(), 6u);
  cache.view(0, same_entries, &tri);  // a's entries: a is read again after them
  cache.view(0, a, &tri);
  EXPECT_EQ(cache.decoded(), 12u);
  EXPECT_EQ(cache.transformed(), 12u);
  cache.world(1, a, world);  // the same indices with the other batch are other points
  EXPECT_EQ(cache.decoded(), 15u);
  ml::Vec3i want[3];
  ml::vertices_world(s.scene, 1, a, want);
  EXPECT_EQ(world[0].x, want[0].x);
  EXPECT_NE(world[0].z, ml::vertex_world(s.scene, 0, 0).z);
  // A triangle whose vertices share an entry (0 and n) is still given whole.
  const uint32_t clash[3] = {0, n, 1};
  ml::ViewTriangle got, expected;
  cache.view(0, clash, &got);
  ml::vertices_world(s.scene, 0, clash, want);
  ml::view_triangle(view, want, &expected);
  expect_same_view(got, expected, "clash");
}

// The cache takes the largest power of two of entries that leaves the bytes asked for free, and none
// when fewer than kMinEntries fit.
TEST(VertexCache, TakesWhatTheArenaHasFree) {
  TwoBatchScene s(3, 20);
  const ml::View view = make(tiler_test::test_camera(64, 48));
  EXPECT_EQ(VertexCache::entries_for(1), VertexCache::kMinEntries);
  EXPECT_EQ(VertexCache::entries_for(65), 128u);
  EXPECT_EQ(VertexCache::entries_for(1u << 30), VertexCache::kMaxEntries);
  const size_t keep = 1000;
  for (uint32_t fits : {0u, 32u, 64u, 100u, 256u, 1024u}) {
    const size_t bytes = keep + (fits ? VertexCache::arena_bytes(fits) : 0);
    std::vector<uint8_t> mem(bytes);
    ml::Arena arena(mem.data(), mem.size());
    VertexCache cache;
    cache.init(arena, s.scene, view, 512, keep);
    const uint32_t want = fits < 64 ? 0 : fits >= 512 ? 512 : fits >= 256 ? 256 : 64;
    EXPECT_EQ(cache.entries(), want) << fits;
    EXPECT_GE(arena.size() - arena.used(), keep) << fits;
  }
}

// init_at_end takes the largest power of two of entries whose bytes fit at the end of the block, none
// when fewer than kMinEntries fit; its entries lie in the bytes it reports, the block's start is left
// as it was, its lookups are the direct ones, and after drop() it holds none.
TEST(VertexCache, TakesTheEndOfABlock) {
  TwoBatchScene s(5, 30);
  const ml::View view = make(tiler_test::test_camera(64, 48));
  for (uint32_t fits : {0u, 63u, 64u, 100u, 256u, 300u}) {
    for (size_t misalign : {0u, 1u, 3u}) {  // the block's start and end off the entries' alignment
      const size_t bytes = misalign + 17 + (fits ? VertexCache::arena_bytes(fits) : 0);
      std::vector<uint8_t> mem(bytes + 8, 0xA5);
      uint8_t* block = mem.data() + misalign;
      VertexCache cache;
      const size_t taken = cache.init_at_end(block, bytes, s.scene, view, 256);
      const uint32_t want = fits < 64 ? 0 : fits >= 256 ? 256 : 64;
      const std::string where = std::to_string(fits) + " misalign " + std::to_string(misalign);
      ASSERT_EQ(cache.entries(), want) << where;
      EXPECT_LE(taken, VertexCache::arena_bytes(want ? want : 1)) << where;
      EXPECT_EQ(taken == 0, want == 0) << where;
      if (want == 0) continue;
      EXPECT_GE(taken, want * sizeof(VertexCache::Entry)) << where;
      for (uint32_t t = 0; t < s.scene.triangle_count; ++t) {
        const ml::Triangle tri = ml::triangle_at(s.scene, t);
        ml::Vec3i world[3];
        ml::ViewTriangle got, expected;
        cache.view(tri.batch, tri.v, &got);
        ml::vertices_world(s.scene, tri.batch, tri.v, world);
        ml::view_triangle(view, world, &expected);
        expect_same_view(got, expected, where);
      }
      for (size_t i = 0; i < misalign + bytes - taken; ++i) ASSERT_EQ(mem[i], 0xA5) << where << " byte " << i;
      for (size_t i = misalign + bytes; i < mem.size(); ++i) ASSERT_EQ(mem[i], 0xA5) << where << " byte " << i;
      cache.drop();
      EXPECT_EQ(cache.entries(), 0u) << where;
    }
  }
}

// ---- the tiler's frames ----------------------------------------------------------------------------

void expect_same_stats(const ml::Stats& a, const ml::Stats& b, const std::string& where) {
  EXPECT_EQ(a.triangles_culled, b.triangles_culled) << where;
  EXPECT_EQ(a.triangles_drawn, b.triangles_drawn) << where;
  EXPECT_EQ(a.triangles_tiled, b.triangles_tiled) << where;
  EXPECT_EQ(a.pixel_writes, b.pixel_writes) << where;
  EXPECT_EQ(a.shading_calls, b.shading_calls) << where;
  EXPECT_EQ(a.cells_visited, b.cells_visited) << where;
  EXPECT_EQ(a.bsp_subtrees_culled, b.bsp_subtrees_culled) << where;
  EXPECT_EQ(a.bands, b.bands) << where;
  EXPECT_EQ(a.texture_loads, b.texture_loads) << where;
  EXPECT_EQ(a.texture_bytes_loaded, b.texture_bytes_loaded) << where;
}

// A compiled scene of crossing triangles (so the BSP splits them: split pieces address appended
// vertices), half of them double-sided.
const mlhost::LoadedScene& crossing_scene() {
  static mlhost::LoadedScene loaded;
  if (loaded.scene.info) return loaded;
  const ml::SceneMesh mesh = tiler_test::crossing_mesh(41, 120);
  ml::CompileResult r = ml::compile_mesh(mesh);
  EXPECT_TRUE(r.ok) << r.error;
  loaded.name = "crossing";
  loaded.blob = std::move(r.blob);
  EXPECT_TRUE(ml::read_scene(loaded.blob.data(), loaded.blob.size, &loaded.scene).ok());
  return loaded;
}

// The tiler with the plan and no cache, with a cache of the least size (most lookups miss) and with
// the whole spare arena (render_spare_bytes, a band at a time: the plan and tiler_cache_bytes) gives the same frame byte
// for byte and the same counts, and the least arena the same image: on the bundled scene, the
// textured banded scene and a scene of split pieces, in 16-row bands and in one band, flat, Gouraud,
// ids and antialiased, from several sides.
TEST(VertexCacheFrames, EveryCacheSizeGivesTheSameFrame) {
  struct Case {
    const mlhost::LoadedScene* scene;
    ml::ShadingMode mode;
    int aa;
  };
  const mlhost::LoadedScene& bundled = textest::load("");
  const mlhost::LoadedScene& banded = textest::load("builtin:banded");
  const mlhost::LoadedScene& crossing = crossing_scene();
  ASSERT_TRUE(bundled.scene.info && banded.scene.info && crossing.scene.info);
  ASSERT_GT(crossing.scene.bsp_split_count, 0u);
  const Case cases[] = {{&bundled, ml::ShadingMode::Flat, 1},     {&bundled, ml::ShadingMode::Gouraud, 2},
                        {&banded, ml::ShadingMode::Unlit, 1},     {&crossing, ml::ShadingMode::Ids, 1},
                        {&crossing, ml::ShadingMode::Flat, 1}};
  int frames = 0, drawing = 0;
  for (const Case& c : cases) {
    const ml::Scene& scene = c.scene->scene;
    for (double turn : {0.0, 130.0, 250.0}) {
      for (int rows : {16, 0}) {
        const ml::Camera cam = textest::camera_for(*c.scene, 120, 90, turn);
        ml::RenderOptions o = textest::options(ml::RendererKind::Tiler, c.mode, c.aa);
        o.output.band_rows = rows;
        o.output.render_rows = rows;  // one band at a time: the plan
        const int bands = rows ? (cam.height + rows - 1) / rows : 1;
        const size_t need = ml::render_arena_bytes(scene, cam, o), plan = ml::tiler_plan_bytes(scene, bands);
        const size_t spare = ml::render_spare_bytes(scene, cam, o);
        EXPECT_EQ(spare, plan + ml::tiler_cache_bytes(scene));
        EXPECT_GE(ml::tiler_cache_bytes(scene), VertexCache::arena_bytes(VertexCache::kMinEntries));
        const std::string where = c.scene->name + " turn " + std::to_string(turn) + " rows " + std::to_string(rows) +
                                  " mode " + std::to_string(int(c.mode));
        const textest::Frame least = textest::render(scene, cam, o, need);
        const textest::Frame uncached = textest::render(scene, cam, o, need + plan);
        const textest::Frame small = textest::render(scene, cam, o, need + plan + VertexCache::arena_bytes(VertexCache::kMinEntries));
        const textest::Frame full = textest::render(scene, cam, o, need + spare);
        for (const textest::Frame* f : {&least, &uncached, &small, &full}) {
          ASSERT_TRUE(f->status.ok()) << where << ": " << f->status.message;
          ASSERT_TRUE(f->contract) << where << ": " << f->contract_error;
        }
        EXPECT_EQ(uncached.pixels, least.pixels) << where;
        EXPECT_EQ(small.pixels, uncached.pixels) << where;
        EXPECT_EQ(full.pixels, uncached.pixels) << where;
        expect_same_stats(small.stats, uncached.stats, where);
        expect_same_stats(full.stats, uncached.stats, where);
        // The caches took their bytes (up to the alignment of what follows them): the least one's
        // entries, and the whole of tiler_cache_bytes.
        const size_t entry = sizeof(VertexCache::Entry);
        EXPECT_GE(small.stats.peak_arena_bytes + 8, uncached.stats.peak_arena_bytes + entry * VertexCache::kMinEntries)
            << where;
        EXPECT_GE(full.stats.peak_arena_bytes + 8, uncached.stats.peak_arena_bytes + ml::tiler_cache_bytes(scene) - 3)
            << where;
        if (turn == 0) {
          EXPECT_GT(full.stats.triangles_drawn, 0u) << where;
        }
        drawing += full.stats.triangles_drawn > 0;
        ++frames;
      }
    }
  }
  EXPECT_EQ(frames, 30);
  EXPECT_GE(drawing, 20);
}

// ---- the scanline renderer's frames ------------------------------------------------------------------

// The free bytes of an arena of `bytes` that the ySortList pass shares with the cache (what the texture
// pager leaves), and the cache it takes at their end: the largest power of two of entries up to
// entries_for(vertices) that fits.
size_t scanline_pass_bytes(const ml::Scene& scene, const ml::RenderOptions& o, size_t bytes) {
  const bool colour = o.shading != ml::ShadingMode::Ids && o.shading != ml::ShadingMode::Lines;
  return bytes - (colour ? ml::TexturePager::arena_bytes(scene, o.texture_pool_bytes) : 0);
}
uint32_t scanline_pass_entries(const ml::Scene& scene, size_t free) {
  uint32_t n = VertexCache::entries_for(scene.vertex_count);  // (scenes with a batch that shares vertices)
  while (n >= VertexCache::kMinEntries && VertexCache::arena_bytes(n) > free) n /= 2;
  return n < VertexCache::kMinEntries ? 0 : n;
}

// The scanline renderer keeps a vertex cache at the end of its arena (scanline_spare_bytes) for the
// batches that share their vertices: the frame is the same byte for byte, with the same counts,
// whether the cache is held through the frame (the spare bytes), dropped when the ySortList reaches it,
// dropped after the pass or never taken; and its bytes count in the peak while it is held. On the
// duck (textured, the kind of model the cache is for), the bundled scene and a scene of split pieces,
// flat, Gouraud, ids and supersampled.
TEST(VertexCacheFrames, ScanlineFramesAreTheSameWhereverTheCacheGoes) {
  struct Case {
    const mlhost::LoadedScene* scene;
    ml::ShadingMode mode;
    int aa;
    int width, height;
  };
  const mlhost::LoadedScene& duck = textest::load(textest::duck_model());
  const mlhost::LoadedScene& bundled = textest::load("");
  const mlhost::LoadedScene& crossing = crossing_scene();
  ASSERT_TRUE(duck.scene.info && bundled.scene.info && crossing.scene.info) << duck.name;
  const Case cases[] = {{&duck, ml::ShadingMode::Flat, 1, 320, 240},    {&duck, ml::ShadingMode::Gouraud, 2, 160, 120},
                        {&bundled, ml::ShadingMode::Flat, 1, 160, 120}, {&bundled, ml::ShadingMode::Ids, 1, 160, 120},
                        {&crossing, ml::ShadingMode::Flat, 3, 120, 90}};
  for (const Case& c : cases) {
    const ml::Scene& scene = c.scene->scene;
    ml::RenderOptions o = textest::options(ml::RendererKind::Scanline, c.mode, c.aa);
    for (double turn : {0.0, 150.0}) {
      const ml::Camera cam = textest::camera_for(*c.scene, c.width, c.height, turn);
      const size_t need = ml::render_arena_bytes(scene, cam, o), spare = ml::render_spare_bytes(scene, cam, o);
      ASSERT_GT(need, 0u);
      EXPECT_EQ(spare, ml::scanline_spare_bytes(scene));
      if (c.scene != &crossing) {  // meshes: a vertex used by several triangles
        EXPECT_EQ(spare, VertexCache::arena_bytes(VertexCache::entries_for(scene.vertex_count)));
      }
      const std::string where = c.scene->name + " mode " + std::to_string(int(c.mode)) + " turn " + std::to_string(turn);
      const textest::Frame least = textest::render(scene, cam, o, need);
      ASSERT_TRUE(least.status.ok()) << where << ": " << least.status.message;
      EXPECT_LE(least.stats.peak_arena_bytes, need) << where;
      // An arena where the whole cache fits at first and the list reaches it on the way: the pieces'
      // 8-byte entries do not fit beside it (the bundled scene, whose least arena holds less than the
      // whole cache; the textured duck's holds it and all its pieces).
      const size_t whole = spare;
      const size_t free = scanline_pass_bytes(scene, o, need);
      const size_t halfway = whole > free ? whole - free + 4 * size_t(least.stats.n) : 0;
      if (c.scene == &bundled) {
        ASSERT_GT(halfway, 0u) << where;
        const size_t free_then = scanline_pass_bytes(scene, o, need + halfway);
        ASSERT_EQ(scanline_pass_entries(scene, free_then), VertexCache::entries_for(scene.vertex_count)) << where;
        EXPECT_LT((free_then - whole) / 8, least.stats.n) << where;
      }
      for (size_t more : {spare, spare / 2, spare / 8, size_t(64), halfway}) {
        const textest::Frame f = textest::render(scene, cam, o, need + more);
        const std::string at = where + " spare " + std::to_string(more);
        ASSERT_TRUE(f.status.ok()) << at << ": " << f.status.message;
        ASSERT_TRUE(f.contract) << at << ": " << f.contract_error;
        EXPECT_EQ(f.pixels, least.pixels) << at;
        expect_same_stats(f.stats, least.stats, at);
        EXPECT_EQ(f.stats.n, least.stats.n) << at;
        EXPECT_EQ(f.stats.m_max, least.stats.m_max) << at;
        EXPECT_LE(f.stats.peak_arena_bytes, need + more) << at;
        if (more == spare && spare > 0) {  // held through the frame: the frame's arrays and the whole cache
          const size_t cache = VertexCache::entries_for(scene.vertex_count) * sizeof(VertexCache::Entry);
          EXPECT_GE(f.stats.peak_arena_bytes + 64, need + cache) << at;
        }
      }
    }
  }
}

// A scene whose batches do not share their vertices (office(8)'s boxes: a vertex per corner and face, 24
// for 12 triangles) takes no cache and asks for no spare bytes: its look-ups would miss two in three.
TEST(VertexCacheFrames, ScanlineTakesNoCacheForBatchesThatShareNoVertices) {
  ml::CompileResult office = ml::build_office_scene(2);
  ASSERT_TRUE(office.ok) << office.error;
  ml::Scene scene;
  ASSERT_TRUE(ml::read_scene(office.blob.data(), office.blob.size, &scene).ok());
  for (uint32_t b = 0; b < scene.batch_count; ++b) EXPECT_GT(scene.batches[b].vertex_count, scene.batches[b].triangle_count);
  EXPECT_EQ(ml::scanline_spare_bytes(scene), 0u);
  const mlhost::LoadedScene& bundled = textest::load("");
  ASSERT_TRUE(bundled.scene.info);
  EXPECT_GT(ml::scanline_spare_bytes(bundled.scene), 0u);
  // The same peak with a larger arena: nothing taken from it.
  ml::Camera cam = ml::frame_sphere(ml::Vec3i{scene.info->sphere_center[0], scene.info->sphere_center[1],
                                              scene.info->sphere_center[2]},
                                    scene.info->sphere_radius, 160, 120, 45 << 16);
  const ml::RenderOptions o = textest::options(ml::RendererKind::Scanline, ml::ShadingMode::Flat);
  const size_t need = ml::render_arena_bytes(scene, cam, o);
  const textest::Frame least = textest::render(scene, cam, o, need), more = textest::render(scene, cam, o, need + 65536);
  ASSERT_TRUE(least.status.ok() && more.status.ok());
  EXPECT_EQ(more.pixels, least.pixels);
  EXPECT_EQ(more.stats.peak_arena_bytes, least.stats.peak_arena_bytes);
}

}  // namespace

// Both renderers' id images against the double-precision oracle (tests/oracle/oracle.h), and against
// each other. The oracle's answer is authoritative at every pixel whose centre is farther than 1/16
// pixel from every projected edge and whose front surface is not a depth tie; the two renderers share
// one coverage rule, so they must agree exactly wherever the front surface is not a tie.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "platform/host/scene_load.h"
#include "render/render.h"
#include "tests/common/mesh_builder.h"
#include "tests/common/checked_render.h"
#include "tests/common/assimp_models.h"
#include "tests/common/engine_scene.h"
#include "tests/oracle/oracle.h"
#include "tests/oracle/scene_triangles.h"
#include "tests/tiler/tiler_test_util.h"
#include "tests/texture/texture_test_util.h"
#include "tools/scenec/scenec.h"
#include "view/view.h"

namespace {

constexpr double kEdgeClearance = 1.0 / 16.0;

testrender::Image render_ids(const ml::Scene& scene, const ml::Camera& camera, ml::RendererKind renderer) {
  ml::RenderOptions o;
  o.renderer = renderer;
  o.shading = ml::ShadingMode::Ids;
  o.aa = 1;
  o.background = 0;
  return testrender::render_checked(scene, camera, o);
}

struct Agreement {
  size_t decisive = 0, mismatches = 0;
  std::string first;
};

Agreement compare(const std::vector<uint32_t>& ids, const oracle::Result& ref) {
  Agreement a;
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x) {
      if (!ref.decisive(x, y, kEdgeClearance)) continue;
      ++a.decisive;
      const size_t i = ref.index(x, y);
      const uint32_t want = uint32_t(ref.id[i] + 1);
      if (ids[i] != want) {
        if (a.mismatches++ == 0)
          a.first = "pixel (" + std::to_string(x) + "," + std::to_string(y) + "): rendered id+1 " + std::to_string(ids[i]) +
                    ", oracle " + std::to_string(want) + ", edge distance " + std::to_string(ref.edge_distance[i]);
      }
    }
  return a;
}

// Checks one renderer against the oracle; `min_decisive` guards against a vacuous comparison.
void check_against_oracle(const ml::Scene& scene, const ml::Camera& camera, ml::RendererKind renderer,
                          double min_decisive_fraction) {
  const testrender::Image img = render_ids(scene, camera, renderer);
  ASSERT_TRUE(img.ok) << img.error;
  const oracle::Result ref = oracle::rasterize(oracle::scene_triangles(scene), oracle::to_oracle_camera(camera));
  const Agreement a = compare(img.pixels, ref);
  ::testing::Test::RecordProperty("decisive_pixels", std::to_string(a.decisive) + " of " +
                                                        std::to_string(camera.width * camera.height));
  EXPECT_EQ(a.mismatches, 0u) << a.mismatches << " of " << a.decisive << " decisive pixels differ; first: " << a.first;
  EXPECT_GE(double(a.decisive), min_decisive_fraction * camera.width * camera.height)
      << "only " << a.decisive << " decisive pixels";
}

const mlhost::LoadedScene& default_scene() {
  static mlhost::LoadedScene scene = [] {
    mlhost::LoadedScene s;
    std::string error;
    if (!mlhost::load_scene("", &s, &error)) ADD_FAILURE() << error;
    return s;
  }();
  return scene;
}

using testfiles::engine_scene;

ml::Camera framing(const ml::Scene& scene, int w, int h) {
  const ml::SceneInfo& i = *scene.info;
  return ml::frame_sphere(ml::Vec3i{i.sphere_center[0], i.sphere_center[1], i.sphere_center[2]}, i.sphere_radius, w, h,
                          45 << 16);
}

// Random triangles, each inside its own depth slab so no two intersect (a crossing would make a
// depth tie along the crossing line); random winding (some back faces), some double-sided.
ml::CompileResult random_scene(uint32_t seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> xy(-4, 4), in_slab(0, 0.8), unit(0, 1);
  std::vector<ml::MeshMaterial> materials(2);
  materials[1].double_sided = true;
  ml::SceneMesh mesh = meshtest::one_node_mesh(std::move(materials), "random");
  for (int t = 0; t < count; ++t) {
    const size_t primitive = unit(rng) < 0.3 ? 1 : 0;
    ml::MeshVertex v[3];
    for (ml::MeshVertex& vertex : v) {
      vertex.position[0] = xy(rng);
      vertex.position[1] = xy(rng);
      vertex.position[2] = -(t + in_slab(rng));
    }
    meshtest::add_triangle(&mesh, primitive, v);
  }
  return ml::compile_mesh(mesh);
}

// random_scene(seed, count), compiled and loaded; false (a test failure) when it is not.
bool load_random_scene(uint32_t seed, int count, mlhost::LoadedScene* s) {
  const ml::CompileResult c = random_scene(seed, count);
  std::string error;
  if (c.ok && mlhost::adopt_compiled(c, "random", s, &error)) return true;
  ADD_FAILURE() << "random scene " << seed << ": " << (c.ok ? error : c.error);
  return false;
}

// A camera inside the scene's box looking at a random point: exercises near-plane and guard-band
// clipping of triangles that reach behind the eye.
ml::Camera inside_camera(const ml::Scene& scene, uint32_t seed, int w, int h) {
  std::mt19937 rng(seed * 7919u + 1);
  const ml::SceneInfo& i = *scene.info;
  auto pick = [&](int axis) {
    std::uniform_int_distribution<int32_t> d(i.bounds_min[axis], i.bounds_max[axis]);
    return d(rng);
  };
  ml::Camera c;
  c.width = w;
  c.height = h;
  c.fov_deg_q16 = 60 << 16;
  c.near = std::max(16, i.sphere_radius / 512);
  do {
    c.eye = ml::Vec3i{pick(0), pick(1), pick(2)};
    c.target = ml::Vec3i{pick(0), pick(1), pick(2)};
  } while (std::abs(c.eye.x - c.target.x) + std::abs(c.eye.y - c.target.y) < i.sphere_radius / 4);
  c.up = ml::Vec3i{0, 0, 1};
  return c;
}

class OracleIds : public ::testing::TestWithParam<ml::RendererKind> {};

TEST_P(OracleIds, DefaultScene) {
  const auto& s = default_scene();
  ASSERT_NE(s.scene.info, nullptr);
  check_against_oracle(s.scene, framing(s.scene, 160, 120), GetParam(), 0.85);
}

TEST_P(OracleIds, TwoCylinderEngineAt160x120) {
  const auto* s = engine_scene();
  if (!s) GTEST_SKIP() << "assimp-testmodels not installed";
  check_against_oracle(s->scene, framing(s->scene, 160, 120), GetParam(), 0.75);
}

TEST_P(OracleIds, RandomScenesFramedAndFromInside) {
  for (uint32_t seed = 1; seed <= 8; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    mlhost::LoadedScene s;
    ASSERT_TRUE(load_random_scene(seed, 12 + int(seed) * 3, &s));
    check_against_oracle(s.scene, framing(s.scene, 96, 72), GetParam(), 0.5);
    check_against_oracle(s.scene, inside_camera(s.scene, seed, 96, 72), GetParam(), 0.3);
  }
}

INSTANTIATE_TEST_SUITE_P(Renderers, OracleIds, ::testing::Values(ml::RendererKind::Tiler, ml::RendererKind::Scanline),
                         [](const ::testing::TestParamInfo<ml::RendererKind>& info) {
                           return info.param == ml::RendererKind::Tiler ? std::string("Tiler") : std::string("Scanline");
                         });

// Triangles that the BSP split into pieces (a piece that is not the whole triangle).
std::vector<bool> split_triangles(const ml::Scene& scene) {
  std::vector<bool> split(scene.triangle_count, false);
  for (uint32_t p = 0; p < scene.bsp_piece_count; ++p) {
    const ml::BspPiece piece = ml::bsp_piece(scene, p);
    const ml::Triangle t = ml::triangle_at(scene, piece.triangle);
    if (piece.v[0] != t.v[0] || piece.v[1] != t.v[1] || piece.v[2] != t.v[2]) split[piece.triangle] = true;
  }
  return split;
}

// Tiler and scanline ids agree at every pixel whose front surface is not a depth tie -- near edges too,
// since both use src/view's edge functions and fill rule, and the tiler tiles a piece of a split
// triangle that reaches the triangle's edges with those edges (clip_to_triangle), not its own through
// quantized split points.
// Returns the pixels compared whose front triangle the BSP split.
size_t check_renderers_agree(const ml::Scene& scene, const ml::Camera& camera) {
  const testrender::Image t = render_ids(scene, camera, ml::RendererKind::Tiler);
  const testrender::Image s = render_ids(scene, camera, ml::RendererKind::Scanline);
  EXPECT_TRUE(t.ok) << "tiler: " << t.error;
  EXPECT_TRUE(s.ok) << "scanline: " << s.error;
  if (!t.ok || !s.ok) return 0;
  const oracle::Result ref = oracle::rasterize(oracle::scene_triangles(scene), oracle::to_oracle_camera(camera));
  const std::vector<bool> split = split_triangles(scene);
  size_t compared = 0, differ = 0, differ_away_from_edges = 0, split_pixels = 0;
  std::string first;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const size_t i = ref.index(x, y);
      if (ref.ambiguous[i]) continue;
      ++compared;
      split_pixels += ref.id[i] >= 0 && split[size_t(ref.id[i])];
      if (t.pixels[i] == s.pixels[i]) continue;
      if (ref.edge_distance[i] > kEdgeClearance) ++differ_away_from_edges;
      if (differ++ == 0)
        first = "pixel (" + std::to_string(x) + "," + std::to_string(y) + "): tiler " + std::to_string(t.pixels[i]) +
                ", scanline " + std::to_string(s.pixels[i]) + "; oracle " + std::to_string(ref.id[i] + 1) + ", then " +
                std::to_string(ref.second_id[i] + 1) + ", relative depth gap " + std::to_string(ref.depth_gap[i]) +
                ", edge distance " + std::to_string(ref.edge_distance[i]);
    }
  EXPECT_EQ(differ, 0u) << differ << " of " << compared << " pixels differ (" << differ_away_from_edges
                        << " of them farther than 1/16 pixel from every edge); first: " << first;
  EXPECT_GT(compared, size_t(camera.width) * size_t(camera.height) / 2);
  return split_pixels;
}

// office(8) seen down its rows: up to hundreds of spans a row, most of them hidden, which the
// scanline renderer's sweep drops where the span in front hides them to their end.
TEST(OracleRenderersAgree, OfficeSeenDownItsRows) {
  const ml::CompileResult r = ml::build_office_scene(8);
  ASSERT_TRUE(r.ok) << r.error;
  ml::Scene office;
  ASSERT_TRUE(ml::read_scene(r.blob.data(), r.blob.size, &office).ok());
  check_renderers_agree(office, tiler_test::hint_camera(r, office, 160, 120));
}

TEST(OracleRenderersAgree, DefaultEngineAndRandomScenes) {
  check_renderers_agree(default_scene().scene, framing(default_scene().scene, 160, 120));
  if (const auto* e = engine_scene()) check_renderers_agree(e->scene, framing(e->scene, 160, 120));
  for (uint32_t seed = 1; seed <= 4; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    mlhost::LoadedScene s;
    ASSERT_TRUE(load_random_scene(seed + 100, 30, &s));
    check_renderers_agree(s.scene, framing(s.scene, 96, 72));
    check_renderers_agree(s.scene, inside_camera(s.scene, seed, 96, 72));
  }
}

// A camera from glTF points, as `maskline render --eye --target --up 0,1,0` makes it.
ml::Camera gltf_camera(const ml::Scene& scene, const double eye[3], const double target[3], int w, int h) {
  ml::Camera c = framing(scene, w, h);
  const mlhost::GltfMapping map = mlhost::gltf_mapping(scene);
  EXPECT_TRUE(mlhost::gltf_point_to_world(map, eye, &c.eye) && mlhost::gltf_point_to_world(map, target, &c.target));
  c.up = ml::Vec3i{0, 1 << 20, 0};
  const ml::SceneInfo& i = *scene.info;
  const double d = std::hypot(double(c.eye.x) - i.sphere_center[0], double(c.eye.y) - i.sphere_center[1],
                              double(c.eye.z) - i.sphere_center[2]);
  c.near = int32_t(std::max(1.0, d > i.sphere_radius ? (d - i.sphere_radius) / 2 : i.sphere_radius / 1024.0));
  return c;
}

// Real models whose BSP cuts triangles almost along one of their edges (sliver pieces, and pieces
// along all three edges but for a sliver): a sample on such an edge must go to one of the pieces, not
// to the background showing through a closed surface, as it did at pixel (137,76) of the duck below
// and (149,116) of Blender's human framed.
TEST(OracleRenderersAgree, SliverPiecesOfRealModels) {
  const mlhost::LoadedScene& duck = textest::load(testfiles::converted_model("Collada/duck_triangulate.dae"));
  const mlhost::LoadedScene& human = textest::load(testfiles::converted_model("BLEND/HUMAN.blend"));
  ASSERT_TRUE(duck.scene.info && human.scene.info) << duck.name << "; " << human.name;
  const double eye[3] = {-0.9372409, 1.298138, 1.463273}, target[3] = {0.1343942, 0.869484, -0.03701563};
  EXPECT_GT(check_renderers_agree(duck.scene, gltf_camera(duck.scene, eye, target, 320, 240)), 5000u);
  EXPECT_GT(check_renderers_agree(human.scene, framing(human.scene, 320, 240)), 500u);
}

// Gouraud colours of split triangles: the tiler makes a split piece's colour planes on its whole
// triangle's screen triangle, or on the part of it over each sample when the near plane or the guard
// band cuts it (shade_triangle gives the triangle's vertex colours, not the split points'), so where
// both renderers show the same triangle their colours agree within the planes' rounding (one level),
// split pieces included.
// Returns the pixels compared of the triangles `counted` marks (the split ones when not given).
size_t check_gouraud_agrees(const ml::Scene& scene, const ml::Camera& camera, std::vector<bool> counted = {}) {
  const std::vector<bool> split = split_triangles(scene);
  if (counted.empty()) counted = split;
  const testrender::Image t_ids = render_ids(scene, camera, ml::RendererKind::Tiler);
  const testrender::Image s_ids = render_ids(scene, camera, ml::RendererKind::Scanline);
  auto gouraud = [&](ml::RendererKind r) {
    ml::RenderOptions o;
    o.renderer = r;
    o.shading = ml::ShadingMode::Gouraud;
    return testrender::render_checked(scene, camera, o);
  };
  const testrender::Image t = gouraud(ml::RendererKind::Tiler), s = gouraud(ml::RendererKind::Scanline);
  EXPECT_TRUE(t.ok && s.ok && t_ids.ok && s_ids.ok) << t.error << s.error;
  if (!(t.ok && s.ok && t_ids.ok && s_ids.ok)) return 0;
  size_t counted_pixels = 0, off = 0;
  int worst = 0;
  std::string first;
  for (size_t i = 0; i < t.pixels.size(); ++i) {
    const uint32_t id = t_ids.pixels[i];
    if (id == 0 || id != s_ids.pixels[i]) continue;
    counted_pixels += counted[id - 1];
    int most = 0;
    for (int shift : {0, 8, 16})
      most = std::max(most, std::abs(int((t.pixels[i] >> shift) & 255) - int((s.pixels[i] >> shift) & 255)));
    worst = std::max(worst, most);
    if (most > 1 && off++ == 0)
      first = "pixel " + std::to_string(i) + " (triangle " + std::to_string(id - 1) + (split[id - 1] ? ", split" : "") +
              "): tiler " + std::to_string(t.pixels[i]) + ", scanline " + std::to_string(s.pixels[i]);
  }
  EXPECT_EQ(off, 0u) << "pixels more than one level apart; first: " << first << "; most " << worst << " levels";
  return counted_pixels;
}

// Triangles whose corners lie on both sides of the camera's near plane (view depth, src/view).
std::vector<bool> near_clipped_triangles(const ml::Scene& scene, const ml::Camera& camera) {
  std::vector<bool> crossing(scene.triangle_count, false);
  ml::View view;
  if (!ml::make_view(camera, &view).ok()) return crossing;
  for (uint32_t t = 0; t < scene.triangle_count; ++t) {
    ml::Vec3i world[3];
    ml::triangle_world(scene, t, world);
    int behind = 0;
    for (const ml::Vec3i& w : world) {
      ml::ViewVertex v;
      ml::view_vertex(view, w, &v);
      behind += v.p.z < view.near;
    }
    crossing[t] = behind == 1 || behind == 2;
  }
  return crossing;
}

// crossing_mesh's triangles (corners anywhere in a cube, so the BSP splits many), each corner with a
// normal of its own so that Gouraud colours vary over every triangle; compiled and loaded.
bool load_crossing_scene(uint32_t seed, int count, mlhost::LoadedScene* s) {
  ml::SceneMesh mesh = tiler_test::crossing_mesh(seed, count);
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  for (ml::MeshPrimitive& prim : mesh.nodes[0].primitives)
    for (ml::MeshVertex& v : prim.vertices) {
      double n[3] = {g(rng), g(rng), g(rng)};
      const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (int k = 0; k < 3; ++k) v.normal[k] = n[k] / len;
    }
  std::string error;
  const ml::CompileResult c = ml::compile_mesh(mesh);
  if (c.ok && mlhost::adopt_compiled(c, "crossing", s, &error)) return true;
  ADD_FAILURE() << "crossing scene " << seed << ": " << (c.ok ? error : c.error);
  return false;
}

// The sum of check(scene, seed) over crossing scenes of 24 triangles, seeds 1 to 6.
template <typename Check>
size_t sum_over_crossing_scenes(Check check) {
  size_t sum = 0;
  for (uint32_t seed = 1; seed <= 6; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    mlhost::LoadedScene s;
    const bool loaded = load_crossing_scene(seed, 24, &s);
    EXPECT_TRUE(loaded);
    if (loaded) sum += check(s.scene, seed);
  }
  return sum;
}

// Split triangles the near plane cuts, seen from inside scenes of crossing triangles: the tiler's
// pieces of them have split points for corners, and their triangle projects in several parts; where
// both renderers show such a triangle their colours agree as elsewhere.
TEST(OracleRenderersAgree, GouraudColoursOfNearClippedSplitTriangles) {
  const size_t near_split_pixels = sum_over_crossing_scenes([](const ml::Scene& scene, uint32_t seed) {
    const ml::Camera camera = inside_camera(scene, seed, 96, 72);
    const std::vector<bool> split = split_triangles(scene), crossing = near_clipped_triangles(scene, camera);
    std::vector<bool> both(split.size());
    for (size_t t = 0; t < split.size(); ++t) both[t] = split[t] && crossing[t];
    return check_gouraud_agrees(scene, camera, both);
  });
  EXPECT_GT(near_split_pixels, 5000u) << "few near-clipped split triangles on screen: the test would hardly test them";
}

// Scenes of crossing triangles, which the BSP cuts everywhere and at every angle: slivers whose cut
// runs almost along a triangle edge, on either side of it. A sliver's cut faces away from that edge;
// taken for it, the piece grew over the far side of the cut (a pixel of a farther triangle drawn over
// a nearer one).
TEST(OracleRenderersAgree, CrossingTriangles) {
  const size_t split_pixels = sum_over_crossing_scenes([](const ml::Scene& scene, uint32_t seed) {
    return check_renderers_agree(scene, framing(scene, 96, 72)) +
           check_renderers_agree(scene, inside_camera(scene, seed, 96, 72));
  });
  EXPECT_GT(split_pixels, 5000u) << "few split triangles on screen: the test would hardly test them";
}

TEST(OracleRenderersAgree, GouraudColoursOfSplitTriangles) {
  size_t split_pixels = 0;
  if (const auto* e = engine_scene()) split_pixels += check_gouraud_agrees(e->scene, framing(e->scene, 160, 120));
  for (uint32_t seed = 1; seed <= 2; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    mlhost::LoadedScene s;
    ASSERT_TRUE(load_random_scene(seed + 100, 30, &s));
    split_pixels += check_gouraud_agrees(s.scene, framing(s.scene, 96, 72));
  }
  EXPECT_GT(split_pixels, 100u) << "few split triangles on screen: the test would hardly test them";
}

}  // namespace

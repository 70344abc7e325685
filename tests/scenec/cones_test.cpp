// Normal cones of BSP subtrees (blob_format.h PackedBspCone, tools/scenec/cones.cpp): every subtree the
// cone test skips for an eye holds only triangles that the renderer's exact facing test calls back
// faces, for random eyes and for eyes placed just behind the cones' subtrees, where the bound is
// tightest; each stored cone covers its subtree's normals; the reader checks the section's count.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "tests/common/mesh_builder.h"
#include "tests/scene/scene_test_util.h"
#include "view/view.h"

using namespace ml;

namespace {

// Every piece of node i's subtree; marks the subtree's nodes in *nodes when given.
std::vector<uint32_t> subtree_pieces(const Scene& s, uint32_t i, std::vector<uint8_t>* nodes = nullptr) {
  std::vector<uint32_t> pieces, stack{i};
  while (!stack.empty()) {
    const uint32_t index = stack.back();
    const BspNode n = bsp_node(s, index);
    stack.pop_back();
    if (nodes) (*nodes)[index] = 1;
    for (uint32_t p = n.first_piece; p < n.first_piece + n.piece_count; ++p) pieces.push_back(p);
    if (n.front != kNone) stack.push_back(n.front);
    if (n.back != kNone) stack.push_back(n.back);
  }
  return pieces;
}

// The renderer's facing of a piece's whole triangle for an eye, and whether its material is double-sided.
int facing(const Scene& s, uint32_t piece, const Vec3i& eye, bool* double_sided) {
  View view{};
  view.eye = eye;
  const uint32_t t = bsp_piece(s, piece).triangle;
  *double_sided = s.materials[s.batches[triangle_at(s, t).batch].material].double_sided != 0;
  Vec3i w[3];
  triangle_world(s, t, w);
  return triangle_facing(view, w);
}

// Checks every node the cone test skips for `eye` (a node inside a skipped subtree is covered by its
// ancestor's check: its pieces are some of those); returns how many it skipped.
int check_eye(const Scene& s, const Vec3i& eye) {
  int skipped = 0;
  std::vector<uint8_t> covered(s.bsp_node_count, 0);
  for (uint32_t i = 0; i < s.bsp_node_count; ++i) {  // parents before children (breadth-first)
    if (covered[i] || !bsp_subtree_faces_away(s, i, eye)) continue;
    ++skipped;
    for (uint32_t p : subtree_pieces(s, i, &covered)) {
      bool double_sided = false;
      EXPECT_LT(facing(s, p, eye, &double_sided), 1) << "node " << i << " piece " << p;
      EXPECT_FALSE(double_sided) << "node " << i << " piece " << p;
    }
  }
  return skipped;
}

// Eyes around the scene and eyes just behind cone subtrees (along minus the cone's axis, at a few
// multiples of the box's size): the test must hold wherever it says yes. Returns the subtrees skipped.
int check_cones(const Scene& s, uint32_t seed, int random_eyes, int placed_eyes) {
  std::mt19937 rng(seed);
  int skipped = 0;
  std::uniform_int_distribution<int32_t> coordinate(-(3 << 16), 3 << 16);
  for (int k = 0; k < random_eyes; ++k) skipped += check_eye(s, Vec3i{coordinate(rng), coordinate(rng), coordinate(rng)});
  std::vector<uint32_t> with_cone;
  for (uint32_t i = 0; i < s.bsp_node_count; ++i)
    if (s.bsp_cones[i].spread != kNoCone) with_cone.push_back(i);
  if (with_cone.empty()) return skipped;
  std::uniform_int_distribution<size_t> pick(0, with_cone.size() - 1);
  std::uniform_real_distribution<double> distance(0.05, 4.0), jitter(-0.5, 0.5);
  for (int k = 0; k < placed_eyes; ++k) {
    const uint32_t i = with_cone[pick(rng)];
    const BspNode box = bsp_node(s, i);
    const PackedBspCone& cone = s.bsp_cones[i];
    const double len = std::sqrt(double(cone.axis[0]) * cone.axis[0] + double(cone.axis[1]) * cone.axis[1] +
                                 double(cone.axis[2]) * cone.axis[2]);
    double size = 0;
    for (int a = 0; a < 3; ++a) size = std::max(size, double(box.bounds_max[a]) - box.bounds_min[a] + 2 * kConeMarginWorld);
    const double d = distance(rng) * size;
    int32_t e[3];
    for (int a = 0; a < 3; ++a) {
      const double centre = 0.5 * (double(box.bounds_min[a]) + box.bounds_max[a]);
      e[a] = int32_t(std::lround(centre - d * cone.axis[a] / len + jitter(rng) * size));
    }
    skipped += check_eye(s, Vec3i{e[0], e[1], e[2]});
  }
  return skipped;
}

// Each cone's claim about its subtree's normals (blob_format.h): 2 |axis| |n - axis / |axis|| <= spread.
void check_cone_bounds(const Scene& s) {
  for (uint32_t i = 0; i < s.bsp_node_count; ++i) {
    const PackedBspCone& cone = s.bsp_cones[i];
    if (cone.spread == kNoCone) continue;
    const double len = std::sqrt(double(cone.axis[0]) * cone.axis[0] + double(cone.axis[1]) * cone.axis[1] +
                                 double(cone.axis[2]) * cone.axis[2]);
    ASSERT_GT(len, 0) << i;
    for (uint32_t p : subtree_pieces(s, i)) {
      Vec3i w[3];
      triangle_world(s, bsp_piece(s, p).triangle, w);
      const double e1[3] = {double(w[1].x) - w[0].x, double(w[1].y) - w[0].y, double(w[1].z) - w[0].z};
      const double e2[3] = {double(w[2].x) - w[0].x, double(w[2].y) - w[0].y, double(w[2].z) - w[0].z};
      const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      const double nl = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (nl == 0) continue;  // degenerate: never drawn
      double gap2 = 0;
      for (int a = 0; a < 3; ++a) gap2 += (n[a] / nl - cone.axis[a] / len) * (n[a] / nl - cone.axis[a] / len);
      EXPECT_LE(2 * len * std::sqrt(gap2), double(cone.spread)) << "node " << i << " piece " << p;
    }
  }
}

const Scene read_cached(const char* name) {
  const CompileResult& r = scenetest::cached(name);
  EXPECT_TRUE(r.ok) << name << ": " << r.error;
  Scene s;
  EXPECT_TRUE(scenetest::read(r.blob, &s).ok()) << name;
  return s;
}

}  // namespace

TEST(SceneCones, SkippedSubtreesHoldOnlyBackFaces) {
  struct Case {
    const char* name;
    int random_eyes, placed_eyes;
  };
  for (const Case& c : {Case{"default", 20, 300}, Case{"office2", 20, 300}, Case{"tessellated", 3, 40}}) {
    const Scene s = read_cached(c.name);
    ASSERT_NE(s.bsp_cones, nullptr) << c.name;
    check_cone_bounds(s);
    EXPECT_GT(check_cones(s, 5, c.random_eyes, c.placed_eyes), 20) << c.name;  // it skips subtrees: it can fail
  }
}

TEST(SceneCones, EngineSkippedSubtreesHoldOnlyBackFaces) {
  if (!scenetest::file_exists(scenetest::engine_path())) GTEST_SKIP();
  const Scene s = read_cached("engine");
  ASSERT_NE(s.bsp_cones, nullptr);
  EXPECT_GT(check_cones(s, 9, 3, 60), 50);
}

TEST(SceneCones, DoubleSidedSubtreesHaveNoCone) {
  // Two stacks of parallel squares facing +z, the second double-sided: cones only where no piece
  // below is double-sided, and some there are.
  ml::MeshMaterial single, both;
  both.double_sided = true;
  ml::SceneMesh mesh = meshtest::one_node_mesh({single, both});
  for (int m = 0; m < 2; ++m)
    for (int k = 0; k < 12; ++k) {
      const double x = m * 30.0, z = k * 2.0;
      meshtest::add_triangle(&mesh, m, {{{x, 0, z}}, {{x + 10, 0, z}}, {{x + 10, 10, z}}});
      meshtest::add_triangle(&mesh, m, {{{x, 0, z}}, {{x + 10, 10, z}}, {{x, 10, z}}});
    }
  const CompileResult r = compile_mesh(mesh);
  ASSERT_TRUE(r.ok) << r.error;
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  ASSERT_NE(s.bsp_cones, nullptr);
  int with_cone = 0, double_sided_subtrees = 0;
  for (uint32_t i = 0; i < s.bsp_node_count; ++i) {
    bool any_double_sided = false;
    for (uint32_t p : subtree_pieces(s, i)) {
      bool double_sided = false;
      facing(s, p, Vec3i{0, 0, 0}, &double_sided);
      any_double_sided |= double_sided;
    }
    const bool cone = s.bsp_cones[i].spread != kNoCone;
    with_cone += cone;
    double_sided_subtrees += any_double_sided;
    EXPECT_FALSE(cone && any_double_sided) << "node " << i;
  }
  EXPECT_GT(with_cone, 0);
  EXPECT_GT(double_sided_subtrees, 0);
}

TEST(SceneCones, ReaderChecksTheCount) {
  Blob blob = scenetest::cached("default").blob;
  SectionEntry* e = scenetest::find_section(&blob, SectionType::BspCones);
  ASSERT_NE(e, nullptr);
  e->count -= 1;
  e->size -= sizeof(PackedBspCone);
  scenetest::fix_crc(&blob);
  Scene s;
  const Status st = scenetest::read(blob, &s);
  EXPECT_EQ(st.code, StatusCode::BadScene);
  EXPECT_STREQ(st.message, "bsp cone count does not match bsp node count");
}

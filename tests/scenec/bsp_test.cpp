// BSP properties: for random eyes the front-to-back order is a valid depth order along sampled rays
// (double math), pieces of split triangles lie in their triangle's plane and cover it, every triangle
// id is represented, and the breadth-first layout the reader requires holds.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "tests/scene/scene_test_util.h"

using namespace ml;

namespace {

using D3 = std::array<double, 3>;

D3 sub(const D3& a, const D3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
D3 cross(const D3& a, const D3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const D3& a, const D3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const D3& a) { return std::sqrt(dot(a, a)); }

D3 world(const Scene& s, uint32_t piece, int k) {
  const Vec3i w = vertex_world(s, ml::triangle_at(s, ml::bsp_piece(s, piece).triangle).batch, ml::bsp_piece(s, piece).v[k]);
  return {double(w.x), double(w.y), double(w.z)};
}

// Ray/triangle (Moller-Trumbore); returns t or -1.
double intersect(const D3& o, const D3& d, const D3& a, const D3& b, const D3& c) {
  const D3 e1 = sub(b, a), e2 = sub(c, a);
  const D3 p = cross(d, e2);
  const double det = dot(e1, p);
  if (std::fabs(det) < 1e-9) return -1;
  const double inv = 1.0 / det;
  const D3 tv = sub(o, a);
  const double u = dot(tv, p) * inv;
  if (u < 0 || u > 1) return -1;
  const D3 q = cross(tv, e1);
  const double v = dot(d, q) * inv;
  if (v < 0 || u + v > 1) return -1;
  return dot(e2, q) * inv;
}

// Largest in-plane band of any batch (bsp.cpp: 2 world units plus the quantization step), plus slack.
double band(const Scene& s) {
  double eps = 0;
  for (uint32_t b = 0; b < s.batch_count; ++b) {
    const int32_t m = std::max(s.batches[b].scale[0], std::max(s.batches[b].scale[1], s.batches[b].scale[2]));
    eps = std::max(eps, 2.0 + m / 65536.0);
  }
  return eps + 1.0;
}

struct Tree {
  std::vector<uint32_t> parent, depth, node_of_piece;
};

Tree tree_of(const Scene& s) {
  Tree t;
  t.parent.assign(s.bsp_node_count, kNone);
  t.depth.assign(s.bsp_node_count, 0);
  t.node_of_piece.assign(s.bsp_piece_count, kNone);
  for (uint32_t i = 0; i < s.bsp_node_count; ++i) {
    for (uint32_t c : {ml::bsp_node(s, i).front, ml::bsp_node(s, i).back}) {
      if (c == kNone) continue;
      t.parent[c] = i;
      t.depth[c] = t.depth[i] + 1;   // breadth-first: the parent's depth is known
    }
    for (uint32_t p = 0; p < ml::bsp_node(s, i).piece_count; ++p) t.node_of_piece[ml::bsp_node(s, i).first_piece + p] = i;
  }
  return t;
}

uint32_t lca(const Tree& t, uint32_t a, uint32_t b) {
  while (t.depth[a] > t.depth[b]) a = t.parent[a];
  while (t.depth[b] > t.depth[a]) b = t.parent[b];
  while (a != b) {
    a = t.parent[a];
    b = t.parent[b];
  }
  return a;
}

// Whether the renderer draws a piece for this eye: its triangle faces the eye or is double-sided.
bool drawn(const Scene& s, uint32_t piece, const D3& eye) {
  const uint32_t t = ml::bsp_piece(s, piece).triangle;
  const Triangle tri = ml::triangle_at(s, t);
  if (s.materials[s.batches[tri.batch].material].double_sided) return true;
  Vec3i w[3];
  triangle_world(s, t, w);
  const D3 a{double(w[0].x), double(w[0].y), double(w[0].z)}, b{double(w[1].x), double(w[1].y), double(w[1].z)},
      c{double(w[2].x), double(w[2].y), double(w[2].z)};
  const D3 u = sub(b, a), v = sub(c, a);
  const D3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  return dot(n, sub(eye, a)) > 0;
}

// Checks the depth order of a scene's BSP from `eyes` random eye points with `rays` rays each.
// Returns the number of ordered hit pairs checked.
size_t check_depth_order(const Scene& s, int eyes, int rays, uint32_t seed) {
  const Tree tree = tree_of(s);
  const double tol = band(s);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  size_t pairs = 0;
  // Piece bounding spheres for a quick reject.
  std::vector<D3> center(s.bsp_piece_count);
  std::vector<double> radius(s.bsp_piece_count);
  for (uint32_t p = 0; p < s.bsp_piece_count; ++p) {
    const D3 a = world(s, p, 0), b = world(s, p, 1), c = world(s, p, 2);
    center[p] = {(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, (a[2] + b[2] + c[2]) / 3};
    radius[p] = std::max(norm(sub(a, center[p])), std::max(norm(sub(b, center[p])), norm(sub(c, center[p])))) + 1;
  }
  for (int e = 0; e < eyes; ++e) {
    D3 eye;
    for (int a = 0; a < 3; ++a) {
      const double lo = s.info->bounds_min[a], hi = s.info->bounds_max[a], mid = (lo + hi) / 2;
      eye[size_t(a)] = mid + unit(rng) * (hi - lo) * (e % 2 ? 0.45 : 0.9);
    }
    const Vec3i eye_i{int32_t(std::lround(eye[0])), int32_t(std::lround(eye[1])), int32_t(std::lround(eye[2]))};
    eye = {double(eye_i.x), double(eye_i.y), double(eye_i.z)};
    const std::vector<uint32_t> order = scenetest::bsp_order(s, eye_i);
    EXPECT_EQ(order.size(), s.bsp_piece_count);
    std::vector<uint32_t> rank(s.bsp_piece_count, kNone);
    for (uint32_t i = 0; i < order.size(); ++i) {
      EXPECT_EQ(rank[order[i]], kNone) << "piece listed twice";
      rank[order[i]] = i;
    }
    for (int r = 0; r < rays; ++r) {
      D3 dir;
      do {
        dir = {unit(rng), unit(rng), unit(rng)};
      } while (norm(dir) > 1 || norm(dir) < 0.1);
      const double len = norm(dir);
      for (double& c : dir) c /= len;
      std::vector<std::pair<double, uint32_t>> hits;
      for (uint32_t p = 0; p < s.bsp_piece_count; ++p) {
        const D3 oc = sub(center[p], eye);
        const double along = dot(oc, dir);
        if (along < -radius[p] || dot(oc, oc) - along * along > radius[p] * radius[p]) continue;
        const double t = intersect(eye, dir, world(s, p, 0), world(s, p, 1), world(s, p, 2));
        if (t > 0) hits.push_back({t, p});
      }
      std::sort(hits.begin(), hits.end());
      for (size_t i = 0; i < hits.size(); ++i) {
        for (size_t j = i + 1; j < hits.size(); ++j) {
          const uint32_t near_p = hits[i].second, far_p = hits[j].second;
          if (rank[near_p] < rank[far_p]) {
            ++pairs;
            continue;
          }
          // The farther piece is drawn first. Valid only within the in-plane band of the plane that
          // separates them: the far piece must be on the eye's side of it (or in the band), the near
          // one on the other side (or in the band).
          const uint32_t na = tree.node_of_piece[near_p], nb = tree.node_of_piece[far_p];
          if (na == nb) {
            // One node's pieces are drawn in any order: two of them on one sight line must not both
            // be drawn (coplanar duplicates aside, at the same distance).
            if (hits[j].first - hits[i].first > tol) {
              EXPECT_FALSE(drawn(s, near_p, eye) && drawn(s, far_p, eye))
                  << "pieces " << near_p << " and " << far_p << " of node " << na << " overlap";
            }
            continue;
          }
          const BspNode& h = ml::bsp_node(s, lca(tree, na, nb));
          auto side = [&](double t) {
            const D3 p{eye[0] + t * dir[0], eye[1] + t * dir[1], eye[2] + t * dir[2]};
            return (h.normal[0] * p[0] + h.normal[1] * p[1] + h.normal[2] * p[2] - double(h.d)) / double(kUnitOne);
          };
          const double eye_side = side(0) >= 0 ? 1.0 : -1.0;
          const double s_far = side(hits[j].first) * eye_side, s_near = side(hits[i].first) * eye_side;
          EXPECT_TRUE(s_far >= -tol && s_near <= tol)
              << "eye " << eye[0] << "," << eye[1] << "," << eye[2] << ": piece " << far_p << " (t "
              << hits[j].first << ", side " << s_far << ") drawn before nearer piece " << near_p << " (t "
              << hits[i].first << ", side " << s_near << ")";
          ++pairs;
        }
      }
    }
  }
  return pairs;
}

void check_pieces(const Scene& s) {
  std::vector<double> piece_area(s.triangle_count, 0.0);
  for (uint32_t p = 0; p < s.bsp_piece_count; ++p) {
    const BspPiece& piece = ml::bsp_piece(s, p);
    const Batch& b = s.batches[ml::triangle_at(s, piece.triangle).batch];
    const double step = std::max(b.scale[0], std::max(b.scale[1], b.scale[2])) / 65536.0;
    Vec3i t[3];
    triangle_world(s, piece.triangle, t);
    const D3 a{double(t[0].x), double(t[0].y), double(t[0].z)};
    const D3 n = cross(sub({double(t[1].x), double(t[1].y), double(t[1].z)}, a),
                       sub({double(t[2].x), double(t[2].y), double(t[2].z)}, a));
    const double nl = norm(n);
    const D3 q0 = world(s, p, 0), q1 = world(s, p, 1), q2 = world(s, p, 2);
    piece_area[piece.triangle] += norm(cross(sub(q1, q0), sub(q2, q0))) / 2;
    if (nl == 0) continue;
    for (const D3& q : {q0, q1, q2}) {
      ASSERT_LE(std::fabs(dot(n, sub(q, a)) / nl), 2.0 + 2 * step)
          << "piece " << p << " of triangle " << piece.triangle << " off its plane";
    }
  }
  double total = 0, covered = 0;
  for (uint32_t t = 0; t < s.triangle_count; ++t) {
    Vec3i w[3];
    triangle_world(s, t, w);
    const D3 a{double(w[0].x), double(w[0].y), double(w[0].z)};
    const double area = norm(cross(sub({double(w[1].x), double(w[1].y), double(w[1].z)}, a),
                                   sub({double(w[2].x), double(w[2].y), double(w[2].z)}, a))) / 2;
    total += area;
    covered += piece_area[t];
  }
  EXPECT_NEAR(covered, total, total * 0.01);
}

void check_ids(const Scene& s) {
  std::vector<uint32_t> seen(s.triangle_count, 0);
  for (uint32_t p = 0; p < s.bsp_piece_count; ++p) ++seen[ml::bsp_piece(s, p).triangle];
  for (uint32_t t = 0; t < s.triangle_count; ++t) ASSERT_GT(seen[t], 0u) << "triangle id " << t << " has no piece";
}

// Random triangles of all sizes crossing each other (many splits), in three batches.
CompileResult random_soup(uint32_t seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-10.0, 10.0), size(0.2, 8.0);
  SceneMesh mesh;
  mesh.materials.resize(2);
  mesh.materials[1].double_sided = true;
  mesh.nodes.resize(1);
  for (int b = 0; b < 3; ++b) {
    MeshPrimitive prim;
    prim.material = uint32_t(b % 2);
    for (int i = 0; i < count / 3; ++i) {
      const double cx = u(rng), cy = u(rng), cz = u(rng), r = size(rng);
      for (int k = 0; k < 3; ++k) {
        MeshVertex v;
        v.position[0] = cx + r * u(rng) / 10;
        v.position[1] = cy + r * u(rng) / 10;
        v.position[2] = cz + r * u(rng) / 10;
        prim.vertices.push_back(v);
      }
      const uint32_t base = uint32_t(prim.vertices.size() - 3);
      prim.triangles.push_back({base, base + 1, base + 2});
    }
    mesh.nodes[0].primitives.push_back(prim);
  }
  return compile_mesh(mesh);
}

// A closed sphere of 2 rings x 2 rings triangles whose radius swells and shrinks in `lobes` bumps a
// turn: a finely tessellated, not quite convex model (as the COLLADA duck) for the second BSP tree.
SceneMesh bumpy_sphere(int rings, double bump, int lobes) {
  SceneMesh mesh;
  mesh.materials.resize(1);
  mesh.nodes.resize(1);
  MeshPrimitive prim;
  prim.material = 0;
  const int segments = 2 * rings;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double th = M_PI * i / rings, ph = 2 * M_PI * j / segments;
      const double r = 1 + bump * std::sin(lobes * th) * std::cos(lobes * ph);
      MeshVertex v{};
      v.position[0] = r * std::sin(th) * std::cos(ph);
      v.position[1] = r * std::cos(th);
      v.position[2] = r * std::sin(th) * std::sin(ph);
      prim.vertices.push_back(v);
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = uint32_t(i * segments + j), b = uint32_t(i * segments + (j + 1) % segments);
      prim.triangles.push_back({a, a + uint32_t(segments), b});
      prim.triangles.push_back({b, a + uint32_t(segments), b + uint32_t(segments)});
    }
  mesh.nodes[0].primitives.push_back(prim);
  return mesh;
}

}  // namespace

TEST(SceneBsp, RandomSoupDepthOrder) {
  for (uint32_t seed : {1u, 2u, 3u}) {
    const CompileResult r = random_soup(seed, 240);
    ASSERT_TRUE(r.ok) << r.error;
    Scene s;
    ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
    EXPECT_GT(r.report.bsp_pieces, r.report.triangles);   // crossing triangles were split
    check_ids(s);
    check_pieces(s);
    EXPECT_GT(check_depth_order(s, 12, 150, seed), 1000u);
  }
}

TEST(SceneBsp, DefaultSceneDepthOrder) {
  const CompileResult& r = scenetest::cached("default");
  ASSERT_TRUE(r.ok) << r.error;
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  check_ids(s);
  check_pieces(s);
  EXPECT_GT(check_depth_order(s, 8, 200, 7), 100u);
}

TEST(SceneBsp, OfficeDepthOrder) {
  const CompileResult& r = scenetest::cached("office2");
  ASSERT_TRUE(r.ok) << r.error;
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  check_ids(s);
  check_pieces(s);
  EXPECT_GT(check_depth_order(s, 8, 150, 11), 100u);
}

TEST(SceneBsp, LargeScenesAreCompleteAndModeratelyDeep) {
  for (const char* name : {"tessellated", "engine"}) {
    const CompileResult& r = scenetest::cached(name);
    if (std::string(name) == "engine" && !scenetest::file_exists(scenetest::engine_path())) continue;
    ASSERT_TRUE(r.ok) << name << ": " << r.error;
    Scene s;
    ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
    check_ids(s);
    check_pieces(s);
    EXPECT_LE(s.info->bsp_depth, 512u) << name;
    EXPECT_LT(r.report.split_ratio, 4.0) << name;
    EXPECT_NEAR(r.report.split_ratio, double(s.bsp_piece_count) / s.triangle_count, 1e-9);
  }
}

// The compiler's subtree boxes are tight: each face of a non-empty subtree's box is touched by a piece
// vertex of that subtree (the reader has already checked that they contain them), and the root's
// count is every piece.
TEST(SceneBsp, SubtreeBoundsAreTightToTheCell) {
  const CompileResult& r = scenetest::cached("office2");
  ASSERT_TRUE(r.ok) << r.error;
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  EXPECT_EQ(ml::bsp_node(s, 0).subtree_pieces, s.bsp_piece_count);
  // Walk each subtree (explicit stack) and collect its vertex box.
  for (uint32_t i = 0; i < s.bsp_node_count; ++i) {
    const BspNode& n = ml::bsp_node(s, i);
    if (n.subtree_pieces == 0) continue;
    int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    std::vector<uint32_t> todo{i};
    while (!todo.empty()) {
      const BspNode& m = ml::bsp_node(s, todo.back());
      todo.pop_back();
      for (uint32_t p = m.first_piece; p < m.first_piece + m.piece_count; ++p)
        for (int k = 0; k < 3; ++k) {
          const D3 w = world(s, p, k);
          for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], int32_t(w[size_t(a)]));
            hi[a] = std::max(hi[a], int32_t(w[size_t(a)]));
          }
        }
      if (m.front != kNone) todo.push_back(m.front);
      if (m.back != kNone) todo.push_back(m.back);
    }
    // The blob keeps boxes in whole cells of the scene grid: the tight box widened to its cells.
    const int32_t cell = int32_t(1) << s.bounds_shift;
    for (int a = 0; a < 3; ++a) {
      ASSERT_LE(n.bounds_min[a], lo[a]) << "node " << i;
      ASSERT_GT(n.bounds_min[a], lo[a] - cell) << "node " << i;
      ASSERT_GE(n.bounds_max[a], hi[a]) << "node " << i;
      ASSERT_LT(n.bounds_max[a], hi[a] + cell) << "node " << i;
      ASSERT_EQ((n.bounds_min[a] - s.info->bounds_min[a]) % cell, 0);
    }
  }
}

// Cells: small triangles strung along x, in a box 50 times longer than it is wide. Every set of more
// than bsp_cell_pieces pieces near the root is cut across x (the box's longest side) with few splits,
// and the order stays a depth order.
TEST(SceneBsp, CellsCutTheLongestSide) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> along(-50.0, 50.0), across(-1.0, 1.0), corner(-0.1, 0.1);
  SceneMesh mesh;
  mesh.materials.resize(1);
  mesh.nodes.resize(1);
  MeshPrimitive prim;
  for (int i = 0; i < 1200; ++i) {
    const double c[3] = {along(rng), across(rng), across(rng)};
    for (int k = 0; k < 3; ++k) {
      MeshVertex v;
      for (int a = 0; a < 3; ++a) v.position[a] = c[a] + corner(rng);
      prim.vertices.push_back(v);
    }
    const uint32_t base = uint32_t(prim.vertices.size() - 3);
    prim.triangles.push_back({base, base + 1, base + 2});
  }
  mesh.nodes[0].primitives.push_back(prim);
  const CompileOptions options;
  const CompileResult r = compile_mesh(mesh, options);
  ASSERT_TRUE(r.ok) << r.error;
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  EXPECT_LT(r.report.split_ratio, 1.05);
  const Tree t = tree_of(s);
  // Every set of more than bsp_cell_pieces pieces near the root (down to about 1/8 of the scene) is a
  // cell: its plane is axis-aligned, across the longest side of its box (here always x).
  int cells_at_depth[3] = {0, 0, 0};
  for (uint32_t i = 0; i < s.bsp_node_count; ++i) {
    const BspNode& n = ml::bsp_node(s, i);
    if (t.depth[i] > 2 || n.subtree_pieces <= uint32_t(options.bsp_cell_pieces)) continue;
    int longest = 0;
    for (int a = 1; a < 3; ++a)
      if (n.bounds_max[a] - n.bounds_min[a] > n.bounds_max[longest] - n.bounds_min[longest]) longest = a;
    EXPECT_EQ(longest, 0) << "node " << i;
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(n.normal[a], a == longest ? 1 << 30 : 0) << "node " << i << " at depth " << t.depth[i] << " axis " << a;
    ++cells_at_depth[t.depth[i]];
  }
  // No such set is left to a triangle's plane: each of the top levels is full of cells.
  for (int depth = 0; depth < 3; ++depth) EXPECT_EQ(cells_at_depth[depth], 1 << depth) << "depth " << depth;
  check_ids(s);
  check_pieces(s);
}

TEST(SceneBsp, DeterministicForASeed) {
  const CompileResult a = random_soup(5, 90), b = random_soup(5, 90);
  ASSERT_TRUE(a.ok && b.ok);
  ASSERT_EQ(a.blob.size, b.blob.size);
  EXPECT_EQ(std::memcmp(a.blob.data(), b.blob.data(), a.blob.size), 0);
}

TEST(SceneBsp, CoplanarAndDegenerateInput) {
  // Many copies of one quad in one plane plus zero-area triangles: one node holds the plane.
  SceneMesh mesh;
  mesh.materials.resize(1);
  mesh.nodes.resize(1);
  MeshPrimitive prim;
  for (int i = 0; i < 50; ++i) {
    const double x = i % 10, z = i / 10;
    for (const auto& p : {std::array<double, 3>{x, 0, z}, {x + 1, 0, z}, {x + 1, 0, z + 1}, {x, 0, z + 1}}) {
      MeshVertex v;
      for (int a = 0; a < 3; ++a) v.position[a] = p[size_t(a)];
      prim.vertices.push_back(v);
    }
    const uint32_t b = uint32_t(prim.vertices.size() - 4);
    prim.triangles.push_back({b, b + 1, b + 2});
    prim.triangles.push_back({b, b + 2, b + 3});
    prim.triangles.push_back({b, b, b + 1});       // degenerate
  }
  MeshVertex top;
  top.position[1] = 3;
  prim.vertices.push_back(top);
  const uint32_t t = uint32_t(prim.vertices.size() - 1);
  prim.triangles.push_back({t, t, t});             // a point
  mesh.nodes[0].primitives.push_back(prim);
  const CompileResult r = compile_mesh(mesh);
  ASSERT_TRUE(r.ok) << r.error;
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  check_ids(s);
  EXPECT_EQ(s.bsp_piece_count, s.triangle_count);   // nothing to split
  EXPECT_LE(s.info->bsp_depth, 4u);
}

TEST(SceneBsp, EngineDepthOrder) {
  if (!scenetest::file_exists(scenetest::engine_path())) GTEST_SKIP();
  const CompileResult& r = scenetest::cached("engine");
  ASSERT_TRUE(r.ok) << r.error;
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  EXPECT_GT(check_depth_order(s, 4, 60, 3), 100u);
}

// A closed mesh stays closed after the BSP: every directed piece edge (by the positions the renderer
// sees) has its reverse in another piece of the same batch. Splits leave no T-junction cracks.
TEST(SceneBsp, PiecesOfClosedMeshesShareEveryEdge) {
  std::vector<CompileResult> owned;
  owned.push_back(build_tessellated_scene(6000));
  {
    // Two closed meshes through each other: a cube grid (split by the knot and vice versa).
    SceneMesh mesh = make_tessellated_scene(3000);
    SceneMesh boxes = scenetest::crossing_boxes_mesh();
    const uint32_t base = uint32_t(mesh.nodes.size());
    for (MeshNode& n : boxes.nodes) {
      for (MeshPrimitive& p : n.primitives) p.material = 0;
      n.parent = n.parent == kNone ? kNone : n.parent + base;
      mesh.nodes.push_back(n);
    }
    owned.push_back(compile_mesh(mesh));
  }
  std::vector<const CompileResult*> results = {&owned[0], &owned[1], &scenetest::cached("tessellated")};
  for (const CompileResult* r : results) {
    ASSERT_TRUE(r->ok) << r->error;
    Scene s;
    ASSERT_TRUE(scenetest::read(r->blob, &s).ok());
    EXPECT_GT(s.bsp_piece_count, s.triangle_count);
    std::map<std::array<int32_t, 7>, int> edges;
    for (uint32_t p = 0; p < s.bsp_piece_count; ++p) {
      const uint32_t batch = ml::triangle_at(s, ml::bsp_piece(s, p).triangle).batch;
      Vec3i w[3];
      for (int k = 0; k < 3; ++k) w[k] = vertex_world(s, batch, ml::bsp_piece(s, p).v[k]);
      for (int k = 0; k < 3; ++k) {
        const Vec3i& a = w[k];
        const Vec3i& b = w[(k + 1) % 3];
        if (a.x == b.x && a.y == b.y && a.z == b.z) continue;
        ++edges[{int32_t(batch), a.x, a.y, a.z, b.x, b.y, b.z}];
      }
    }
    size_t open = 0;
    for (const auto& [e, count] : edges) {
      const auto reverse = edges.find({e[0], e[4], e[5], e[6], e[1], e[2], e[3]});
      if (reverse == edges.end() || reverse->second != count) ++open;
    }
    EXPECT_EQ(open, 0u) << open << " of " << edges.size() << " directed piece edges have no matching reverse edge";
  }
}

// build_bsp keeps the tree with the fewest pieces of its three scorings, each a valid tree (every
// triangle's pieces, depth order): a bumpy closed sphere takes the second scoring (half the split
// weight, four times the candidates), the bundled scene the third (twice the weight, twice the
// candidates), blob for blob the tree that scoring alone builds; so does a scene large enough for
// the threaded builds.
TEST(SceneBsp, TheTreeWithTheFewestPiecesIsKept) {
  CompileOptions first, second, third;
  first.bsp_more_trees = second.bsp_more_trees = third.bsp_more_trees = false;
  second.bsp_split_weight = first.bsp_split_weight / 2;
  second.bsp_triangle_candidates = first.bsp_triangle_candidates * 4;
  third.bsp_split_weight = first.bsp_split_weight * 2;
  third.bsp_triangle_candidates = first.bsp_triangle_candidates * 2;
  const auto same_blob = [](const CompileResult& a, const CompileResult& b) {
    return a.blob.size == b.blob.size && memcmp(a.blob.data(), b.blob.data(), a.blob.size) == 0;
  };
  const auto check_kept = [&](const CompileResult& kept, const CompileResult* alone, size_t winner) {
    ASSERT_TRUE(kept.ok && alone[0].ok && alone[1].ok && alone[2].ok);
    for (size_t i = 0; i < 3; ++i) {
      if (i == winner) continue;
      EXPECT_LT(kept.report.bsp_pieces, alone[i].report.bsp_pieces) << "scoring " << i;
    }
    EXPECT_TRUE(same_blob(kept, alone[winner]));
    Scene s;
    ASSERT_TRUE(scenetest::read(kept.blob, &s).ok());
    check_ids(s);
    check_pieces(s);
    EXPECT_GT(check_depth_order(s, 8, 150, 3), 100u);
  };
  const SceneMesh sphere = bumpy_sphere(16, 0.3, 7);  // pieces 1,334 / 1,156 / 1,290
  const CompileResult sphere_alone[3] = {compile_mesh(sphere, first), compile_mesh(sphere, second),
                                         compile_mesh(sphere, third)};
  check_kept(compile_mesh(sphere), sphere_alone, 1);
  const CompileResult bundled_alone[3] = {build_default_scene(first), build_default_scene(second),
                                          build_default_scene(third)};
  check_kept(scenetest::cached("default"), bundled_alone, 2);  // 4,017 / 4,069 / 3,914
  // From 4,096 triangles the second scoring's tree is built on a thread of its own: the same choice.
  const CompileResult tessellated_alone[3] = {build_tessellated_scene(5000, first),
                                              build_tessellated_scene(5000, second),
                                              build_tessellated_scene(5000, third)};
  size_t fewest = 0;
  for (size_t i = 1; i < 3; ++i)
    if (tessellated_alone[i].report.bsp_pieces < tessellated_alone[fewest].report.bsp_pieces) fewest = i;
  const CompileResult tessellated = build_tessellated_scene(5000);
  ASSERT_GE(tessellated.report.triangles, 4096u);
  check_kept(tessellated, tessellated_alone, fewest);
}

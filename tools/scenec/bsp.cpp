// The BSP builder (issue #3 item 5): a BSP tree over every triangle of the scene in world space, for
// front-to-back traversal by the renderers.
//
// Geometry is what the renderer will see: the integer world positions of the quantized vertices
// (scene/reader.cpp vertex_world). Pieces are classified against a node's plane exactly in int64:
//   s = dot(normal_q30, p) - d      (world units * 2^30)
// A vertex with |s| <= eps is "in the plane", eps = 2 world units plus the quantization step of the
// piece's batch (quantized split points may sit that far off their triangle's plane). A piece with
// every vertex in the band stays in the node; one with vertices on both sides beyond the band is split
// (Sutherland-Hodgman against the band, vertices in the band go to both halves; the halves are
// fan-triangulated); the others go wholly to the front or back child.
//
// Plane choice per node: candidates are the planes of the original triangles of a few sampled pieces
// (a piece's plane is its original triangle's plane, so all pieces of a chosen triangle leave the
// subtree together) plus, for larger sets, three axis-aligned planes through the median of sampled
// piece centroids (they keep convex, finely tessellated objects from turning into long chains).
// Each candidate is scored on a sample of the pieces: splits * split_weight + |front - back|.
// An axis plane is only taken when both sides keep at most 7/8 of the pieces, and at most
// kMaxAxisNodesOnPath of them lie on any root-to-leaf path, so the build always terminates.
//
// Cells (Greene's octree of BSP trees, where it is cheap): a set of more than bsp_cell_pieces pieces
// is first offered an axis-aligned plane across the longest side of its pieces' box, near the middle,
// and takes it when it cuts at most bsp_cell_split_permille of the sampled pieces (and leaves each side
// at most 7/8 of them). Such planes make compact subtrees whose boxes the tiler's subtree test can cull
// whole; cutting every set at its median, as Greene does, split too many of 2CylinderEngine's long
// triangles (split ratio 2.69 -> 3.10 .. 6.24 for cells of 1024 .. 32 pieces, frames 1 % .. 45 % slower).
//
// Split points are computed on exact (unquantized) positions, so quantization error never accumulates
// over repeated splits, and snapped to the quantized point nearest the split edge's line. A last pass
// (conform) removes T-junctions within each batch: neighbouring pieces share every edge exactly.
// Nodes are emitted breadth-first, each node's pieces contiguous (the layout read_scene checks).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <thread>
#include <unordered_map>

#include "scene/scene.h"
#include "tools/scenec/internal.h"

namespace ml {
namespace scenec_detail {
namespace {

constexpr uint32_t kMaxAxisNodesOnPath = 40;
// Largest set tested for one leaf of mutually hidden pieces (the test is quadratic).
constexpr size_t kMaxHiddenLeafPieces = 2048;
// Planes as the blob stores them: normal Q1.14 (a Q1.30 value times 2^16), offset Q12 (2^18 in Q1.30).
constexpr int32_t kNormalToUnit = 1 << (kUnitBits - kNormalBits);
constexpr int64_t kPlaneOffsetStep = int64_t(1) << 18;
int64_t ceil_to_step(int64_t d) { return div_floor(d + kPlaneOffsetStep - 1, kPlaneOffsetStep) * kPlaneOffsetStep; }

struct Piece {
  uint32_t v[3];
  uint32_t tri;
};

struct Plane {
  int32_t n[3];
  int64_t d;
};

struct TmpNode {
  Plane plane{};
  uint32_t front = kNone;
  uint32_t back = kNone;
  uint32_t depth = 1;
  std::vector<Piece> on;
};

struct Task {
  std::vector<Piece> pieces;
  uint32_t parent = kNone;
  bool is_front = false;
  uint32_t depth = 1;
  uint32_t axis_nodes = 0;
};

class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  size_t below(size_t n) { return size_t(next() % n); }

 private:
  uint64_t state_;
};

enum class Side { On, Front, Back, Split };

class Builder {
 public:
  Builder(const std::vector<Material>& materials, const std::vector<Batch>& batches,
          const std::vector<Triangle>& triangles, std::vector<Vertex>* vertices, const CompileOptions& options)
      : batches_(batches), triangles_(triangles), vertices_(*vertices), options_(options),
        rng_(options.bsp_seed) {
    single_sided_.resize(batches_.size());
    for (size_t i = 0; i < batches_.size(); ++i)
      single_sided_[i] = batches_[i].material < materials.size() && materials[batches_[i].material].double_sided == 0;
    world_.resize(vertices_.size(), Vec3i{0, 0, 0});
    exact_.resize(vertices_.size());
    for (const Batch& b : batches_) {
      for (uint32_t i = 0; i < b.vertex_count; ++i) {
        const Vec3i w = dequantize(b, vertices_[b.first_vertex + i].position);
        world_[b.first_vertex + i] = w;
        exact_[b.first_vertex + i] = {double(w.x), double(w.y), double(w.z)};
      }
    }
    // Vertices of one batch at one quantized position are one point for the T-junction bookkeeping.
    canon_.resize(vertices_.size());
    {
      std::unordered_map<uint64_t, uint32_t> seen;
      for (uint32_t bi = 0; bi < batches_.size(); ++bi) {
        seen.clear();
        const Batch& b = batches_[bi];
        for (uint32_t i = b.first_vertex; i < b.first_vertex + b.vertex_count; ++i) {
          const int16_t* q = vertices_[i].position;
          const uint64_t key = (uint64_t(uint16_t(q[0])) << 32) | (uint64_t(uint16_t(q[1])) << 16) | uint16_t(q[2]);
          canon_[i] = seen.emplace(key, i).first->second;
        }
      }
    }
    // Mesh adjacency of the original vertices (by canonical id), for mesh-line planes.
    neighbours_.resize(vertices_.size());
    for (const Triangle& t : triangles_) {
      for (int e = 0; e < 3; ++e) {
        const uint32_t a = canon_[t.v[e]], b = canon_[t.v[(e + 1) % 3]];
        if (a == b) continue;
        for (auto [x, y] : {std::pair<uint32_t, uint32_t>{a, b}, {b, a}}) {
          std::vector<uint32_t>& list = neighbours_[x];
          if (std::find(list.begin(), list.end(), y) == list.end()) list.push_back(y);
        }
      }
    }
    lines_of_.resize(vertices_.size());
    vertex_batch_.assign(vertices_.size(), kNone);
    for (uint32_t bi = 0; bi < batches_.size(); ++bi) {
      for (uint32_t i = 0; i < batches_[bi].vertex_count; ++i) vertex_batch_[batches_[bi].first_vertex + i] = bi;
    }
    eps_.resize(batches_.size());
    for (size_t i = 0; i < batches_.size(); ++i) {
      const int32_t s = std::max(batches_[i].scale[0], std::max(batches_[i].scale[1], batches_[i].scale[2]));
      eps_[i] = int64_t(std::llround((2.0 + s / 65536.0) * double(int64_t(1) << kUnitBits)));
      eps_max_ = std::max(eps_max_, eps_[i]);
    }
  }

  bool run(BspResult* out, std::string* error) {
    if (triangles_.empty()) return true;
    const size_t piece_limit = triangles_.size() * 16 + (size_t(1) << 20);
    size_t piece_total = 0;
    std::vector<Task> stack;
    {
      Task root;
      root.pieces.resize(triangles_.size());
      for (uint32_t t = 0; t < triangles_.size(); ++t) {
        root.pieces[t] = Piece{{triangles_[t].v[0], triangles_[t].v[1], triangles_[t].v[2]}, t};
      }
      stack.push_back(std::move(root));
    }
    uint32_t max_depth = 0;
    while (!stack.empty()) {
      Task task = std::move(stack.back());
      stack.pop_back();
      if (task.depth > kMaxBspDepth) {
        *error = "bsp deeper than " + std::to_string(kMaxBspDepth) + " levels";
        return false;
      }
      const uint32_t index = uint32_t(nodes_.size());
      nodes_.emplace_back();
      nodes_[index].depth = task.depth;
      max_depth = std::max(max_depth, task.depth);
      if (task.parent != kNone) {
        (task.is_front ? nodes_[task.parent].front : nodes_[task.parent].back) = index;
      }
      bool axis = false, cut = false;
      uint32_t plane_triangle = kNone;
      Task front, back;
      std::vector<Piece> on;
      Plane plane{};
      if (task.pieces.size() > size_t(std::max(1, options_.bsp_cell_pieces)) && cell_plane(task.pieces, &plane)) {
        // Not counted in axis_nodes: each side keeps at most 7/8 of the pieces, so cells end.
        partition(plane, task.pieces, &on, &front.pieces, &back.pieces);
      } else if (mutually_hidden(task.pieces, &plane)) {
        // No piece can hide another that is drawn: one leaf holds them all, in any order.
        on = std::move(task.pieces);
      } else if ((plane = choose_plane(task.pieces, task.axis_nodes < kMaxAxisNodesOnPath, &axis, &cut,
                                       &plane_triangle)),
                 !axis && !cut && plane_triangle == kNone) {
        // Only degenerate pieces left (no piece has a plane): they draw nothing and no plane separates
        // them, so they all stay in this leaf.
        on = std::move(task.pieces);
      } else {
        partition(plane, task.pieces, &on, &front.pieces, &back.pieces);
      }
      if (on.empty() && plane_triangle != kNone && (front.pieces.empty() || back.pieces.empty())) {
        // No progress: the chosen triangle's pieces drifted out of the band (quantized split points).
        // They are within a few quantization steps of its plane, so they stay in this node.
        for (std::vector<Piece>* side : {&front.pieces, &back.pieces}) {
          auto moved = std::stable_partition(side->begin(), side->end(),
                                             [&](const Piece& p) { return p.tri != plane_triangle; });
          on.insert(on.end(), moved, side->end());
          side->erase(moved, side->end());
        }
      }
      task.pieces.clear();
      task.pieces.shrink_to_fit();
      piece_total += on.size();
      if (piece_total + front.pieces.size() + back.pieces.size() > piece_limit) {
        *error = "bsp split too many triangles";
        return false;
      }
      nodes_[index].plane = plane;
      nodes_[index].on = std::move(on);
      for (Task* child : {&back, &front}) {
        if (child->pieces.empty()) continue;
        child->parent = index;
        child->is_front = child == &front;
        child->depth = task.depth + 1;
        child->axis_nodes = task.axis_nodes + (axis ? 1 : 0);
        stack.push_back(std::move(*child));
      }
    }
    conform();
    emit_breadth_first(out);
    out->depth = max_depth;
    out->split_vertices = split_vertices_;
    return true;
  }

 private:
  static int64_t eval(const Plane& p, const Vec3i& w) {
    return int64_t(p.n[0]) * w.x + int64_t(p.n[1]) * w.y + int64_t(p.n[2]) * w.z - p.d;
  }
  int64_t eval(const Plane& p, uint32_t v) const { return eval(p, world_[v]); }

  int64_t eps_of(const Piece& piece) const { return eps_[triangles_[piece.tri].batch]; }

  // Where a piece with vertices a, b, c (and in-plane band eps) lies: bit 0, a vertex beyond the band
  // in front; bit 1, one behind (both: split; none: on the plane). s gets the vertices' values, unless
  // it is null.
  static int sides_of(const Plane& p, const Vec3i& a, const Vec3i& b, const Vec3i& c, int64_t eps, int64_t* s) {
    const int64_t va = eval(p, a), vb = eval(p, b), vc = eval(p, c);
    if (s) s[0] = va, s[1] = vb, s[2] = vc;
    const bool front = va > eps || vb > eps || vc > eps, back = va < -eps || vb < -eps || vc < -eps;
    return int(front) | int(back) << 1;
  }
  Side classify(const Plane& p, const Piece& piece, int64_t s[3]) const {
    static constexpr Side kBySides[4] = {Side::On, Side::Front, Side::Back, Side::Split};
    return kBySides[sides_of(p, world_[piece.v[0]], world_[piece.v[1]], world_[piece.v[2]], eps_of(piece), s)];
  }

  // The plane of triangle t's original vertices; false when t is degenerate.
  bool triangle_plane(uint32_t t, Plane* out) const {
    const Triangle& tri = triangles_[t];
    const Vec3i& a = world_[tri.v[0]];
    const Vec3i& b = world_[tri.v[1]];
    const Vec3i& c = world_[tri.v[2]];
    const int64_t ux = int64_t(b.x) - a.x, uy = int64_t(b.y) - a.y, uz = int64_t(b.z) - a.z;
    const int64_t vx = int64_t(c.x) - a.x, vy = int64_t(c.y) - a.y, vz = int64_t(c.z) - a.z;
    const int64_t cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
    if (cx == 0 && cy == 0 && cz == 0) return false;
    const double len = std::sqrt(double(cx) * double(cx) + double(cy) * double(cy) + double(cz) * double(cz));
    // The blob stores planes as Q1.14 normals and offsets in 1/4096 world unit (blob_format.h):
    // classify against exactly that plane.
    const double one = double(kNormalOne);
    for (int k = 0; k < 3; ++k) out->n[k] = int32_t(std::llround(double(k == 0 ? cx : (k == 1 ? cy : cz)) / len * one)) * kNormalToUnit;
    const Vec3i n{out->n[0], out->n[1], out->n[2]};
    out->d = div_round(div_round(dot64(n, a) + dot64(n, b) + dot64(n, c), 3), kPlaneOffsetStep) * kPlaneOffsetStep;
    return true;
  }

  Plane choose_plane(const std::vector<Piece>& pieces, bool allow_axis, bool* chose_axis, bool* chose_cut,
                     uint32_t* triangle) {
    *chose_axis = false;
    *chose_cut = false;
    *triangle = kNone;
    const size_t n = pieces.size();
    // Scoring sample.
    draw_sample(pieces);
    // Candidates: planes of sampled pieces' triangles.
    std::vector<Plane> tri_cands;
    std::vector<uint32_t> tri_ids;
    // More candidates where a choice matters most (large sets near the root).
    const size_t k = size_t(std::max(1, options_.bsp_triangle_candidates)) + std::min<size_t>(n / 512, 48);
    if (n <= k) {
      for (const Piece& p : pieces) add_triangle_candidate(p.tri, &tri_cands, &tri_ids);
    } else {
      for (size_t i = 0; i < k; ++i) add_triangle_candidate(pieces[rng_.below(n)].tri, &tri_cands, &tri_ids);
      if (tri_cands.empty()) {
        for (const Piece& p : pieces) {
          if (add_triangle_candidate(p.tri, &tri_cands, &tri_ids)) break;
        }
      }
    }
    Plane best_tri{};
    uint32_t best_tri_id = kNone;
    int64_t best_tri_score = INT64_MAX;
    for (size_t i = 0; i < tri_cands.size(); ++i) {
      if (repeats_earlier(tri_cands, i)) continue;  // (the same score: the earlier one stays the best)
      const int64_t score = score_plane(tri_cands[i], pieces, best_tri_score);
      if (score < best_tri_score) {
        best_tri_score = score;
        best_tri = tri_cands[i];
        best_tri_id = tri_ids[i];
      }
    }
    // Mesh-line planes: a plane through a triangle edge and the straightest continuation of that edge
    // in the mesh (a meridian or a parallel of a tessellated sphere or torus) often splits nothing
    // where every triangle plane splits many.
    {
      Plane best_cut{};
      int64_t best_cut_score = INT64_MAX;
      std::vector<Plane> cuts;
      for (uint32_t t : tri_ids) add_line_planes(t, &cuts);
      for (size_t i = 0; i < cuts.size(); ++i) {
        if (repeats_earlier(cuts, i)) continue;
        const Plane& c = cuts[i];
        // (A cut is taken only below the best triangle plane's score.)
        const int64_t score = score_plane(c, pieces, std::min(best_cut_score, best_tri_score));
        if (score < best_cut_score) {
          best_cut_score = score;
          best_cut = c;
        }
      }
      if (best_cut_score < best_tri_score && cut_makes_progress(best_cut, pieces)) {
        best_tri_score = best_cut_score;
        best_tri = best_cut;
        best_tri_id = kNone;
        *chose_cut = true;
      }
    }
    if (allow_axis && n >= size_t(std::max(2, options_.bsp_axis_min_pieces))) {
      Plane best_axis{};
      int64_t best_axis_score = INT64_MAX;
      // Positions just past the far end of sampled pieces (a plane there splits none of them), at
      // quantiles around the middle, on each axis.
      std::vector<int32_t> ends(sampled_.size());
      const int positions = std::max(1, options_.bsp_axis_positions);
      for (int axis = 0; axis < 3; ++axis) {
        for (size_t i = 0; i < sampled_.size(); ++i) ends[i] = sampled_[i].far_end(axis);
        std::sort(ends.begin(), ends.end());
        for (int q = 0; q < positions; ++q) {
          // quantiles spread over [0.25, 0.75]
          const double f = positions == 1 ? 0.5 : 0.25 + 0.5 * q / (positions - 1);
          const Plane c = axis_plane(axis, ends[std::min(ends.size() - 1, size_t(f * double(ends.size() - 1) + 0.5))]);
          // (An axis plane is taken only below the best other plane's score.)
          const int64_t score = score_plane(c, pieces, std::min(best_axis_score, best_tri_score));
          if (score < best_axis_score) {
            best_axis_score = score;
            best_axis = c;
          }
        }
      }
      if (best_axis_score < best_tri_score && axis_makes_progress(best_axis, pieces)) {
        *chose_axis = true;
        *chose_cut = false;
        return best_axis;
      }
    }
    if (*chose_cut) return best_tri;
    if (best_tri_score != INT64_MAX) {
      *triangle = best_tri_id;
      return best_tri;
    }
    // Only degenerate triangles left: they draw nothing, so any plane will do (run() keeps them all in
    // the node).
    Plane any{};
    any.n[0] = kUnitOne;
    any.d = int64_t(world_[pieces[0].v[0]].x) * kUnitOne;
    return any;
  }

  // A cell's plane (see the top of the file): the longest side of the pieces' box first, then the
  // others; on each, positions just past the far end of sampled pieces between the 0.3 and 0.7
  // quantiles, the best by score_plane. False when no axis has one that cuts few enough pieces.
  bool cell_plane(const std::vector<Piece>& pieces, Plane* out) {
    int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    for (const Piece& p : pieces)
      for (uint32_t v : p.v)
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], coord(world_[v], a));
          hi[a] = std::max(hi[a], coord(world_[v], a));
        }
    draw_sample(pieces);
    int order[3] = {0, 1, 2};
    std::stable_sort(order, order + 3, [&](int a, int b) { return int64_t(hi[a]) - lo[a] > int64_t(hi[b]) - lo[b]; });
    std::vector<int32_t> ends(sampled_.size());
    for (int axis : order) {
      for (size_t i = 0; i < sampled_.size(); ++i) ends[i] = sampled_[i].far_end(axis);
      std::sort(ends.begin(), ends.end());
      Plane best{};
      int64_t best_score = INT64_MAX;
      constexpr int kPositions = 9;
      for (int q = 0; q < kPositions; ++q) {
        const double f = 0.3 + 0.4 * q / (kPositions - 1);
        const Plane c = axis_plane(axis, ends[std::min(ends.size() - 1, size_t(f * double(ends.size() - 1) + 0.5))]);
        const int64_t score = score_plane(c, pieces, best_score);
        if (score < best_score) {
          best_score = score;
          best = c;
        }
      }
      size_t splits = 0;
      for (const SampledPiece& piece : sampled_) splits += piece.sides(best) == 3;
      if (splits * 1000 <= size_t(std::max(0, options_.bsp_cell_split_permille)) * sampled_.size() &&
          axis_makes_progress(best, pieces)) {
        *out = best;
        return true;
      }
    }
    return false;
  }

  // The scoring sample: every piece of a small set, else bsp_sample_size drawn at random; each piece's
  // vertices and band copied out (score_plane reads them for every candidate plane).
  void draw_sample(const std::vector<Piece>& pieces) {
    const size_t n = pieces.size();
    const size_t sample_size = std::min(n, size_t(std::max(16, options_.bsp_sample_size)));
    sampled_.resize(sample_size);
    for (size_t i = 0; i < sample_size; ++i) {
      const Piece& piece = pieces[sample_size == n ? i : rng_.below(n)];
      for (int k = 0; k < 3; ++k) sampled_[i].p[k] = world_[piece.v[k]];
      sampled_[i].eps = eps_of(piece);
    }
  }

  // The axis plane just past coordinate `at` (beyond the in-plane band of a vertex there).
  Plane axis_plane(int axis, int32_t at) const {
    Plane c{};
    c.n[axis] = kUnitOne;
    c.d = ceil_to_step((int64_t(at) + 3) * int64_t(kUnitOne) + eps_max_);
    return c;
  }

  static int32_t coord(const Vec3i& v, int axis) { return axis == 0 ? v.x : (axis == 1 ? v.y : v.z); }

  // Whether planes[i] is one of the planes before it: a candidate drawn twice, or coplanar triangles.
  static bool repeats_earlier(const std::vector<Plane>& planes, size_t i) {
    const Plane& p = planes[i];
    for (size_t j = 0; j < i; ++j)
      if (planes[j].d == p.d && planes[j].n[0] == p.n[0] && planes[j].n[1] == p.n[1] && planes[j].n[2] == p.n[2])
        return true;
    return false;
  }

  bool add_triangle_candidate(uint32_t tri, std::vector<Plane>* out, std::vector<uint32_t>* ids) const {
    if (std::find(ids->begin(), ids->end(), tri) != ids->end()) return true;  // drawn again: nothing new
    Plane p;
    if (!triangle_plane(tri, &p)) return false;
    out->push_back(p);
    ids->push_back(tri);
    return true;
  }

  // The plane's score on the sample (the lower the better), or INT64_MAX as soon as it cannot be below
  // `below` (the best score so far: a plane that cannot beat it is not taken, so the choice is the
  // same as with every score complete). The score only grows with the sample's splits, and the
  // imbalance can shrink by at most the pieces still to classify: that bound is tested every 32 pieces
  // (compiling 2CylinderEngine 7.9 s -> 5.8 s; testing it every 16 or 64 pieces: the same time).
  int64_t score_plane(const Plane& p, const std::vector<Piece>& pieces, int64_t below = INT64_MAX) const {
    int64_t front = 0, back = 0, split = 0;
    const int64_t balance = pieces.size() <= size_t(options_.bsp_chain_pieces) ? 0 : options_.bsp_balance_weight;
    const int64_t split_cost = int64_t(options_.bsp_split_weight) * 4;
    if (balance < 0 || split_cost < 0) below = INT64_MAX;  // (the bound holds for weights >= 0 only)
    const auto score = [&](int64_t left) {
      const int64_t imbalance = front > back ? front - back : back - front;
      return split * split_cost + std::max<int64_t>(0, imbalance - left) * balance;
    };
    const size_t n = sampled_.size();
    for (size_t at = 0; at < n;) {
      for (const size_t end = std::min(n, at + 32); at < end; ++at) {
        const int sides = sampled_[at].sides(p);  // (counted without branches)
        front += sides == 1;
        back += sides == 2;
        split += sides == 3;
      }
      if (at < n && score(int64_t(n - at)) >= below) return INT64_MAX;
    }
    return score(0);
  }

  // True when the pieces can share one leaf: every piece is single-sided and lies behind (or within
  // the in-plane band of) every other piece's triangle plane, like the faces of a convex solid. Of
  // such a set, the pieces drawn (facing the eye) never overlap on screen: a piece B faces the eye, so
  // the eye is in front of B's plane and the sight line to B stays in front of it, where no other
  // piece reaches (but for the band). *plane gets one piece's plane (a leaf's plane orders nothing).
  bool mutually_hidden(const std::vector<Piece>& pieces, Plane* plane) const {
    if (pieces.size() < 2 || pieces.size() > kMaxHiddenLeafPieces) return false;
    std::vector<Plane> planes(pieces.size());
    std::vector<bool> has_plane(pieces.size());
    for (size_t i = 0; i < pieces.size(); ++i) {
      if (!single_sided_[triangles_[pieces[i].tri].batch]) return false;
      has_plane[i] = triangle_plane(pieces[i].tri, &planes[i]);
    }
    bool any = false;
    for (size_t b = 0; b < pieces.size(); ++b) {
      if (!has_plane[b]) continue;
      if (!any) *plane = planes[b];
      any = true;
      for (size_t a = 0; a < pieces.size(); ++a) {
        if (a == b) continue;
        const int64_t eps = std::max(eps_of(pieces[a]), eps_of(pieces[b]));
        for (uint32_t v : pieces[a].v)
          if (eval(planes[b], v) > eps) return false;
      }
    }
    return any;
  }

  // Planes through each edge a-b of triangle t and the neighbour c of b that continues a-b most
  // straightly (within about 30 degrees, not collinear).
  void add_line_planes(uint32_t t, std::vector<Plane>* out) const {
    const Triangle& tri = triangles_[t];
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = canon_[tri.v[e]], b = canon_[tri.v[(e + 1) % 3]];
      const std::array<double, 3>& pa = exact_[a];
      const std::array<double, 3>& pb = exact_[b];
      const double ab[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
      const double lab = std::sqrt(ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]);
      if (!(lab > 0)) continue;
      uint32_t best = kNone;
      double best_cos = 0.85;
      for (uint32_t c : neighbours_[b]) {
        if (c == a) continue;
        const std::array<double, 3>& pc = exact_[c];
        const double bc[3] = {pc[0] - pb[0], pc[1] - pb[1], pc[2] - pb[2]};
        const double lbc = std::sqrt(bc[0] * bc[0] + bc[1] * bc[1] + bc[2] * bc[2]);
        if (!(lbc > 0)) continue;
        const double cosine = (ab[0] * bc[0] + ab[1] * bc[1] + ab[2] * bc[2]) / (lab * lbc);
        if (cosine > best_cos && cosine < 0.99999) {
          best_cos = cosine;
          best = c;
        }
      }
      if (best == kNone) continue;
      const std::array<double, 3>& pc = exact_[best];
      const double bc[3] = {pc[0] - pb[0], pc[1] - pb[1], pc[2] - pb[2]};
      const double n[3] = {ab[1] * bc[2] - ab[2] * bc[1], ab[2] * bc[0] - ab[0] * bc[2], ab[0] * bc[1] - ab[1] * bc[0]};
      const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (!(len > 0)) continue;
      Plane p{};
      for (int k = 0; k < 3; ++k) p.n[k] = int32_t(std::llround(n[k] / len * double(kNormalOne))) * kNormalToUnit;
      const Vec3i nv{p.n[0], p.n[1], p.n[2]};
      const int64_t sum = dot64(nv, world_[a]) + dot64(nv, world_[b]) + dot64(nv, world_[best]);
      p.d = div_round(div_round(sum, 3), kPlaneOffsetStep) * kPlaneOffsetStep;
      out->push_back(p);
    }
  }

  // A mesh-line plane is taken only when each side keeps fewer pieces than the node (so the build
  // terminates).
  bool cut_makes_progress(const Plane& p, const std::vector<Piece>& pieces) const {
    size_t front, back;
    count_sides(p, pieces, &front, &back);
    return front < pieces.size() && back < pieces.size();
  }

  // Pieces a plane would send to each side (a split piece goes to both, pieces on it to neither).
  void count_sides(const Plane& p, const std::vector<Piece>& pieces, size_t* front, size_t* back) const {
    *front = *back = 0;
    int64_t s[3];
    for (const Piece& piece : pieces) {
      const Side side = classify(p, piece, s);
      *front += side == Side::Front || side == Side::Split;
      *back += side == Side::Back || side == Side::Split;
    }
  }

  bool axis_makes_progress(const Plane& p, const std::vector<Piece>& pieces) const {
    size_t front, back;
    count_sides(p, pieces, &front, &back);
    const size_t limit = pieces.size() * 7 / 8;
    return front <= limit && back <= limit;
  }

  void partition(const Plane& p, const std::vector<Piece>& in, std::vector<Piece>* on,
                 std::vector<Piece>* front, std::vector<Piece>* back) {
    split_cache_.clear();
    int64_t s[3];
    for (const Piece& piece : in) {
      switch (classify(p, piece, s)) {
        case Side::On: on->push_back(piece); break;
        case Side::Front: front->push_back(piece); break;
        case Side::Back: back->push_back(piece); break;
        case Side::Split: split(p, piece, s, front, back); break;
      }
    }
  }

  void split(const Plane& plane, const Piece& piece, const int64_t s[3], std::vector<Piece>* front, std::vector<Piece>* back) {
    const int64_t eps = eps_of(piece);
    const uint32_t batch = triangles_[piece.tri].batch;
    int sign[3];
    for (int k = 0; k < 3; ++k) sign[k] = s[k] > eps ? 1 : (s[k] < -eps ? -1 : 0);
    uint32_t fp[4], bp[4];
    int nf = 0, nb = 0;
    for (int k = 0; k < 3; ++k) {
      const int k1 = (k + 1) % 3;
      if (sign[k] >= 0) fp[nf++] = piece.v[k];
      if (sign[k] <= 0) bp[nb++] = piece.v[k];
      if (sign[k] * sign[k1] < 0) {
        const uint32_t m = split_vertex(piece.v[k], piece.v[k1], plane, batch);
        fp[nf++] = m;
        bp[nb++] = m;
      }
    }
    for (int j = 1; j + 1 < nf; ++j) front->push_back(Piece{{fp[0], fp[j], fp[j + 1]}, piece.tri});
    for (int j = 1; j + 1 < nb; ++j) back->push_back(Piece{{bp[0], bp[j], bp[j + 1]}, piece.tri});
  }

  // The point where edge a-b crosses the plane (s values sa, sb of opposite signs), with interpolated
  // attributes, quantized with `batch`. Shared by the two pieces (and neighbours) using that edge.
  // The crossing is computed on the vertices' exact (unquantized) positions, which lie exactly in
  // their original triangle's plane, so quantization error does not accumulate over repeated splits.
  uint32_t split_vertex(uint32_t a, uint32_t b, const Plane& plane, uint32_t batch) {
    if (a > b) std::swap(a, b);
    const uint64_t key = (uint64_t(a) << 32) | b;
    const auto found = split_cache_.find(key);
    if (found != split_cache_.end()) return found->second;
    const std::array<double, 3> pa = exact_[a], pb = exact_[b];
    auto side = [&](const std::array<double, 3>& q) {
      return double(plane.n[0]) * q[0] + double(plane.n[1]) * q[1] + double(plane.n[2]) * q[2] - double(plane.d);
    };
    const double sa = side(pa), sb = side(pb);
    double t = sa != sb ? sa / (sa - sb) : 0.5;
    if (!(t >= 0)) t = 0;
    if (t > 1) t = 1;
    const Vertex& va = vertices_[a];
    const Vertex& vb = vertices_[b];
    const Batch& bt = batches_[batch];
    Vertex v{};
    double normal[3];
    std::array<double, 3> exact;
    for (int k = 0; k < 3; ++k) {
      exact[size_t(k)] = pa[size_t(k)] + t * (pb[size_t(k)] - pa[size_t(k)]);
      v.position[k] = quantize_axis(bt, k, exact[size_t(k)]);
      normal[k] = va.normal[k] + t * (double(vb.normal[k]) - va.normal[k]);
    }
    snap_to_edge(bt, pa, pb, exact, v.position);
    quantize_normal(normal, v.normal);
    for (int k = 0; k < 2; ++k) {
      const double uv = va.uv[k] + t * (double(vb.uv[k]) - va.uv[k]);
      v.uv[k] = int32_t(std::llround(std::min(std::max(uv, -2147483648.0), 2147483647.0)));
    }
    const uint32_t index = uint32_t(vertices_.size());
    vertices_.push_back(v);
    world_.push_back(dequantize(bt, v.position));
    exact_.push_back(exact);
    split_cache_.emplace(key, index);
    canon_.push_back(index);
    vertex_batch_.push_back(batch);
    lines_of_.emplace_back();
    const uint32_t line = line_through(a, b);
    lines_of_[index].push_back(line);
    line_points_[line].push_back(index);
    ++split_vertices_;
    return index;
  }

  // Among the quantized points around `exact` (the nearest one per axis, +-1 step), the one nearest the
  // line through pa and pb, then nearest `exact`. The split edge lies along an edge of the original
  // triangle, and a neighbour that shares that edge without being split keeps it straight: the closer
  // the split point stays to the line, the thinner the sliver (gap or overlap) at that T-junction.
  static void snap_to_edge(const Batch& bt, const std::array<double, 3>& pa, const std::array<double, 3>& pb,
                           const std::array<double, 3>& exact, int16_t q[3]) {
    const double dir[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
    const double len2 = dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2];
    if (!(len2 > 0)) return;
    int16_t best[3] = {q[0], q[1], q[2]};
    double best_cost = -1;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const int d[3] = {dx, dy, dz};
          int16_t c[3];
          bool ok = true;
          for (int k = 0; k < 3; ++k) {
            const int v = q[k] + d[k];
            ok &= v >= -32768 && v <= 32767;
            c[k] = int16_t(v);
          }
          if (!ok) continue;
          const Vec3i w = dequantize(bt, c);
          const double r[3] = {w.x - pa[0], w.y - pa[1], w.z - pa[2]};
          const double e[3] = {w.x - exact[0], w.y - exact[1], w.z - exact[2]};
          const double along = (r[0] * dir[0] + r[1] * dir[1] + r[2] * dir[2]) / len2;
          double line2 = 0, point2 = 0;
          for (int k = 0; k < 3; ++k) {
            const double off = r[k] - along * dir[k];
            line2 += off * off;
            point2 += e[k] * e[k];
          }
          const double cost = 4 * std::sqrt(line2) + std::sqrt(point2);
          if (best_cost < 0 || cost < best_cost) {
            best_cost = cost;
            for (int k = 0; k < 3; ++k) best[k] = c[k];
          }
        }
      }
    }
    for (int k = 0; k < 3; ++k) q[k] = best[k];
  }

  uint32_t common_line(uint32_t a, uint32_t b) const {
    const std::vector<uint32_t>& la = lines_of_[canon_[a]];
    const std::vector<uint32_t>& lb = lines_of_[canon_[b]];
    for (uint32_t x : la) {
      for (uint32_t y : lb) {
        if (x == y) return x;
      }
    }
    return kNone;
  }

  uint32_t line_through(uint32_t a, uint32_t b) {
    uint32_t line = common_line(a, b);
    if (line != kNone) return line;
    line = uint32_t(line_geom_.size());
    const std::array<double, 3>& pa = exact_[a];
    const std::array<double, 3>& pb = exact_[b];
    line_geom_.push_back({pa[0], pa[1], pa[2], pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]});
    line_points_.emplace_back();
    lines_of_[canon_[a]].push_back(line);
    lines_of_[canon_[b]].push_back(line);
    return line;
  }

  bool same_world(uint32_t a, uint32_t b) const {
    return world_[a].x == world_[b].x && world_[a].y == world_[b].y && world_[a].z == world_[b].z;
  }

  // Where vertex v lies along the line, from its quantized position (as the renderer sees it): two
  // split points less than a quantization step apart (two nearby planes cut one edge) may quantize in
  // the other order than their exact positions, and the pieces must meet where they are drawn.
  double line_param(uint32_t line, uint32_t v) const {
    const std::array<double, 6>& g = line_geom_[line];
    const Vec3i& w = world_[v];
    const double p[3] = {double(w.x), double(w.y), double(w.z)};
    const double len2 = g[3] * g[3] + g[4] * g[4] + g[5] * g[5];
    return ((p[0] - g[0]) * g[3] + (p[1] - g[1]) * g[4] + (p[2] - g[2]) * g[5]) / len2;
  }

  // Split point m with the attributes of edge u-v (same position; the normal and uv of the piece's
  // own triangle, which may differ from the triangle that created m at a hard edge).
  uint32_t variant(uint32_t m, uint32_t u, uint32_t v, double t) {
    const Vertex& vu = vertices_[u];
    const Vertex& vv = vertices_[v];
    Vertex x = vertices_[m];
    double normal[3];
    for (int k = 0; k < 3; ++k) normal[k] = vu.normal[k] + t * (double(vv.normal[k]) - vu.normal[k]);
    quantize_normal(normal, x.normal);
    for (int k = 0; k < 2; ++k) {
      const double uv = vu.uv[k] + t * (double(vv.uv[k]) - vu.uv[k]);
      x.uv[k] = int32_t(std::llround(std::min(std::max(uv, -2147483648.0), 2147483647.0)));
    }
    const Vertex& vm = vertices_[m];
    if (std::memcmp(x.normal, vm.normal, sizeof(x.normal)) == 0 && std::memcmp(x.uv, vm.uv, sizeof(x.uv)) == 0) return m;
    const uint64_t key = (uint64_t(m) << 32) ^ (uint64_t(uint16_t(x.normal[0])) << 16) ^ uint16_t(x.normal[1]) ^
                         (uint64_t(uint16_t(x.normal[2])) << 24) ^ (uint64_t(uint32_t(x.uv[0])) * 0x9E3779B1u) ^
                         (uint64_t(uint32_t(x.uv[1])) * 0x85EBCA77u);
    const auto found = variant_cache_.find(key);
    if (found != variant_cache_.end()) {
      const Vertex& y = vertices_[found->second];
      if (std::memcmp(&y, &x, sizeof(Vertex)) == 0) return found->second;
    }
    const uint32_t index = uint32_t(vertices_.size());
    vertices_.push_back(x);
    world_.push_back(world_[m]);
    exact_.push_back(exact_[m]);
    canon_.push_back(canon_[m]);
    vertex_batch_.push_back(vertex_batch_[m]);
    lines_of_.emplace_back();
    variant_cache_[key] = index;
    ++split_vertices_;
    return index;
  }

  // Removes T-junctions: a piece edge that another piece's split put a point on gets that point as a
  // vertex too (the piece becomes a fan), so neighbouring pieces share every edge exactly and the
  // renderers' fill rule leaves no crack where quantized split points sit off the original edge.
  void conform() {
    std::vector<std::pair<double, uint32_t>> on_edge[3];
    std::vector<uint32_t> poly;
    for (TmpNode& node : nodes_) {
      std::vector<Piece> out;
      bool changed = false;
      for (const Piece& piece : node.on) {
        size_t extra = 0;
        for (int e = 0; e < 3; ++e) {
          on_edge[e].clear();
          const uint32_t u = piece.v[e], v = piece.v[(e + 1) % 3];
          const uint32_t line = common_line(u, v);
          if (line == kNone || line_points_[line].empty()) continue;
          const double pu = line_param(line, u), pv = line_param(line, v);
          const double lo = std::min(pu, pv), hi = std::max(pu, pv), margin = (hi - lo) * 1e-9;
          for (uint32_t m : line_points_[line]) {
            if (canon_[m] == canon_[u] || canon_[m] == canon_[v]) continue;
            if (batch_of_vertex(m) != triangles_[piece.tri].batch) continue;
            const double pm = line_param(line, m);
            if (pm <= lo + margin || pm >= hi - margin) continue;
            on_edge[e].push_back({(pm - pu) / (pv - pu), m});
          }
          std::sort(on_edge[e].begin(), on_edge[e].end());
          on_edge[e].erase(std::unique(on_edge[e].begin(), on_edge[e].end(),
                                       [&](const std::pair<double, uint32_t>& x, const std::pair<double, uint32_t>& y) {
                                         return canon_[x.second] == canon_[y.second] || same_world(x.second, y.second);
                                       }),
                           on_edge[e].end());
          extra += on_edge[e].size();
        }
        if (extra == 0) {
          out.push_back(piece);
          continue;
        }
        changed = true;
        // Fan from the corner opposite the edge with the most new points.
        int busiest = 0;
        for (int e = 1; e < 3; ++e) {
          if (on_edge[e].size() > on_edge[busiest].size()) busiest = e;
        }
        const int apex = (busiest + 2) % 3;
        poly.clear();
        for (int i = 0; i < 3; ++i) {
          const int e = (apex + i) % 3;
          const uint32_t u = piece.v[e], v = piece.v[(e + 1) % 3];
          poly.push_back(u);
          for (const auto& [t, m] : on_edge[e]) poly.push_back(variant(m, u, v, t));
        }
        for (size_t j = 1; j + 1 < poly.size(); ++j) out.push_back(Piece{{poly[0], poly[j], poly[j + 1]}, piece.tri});
      }
      if (changed) node.on = std::move(out);
    }
  }

  // The batch a split vertex was quantized with (original vertices: the batch whose range holds them).
  uint32_t batch_of_vertex(uint32_t v) const { return v < vertex_batch_.size() ? vertex_batch_[v] : kNone; }

  void emit_breadth_first(BspResult* out) const {
    out->nodes.clear();
    out->pieces.clear();
    if (nodes_.empty()) return;
    std::vector<uint32_t> order;
    order.reserve(nodes_.size());
    order.push_back(0);
    for (size_t i = 0; i < order.size(); ++i) {
      const TmpNode& t = nodes_[order[i]];
      BspNode n{};
      for (int k = 0; k < 3; ++k) n.normal[k] = t.plane.n[k];
      n.d = t.plane.d;
      n.front = kNone;
      n.back = kNone;
      if (t.front != kNone) {
        n.front = uint32_t(order.size());
        order.push_back(t.front);
      }
      if (t.back != kNone) {
        n.back = uint32_t(order.size());
        order.push_back(t.back);
      }
      n.first_piece = uint32_t(out->pieces.size());
      n.piece_count = uint32_t(t.on.size());
      for (const Piece& p : t.on) out->pieces.push_back(BspPiece{{p.v[0], p.v[1], p.v[2]}, p.tri});
      out->nodes.push_back(n);
    }
  }

  const std::vector<Batch>& batches_;
  std::vector<bool> single_sided_;             // per batch: its material culls back faces
  const std::vector<Triangle>& triangles_;
  std::vector<Vertex>& vertices_;
  const CompileOptions& options_;
  Rng rng_;
  std::vector<Vec3i> world_;                   // as the renderer sees them
  std::vector<std::array<double, 3>> exact_;   // unquantized (split points exactly on their edges)
  std::vector<int64_t> eps_;
  int64_t eps_max_ = 0;
  std::vector<TmpNode> nodes_;
  struct SampledPiece {
    Vec3i p[3];   // its vertices' world positions
    int64_t eps;  // its in-plane band (eps_of)
    int sides(const Plane& plane) const { return sides_of(plane, p[0], p[1], p[2], eps, nullptr); }
    int32_t far_end(int axis) const { return std::max(coord(p[0], axis), std::max(coord(p[1], axis), coord(p[2], axis))); }
  };
  std::vector<SampledPiece> sampled_;  // the scoring sample (draw_sample)
  std::unordered_map<uint64_t, uint32_t> split_cache_;
  uint32_t split_vertices_ = 0;
  // T-junction bookkeeping: every split point lies on a line through the two vertices of the edge it
  // split; lines are shared by all vertices known to lie on them (by canonical id).
  std::vector<uint32_t> canon_;
  std::vector<std::vector<uint32_t>> neighbours_;    // mesh neighbours of each original canonical vertex
  std::vector<uint32_t> vertex_batch_;
  std::vector<std::vector<uint32_t>> lines_of_;       // per canonical vertex
  std::vector<std::array<double, 6>> line_geom_;     // origin, direction (exact positions)
  std::vector<std::vector<uint32_t>> line_points_;   // split points on each line
  std::unordered_map<uint64_t, uint32_t> variant_cache_;
};

}  // namespace

int16_t quantize_axis(const Batch& b, int axis, double w) {
  const double scale = double(b.scale[axis]);
  const double q = std::nearbyint((w - double(b.offset[axis])) * 65536.0 / scale);
  const int64_t q0 = int64_t(std::min(std::max(q, -32768.0), 32767.0));
  int64_t best = q0;
  double best_err = -1;
  for (int64_t c = q0 - 1; c <= q0 + 1; ++c) {
    if (c < -32768 || c > 32767) continue;
    const double world = double(int64_t(b.offset[axis]) + ((c * b.scale[axis]) >> 16));
    const double err = std::fabs(world - w);
    if (best_err < 0 || err < best_err) {
      best_err = err;
      best = c;
    }
  }
  return int16_t(best);
}

void quantize_normal(const double n[3], int16_t out[3]) {
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(len > 1e-12) || !std::isfinite(len)) {
    out[0] = out[1] = out[2] = 0;
    return;
  }
  for (int k = 0; k < 3; ++k) {
    const double c = std::min(std::max(n[k] / len, -1.0), 1.0);
    out[k] = int16_t(std::lround(c * kNormalOne));
  }
}

void fill_subtree_bounds(const std::vector<Batch>& batches, const std::vector<Triangle>& triangles,
                         const std::vector<Vertex>& vertices, BspResult* bsp) {
  for (size_t i = bsp->nodes.size(); i-- > 0;) {
    BspNode& n = bsp->nodes[i];
    bool any = false;
    int32_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    auto add = [&](const int32_t p[3]) {
      for (int a = 0; a < 3; ++a) {
        lo[a] = any ? std::min(lo[a], p[a]) : p[a];
        hi[a] = any ? std::max(hi[a], p[a]) : p[a];
      }
      any = true;
    };
    for (uint32_t k = n.first_piece; k < n.first_piece + n.piece_count; ++k) {
      const BspPiece& piece = bsp->pieces[k];
      for (uint32_t v : piece.v) {
        const Vec3i w = dequantize(batches[triangles[piece.triangle].batch], vertices[v].position);
        const int32_t p[3] = {w.x, w.y, w.z};
        add(p);
      }
    }
    uint32_t count = n.piece_count;
    for (uint32_t c : {n.front, n.back}) {
      if (c == kNone) continue;
      const BspNode& m = bsp->nodes[c];
      count += m.subtree_pieces;
      if (m.subtree_pieces == 0) continue;  // an empty child's box says nothing
      add(m.bounds_min);
      add(m.bounds_max);
    }
    n.subtree_pieces = count;
    for (int a = 0; a < 3; ++a) {
      n.bounds_min[a] = lo[a];
      n.bounds_max[a] = hi[a];
    }
  }
  // A subtree without pieces takes its parent's box, so children always nest (parents come first).
  for (BspNode& n : bsp->nodes)
    for (uint32_t c : {n.front, n.back}) {
      if (c == kNone || bsp->nodes[c].subtree_pieces != 0) continue;
      std::copy(n.bounds_min, n.bounds_min + 3, bsp->nodes[c].bounds_min);
      std::copy(n.bounds_max, n.bounds_max + 3, bsp->nodes[c].bounds_max);
    }
}

// Three scorings of the candidate planes, the tree with the fewest pieces kept (the earlier on a tie):
// the options' own; one that weighs a split half as much and tries four times the triangle planes a
// node; one that weighs a split twice as much and tries twice the triangle planes. None wins
// everywhere. A closed, finely tessellated model takes the second: the COLLADA duck's split ratio 2.03
// -> 1.73, its tiler frame at 320x240 13.33 M -> 11.72 M instructions. Scenes of many separate objects
// take the third: the bundled scene 1.0499 -> 1.0230 (6.82 M -> 6.53 M), tessellated(100000) 1.2308 ->
// 1.1437 (106.4 M -> 99.9 M). 2CylinderEngine keeps the first (2.6539; the second scoring alone made
// its frame 62.1 M instead of 55.4 M). Fewer pieces is a proxy: office(8) takes the third with 1.3511
// -> 1.3006 and its frame goes 2.18 M -> 2.24 M. The other builds cost more than the first, with their
// wider searches (compiling 2CylinderEngine: about 13 s one after another, 5 s for the first alone).
struct OtherScoring {
  int weight_times, weight_over, candidates_times;  // of bsp_split_weight and bsp_triangle_candidates
};
constexpr OtherScoring kOtherScorings[] = {{1, 2, 4}, {2, 1, 2}};

// A tree of one scoring (bsp_more_trees aside), from the unsplit vertices.
struct ScoredTree {
  std::vector<Vertex> vertices;  // the unsplit ones and the build's split vertices
  BspResult result;
  bool ok = false;
};
void build_scored(const std::vector<Material>& materials, const std::vector<Batch>& batches,
                  const std::vector<Triangle>& triangles, const std::vector<Vertex>& unsplit,
                  const CompileOptions& options, const OtherScoring& o, ScoredTree* out) {
  CompileOptions other = options;
  other.bsp_split_weight = std::max(1, options.bsp_split_weight * o.weight_times / o.weight_over);
  other.bsp_triangle_candidates = options.bsp_triangle_candidates * o.candidates_times;
  out->vertices = unsplit;
  std::string error;
  out->ok = Builder(materials, batches, triangles, &out->vertices, other).run(&out->result, &error);
}

// Scenes of at least this many triangles build the second scoring's tree on a thread of its own, beside
// the first and third (the builds share only their inputs, read-only; the same trees as one after
// another): compiling 2CylinderEngine takes about 9 s instead of 13 on two cores, tessellated(100000) 3.4 s
// instead of 7.5.
constexpr size_t kThreadedTriangles = 4096;

bool build_bsp(const std::vector<Material>& materials, const std::vector<Batch>& batches,
               const std::vector<Triangle>& triangles, std::vector<Vertex>* vertices,
               const CompileOptions& options, BspResult* out, std::string* error) {
  if (!options.bsp_more_trees) return Builder(materials, batches, triangles, vertices, options).run(out, error);
  const std::vector<Vertex> unsplit = *vertices;
  constexpr size_t kOthers = sizeof(kOtherScorings) / sizeof(kOtherScorings[0]);
  ScoredTree others[kOthers];
  const auto build_other = [&](size_t i) {
    build_scored(materials, batches, triangles, unsplit, options, kOtherScorings[i], &others[i]);
  };
  std::thread second;
  if (triangles.size() >= kThreadedTriangles) second = std::thread(build_other, 0);
  const bool ok = Builder(materials, batches, triangles, vertices, options).run(out, error);
  for (size_t i = second.joinable() ? 1 : 0; ok && i < kOthers; ++i) build_other(i);
  if (second.joinable()) second.join();
  if (!ok) return false;
  for (ScoredTree& other : others) {  // the fewest pieces, the earlier scoring on a tie
    if (!other.ok || other.result.pieces.size() >= out->pieces.size()) continue;
    *out = std::move(other.result);
    *vertices = std::move(other.vertices);
  }
  return true;
}

}  // namespace scenec_detail
}  // namespace ml

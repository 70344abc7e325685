// Helpers for the tiler tests: random screen triangles, a recording writer and sink, pyramid
// invariant checks, and a tiny in-memory scene (no blob) with a valid BSP.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <string>
#include <random>
#include <vector>

#include "tests/common/mesh_builder.h"
#include "platform/host/image_sink.h"

#include "core/sink.h"
#include "scene/scene.h"
#include "tiler/pyramid.h"
#include "tools/scenec/scenec.h"
#include "tiler/tile.h"
#include "view/view.h"

namespace tiler_test {

// A random projected triangle around a width x height screen (subpixels), ordered area2 > 0.
// `span` scales the vertex spread (pixels); some land off screen on purpose.
inline bool random_triangle(std::mt19937& rng, int width, int height, int span, ml::ScreenTriangle* t) {
  std::uniform_int_distribution<int> cx(-width / 4 * 256, width * 5 / 4 * 256);
  std::uniform_int_distribution<int> cy(-height / 4 * 256, height * 5 / 4 * 256);
  std::uniform_int_distribution<int> d(-span * 256, span * 256);
  const int x = cx(rng), y = cy(rng);
  *t = ml::ScreenTriangle{};
  for (int i = 0; i < 3; ++i) {
    t->v[i].x = x + d(rng);
    t->v[i].y = y + d(rng);
    // Snap some vertices to pixel corners and centres to provoke ties.
    if (rng() % 4 == 0) t->v[i].x &= ~255;
    if (rng() % 4 == 0) t->v[i].y = (t->v[i].y & ~255) | 128;
  }
  int64_t area2 = (int64_t(t->v[1].x) - t->v[0].x) * (int64_t(t->v[2].y) - t->v[0].y) -
                  (int64_t(t->v[1].y) - t->v[0].y) * (int64_t(t->v[2].x) - t->v[0].x);
  if (area2 == 0) return false;
  if (area2 < 0) {
    std::swap(t->v[1], t->v[2]);
    area2 = -area2;
  }
  t->area2 = area2;
  t->front_facing = true;
  return true;
}

// Records every write per sample.
class RecordingWriter : public ml::CoverageWriter {
 public:
  RecordingWriter(int w, int h) : width(w), height(h), count(size_t(w) * size_t(h), 0), owner(size_t(w) * size_t(h), -1) {}
  bool write(int x, int y, int w, int h) override {
    ++calls;
    if (x < 0 || y < 0 || w <= 0 || h <= 0 || x + w > width || y + h > height) {
      out_of_bounds = true;
      return true;
    }
    for (int yy = y; yy < y + h; ++yy)
      for (int xx = x; xx < x + w; ++xx) {
        ++count[size_t(yy) * size_t(width) + size_t(xx)];
        owner[size_t(yy) * size_t(width) + size_t(xx)] = current;
      }
    return true;
  }
  int width, height;
  std::vector<int> count;
  std::vector<int> owner;
  int current = 0;
  int calls = 0;
  bool out_of_bounds = false;
};

// A pyramid with its own memory.
struct OwnedPyramid {
  explicit OwnedPyramid(int w, int h) {
    ml::PyramidLayout layout;
    EXPECT_TRUE(ml::make_pyramid_layout(w, h, &layout));
    memory.resize(ml::Pyramid::arena_bytes(layout) + 16);
    ml::Arena arena(memory.data(), memory.size());
    EXPECT_TRUE(pyramid.allocate(layout, arena));
    pyramid.clear();
  }
  std::vector<uint8_t> bytes() const {
    std::vector<uint8_t> out;
    const ml::PyramidLayout& l = pyramid.layout;
    for (int lev = 0; lev + 1 < l.levels; ++lev) {
      const uint8_t* p = reinterpret_cast<const uint8_t*>(pyramid.triage[lev]);
      out.insert(out.end(), p, p + size_t(l.cols[lev]) * size_t(l.rows[lev]) * 16);
    }
    const uint8_t* p = reinterpret_cast<const uint8_t*>(pyramid.blocks);
    const int f = l.levels - 1;
    out.insert(out.end(), p, p + size_t(l.cols[f]) * size_t(l.rows[f]) * 8);
    return out;
  }
  std::vector<uint8_t> memory;
  ml::Pyramid pyramid;
};

// Covered-sample bitmap implied by the pyramid: a sample is covered when its finest bit is set or
// any ancestor subcell is covered (children below a covered subcell may be stale).
inline std::vector<uint8_t> covered_samples(const ml::Pyramid& p) {
  const ml::PyramidLayout& l = p.layout;
  std::vector<uint8_t> out(size_t(l.width) * size_t(l.height), 0);
  for (int y = 0; y < l.height; ++y)
    for (int x = 0; x < l.width; ++x) {
      bool cov = false;
      for (int lev = 0; lev < l.levels && !cov; ++lev) {
        const int s = l.shift(lev), sub = s - 3;
        const uint64_t bit = uint64_t(1) << (((y >> sub) & 7) * 8 + ((x >> sub) & 7));
        if (lev == l.finest()) cov = (p.block(x >> s, y >> s) & bit) != 0;
        else cov = (p.mask(lev, x >> s, y >> s).c & bit) != 0;
      }
      out[size_t(y) * size_t(l.width) + size_t(x)] = cov;
    }
  return out;
}

// P1 and P2 over every mask that is not below a covered subcell. Returns a failure description or "".
inline std::string check_pyramid(const ml::Pyramid& p) {
  const ml::PyramidLayout& l = p.layout;
  std::string err;
  // Recursive walk from the root (test code: recursion is fine here).
  std::function<void(int, int, int)> walk = [&](int lev, int mx, int my) {
    if (!err.empty() || lev == l.finest()) return;
    const ml::TriageMask& m = p.mask(lev, mx, my);
    if (m.c & m.v) err = "P1: c & v != 0 at level " + std::to_string(lev);
    const int s = l.shift(lev), sub = s - 3;
    for (int bit = 0; bit < 64 && err.empty(); ++bit) {
      const int cx = mx * 8 + (bit & 7), cy = my * 8 + (bit >> 3);
      if ((cx << sub) >= l.width || (cy << sub) >= l.height) {
        if (!(m.c >> bit & 1)) err = "off-screen subcell not covered";
        continue;
      }
      if (m.c >> bit & 1) continue;  // stale children allowed
      bool child_all, child_none;
      if (lev + 1 == l.finest()) {
        const uint64_t b = p.block(cx, cy);
        child_all = b == ~uint64_t(0);
        child_none = b == 0;
      } else {
        const ml::TriageMask& c = p.mask(lev + 1, cx, cy);
        child_all = c.c == ~uint64_t(0);
        child_none = c.v == ~uint64_t(0);
      }
      const bool vac = m.v >> bit & 1;
      if (child_all) err = "P2: child all covered but parent subcell not covered";
      else if (vac != child_none)
        err = "P2: parent vacant=" + std::to_string(vac) + " but child vacant=" + std::to_string(child_none) +
              " at level " + std::to_string(lev);
      else walk(lev + 1, cx, cy);
    }
  };
  walk(0, 0, 0);
  return err;
}

// The host's checking sink (platform/host/image_sink.h) with the image and per-pixel write counts
// as plain vectors once the frame ends (never-written pixels read 0xDEADBEEF).
class CountingSink : public mlhost::ImageSink {
 public:
  bool begin_frame(const ml::FrameInfo& f) override {
    ++begins;
    width = f.width;
    height = f.height;
    return ImageSink::begin_frame(f);
  }
  bool flush(const ml::Flush& b) override {
    ++calls;
    if (b.x != 0 || b.y < 0 || b.width != width || b.y + b.height > height) out_of_bounds = true;
    return ImageSink::flush(b);
  }
  bool end_frame() override {
    ++ends;
    const bool ok = ImageSink::end_frame();
    image = pixels();
    count.assign(writes().begin(), writes().end());
    for (size_t i = 0; i < image.size(); ++i)
      if (count[i] == 0) image[i] = 0xDEADBEEF;
    return ok;
  }
  int width = 0, height = 0;
  int begins = 0, ends = 0, calls = 0;
  bool out_of_bounds = false;
  std::vector<ml::Pixel> image;
  std::vector<int> count;
};

// An in-memory scene of triangles in planes z = const (world units), seen by a camera on +z looking
// at the origin. The BSP has one node per distinct z, balanced, +z in front: for that camera a
// valid front-to-back order. Vertices are stored with scale 1.0 and offset 0.
struct TestScene {
  struct Tri {
    int16_t p[3][3];
    bool double_sided = true;
  };
  std::vector<ml::Material> materials;
  std::vector<ml::Batch> batches;
  std::vector<ml::Vertex> vertices;
  std::vector<ml::Triangle> triangles;
  std::vector<ml::BspNode> nodes;
  std::vector<ml::BspPiece> pieces;
  ml::SceneInfo info{};
  ml::Scene scene;   // read from `blob` by pack()

  // Vertices are shared when equal (so meshes are watertight).
  void build(const std::vector<Tri>& tris) {
    materials.clear();
    batches.clear();
    vertices.clear();
    triangles.clear();
    nodes.clear();
    pieces.clear();
    for (int m = 0; m < 2; ++m) {
      ml::Material mat{};
      mat.base_color[0] = uint8_t(200 - 100 * m);
      mat.base_color[1] = 120;
      mat.base_color[2] = uint8_t(60 + 100 * m);
      mat.base_color[3] = 255;
      mat.texture = ml::kNone;
      mat.double_sided = uint8_t(m == 0);
      materials.push_back(mat);
      ml::Batch b{};
      b.material = uint32_t(m);
      b.node = ml::kNone;
      for (int i = 0; i < 3; ++i) b.scale[i] = 65536;
      batches.push_back(b);
    }
    for (size_t t = 0; t < tris.size(); ++t) {
      ml::Triangle tri{};
      tri.batch = tris[t].double_sided ? 0 : 1;
      for (int i = 0; i < 3; ++i) {
        uint32_t found = uint32_t(vertices.size());
        for (uint32_t v = 0; v < vertices.size(); ++v)
          if (!std::memcmp(vertices[v].position, tris[t].p[i], sizeof(int16_t) * 3)) found = v;
        if (found == vertices.size()) {
          ml::Vertex v{};
          std::memcpy(v.position, tris[t].p[i], sizeof(int16_t) * 3);
          // Varied unit normals (Q1.14) so that Gouraud shading has something to interpolate.
          static const int16_t kNormals[4][3] = {{0, 0, 16384}, {9830, 0, 13107}, {0, -9830, 13107}, {-9830, 0, 13107}};
          for (int k = 0; k < 3; ++k) v.normal[k] = kNormals[vertices.size() % 4][k];
          vertices.push_back(v);
        }
        tri.v[i] = found;
      }
      triangles.push_back(tri);
    }
    batches[0].first_vertex = batches[1].first_vertex = 0;
    batches[0].vertex_count = batches[1].vertex_count = uint32_t(vertices.size());
    batches[0].triangle_count = batches[1].triangle_count = uint32_t(triangles.size());
    // Planes: distinct z values, sorted.
    std::vector<int> zs;
    for (const Tri& t : tris) zs.push_back(t.p[0][2]);
    std::sort(zs.begin(), zs.end());
    zs.erase(std::unique(zs.begin(), zs.end()), zs.end());
    uint32_t depth = 0;
    std::function<uint32_t(int, int, uint32_t)> make = [&](int lo, int hi, uint32_t d) -> uint32_t {
      if (lo > hi) return ml::kNone;
      depth = std::max(depth, d);
      const int mid = (lo + hi) / 2;
      const uint32_t id = uint32_t(nodes.size());
      nodes.push_back(ml::BspNode{});
      ml::BspNode n{};
      n.normal[2] = 1 << 30;
      n.d = int64_t(zs[size_t(mid)]) * (int64_t(1) << 30);
      n.first_piece = uint32_t(pieces.size());
      for (size_t t = 0; t < tris.size(); ++t)
        if (tris[t].p[0][2] == zs[size_t(mid)])
          pieces.push_back(ml::BspPiece{{triangles[t].v[0], triangles[t].v[1], triangles[t].v[2]}, uint32_t(t)});
      n.piece_count = uint32_t(pieces.size()) - n.first_piece;
      n.front = make(mid + 1, hi, d + 1);
      n.back = make(lo, mid - 1, d + 1);
      // Subtree box and count (blob_format.h): own piece vertices (scale 1, offset 0: world = q)
      // and the children's boxes; every node here holds pieces.
      n.subtree_pieces = n.piece_count;
      for (int a = 0; a < 3; ++a) {
        n.bounds_min[a] = INT32_MAX;
        n.bounds_max[a] = INT32_MIN;
      }
      for (uint32_t p = n.first_piece; p < n.first_piece + n.piece_count; ++p)
        for (uint32_t v : pieces[p].v)
          for (int a = 0; a < 3; ++a) {
            n.bounds_min[a] = std::min<int32_t>(n.bounds_min[a], vertices[v].position[a]);
            n.bounds_max[a] = std::max<int32_t>(n.bounds_max[a], vertices[v].position[a]);
          }
      for (uint32_t c : {n.front, n.back}) {
        if (c == ml::kNone) continue;
        n.subtree_pieces += nodes[c].subtree_pieces;
        for (int a = 0; a < 3; ++a) {
          n.bounds_min[a] = std::min(n.bounds_min[a], nodes[c].bounds_min[a]);
          n.bounds_max[a] = std::max(n.bounds_max[a], nodes[c].bounds_max[a]);
        }
      }
      nodes[id] = n;
      return id;
    };
    make(0, int(zs.size()) - 1, 1);
    to_breadth_first();
    info = ml::SceneInfo{};
    info.sphere_radius = 1000;
    info.bsp_depth = depth;
    pack();
  }

  // The blob stores nodes breadth-first with each node's pieces in node order (blob_format.h).
  void to_breadth_first() {
    if (nodes.empty()) return;
    std::vector<ml::BspNode> out;
    std::vector<ml::BspPiece> out_pieces;
    std::vector<uint32_t> order{0};
    for (size_t i = 0; i < order.size(); ++i) {
      ml::BspNode n = nodes[order[i]];
      const uint32_t first = n.first_piece;
      n.first_piece = uint32_t(out_pieces.size());
      for (uint32_t p = 0; p < n.piece_count; ++p) out_pieces.push_back(pieces[first + p]);
      for (uint32_t* c : {&n.front, &n.back}) {
        if (*c == ml::kNone) continue;
        order.push_back(*c);
        *c = uint32_t(order.size() - 1);
      }
      out.push_back(n);
    }
    nodes = out;
    pieces = out_pieces;
  }

  // Packs the tables into a blob (scenec's packer) and reads it back: `scene` is what a renderer
  // gets from a file. Call again after changing the tables.
  void pack() {
    ml::SceneTables t;
    t.info = info;
    for (int a = 0; a < 3; ++a) {
      t.info.bounds_min[a] = INT16_MAX;
      t.info.bounds_max[a] = INT16_MIN;
      for (const ml::Vertex& v : vertices) {
        t.info.bounds_min[a] = std::min<int32_t>(t.info.bounds_min[a], v.position[a]);
        t.info.bounds_max[a] = std::max<int32_t>(t.info.bounds_max[a], v.position[a]);
      }
      if (vertices.empty()) t.info.bounds_min[a] = t.info.bounds_max[a] = 0;
    }
    t.materials = materials;
    t.batches = batches;
    t.vertices = vertices;
    t.triangles = triangles;
    t.bsp_nodes = nodes;
    t.bsp_pieces = pieces;
    std::string error;
    blob = ml::Blob();
    scene = ml::Scene{};
    if (!ml::pack_scene(t, &blob, &error)) {
      status = ml::error(ml::StatusCode::BadScene, "pack failed");
      return;
    }
    status = ml::read_scene(blob.data(), blob.size, &scene);
  }

  ml::Blob blob;
  ml::Status status;
};

// The camera a compiled scene suggests (the office scene looks down its rows; CompileResult::camera),
// else the framing of its bounding sphere.
inline ml::Camera hint_camera(const ml::CompileResult& r, const ml::Scene& s, int w, int h) {
  ml::Camera cam = ml::frame_sphere(ml::Vec3i{s.info->sphere_center[0], s.info->sphere_center[1],
                                              s.info->sphere_center[2]},
                                    s.info->sphere_radius, w, h, 45 << 16);
  if (!r.camera.valid) return cam;
  auto round3 = [](const double* v, double k) {
    return ml::Vec3i{int32_t(std::llround(v[0] * k)), int32_t(std::llround(v[1] * k)), int32_t(std::llround(v[2] * k))};
  };
  cam.eye = round3(r.camera.eye, 1);
  cam.target = round3(r.camera.target, 1);
  cam.up = round3(r.camera.up, 1 << 20);
  cam.near = std::max(16, s.info->sphere_radius / 1024);
  return cam;
}

inline ml::Camera test_camera(int w, int h) {
  ml::Camera c;
  c.eye = ml::Vec3i{0, 0, 1000};
  c.target = ml::Vec3i{0, 0, 0};
  c.up = ml::Vec3i{0, 1, 0};
  c.fov_deg_q16 = 60 << 16;
  c.near = 1;
  c.width = w;
  c.height = h;
  return c;
}

// Random triangles in a few z planes in front of test_camera.
inline std::vector<TestScene::Tri> random_scene(std::mt19937& rng, int count, int spread) {
  std::vector<TestScene::Tri> out;
  std::uniform_int_distribution<int> xy(-700, 700), d(-spread, spread), zi(0, 7);
  for (int i = 0; i < count; ++i) {
    TestScene::Tri t;
    const int cx = xy(rng), cy = xy(rng), z = zi(rng) * 60 - 200;
    for (int v = 0; v < 3; ++v) {
      t.p[v][0] = int16_t(cx + d(rng));
      t.p[v][1] = int16_t(cy + d(rng));
      t.p[v][2] = int16_t(z);
    }
    t.double_sided = rng() % 4 != 0;
    out.push_back(t);
  }
  return out;
}

// A mesh of `count` triangles with random corners in [-2, 2]^3, so they cross and the BSP splits them
// (split pieces address appended vertices); every other one in a double-sided material.
inline ml::SceneMesh crossing_mesh(uint32_t seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coord(-2, 2);
  std::vector<ml::MeshMaterial> materials(2);
  for (uint32_t m = 0; m < 2; ++m) {
    materials[m].base_color[0] = 0.2 + 0.6 * m;
    materials[m].double_sided = m == 1;
  }
  ml::SceneMesh mesh = meshtest::one_node_mesh(std::move(materials));
  for (int t = 0; t < count; ++t) {
    ml::MeshVertex v[3];
    for (ml::MeshVertex& vertex : v)
      for (double& c : vertex.position) c = coord(rng);
    meshtest::add_triangle(&mesh, size_t(t) % 2, v);
  }
  return mesh;
}

}  // namespace tiler_test

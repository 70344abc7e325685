// tile_poly and the tiler frame: T5, T6, S1-S7 of the digest's §5, exact coverage, once-only writes
// through tiler_render, arena sizing, work image.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <tuple>

#include "core/arena.h"
#include "core/band.h"
#include "render/render.h"
#include "tests/tiler/tiler_test_util.h"
#include "tiler/tile.h"
#include "tiler/tiler.h"
#include "tools/scenec/scenec.h"

namespace {

using tiler_test::CountingSink;
using tiler_test::hint_camera;
using tiler_test::OwnedPyramid;
using tiler_test::RecordingWriter;

ml::ConvexPoly poly_of(const ml::ScreenTriangle& t, int w, int h, ml::TriangleSetup* s) {
  ml::setup_triangle(t, w, h, s);
  ml::ConvexPoly p;
  ml::poly_from_setup(*s, &p);
  return p;
}

// T5: a polygon mask has Pc & Pv == 0 and Pc ⊆ true coverage ⊆ ~Pv, per subcell, against brute
// force over every sample of the subcell (cells of 8x8 subcells of 1..64 samples).
TEST(TilerMask, PolygonMaskBracketsTrueCoverage) {
  std::mt19937 rng(9);
  int tested = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int sub = 1 << (rng() % 4);  // subcell side in samples
    const int side = 8 * sub;
    ml::ScreenTriangle t;
    if (!tiler_test::random_triangle(rng, side, side, side, &t)) continue;
    ml::TriangleSetup s;
    const ml::ConvexPoly poly = poly_of(t, side, side, &s);
    ml::TriageMask m;
    const bool touches = ml::polygon_mask(poly, 0, 0, int64_t(side) * 256, &m);
    for (int bit = 0; bit < 64; ++bit) {
      int in = 0;
      for (int y = 0; y < sub; ++y)
        for (int x = 0; x < sub; ++x) in += ml::covers_pixel(s, (bit & 7) * sub + x, (bit >> 3) * sub + y);
      if (!touches) {
        ASSERT_EQ(in, 0) << "rejected polygon covers a sample";
        continue;
      }
      ASSERT_EQ(m.c & m.v, 0u);
      if (m.c >> bit & 1) {
        ASSERT_EQ(in, sub * sub) << trial;
      }
      if (m.v >> bit & 1) {
        ASSERT_EQ(in, 0) << trial;
      }
    }
    ++tested;
  }
  EXPECT_GT(tested, 2500);
}

// T6: Greene's Table 4.1, all nine cases, and the listing's misprint is not what we compute.
TEST(TilerMask, CompositingFollowsTable41) {
  enum { Cov, Act, Vac };
  auto mask = [](int st) { return ml::TriageMask{st == Cov ? 1u : 0u, st == Vac ? 1u : 0u}; };
  struct Case {
    int screen, poly;
    bool write, subdivide;
    int result;
  };
  const Case cases[9] = {
      {Cov, Cov, false, false, Cov}, {Cov, Act, false, false, Cov}, {Cov, Vac, false, false, Cov},
      {Act, Cov, false, true, Act},  {Act, Act, false, true, Act},  {Act, Vac, false, false, Act},
      {Vac, Cov, true, false, Cov},  {Vac, Act, false, true, Vac},  {Vac, Vac, false, false, Vac},
  };
  for (const Case& c : cases) {
    ml::TriageMask s = mask(c.screen);
    const ml::TriageMask p = mask(c.poly);
    uint64_t w, a;
    ml::composite(&s, p, &w, &a);
    EXPECT_EQ((w & 1) != 0, c.write) << c.screen << c.poly;
    EXPECT_EQ((a & 1) != 0, c.subdivide) << c.screen << c.poly;
    const int result = (s.c & 1) ? Cov : (s.v & 1) ? Vac : Act;
    EXPECT_EQ(result, c.result) << c.screen << c.poly;
    // The thesis listing's A = ~(W | Pv | Pc) skips case 4 and subdivides case 2.
    const uint64_t wrong = ~(w | p.v | p.c) & 1;
    if (c.screen == Act && c.poly == Cov) {
      EXPECT_NE(wrong, a & 1);
    }
    if (c.screen == Cov && c.poly == Act) {
      EXPECT_NE(wrong, a & 1);
    }
  }
}

// The tiler computes a part's sample box first and its edges only when the box holds a sample of the
// band: the two together are poly_in_samples (setup_triangle's edges, the box of the samples), for
// every sampling, on triangles on, beside and far off the screen, with vertices on sample centres.
TEST(TilerTile, SampleBoxAndEdgesArePolyInSamples) {
  std::mt19937 rng(77);
  const int pw = 20, ph = 12;
  for (int factor : {1, 2, 4, 8})
    for (bool jittered : {false, true}) {
      if (jittered && factor == 1) continue;
      for (int i = 0; i < 3000; ++i) {
        ml::ScreenTriangle t;
        const int span = (i % 3 == 0) ? 9000 : (i % 3 == 1) ? 30 : 1;
        if (!tiler_test::random_triangle(rng, pw, ph, span, &t)) continue;
        ml::TriangleSetup s;
        ml::setup_triangle(t, pw, ph, &s);
        ml::ConvexPoly want;
        ml::poly_in_samples(t, s, factor, pw, ph, &want, jittered);
        ml::ConvexPoly got;
        ml::sample_box(std::min({t.v[0].x, t.v[1].x, t.v[2].x}), std::min({t.v[0].y, t.v[1].y, t.v[2].y}),
                       std::max({t.v[0].x, t.v[1].x, t.v[2].x}), std::max({t.v[0].y, t.v[1].y, t.v[2].y}), factor,
                       pw, ph, jittered, &got);
        ml::poly_edges(t, &got);
        ASSERT_EQ(got.min_x, want.min_x) << i;
        ASSERT_EQ(got.min_y, want.min_y) << i;
        ASSERT_EQ(got.max_x, want.max_x) << i;
        ASSERT_EQ(got.max_y, want.max_y) << i;
        ASSERT_EQ(got.n, want.n);
        for (int k = 0; k < got.n; ++k) {
          ASSERT_EQ(got.edge[k].a, want.edge[k].a);
          ASSERT_EQ(got.edge[k].b, want.edge[k].b);
          ASSERT_EQ(got.edge[k].c, want.edge[k].c);
        }
      }
    }
}

// S1, S3, S4, exactness: random triangles tiled front to back give each sample to the first
// triangle (in order) whose src/view coverage contains it, written exactly once; S2/S5 after the
// background: every sample written once and the root covered.
// Ownership against brute force on screens small enough that every polygon takes the small-box path,
// with triangles reaching far into the guard band (edge steps near the 32-bit row limit, where the
// tiler must fall back to the descent), at one and at 8 x 8 samples a pixel.
TEST(TilerTile, SmallBoxesWithLongEdgesEqualBruteForce) {
  std::mt19937 rng(21);
  for (int factor : {1, 8}) {
    const int pw = 3, ph = 4, w = pw * factor, h = ph * factor, pitch = 256 / factor;
    for (int rep = 0; rep < 20; ++rep) {
      OwnedPyramid op(w, h);
      ml::HierTiler tiler;
      tiler.init(&op.pyramid, pitch, nullptr);
      RecordingWriter rec(w, h);
      std::vector<int> expect(size_t(w) * size_t(h), -1);
      for (int i = 0; i < 40; ++i) {
        ml::ScreenTriangle t;
        const int span = (i % 3 == 0) ? 8000 : (i % 3 == 1) ? 600 : 4;
        if (!tiler_test::random_triangle(rng, pw, ph, span, &t)) continue;
        ml::TriangleSetup s;
        ml::setup_triangle(t, pw, ph, &s);
        ml::ConvexPoly poly;
        ml::poly_in_samples(t, s, factor, pw, ph, &poly);
        rec.current = i;
        ASSERT_NE(tiler.tile(poly, rec), ml::TileResult::Failed);
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x)
            if (expect[size_t(y) * size_t(w) + size_t(x)] < 0 &&
                ml::covers_point(s, int64_t(x) * pitch + pitch / 2, int64_t(y) * pitch + pitch / 2))
              expect[size_t(y) * size_t(w) + size_t(x)] = i;
      }
      ASSERT_FALSE(rec.out_of_bounds);
      for (size_t p = 0; p < expect.size(); ++p) {
        ASSERT_LE(rec.count[p], 1) << "sample written twice at " << p % size_t(w) << "," << p / size_t(w);
        ASSERT_EQ(rec.count[p] ? rec.owner[p] : -1, expect[p])
            << "at " << p % size_t(w) << "," << p / size_t(w) << ", " << factor << "x" << factor << " samples";
      }
    }
  }
}

// The row-by-row path at every box size it takes (one block, up to 56 samples a side in a 64-bit row
// word, 57 to 120 in a 128-bit one on 64-bit hosts; 32 on the boards) and past it (the descent), for polygons
// of up to six edges with up to three left and three right bounds: two triangles intersected, as a
// split piece is clipped to its triangle. Ownership front to back against brute force (a sample is a
// polygon's when every edge function is >= 0 at its centre), at one and at 2 x 2 samples a pixel.
TEST(TilerTile, IntersectedTrianglesOfEverySizeEqualBruteForce) {
  std::mt19937 rng(33);
  for (int factor : {1, 2}) {
    const int pw = 300 / factor, ph = 160 / factor, w = pw * factor, h = ph * factor, pitch = 256 / factor;
    OwnedPyramid op(w, h);
    ml::HierTiler tiler;
    tiler.init(&op.pyramid, pitch, nullptr);
    RecordingWriter rec(w, h);
    std::vector<int> expect(size_t(w) * size_t(h), -1);
    // Polygons whose box is 57 to 248 samples a side (the wide rows on 64-bit hosts), inside one block,
    // or wider (the descent).
    int wide = 0, one_block = 0, beyond = 0;
    for (int i = 0; i < 600; ++i) {
      // Boxes inside one block, up to 56 samples, 57 to about 140, and a few up to the screen's width.
      const int span = std::max(1, (i % 4 == 0   ? 1 + int(rng() % 4)
                                    : i % 16 == 1 ? 150 + int(rng() % 200)
                                                  : 10 + int(rng() % 60)) /
                                       factor);
      ml::ScreenTriangle a, b;
      if (!tiler_test::random_triangle(rng, pw, ph, span, &a)) continue;
      b = a;  // the second triangle near the first: their intersection is mostly not empty
      for (ml::ScreenVertex& v : b.v) {
        v.x += int(rng() % 4001) - 2000;
        v.y += int(rng() % 4001) - 2000;
      }
      const int64_t area2 = (int64_t(b.v[1].x) - b.v[0].x) * (int64_t(b.v[2].y) - b.v[0].y) -
                            (int64_t(b.v[1].y) - b.v[0].y) * (int64_t(b.v[2].x) - b.v[0].x);
      if (area2 <= 0) continue;
      ml::TriangleSetup sa, sb;
      ml::setup_triangle(a, pw, ph, &sa);
      ml::setup_triangle(b, pw, ph, &sb);
      ml::ConvexPoly pa, pb;
      ml::poly_in_samples(a, sa, factor, pw, ph, &pa);
      ml::poly_in_samples(b, sb, factor, pw, ph, &pb);
      ml::ConvexPoly poly = pa;
      for (int k = 0; k < 3; ++k) poly.edge[poly.n++] = pb.edge[k];
      poly.min_x = std::max(pa.min_x, pb.min_x);
      poly.min_y = std::max(pa.min_y, pb.min_y);
      poly.max_x = std::min(pa.max_x, pb.max_x);
      poly.max_y = std::min(pa.max_y, pb.max_y);
      const int side = std::max(poly.max_x - poly.min_x, poly.max_y - poly.min_y) + 1;
      wide += side > 56 && side <= 248;
      beyond += side > 248;
      one_block += (poly.min_x ^ poly.max_x) < 8 && (poly.min_y ^ poly.max_y) < 8;
      rec.current = i;
      ASSERT_NE(tiler.tile(poly, rec), ml::TileResult::Failed);
      for (int y = poly.min_y; y <= poly.max_y; ++y)
        for (int x = poly.min_x; x <= poly.max_x; ++x)
          if (expect[size_t(y) * size_t(w) + size_t(x)] < 0 &&
              ml::covers_point(sa, int64_t(x) * pitch + pitch / 2, int64_t(y) * pitch + pitch / 2) &&
              ml::covers_point(sb, int64_t(x) * pitch + pitch / 2, int64_t(y) * pitch + pitch / 2))
            expect[size_t(y) * size_t(w) + size_t(x)] = i;
    }
    EXPECT_GT(wide, 40) << factor;  // the wide rows are reached
    EXPECT_GT(beyond, 3) << factor;  // and the descent past them
    EXPECT_GT(one_block, 20) << factor;
    ASSERT_FALSE(rec.out_of_bounds);
    for (size_t p = 0; p < expect.size(); ++p) {
      ASSERT_LE(rec.count[p], 1) << "sample written twice at " << p % size_t(w) << "," << p / size_t(w);
      ASSERT_EQ(rec.count[p] ? rec.owner[p] : -1, expect[p])
          << "at " << p % size_t(w) << "," << p / size_t(w) << ", " << factor << "x" << factor << " samples";
    }
  }
}

TEST(TilerTile, OwnershipEqualsBruteForceFrontToBack) {
  std::mt19937 rng(1);
  for (auto [w, h] : {std::pair<int, int>{320, 240}, {64, 64}, {77, 131}, {600, 9}, {1, 1}, {513, 300}}) {
    for (int rep = 0; rep < 3; ++rep) {
      OwnedPyramid op(w, h);
      ml::HierTiler tiler;
      tiler.init(&op.pyramid, 256, nullptr);
      RecordingWriter rec(w, h);
      std::vector<int> expect(size_t(w) * size_t(h), -1);
      const int count = 60 + rep * 40;
      for (int i = 0; i < count; ++i) {
        ml::ScreenTriangle t;
        const int span = (i % 5 == 0) ? std::max(w, h) : 1 + int(rng() % uint32_t(std::max(2, std::max(w, h) / 6)));
        if (!tiler_test::random_triangle(rng, w, h, span, &t)) continue;
        ml::TriangleSetup s;
        const ml::ConvexPoly poly = poly_of(t, w, h, &s);
        rec.current = i;
        tiler.tile(poly, rec);
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x)
            if (expect[size_t(y) * size_t(w) + size_t(x)] < 0 && ml::covers_pixel(s, x, y))
              expect[size_t(y) * size_t(w) + size_t(x)] = i;
      }
      ASSERT_FALSE(rec.out_of_bounds);
      for (size_t p = 0; p < expect.size(); ++p) {
        ASSERT_LE(rec.count[p], 1) << "sample written twice at " << p % size_t(w) << "," << p / size_t(w);
        ASSERT_EQ(rec.count[p] ? rec.owner[p] : -1, expect[p])
            << "at " << p % size_t(w) << "," << p / size_t(w) << " size " << w << "x" << h;
      }
      rec.current = -2;
      ASSERT_TRUE(tiler.background(rec));
      for (size_t p = 0; p < expect.size(); ++p) {
        ASSERT_EQ(rec.count[p], 1);
        if (expect[p] < 0) {
          ASSERT_EQ(rec.owner[p], -2);
        }
      }
      EXPECT_EQ(op.pyramid.mask(0, 0, 0).c, ~uint64_t(0));
    }
  }
}

// Watertight: a fan/grid mesh with shared vertices covering the screen leaves no sample unwritten
// and writes none twice.
TEST(TilerTile, SharedEdgeMeshIsWatertight) {
  std::mt19937 rng(4);
  const int w = 203, h = 157;
  for (int rep = 0; rep < 4; ++rep) {
    const int n = 4 + rep * 3;
    std::vector<std::pair<int, int>> grid;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        int x = -300 + i * (w * 256 + 600) / n, y = -300 + j * (h * 256 + 600) / n;
        if (i > 0 && i < n) x += int(rng() % 601) - 300;
        if (j > 0 && j < n) y += int(rng() % 601) - 300;
        grid.push_back({x, y});
      }
    OwnedPyramid op(w, h);
    ml::HierTiler tiler;
    tiler.init(&op.pyramid, 256, nullptr);
    RecordingWriter rec(w, h);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int q[4] = {j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i};
        const int tris[2][3] = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
        for (const auto& tv : tris) {
          ml::ScreenTriangle t{};
          for (int k = 0; k < 3; ++k) {
            t.v[k].x = grid[size_t(tv[k])].first;
            t.v[k].y = grid[size_t(tv[k])].second;
          }
          t.area2 = (int64_t(t.v[1].x) - t.v[0].x) * (int64_t(t.v[2].y) - t.v[0].y) -
                    (int64_t(t.v[1].y) - t.v[0].y) * (int64_t(t.v[2].x) - t.v[0].x);
          if (t.area2 < 0) {
            std::swap(t.v[1], t.v[2]);
            t.area2 = -t.area2;
          }
          if (t.area2 == 0) continue;
          ml::TriangleSetup s;
          tiler.tile(poly_of(t, w, h, &s), rec);
        }
      }
    for (size_t p = 0; p < rec.count.size(); ++p) ASSERT_EQ(rec.count[p], 1) << p;
    EXPECT_EQ(op.pyramid.mask(0, 0, 0).c, ~uint64_t(0));
  }
}

// S6: once a region is covered, polygons inside it visit no cell and write nothing.
TEST(TilerTile, CoveredRegionsCostNothing) {
  const int w = 320, h = 240;
  OwnedPyramid op(w, h);
  ml::HierTiler tiler;
  tiler.init(&op.pyramid, 256, nullptr);
  RecordingWriter rec(w, h);
  ml::ScreenTriangle big{};
  big.v[0] = {-1000 * 256, -1000 * 256, 0, 0, {}};
  big.v[1] = {2000 * 256, -1000 * 256, 0, 0, {}};
  big.v[2] = {-1000 * 256, 2000 * 256, 0, 0, {}};
  big.area2 = 1;  // only the sign matters to setup
  ml::TriangleSetup s;
  const ml::TriageMask root = op.pyramid.mask(0, 0, 0);
  const uint64_t partly_off = uint64_t(__builtin_popcountll(~(root.c | root.v)));
  EXPECT_EQ(partly_off, 5u);  // 240 = 3.75 x 64: the fourth row of root subcells
  ASSERT_EQ(tiler.tile(poly_of(big, w, h, &s), rec), ml::TileResult::Tiled);
  // The root writes its vacant subcells as 64x64 blocks; only the partly off-screen ones are entered.
  EXPECT_EQ(tiler.cells_visited, 1u + partly_off);
  EXPECT_EQ(op.pyramid.mask(0, 0, 0).c, ~uint64_t(0));
  const int calls = rec.calls;
  std::mt19937 rng(8);
  for (int i = 0; i < 200; ++i) {
    ml::ScreenTriangle t;
    if (!tiler_test::random_triangle(rng, w, h, 50, &t)) continue;
    const uint64_t before = tiler.cells_visited;
    const ml::TileResult r = tiler.tile(poly_of(t, w, h, &s), rec);
    EXPECT_EQ(r, ml::TileResult::Hidden);
    EXPECT_EQ(tiler.cells_visited, before);
  }
  EXPECT_EQ(rec.calls, calls);
}

// S7: the visibility query never changes the pyramid and answers whether some sample the polygon
// covers is still uncovered.
TEST(TilerTile, VisibilityQueryIsExactAndPure) {
  std::mt19937 rng(12);
  const int w = 150, h = 100;
  OwnedPyramid op(w, h);
  ml::HierTiler tiler;
  tiler.init(&op.pyramid, 256, nullptr);
  RecordingWriter rec(w, h);
  int visible = 0, hidden = 0;
  for (int i = 0; i < 400; ++i) {
    ml::ScreenTriangle t;
    if (!tiler_test::random_triangle(rng, w, h, i < 200 ? 30 : 8, &t)) continue;
    ml::TriangleSetup s;
    const ml::ConvexPoly poly = poly_of(t, w, h, &s);
    const auto before = op.bytes();
    const bool vis = tiler.visible(poly);
    ASSERT_EQ(op.bytes(), before);
    bool brute = false;
    for (int y = 0; y < h && !brute; ++y)
      for (int x = 0; x < w && !brute; ++x)
        brute = ml::covers_pixel(s, x, y) && rec.count[size_t(y) * size_t(w) + size_t(x)] == 0;
    ASSERT_EQ(vis, brute) << i;
    (vis ? visible : hidden)++;
    if (i % 2 == 0) tiler.tile(poly, rec);
  }
  EXPECT_GT(visible, 20);
  EXPECT_GT(hidden, 20);
}

// ---- the frame (tiler_render) -----------------------------------------------------------------

struct Frame {
  CountingSink sink;
  ml::Stats stats;
  ml::Status status;
};

Frame render(const ml::Scene& scene, const ml::Camera& cam, ml::ShadingMode mode, ml::WorkImage* work = nullptr,
             size_t arena_bytes = 0, ml::OutputOptions output = ml::OutputOptions{}) {
  Frame f;
  ml::RenderOptions opt;
  opt.shading = mode;
  opt.work = work;
  opt.output = output;
  const size_t need = ml::render_arena_bytes(scene, cam, opt);
  // Poisoned, so a pixel the renderer skips in a band shows (platform/host/image_sink.h).
  std::vector<uint8_t> mem(arena_bytes ? arena_bytes : need, mlhost::kPoisonByte);
  ml::Arena arena(mem.data(), mem.size());
  f.status = ml::render(scene, cam, opt, arena, f.sink, &f.stats);
  return f;
}

// Brute-force Ids image of a TestScene: pieces in BSP order (front to back for test_camera), the
// first covering piece owns the pixel.
std::vector<ml::Pixel> brute_ids(const tiler_test::TestScene& ts, const ml::Camera& cam) {
  ml::View view;
  EXPECT_TRUE(ml::make_view(cam, &view).ok());
  std::vector<ml::Pixel> img(size_t(cam.width) * size_t(cam.height), 0);
  std::vector<uint32_t> order;
  std::function<void(uint32_t)> walk = [&](uint32_t n) {
    if (n == ml::kNone) return;
    walk(ts.nodes[n].front);
    for (uint32_t p = 0; p < ts.nodes[n].piece_count; ++p) order.push_back(ts.nodes[n].first_piece + p);
    walk(ts.nodes[n].back);
  };
  walk(0);
  for (uint32_t p : order) {
    const ml::BspPiece& piece = ts.pieces[p];
    ml::Vec3i world[3];
    for (int i = 0; i < 3; ++i) world[i] = ml::vertex_world(ts.scene, ts.triangles[piece.triangle].batch, piece.v[i]);
    ml::ScreenTriangle parts[ml::kMaxClipTriangles];
    const int n = ml::project_triangle(view, world, parts);
    const bool ds = ts.materials[ts.batches[ts.triangles[piece.triangle].batch].material].double_sided;
    for (int i = 0; i < n; ++i) {
      if (!parts[i].front_facing && !ds) continue;
      ml::TriangleSetup s;
      ml::setup_triangle(parts[i], cam.width, cam.height, &s);
      for (int y = std::max(0, s.min_y); y <= s.max_y; ++y)
        for (int x = std::max(0, s.min_x); x <= s.max_x; ++x) {
          ml::Pixel& px = img[size_t(y) * size_t(cam.width) + size_t(x)];
          if (px == 0 && ml::covers_pixel(s, x, y)) px = piece.triangle + 1;
        }
    }
  }
  return img;
}

TEST(TilerRender, RandomScenesWriteEveryPixelOnceAndMatchBruteForce) {
  std::mt19937 rng(31);
  for (int rep = 0; rep < 6; ++rep) {
    tiler_test::TestScene ts;
    ts.build(tiler_test::random_scene(rng, 40 + rep * 30, 60 + rep * 40));
    const ml::Camera cam = tiler_test::test_camera(rep % 2 ? 320 : 173, rep % 2 ? 240 : 211);
    for (ml::ShadingMode mode : {ml::ShadingMode::Ids, ml::ShadingMode::Flat, ml::ShadingMode::Gouraud}) {
      Frame f = render(ts.scene, cam, mode);
      ASSERT_TRUE(f.status.ok()) << f.status.message;
      EXPECT_EQ(f.sink.begins, 1);
      EXPECT_EQ(f.sink.ends, 1);
      ASSERT_FALSE(f.sink.out_of_bounds);
      for (int c : f.sink.count) ASSERT_EQ(c, 1);
      EXPECT_EQ(f.stats.pixel_writes, uint64_t(cam.width) * uint64_t(cam.height));
      EXPECT_EQ(f.stats.sink_calls, uint64_t(f.sink.calls));
      EXPECT_GT(f.stats.cells_visited, 0u);
      EXPECT_GT(f.stats.triangles_drawn, 10u);
      EXPECT_EQ(f.stats.triangles_drawn + f.stats.triangles_culled, uint64_t(f.stats.bsp_pieces) * f.stats.render_bands);
      if (mode == ml::ShadingMode::Ids) {
        const auto expect = brute_ids(ts, cam);
        for (size_t p = 0; p < expect.size(); ++p) ASSERT_EQ(f.sink.image[p], expect[p]) << "pixel " << p;
      }
    }
  }
}

// Bands are an output detail: any band height and buffer count gives the image of one band, each
// pixel once, with one flush a band.
TEST(TilerRender, BandSplitGivesTheSameImageAsOneBand) {
  std::mt19937 rng(77);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 120, 160));
  const ml::Camera cam = tiler_test::test_camera(173, 131);
  for (ml::ShadingMode mode : {ml::ShadingMode::Ids, ml::ShadingMode::Gouraud}) {
    ml::OutputOptions whole;
    whole.band_rows = 0;
    const Frame one = render(ts.scene, cam, mode, nullptr, 0, whole);
    ASSERT_TRUE(one.status.ok()) << one.status.message;
    EXPECT_EQ(one.stats.bands, 1u);
    for (int rows : {1, 7, 8, 16, 64, 130, 131}) {
      for (int buffers : {1, 2}) {
        ml::OutputOptions out;
        out.band_rows = rows;
        out.buffers = buffers;
        const Frame f = render(ts.scene, cam, mode, nullptr, 0, out);
        ASSERT_TRUE(f.status.ok()) << f.status.message;
        ASSERT_TRUE(f.sink.contract_ok()) << f.sink.contract_error();
        EXPECT_EQ(f.stats.bands, uint32_t((131 + rows - 1) / rows));
        EXPECT_EQ(f.sink.calls, int(f.stats.bands));
        EXPECT_EQ(f.stats.pixel_writes, 173u * 131u);
        ASSERT_EQ(f.sink.image, one.sink.image) << "band rows " << rows << ", buffers " << buffers;
      }
    }
  }
}

// The band plan and the subtrees' kept screen rectangles (arena bytes to spare, render_spare_bytes, one band
// rendered at a time) change nothing but the work: the same image and the same counts as the least arena (but
// tiled parts), at 16 bands or fewer (exact plan) and at more (bands grouped, each still tested), and in one
// band (the triangles' facing bits alone), with their bytes showing in the peak.
TEST(TilerRender, BandPlanGivesTheSameFrameAsTheLeastArena) {
  std::mt19937 rng(91);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 150, 160));
  const ml::Camera cam = tiler_test::test_camera(173, 131);
  for (ml::ShadingMode mode : {ml::ShadingMode::Ids, ml::ShadingMode::Flat, ml::ShadingMode::Gouraud}) {
    for (int rows : {1, 5, 9, 16, 130, 131}) {
      ml::OutputOptions out;
      out.band_rows = rows;
      out.render_rows = rows;
      ml::RenderOptions opt;
      opt.shading = mode;
      opt.output = out;
      const size_t need = ml::render_arena_bytes(ts.scene, cam, opt);
      const size_t spare = ml::render_spare_bytes(ts.scene, cam, opt);
      // A byte a piece up to 16 bands, two beyond (and one of alignment), none in one band; + 2 bits a triangle;
      // + 8 bytes a BSP node for the subtrees' screen rectangles (and 3 of alignment), none in one band;
      // + the vertex cache.
      const int bands = (cam.height + rows - 1) / rows;
      const size_t entries = bands == 1  ? 0
                             : bands > 16 ? 2 * size_t(ts.scene.bsp_piece_count) + 1
                                          : size_t(ts.scene.bsp_piece_count);
      const size_t rects = bands == 1 ? 0 : 8 * size_t(ts.scene.bsp_node_count) + 3;
      EXPECT_EQ(spare, entries + (ts.scene.triangle_count + 3) / 4 + rects + ml::tiler_cache_bytes(ts.scene));
      const Frame least = render(ts.scene, cam, mode, nullptr, need, out);
      const Frame planned = render(ts.scene, cam, mode, nullptr, need + spare, out);
      ASSERT_TRUE(least.status.ok() && planned.status.ok());
      ASSERT_TRUE(planned.sink.contract_ok()) << planned.sink.contract_error();
      ASSERT_EQ(planned.sink.image, least.sink.image) << "band rows " << rows;
      EXPECT_EQ(planned.stats.triangles_drawn, least.stats.triangles_drawn);
      EXPECT_EQ(planned.stats.triangles_culled, least.stats.triangles_culled);
      // With the plan only larger subtrees are culled whole: a hidden piece the walk reaches is handed
      // to tile_poly (counted as tiled) and found hidden there, visiting no cell.
      EXPECT_GE(planned.stats.triangles_tiled, least.stats.triangles_tiled);
      EXPECT_EQ(planned.stats.cells_visited, least.stats.cells_visited);
      EXPECT_EQ(planned.stats.shading_calls, least.stats.shading_calls);
      // The plan's bytes (less what their alignment did not take), and at most the pyramid's alignment after them.
      EXPECT_GE(planned.stats.peak_arena_bytes, least.stats.peak_arena_bytes + spare - 4) << "band rows " << rows;
      EXPECT_LE(planned.stats.peak_arena_bytes, least.stats.peak_arena_bytes + spare + 16) << "band rows " << rows;
    }
  }
}

// The plan keeps each triangle's facing for the other pieces of a triangle the BSP split: on a
// compiled scene of crossing triangles in random orientations, half of them double-sided (so split
// pieces, back faces and both sides of double-sided ones), seen from all around, the planned frame is
// the least arena's, with one-byte and two-byte plan entries, and in one band (the facing bits alone).
TEST(TilerRender, BandPlanSharesFacingAmongSplitPieces) {
  const ml::SceneMesh mesh = tiler_test::crossing_mesh(23, 80);
  const ml::CompileResult r = ml::compile_mesh(mesh);
  ASSERT_TRUE(r.ok) << r.error;
  ml::Scene s;
  ASSERT_TRUE(ml::read_scene(r.blob.data(), r.blob.size, &s).ok());
  ASSERT_GT(s.bsp_split_count, 0u);
  const ml::Vec3i c{s.info->sphere_center[0], s.info->sphere_center[1], s.info->sphere_center[2]};
  const int32_t d = s.info->sphere_radius * 3;
  for (const ml::Vec3i& eye : {ml::Vec3i{c.x, c.y, c.z + d}, ml::Vec3i{c.x, c.y, c.z - d}, ml::Vec3i{c.x + d, c.y + d / 2, c.z},
                               ml::Vec3i{c.x - d / 2, c.y - d, c.z + d / 3}}) {
    // 14 bands (a byte a piece), 97 (two bytes, exact), 300 (two bytes, groups of two bands) and one.
    for (auto [h, rows, mode] : {std::tuple<int, int, ml::ShadingMode>{97, 7, ml::ShadingMode::Ids}, {97, 7, ml::ShadingMode::Flat},
                                 {97, 1, ml::ShadingMode::Ids}, {300, 1, ml::ShadingMode::Flat},
                                 {97, 97, ml::ShadingMode::Gouraud}}) {
      ml::Camera cam = tiler_test::test_camera(120, h);
      // The tall screen from closer, so the triangles reach its last bands.
      const int k = h > 256 ? 2 : 5;
      cam.eye = ml::Vec3i{c.x + (eye.x - c.x) * k / 5, c.y + (eye.y - c.y) * k / 5, c.z + (eye.z - c.z) * k / 5};
      cam.target = c;
      cam.near = std::max(1, s.info->sphere_radius / 1024);
      ml::OutputOptions out;
      out.band_rows = rows;
      out.render_rows = rows;
      ml::RenderOptions opt;
      opt.shading = mode;
      opt.output = out;
      const size_t need = ml::render_arena_bytes(s, cam, opt);
      const Frame least = render(s, cam, mode, nullptr, need, out);
      const Frame planned = render(s, cam, mode, nullptr, need + ml::render_spare_bytes(s, cam, opt), out);
      ASSERT_TRUE(least.status.ok() && planned.status.ok());
      ASSERT_TRUE(planned.sink.contract_ok()) << planned.sink.contract_error();
      ASSERT_EQ(planned.sink.image, least.sink.image);
      EXPECT_EQ(planned.stats.triangles_drawn, least.stats.triangles_drawn);
      EXPECT_EQ(planned.stats.shading_calls, least.stats.shading_calls);
      EXPECT_GT(planned.stats.triangles_drawn, 0u);
    }
  }
}

// Several bands rendered at once (core/band.h's render bands, when the arena has room beyond the least)
// give the least arena's frame: the same bands reach the sink, with the same bytes, whatever rows are
// rendered at once (two bands, three, all of them, or as many as the spare arena holds), in every
// output format (Mono1's pages, Grey4's nibbles), shaded, as ids and antialiased; the pieces are drawn
// once a render band, and the walk runs once for all its bands.
TEST(TilerRender, BandsRenderedAtOnceGiveTheLeastArenasFrame) {
  if (!ml::kRenderBands) GTEST_SKIP() << "a 32-bit target";
  std::mt19937 rng(57);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 120, 160));
  const ml::Camera cam = tiler_test::test_camera(101, 75);
  struct Case {
    ml::ShadingMode mode;
    int aa;
    ml::FilterKind filter;
    ml::SamplePattern samples;
    ml::PixelFormat format;
    int band_rows;
  };
  const Case cases[] = {
      {ml::ShadingMode::Ids, 1, ml::FilterKind::Box, ml::SamplePattern::Regular, ml::PixelFormat::Id32, 8},
      {ml::ShadingMode::Flat, 1, ml::FilterKind::Box, ml::SamplePattern::Regular, ml::PixelFormat::Xrgb8888, 16},
      {ml::ShadingMode::Gouraud, 1, ml::FilterKind::Box, ml::SamplePattern::Regular, ml::PixelFormat::Rgb565Be, 1},
      {ml::ShadingMode::Flat, 1, ml::FilterKind::Box, ml::SamplePattern::Regular, ml::PixelFormat::Mono1, 8},
      {ml::ShadingMode::Gouraud, 1, ml::FilterKind::Box, ml::SamplePattern::Regular, ml::PixelFormat::Grey4, 7},
      {ml::ShadingMode::Flat, 4, ml::FilterKind::Box, ml::SamplePattern::Regular, ml::PixelFormat::Xrgb8888, 16},
      {ml::ShadingMode::Flat, 2, ml::FilterKind::Cosine, ml::SamplePattern::Regular, ml::PixelFormat::Xrgb8888, 10},
      {ml::ShadingMode::Gouraud, 4, ml::FilterKind::Box, ml::SamplePattern::Jittered, ml::PixelFormat::Grey8, 16},
  };
  for (const Case& c : cases) {
    ml::RenderOptions o;
    o.shading = c.mode;
    o.aa = c.aa;
    o.filter = c.filter;
    o.samples = c.samples;
    o.output.format = c.format;
    o.output.band_rows = c.band_rows;
    const size_t need = ml::render_arena_bytes(ts.scene, cam, o);
    auto run = [&](size_t bytes) {
      Frame f;
      std::vector<uint8_t> mem(bytes, mlhost::kPoisonByte);
      ml::Arena arena(mem.data(), mem.size());
      f.status = ml::render(ts.scene, cam, o, arena, f.sink, &f.stats);
      return f;
    };
    const Frame least = run(need);
    ASSERT_TRUE(least.status.ok()) << least.status.message;
    const int bands = (cam.height + c.band_rows - 1) / c.band_rows;
    EXPECT_EQ(least.stats.render_bands, uint32_t(bands)) << "mode " << int(c.mode) << " format " << int(c.format);
    const int whole = bands * c.band_rows;
    for (int rows : {2 * c.band_rows, 3 * c.band_rows, whole, -1}) {
      o.output.render_rows = std::max(rows, 0);  // -1: as many as render_spare_bytes holds (all)
      const size_t bytes = rows < 0 ? need + ml::render_spare_bytes(ts.scene, cam, o)
                                    : need + ml::tiler_render_rows_bytes(cam, o, rows);
      const std::string where = "mode " + std::to_string(int(c.mode)) + " aa " + std::to_string(c.aa) + " format " +
                                std::to_string(int(c.format)) + " rows " + std::to_string(rows);
      const Frame f = run(bytes);
      ASSERT_TRUE(f.status.ok()) << where << ": " << f.status.message;
      ASSERT_TRUE(f.sink.contract_ok()) << where << ": " << f.sink.contract_error();
      EXPECT_FALSE(f.sink.out_of_bounds) << where;
      EXPECT_EQ(f.sink.image, least.sink.image) << where;
      EXPECT_EQ(f.sink.calls, least.sink.calls) << where;
      EXPECT_EQ(f.stats.bands, least.stats.bands) << where;
      const int at_once = rows < 0 ? whole : rows;
      EXPECT_EQ(f.stats.render_bands, uint32_t((cam.height + at_once - 1) / at_once)) << where;
      EXPECT_EQ(f.stats.triangles_drawn + f.stats.triangles_culled, uint64_t(f.stats.bsp_pieces) * f.stats.render_bands)
          << where;
      // A byte short of those rows' bytes: one band fewer at once.
      const Frame fewer = run(bytes - 1);
      ASSERT_TRUE(fewer.status.ok()) << where;
      EXPECT_EQ(fewer.sink.image, least.sink.image) << where;
      if (rows > 0) {
        EXPECT_GT(fewer.stats.render_bands, f.stats.render_bands) << where;
      }
    }
  }
}

// The tiler's own entry (what a firmware image of the tiler alone links) gives render()'s frame,
// stats and arena size, whatever options.renderer says.
TEST(TilerRender, OwnEntryMatchesRender) {
  std::mt19937 rng(78);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 60, 120));
  const ml::Camera cam = tiler_test::test_camera(96, 64);
  for (ml::ShadingMode mode : {ml::ShadingMode::Flat, ml::ShadingMode::Ids}) {
    Frame whole = render(ts.scene, cam, mode);
    ASSERT_TRUE(whole.status.ok());
    ml::RenderOptions other;
    other.shading = mode;
    other.renderer = ml::RendererKind::Scanline;  // ignored by the entry
    ml::RenderOptions plain;
    plain.shading = mode;
    const size_t bytes = ml::render_tiler_arena_bytes(ts.scene, cam, other);
    EXPECT_EQ(bytes, ml::render_arena_bytes(ts.scene, cam, plain));
    std::vector<uint8_t> mem(bytes, mlhost::kPoisonByte);
    ml::Arena arena(mem.data(), mem.size());
    Frame one;
    one.status = ml::render_tiler(ts.scene, cam, other, arena, one.sink, &one.stats);
    ASSERT_TRUE(one.status.ok());
    EXPECT_EQ(one.sink.image, whole.sink.image);
    EXPECT_EQ(one.stats.triangles_tiled, whole.stats.triangles_tiled);
    EXPECT_EQ(one.stats.sink_calls, whole.stats.sink_calls);
  }
}

// Colours: every pixel of a Flat or Gouraud frame is the colour src/shade gives its owner (from
// the Ids frame) at that pixel: flat colour, or ColorPlanes::at for smooth triangles.
TEST(TilerRender, ColoursMatchShadeForTheOwner) {
  std::mt19937 rng(77);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 80, 200));
  const ml::Camera cam = tiler_test::test_camera(160, 120);
  ml::View view;
  ASSERT_TRUE(ml::make_view(cam, &view).ok());
  const ml::Light light = ml::make_light(view);
  Frame ids = render(ts.scene, cam, ml::ShadingMode::Ids);
  ASSERT_TRUE(ids.status.ok());
  int smooth_pixels = 0;
  for (ml::ShadingMode mode : {ml::ShadingMode::Flat, ml::ShadingMode::Gouraud, ml::ShadingMode::Unlit}) {
    Frame f = render(ts.scene, cam, mode);
    ASSERT_TRUE(f.status.ok());
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) {
        const size_t i = size_t(y) * size_t(cam.width) + size_t(x);
        const ml::Pixel id = ids.sink.image[i];
        if (id == 0) {
          ASSERT_EQ(f.sink.image[i], ml::RenderOptions{}.background);
          continue;
        }
        const uint32_t tri = id - 1;
        ml::Vec3i world[3];
        ml::triangle_world(ts.scene, tri, world);
        ml::ScreenTriangle parts[ml::kMaxClipTriangles];
        ASSERT_EQ(ml::project_triangle(view, world, parts), 1);
        ml::TriangleColors colors;
        ml::shade_triangle(ts.scene, light, mode, tri, parts[0].front_facing, &colors);
        ml::Pixel expect = colors.flat;
        if (colors.smooth) {
          ml::ColorPlanes planes;
          ml::make_color_planes(parts[0], colors, &planes);
          expect = planes.at(x, y);
          ++smooth_pixels;
        }
        ASSERT_EQ(f.sink.image[i], expect) << "pixel " << x << "," << y << " mode " << int(mode);
      }
  }
  EXPECT_GT(smooth_pixels, 1000);
}

TEST(TilerRender, ScreenCoveringMeshLeavesNoBackground) {
  std::vector<tiler_test::TestScene::Tri> tris;
  const int n = 9, lo = -1500, step = 3000 / n;
  std::mt19937 rng(2);
  std::vector<int> jx((n + 1) * (n + 1)), jy((n + 1) * (n + 1));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const bool inner = i > 0 && i < n && j > 0 && j < n;
      jx[size_t(j * (n + 1) + i)] = lo + i * step + (inner ? int(rng() % 101) - 50 : 0);
      jy[size_t(j * (n + 1) + i)] = lo + j * step + (inner ? int(rng() % 101) - 50 : 0);
    }
  auto vtx = [&](int i, int j, int16_t* p) {
    p[0] = int16_t(jx[size_t(j * (n + 1) + i)]);
    p[1] = int16_t(jy[size_t(j * (n + 1) + i)]);
    p[2] = 0;
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      tiler_test::TestScene::Tri a, b;
      vtx(i, j, a.p[0]); vtx(i + 1, j, a.p[1]); vtx(i + 1, j + 1, a.p[2]);
      vtx(i, j, b.p[0]); vtx(i + 1, j + 1, b.p[1]); vtx(i, j + 1, b.p[2]);
      a.double_sided = b.double_sided = true;
      tris.push_back(a);
      tris.push_back(b);
    }
  tiler_test::TestScene ts;
  ts.build(tris);
  for (auto [w, h] : {std::pair<int, int>{320, 240}, {97, 300}}) {
    Frame f = render(ts.scene, tiler_test::test_camera(w, h), ml::ShadingMode::Ids);
    ASSERT_TRUE(f.status.ok());
    for (size_t p = 0; p < f.sink.image.size(); ++p) {
      ASSERT_EQ(f.sink.count[p], 1);
      ASSERT_NE(f.sink.image[p], 0u) << "background at pixel " << p;
    }
  }
}

// BSP pieces cut from triangles with split vertices off the triangle's edge by a world unit (as
// quantization does): the tiler clips each piece to its triangle, so a mesh of split triangles
// covers exactly what the triangles cover: ids equal brute force over the whole triangles, no
// background, every pixel once.
TEST(TilerRender, SplitPiecesCoverExactlyTheirTriangles) {
  std::vector<tiler_test::TestScene::Tri> tris;
  const int n = 6, lo = -900, step = 1800 / n;
  std::mt19937 rng(19);
  auto at = [&](int i, int j, int16_t* p) {
    const bool inner = i > 0 && i < n && j > 0 && j < n;
    p[0] = int16_t(lo + i * step + (inner ? (i * 37 + j * 11) % 61 - 30 : 0));
    p[1] = int16_t(lo + j * step + (inner ? (i * 13 + j * 29) % 61 - 30 : 0));
    p[2] = 0;
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      tiler_test::TestScene::Tri a, b;
      at(i, j, a.p[0]); at(i + 1, j, a.p[1]); at(i + 1, j + 1, a.p[2]);
      at(i, j, b.p[0]); at(i + 1, j + 1, b.p[1]); at(i, j + 1, b.p[2]);
      tris.push_back(a);
      tris.push_back(b);
    }
  tiler_test::TestScene ts;
  ts.build(tris);
  // Split every triangle from vertex 0 to a point near the middle of edge 1-2, off it by one unit
  // across the edge, alternately inside and outside.
  std::vector<ml::BspPiece> pieces;
  for (uint32_t t = 0; t < ts.triangles.size(); ++t) {
    const ml::Triangle& tri = ts.triangles[t];
    const int16_t* b = ts.vertices[tri.v[1]].position;
    const int16_t* c = ts.vertices[tri.v[2]].position;
    ml::Vertex m = ts.vertices[tri.v[1]];
    m.position[0] = int16_t((b[0] + c[0]) / 2 + ((t % 2) ? 1 : -1) * (c[1] > b[1] ? 1 : -1));
    m.position[1] = int16_t((b[1] + c[1]) / 2 + ((t % 2) ? 1 : -1) * (c[0] > b[0] ? -1 : 1));
    const uint32_t mi = uint32_t(ts.vertices.size());
    ts.vertices.push_back(m);
    pieces.push_back(ml::BspPiece{{tri.v[0], tri.v[1], mi}, t});
    pieces.push_back(ml::BspPiece{{tri.v[0], mi, tri.v[2]}, t});
  }
  ts.pieces = pieces;
  ASSERT_EQ(ts.nodes.size(), 1u);
  ts.nodes[0].first_piece = 0;
  ts.nodes[0].piece_count = uint32_t(pieces.size());
  ts.nodes[0].subtree_pieces = uint32_t(pieces.size());
  for (const ml::Vertex& v : ts.vertices)
    for (int a = 0; a < 3; ++a) {
      ts.nodes[0].bounds_min[a] = std::min<int32_t>(ts.nodes[0].bounds_min[a], v.position[a]);
      ts.nodes[0].bounds_max[a] = std::max<int32_t>(ts.nodes[0].bounds_max[a], v.position[a]);
    }
  ts.pack();
  ASSERT_TRUE(ts.status.ok()) << ts.status.message;
  for (auto [w, h] : {std::pair<int, int>{160, 120}, {320, 240}, {97, 131}}) {
    const ml::Camera cam = tiler_test::test_camera(w, h);
    Frame f = render(ts.scene, cam, ml::ShadingMode::Ids);
    ASSERT_TRUE(f.status.ok()) << f.status.message;
    ml::View view;
    ASSERT_TRUE(ml::make_view(cam, &view).ok());
    std::vector<ml::Pixel> expect(size_t(w) * size_t(h), 0);
    for (uint32_t t = 0; t < ts.triangles.size(); ++t) {
      ml::Vec3i world[3];
      ml::triangle_world(ts.scene, t, world);
      ml::ScreenTriangle parts[ml::kMaxClipTriangles];
      ASSERT_EQ(ml::project_triangle(view, world, parts), 1);
      ml::TriangleSetup s;
      ml::setup_triangle(parts[0], w, h, &s);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          if (ml::covers_pixel(s, x, y)) {
            ASSERT_EQ(expect[size_t(y) * size_t(w) + size_t(x)], 0u) << "mesh overlaps";
            expect[size_t(y) * size_t(w) + size_t(x)] = t + 1;
          }
    }
    for (size_t p = 0; p < expect.size(); ++p) {
      ASSERT_EQ(f.sink.count[p], 1);
      ASSERT_NE(expect[p], 0u) << "test mesh must cover the screen";
      ASSERT_EQ(f.sink.image[p], expect[p]) << "pixel " << p % size_t(w) << "," << p / size_t(w) << " at " << w << "x" << h;
    }
  }
}

TEST(TilerRender, ArenaTooSmallNamesBytesAndWritesNothing) {
  std::mt19937 rng(6);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 30, 100));
  const ml::Camera cam = tiler_test::test_camera(320, 240);
  const ml::RenderOptions defaults;
  const size_t need = ml::render_arena_bytes(ts.scene, cam, defaults);
  const size_t bands = ml::BandOutput::arena_bytes(defaults.output, 320, 240);
  EXPECT_EQ(bands, 320u * 16u * 4u + 3u);                // one 16-row XRGB8888 band, worst-case alignment
  EXPECT_LT(need - bands, 2u * 1024u);  // the band's pyramid, the BSP stack and a row of colours
  for (size_t give : {size_t(0), size_t(100), need - 1}) {
    Frame f = render(ts.scene, cam, ml::ShadingMode::Flat, nullptr, give ? give : 1);
    EXPECT_EQ(f.status.code, ml::StatusCode::ArenaTooSmall);
    EXPECT_EQ(f.status.value, need);
    EXPECT_EQ(f.sink.begins, 0);
    EXPECT_EQ(f.sink.calls, 0);
  }
  Frame ok = render(ts.scene, cam, ml::ShadingMode::Flat, nullptr, need);
  EXPECT_TRUE(ok.status.ok());
  EXPECT_LE(ok.stats.peak_arena_bytes, need);
  EXPECT_EQ(ok.stats.pyramid_bytes, 736u);  // 320x16: 1 + 5 triage masks, 80 blocks
  // The whole frame as one band: the pyramid of the full screen.
  ml::OutputOptions whole;
  whole.band_rows = 0;
  Frame one = render(ts.scene, cam, ml::ShadingMode::Flat, nullptr, 0, whole);
  EXPECT_TRUE(one.status.ok());
  EXPECT_EQ(one.stats.pyramid_bytes, 9936u);
}

TEST(TilerRender, SceneWithoutBspIsUnsupported) {
  std::mt19937 rng(6);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 5, 100));
  ts.scene.bsp_node_count = 0;
  Frame f = render(ts.scene, tiler_test::test_camera(64, 64), ml::ShadingMode::Flat);
  EXPECT_EQ(f.status.code, ml::StatusCode::Unsupported);
  EXPECT_EQ(f.sink.calls, 0);
}

TEST(TilerRender, WorkImageSumsToCellsVisited) {
  std::mt19937 rng(14);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 60, 150));
  const int w = 200, h = 150;  // not multiples of 64: partly off-screen cells
  std::vector<uint32_t> q16(size_t(w) * size_t(h), 0);
  ml::WorkImage work;
  work.q16 = q16.data();
  work.width = w;
  work.height = h;
  Frame f = render(ts.scene, tiler_test::test_camera(w, h), ml::ShadingMode::Flat, &work);
  ASSERT_TRUE(f.status.ok());
  uint64_t sum = 0;
  for (uint32_t v : q16) sum += v;
  // Each visit adds floor(65536 / on-screen pixels) to each on-screen pixel: just under 65536.
  EXPECT_LE(sum, f.stats.cells_visited * 65536u);
  EXPECT_GE(sum, f.stats.cells_visited * 65536u - f.stats.cells_visited * uint64_t(w) * h / 1000 - f.stats.cells_visited * 4096u);
  EXPECT_GT(f.stats.cells_visited, 0u);
}

TEST(TilerRender, BackFacesCulledUnlessDoubleSided) {
  // One single-sided triangle facing away from the camera, one double-sided facing away.
  tiler_test::TestScene::Tri a, b;
  const int16_t cw[3][2] = {{-400, -400}, {-400, 400}, {400, -400}};  // clockwise seen from +z
  for (int i = 0; i < 3; ++i) {
    a.p[i][0] = cw[i][0]; a.p[i][1] = cw[i][1]; a.p[i][2] = 0;
    b.p[i][0] = int16_t(cw[i][0] / 2); b.p[i][1] = int16_t(cw[i][1] / 2); b.p[i][2] = 100;
  }
  a.double_sided = false;
  b.double_sided = true;
  tiler_test::TestScene ts;
  ts.build({a, b});
  ml::OutputOptions one_band;
  one_band.band_rows = 0;
  Frame f = render(ts.scene, tiler_test::test_camera(120, 90), ml::ShadingMode::Ids, nullptr, 0, one_band);
  ASSERT_TRUE(f.status.ok());
  EXPECT_EQ(f.stats.triangles_drawn, 1u);
  EXPECT_EQ(f.stats.triangles_culled, 1u);
  for (ml::Pixel p : f.sink.image) EXPECT_NE(p, 1u);  // triangle 0 never shows
}


// The same scene with every BSP subtree box widened to the whole world range: the eye is inside every
// box, so no subtree can be culled (the tiler's reference for "culling off").
// The packed nodes are copied with every box set to the whole grid, and the grid (origin and cell in
// a copy of SceneInfo) to [-2^19, 2^19).
struct Unculled {
  std::vector<uint8_t> nodes;
  ml::SceneInfo info;
  ml::Scene scene;
  explicit Unculled(const ml::Scene& s) : info(*s.info), scene(s) {
    widen(s.wide ? sizeof(ml::PackedBspNode<uint32_t>) : sizeof(ml::PackedBspNode<uint16_t>),
          s.wide ? offsetof(ml::PackedBspNode<uint32_t>, cells) : offsetof(ml::PackedBspNode<uint16_t>, cells));
    for (int a = 0; a < 3; ++a) info.bounds_min[a] = -(1 << 19);
    scene.info = &info;
    scene.bounds_shift = 12;
    scene.bsp_nodes = nodes.data();
  }
  void widen(size_t node_bytes, size_t cells_at) {
    const uint8_t* src = static_cast<const uint8_t*>(scene.bsp_nodes);
    nodes.assign(src, src + node_bytes * scene.bsp_node_count);
    for (size_t i = 0; i < scene.bsp_node_count; ++i)
      for (int k = 0; k < 6; ++k) nodes[i * node_bytes + cells_at + size_t(k)] = k < 3 ? 0 : 255;
  }
};

void expect_same_frame(const Frame& culled, const Frame& plain, const ml::Camera& cam) {
  ASSERT_TRUE(culled.status.ok()) << culled.status.message;
  ASSERT_TRUE(plain.status.ok()) << plain.status.message;
  ASSERT_FALSE(culled.sink.out_of_bounds);
  for (int c : culled.sink.count) ASSERT_EQ(c, 1);
  EXPECT_EQ(plain.stats.bsp_subtrees_culled, 0u);
  EXPECT_EQ(culled.stats.triangles_drawn, plain.stats.triangles_drawn);
  EXPECT_EQ(culled.stats.triangles_drawn + culled.stats.triangles_culled, uint64_t(culled.stats.bsp_pieces) * culled.stats.render_bands);
  for (size_t p = 0; p < culled.sink.image.size(); ++p)
    ASSERT_EQ(culled.sink.image[p], plain.sink.image[p]) << "pixel " << p % size_t(cam.width) << ","
                                                          << p / size_t(cam.width);
}

// Subtree culling: triangles on the left, behind a wall that hides the left half of the screen, sit
// in subtrees the tiler skips whole; the image still equals brute force and the unculled render.
TEST(TilerCull, HiddenSubtreesAreSkippedWithoutChangingTheImage) {
  std::mt19937 rng(5);
  std::vector<tiler_test::TestScene::Tri> tris = tiler_test::random_scene(rng, 200, 60);
  for (auto& t : tris)
    for (auto& p : t.p) p[0] = int16_t(-250 - std::abs(p[0]) / 2);  // x in [-640, -250]
  // The wall at z = 400 (camera at z = 1000): x <= -20, so it hides everything above on screen.
  tiler_test::TestScene::Tri w0, w1;
  const int16_t wall[4][2] = {{-3000, -3000}, {-20, -3000}, {-20, 3000}, {-3000, 3000}};
  for (int i = 0; i < 3; ++i) {
    const int a = i, b = i == 0 ? 0 : i + 1;
    w0.p[i][0] = wall[a][0]; w0.p[i][1] = wall[a][1]; w0.p[i][2] = 400;
    w1.p[i][0] = wall[b][0]; w1.p[i][1] = wall[b][1]; w1.p[i][2] = 400;
  }
  tris.push_back(w0);
  tris.push_back(w1);
  // Something visible on the right, in front of and behind the wall's plane.
  for (int z : {450, 100}) {
    tiler_test::TestScene::Tri t;
    const int16_t v[3][2] = {{100, -200}, {400, -200}, {250, 200}};
    for (int i = 0; i < 3; ++i) {
      t.p[i][0] = v[i][0]; t.p[i][1] = int16_t(v[i][1] + (z == 100 ? 150 : 0)); t.p[i][2] = int16_t(z);
    }
    tris.push_back(t);
  }
  tiler_test::TestScene ts;
  ts.build(tris);
  for (auto [w, h] : {std::pair<int, int>{320, 240}, {101, 77}}) {
    const ml::Camera cam = tiler_test::test_camera(w, h);
    const Unculled plain(ts.scene);
    const Frame culled = render(ts.scene, cam, ml::ShadingMode::Ids);
    const Frame reference = render(plain.scene, cam, ml::ShadingMode::Ids);
    expect_same_frame(culled, reference, cam);
    EXPECT_GT(culled.stats.bsp_subtrees_culled, 0u);
    const auto expect = brute_ids(ts, cam);
    for (size_t p = 0; p < expect.size(); ++p) ASSERT_EQ(culled.sink.image[p], expect[p]) << "pixel " << p;
  }
}

// The occluded office (the benchmark scene): most subtrees are culled from the hint camera, and for
// it and orbiting cameras (partly outside, partly inside the rooms) the image equals the unculled one.
TEST(TilerCull, OfficeMatchesUnculledRender) {
  const ml::CompileResult r = ml::build_office_scene(4);
  ASSERT_TRUE(r.ok) << r.error;
  ml::Scene s;
  ASSERT_TRUE(ml::read_scene(r.blob.data(), r.blob.size, &s).ok());
  const Unculled plain(s);
  std::vector<ml::Camera> cams;
  cams.push_back(hint_camera(r, s, 320, 240));
  cams.push_back(hint_camera(r, s, 133, 97));
  const ml::Vec3i c{s.info->sphere_center[0], s.info->sphere_center[1], s.info->sphere_center[2]};
  for (int k = 0; k < 6; ++k) {
    ml::Camera cam = hint_camera(r, s, 160, 120);
    // Orbit around the centre at several distances, some inside the bounding sphere.
    const int32_t rad = s.info->sphere_radius * (k % 3 + 1) / 2;
    const int32_t ox = (k & 1) ? rad : -rad / 2, oz = (k & 2) ? rad / 2 : -rad;
    cam.eye = ml::Vec3i{c.x + ox, c.y + rad / 4, c.z + oz};
    cam.target = c;
    cam.up = ml::Vec3i{0, 1, 0};
    cams.push_back(cam);
  }
  uint32_t culled_total = 0;
  for (const ml::Camera& cam : cams) {
    const Frame culled = render(s, cam, ml::ShadingMode::Ids);
    const Frame reference = render(plain.scene, cam, ml::ShadingMode::Ids);
    expect_same_frame(culled, reference, cam);
    culled_total += culled.stats.bsp_subtrees_culled;
  }
  const Frame hint = render(s, cams[0], ml::ShadingMode::Flat);
  ASSERT_TRUE(hint.status.ok());
  EXPECT_GT(hint.stats.bsp_subtrees_culled, 0u);
  EXPECT_GT(culled_total, hint.stats.bsp_subtrees_culled);
}

// One frame in the least arena, or with the spare bytes too, the arena poisoned first.
Frame render_frame(const ml::Scene& s, const ml::Camera& cam, const ml::RenderOptions& opt, bool spare) {
  Frame f;
  const size_t bytes = ml::render_arena_bytes(s, cam, opt) + (spare ? ml::render_spare_bytes(s, cam, opt) : 0);
  std::vector<uint8_t> mem(bytes, mlhost::kPoisonByte);
  ml::Arena arena(mem.data(), mem.size());
  f.status = ml::render(s, cam, opt, arena, f.sink, &f.stats);
  return f;
}

// Culled and unculled frames of a scene from one camera, 8-row bands, with and without the band plan
// (the arena's spare bytes; each has its own threshold): equal images; returns the subtrees culled.
uint32_t expect_same_with_and_without_plan(const ml::Scene& scene, const ml::Camera& cam) {
  const Unculled plain(scene);
  uint32_t culled_total = 0;
  // The least arena; the spare bytes with one band at a time (the plan), and with every band at once.
  for (auto [spare, render_rows] : {std::pair<bool, int>{false, 0}, {true, 8}, {true, 0}}) {
    ml::RenderOptions opt;
    opt.shading = ml::ShadingMode::Ids;
    opt.output.band_rows = 8;
    opt.output.render_rows = render_rows;
    const Frame culled = render_frame(scene, cam, opt, spare);
    expect_same_frame(culled, render_frame(plain.scene, cam, opt, spare), cam);
    culled_total += culled.stats.bsp_subtrees_culled;
  }
  return culled_total;
}

// The subtree test (the box's view-space bounds) on random scenes and the compiled office, seen from
// random eyes, some among the triangles and close to them, some outside: every culled frame equals
// the unculled one, and the eyes together cull subtrees.
TEST(TilerCull, RandomEyesWithBandsAndPlanMatchUnculledRender) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> coord(-1400, 1400);
  auto random_camera = [&](int k, const ml::Vec3i& centre, int32_t radius) {
    ml::Camera cam = tiler_test::test_camera(k % 2 ? 160 : 97, k % 2 ? 120 : 133);
    const int64_t reach = k < 2 ? radius / 2 : radius * 2;  // among the triangles, or outside
    auto at = [&](int32_t c) { return int32_t(c + coord(rng) * reach / 1400); };
    cam.eye = ml::Vec3i{at(centre.x), at(centre.y), at(centre.z)};
    cam.target = ml::Vec3i{centre.x + coord(rng) * radius / 8000, centre.y, centre.z + coord(rng) * radius / 8000};
    if (cam.eye.x == cam.target.x && cam.eye.z == cam.target.z) cam.eye.x += 1 + radius / 10;
    cam.near = std::max(1, radius / 1024);
    return cam;
  };
  uint32_t culled_total = 0;
  for (int rep = 0; rep < 4; ++rep) {
    tiler_test::TestScene ts;
    ts.build(tiler_test::random_scene(rng, 150 + rep * 20, 120));
    for (int k = 0; k < 4; ++k) culled_total += expect_same_with_and_without_plan(ts.scene, random_camera(k, ml::Vec3i{0, 0, 0}, 900));
  }
  const ml::CompileResult r = ml::build_office_scene(4);
  ASSERT_TRUE(r.ok) << r.error;
  ml::Scene s;
  ASSERT_TRUE(ml::read_scene(r.blob.data(), r.blob.size, &s).ok());
  const ml::Vec3i c{s.info->sphere_center[0], s.info->sphere_center[1], s.info->sphere_center[2]};
  for (int k = 0; k < 8; ++k) culled_total += expect_same_with_and_without_plan(s, random_camera(k, c, s.info->sphere_radius));
  EXPECT_GT(culled_total, 0u);
}

// The host's subtree rectangle (corner_rect) keeps one pixel of margin, for the pixel a split piece's
// box may grow by: with antialiasing too (regular and jittered samples, box and cosine filters, each
// rounding a piece's box to samples its own way), in one band and a band at a time with and without
// the kept rectangles, culled frames equal unculled ones.
TEST(TilerCull, AntialiasedFramesMatchUnculledRender) {
  const ml::CompileResult r = ml::build_office_scene(4);
  ASSERT_TRUE(r.ok) << r.error;
  ml::Scene office;
  ASSERT_TRUE(ml::read_scene(r.blob.data(), r.blob.size, &office).ok());
  std::mt19937 rng(23);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 160, 120));
  const std::vector<std::pair<const ml::Scene*, ml::Camera>> views = {
      {&office, hint_camera(r, office, 120, 90)}, {&office, hint_camera(r, office, 97, 71)},
      {&ts.scene, tiler_test::test_camera(101, 77)}};
  uint32_t culled_total = 0;
  for (const auto& [scene, cam] : views) {
    const Unculled plain(*scene);
    for (int variant = 0; variant < 9; ++variant) {
      ml::RenderOptions opt;
      opt.aa = variant % 3 == 0 ? 2 : variant % 3 == 1 ? 4 : 8;
      opt.samples = variant % 3 == 1 ? ml::SamplePattern::Regular : ml::SamplePattern::Jittered;
      opt.filter = variant % 3 == 2 ? ml::FilterKind::Cosine : ml::FilterKind::Box;
      const bool spare = variant < 6;  // the least arena: no kept rectangles
      opt.output.band_rows = variant < 3 ? 16 : 8;
      opt.output.render_rows = variant < 3 ? 0 : 8;
      const Frame culled = render_frame(*scene, cam, opt, spare);
      expect_same_frame(culled, render_frame(plain.scene, cam, opt, spare), cam);
      culled_total += culled.stats.bsp_subtrees_culled;
    }
  }
  EXPECT_GT(culled_total, 0u);
}

}  // namespace

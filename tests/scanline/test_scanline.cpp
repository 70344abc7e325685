// Tests of the scanline renderer (src/scanline): sorts, 128-bit helpers, streaming contract, arena
// sizing, exact coverage against src/view, depth order, blending, hidden lines, antialiasing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <map>
#include <set>
#include <cstring>
#include <vector>

#include "core/arena.h"
#include "platform/host/image_sink.h"
#include "core/band.h"
#include "render/render.h"
#include "scanline/internal.h"
#include "scanline/scanline.h"
#include "scanline/sort.h"
#include "scanline/wide.h"
#include "tests/scanline/blob_builder.h"
#include "view/view.h"

namespace {

using scantest::BuiltScene;
using scantest::Material;
using scantest::Prim;

// The host's checking sink, recording which pixel rows arrive in which order, and the image.
struct RecordingSink : mlhost::ImageSink {
  int begins = 0, ends = 0, fills = 0, bad_calls = 0;
  int width = 0, height = 0;
  std::vector<int> rows;
  std::vector<ml::Pixel> image;
  bool begin_frame(const ml::FrameInfo& f) override {
    ++begins;
    width = f.width;
    height = f.height;
    image.assign(size_t(width) * size_t(height), 0xDEADBEEF);
    return ImageSink::begin_frame(f);
  }
  bool flush(const ml::Flush& b) override {
    if (b.x != 0 || b.width != width || b.y < 0 || b.y + b.height > height) { ++bad_calls; return true; }
    for (int r = 0; r < b.height; ++r) rows.push_back(b.y + r);
    const bool ok = ImageSink::flush(b);
    for (int r = 0; r < b.height; ++r)
      for (int x = 0; x < width; ++x) image[size_t(b.y + r) * size_t(width) + size_t(x)] = ImageSink::at(x, b.y + r);
    return ok;
  }
  bool end_frame() override { ++ends; return ImageSink::end_frame(); }
  ml::Pixel at(int x, int y) const { return image[size_t(y) * size_t(width) + size_t(x)]; }
  size_t calls() const { return size_t(begins + ends + fills) + rows.size(); }
};

struct Result {
  ml::Status status;
  ml::Stats stats;
  RecordingSink sink;
  size_t bytes = 0;
};

ml::RenderOptions options(ml::ShadingMode mode, int aa = 1, uint32_t seed = 1) {
  ml::RenderOptions o;
  o.renderer = ml::RendererKind::Scanline;
  o.shading = mode;
  o.aa = aa;
  o.seed = seed;
  o.background = 0x102030;
  return o;
}

void render(const ml::Scene& scene, const ml::Camera& cam, const ml::RenderOptions& o, Result* r) {
  r->bytes = ml::render_arena_bytes(scene, cam, o);
  std::vector<uint64_t> storage(r->bytes / 8 + 2);
  ml::Arena arena(storage.data(), r->bytes);
  r->status = ml::render(scene, cam, o, arena, r->sink, &r->stats);
}

ml::Camera camera_at(ml::Vec3i eye, ml::Vec3i target, int w, int h, int32_t near = 16) {
  ml::Camera c;
  c.eye = eye;
  c.target = target;
  c.up = ml::Vec3i{0, 1, 0};
  c.fov_deg_q16 = 50 << 16;
  c.near = near;
  c.width = w;
  c.height = h;
  return c;
}

// Expected id image at 1x1 from src/view alone: per pixel, the covering piece with the largest
// depth computed in double (ties: smaller id); used where one triangle or no overlap is involved.
std::vector<uint32_t> coverage_ids(const ml::Scene& scene, const ml::Camera& cam, std::vector<int>* count) {
  ml::View view;
  EXPECT_TRUE(ml::make_view(cam, &view).ok());
  std::vector<uint32_t> ids(size_t(cam.width) * size_t(cam.height), 0);
  count->assign(ids.size(), 0);
  for (uint32_t id = 0; id < scene.triangle_count; ++id) {
    const ml::Material& m = scene.materials[scene.batches[ml::triangle_at(scene, id).batch].material];
    ml::Vec3i w[3];
    ml::triangle_world(scene, id, w);
    ml::ScreenTriangle pieces[ml::kMaxClipTriangles];
    const int n = ml::project_triangle(view, w, pieces);
    for (int k = 0; k < n; ++k) {
      if (!pieces[k].front_facing && !m.double_sided) continue;
      ml::TriangleSetup s;
      ml::setup_triangle(pieces[k], cam.width, cam.height, &s);
      for (int y = s.min_y; y <= s.max_y; ++y)
        for (int x = s.min_x; x <= s.max_x; ++x)
          if (ml::covers_pixel(s, x, y)) {
            ids[size_t(y) * size_t(cam.width) + size_t(x)] = id + 1;
            (*count)[size_t(y) * size_t(cam.width) + size_t(x)]++;
          }
    }
  }
  return ids;
}

// A smooth UV sphere (normals = positions / r), counter-clockwise seen from outside.
Prim sphere(int32_t r, int stacks, int slices, ml::Vec3i c = {0, 0, 0}) {
  Prim p;
  for (int i = 0; i <= stacks; ++i) {
    const double th = M_PI * i / stacks;
    for (int j = 0; j <= slices; ++j) {
      const double ph = 2 * M_PI * j / slices;
      const double n[3] = {std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)};
      p.pos.push_back({c.x + int32_t(std::lround(r * n[0])), c.y + int32_t(std::lround(r * n[1])),
                       c.z + int32_t(std::lround(r * n[2]))});
      p.normal.push_back({n[0], n[1], n[2]});
    }
  }
  for (int i = 0; i < stacks; ++i)
    for (int j = 0; j < slices; ++j) {
      const uint32_t a = uint32_t(i * (slices + 1) + j), b = a + uint32_t(slices + 1);
      if (i != 0) p.tris.push_back({a, a + 1, b});
      if (i != stacks - 1) p.tris.push_back({a + 1, b + 1, b});
    }
  return p;
}

// An axis-aligned cube, counter-clockwise seen from outside, two triangles per face.
Prim cube(int32_t h) {
  Prim p;
  for (int i = 0; i < 8; ++i) p.pos.push_back({(i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? h : -h});
  const uint32_t f[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : f) {
    p.tris.push_back({q[0], q[1], q[2]});
    p.tris.push_back({q[0], q[2], q[3]});
  }
  return p;
}

// ---- sorts -------------------------------------------------------------------------------------

std::vector<std::vector<uint16_t>> key_sets(std::mt19937& rng, uint32_t n) {
  std::vector<uint16_t> random(n), few(n), sorted, reversed, equal(n, 7);
  for (auto& v : random) v = uint16_t(rng());
  for (auto& v : few) v = uint16_t(rng() % 4);
  sorted = random;
  std::sort(sorted.begin(), sorted.end());
  reversed = sorted;
  std::reverse(reversed.begin(), reversed.end());
  std::vector<uint16_t> organ = sorted;  // ascending then descending
  std::reverse(organ.begin() + n / 2, organ.end());
  return {random, few, sorted, reversed, equal, organ};
}

TEST(ScanlineSort, QuickSortMatchesStdSort) {
  std::mt19937 rng(3);
  for (uint32_t n : {0u, 1u, 2u, 3u, 11u, 12u, 13u, 50u, 257u, 1000u, 20000u}) {
    for (auto keys : key_sets(rng, n)) {
      struct E { uint16_t k; uint32_t tag; };
      std::vector<E> a;
      for (uint32_t i = 0; i < n; ++i) a.push_back(E{keys[i], i});
      uint64_t work = 0;
      ml::scan::quick_sort(a.data(), n, [](const E& e) { return e.k; }, &work);
      std::vector<uint16_t> expect = keys;
      std::sort(expect.begin(), expect.end());
      std::vector<uint32_t> tags;
      for (uint32_t i = 0; i < n; ++i) {
        ASSERT_EQ(a[i].k, expect[i]) << "n=" << n << " i=" << i;
        tags.push_back(a[i].tag);
      }
      std::sort(tags.begin(), tags.end());
      for (uint32_t i = 0; i < n; ++i) {
        ASSERT_EQ(tags[i], i);  // a permutation
      }
      if (n > 1) {
        EXPECT_GT(work, 0u);
      }
      // O(n log n) even for equal keys: a generous bound on the counted work.
      EXPECT_LE(work, uint64_t(20) * n * (1 + uint64_t(std::log2(n + 1))) + 64);
    }
  }
}

TEST(ScanlineSort, HeapAndInsertionSortMatchStdSort) {
  std::mt19937 rng(5);
  for (uint32_t n : {0u, 1u, 2u, 5u, 47u, 48u, 49u, 300u, 5000u}) {
    for (auto keys : key_sets(rng, n)) {
      for (int variant = 0; variant < 3; ++variant) {
        std::vector<uint32_t> idx(n);
        for (uint32_t i = 0; i < n; ++i) idx[i] = i;
        uint64_t work = 0;
        auto key = [&](uint32_t i) { return keys[i]; };
        if (variant == 0) ml::scan::heap_sort(idx.data(), n, key, &work);
        else if (variant == 1) ml::scan::active_sort(idx.data(), n, key, &work);
        else if (n <= 5000) ml::scan::insertion_sort(idx.data(), n, key, &work);
        std::vector<uint16_t> got, expect = keys;
        for (uint32_t i : idx) got.push_back(keys[i]);
        std::sort(expect.begin(), expect.end());
        ASSERT_EQ(got, expect) << "variant " << variant << " n=" << n;
      }
    }
  }
}

TEST(ScanlineWide, PortableMatchesInt128) {
  std::mt19937_64 rng(11);
  for (int it = 0; it < 20000; ++it) {
    int64_t a[3], b[3];
    for (int i = 0; i < 3; ++i) {
      a[i] = int64_t(rng() >> (33 + rng() % 30)) * ((rng() & 1) ? 1 : -1);
      b[i] = int64_t(rng() >> (14 + rng() % 48)) * ((rng() & 1) ? 1 : -1);
    }
    const int shift = int(rng() % 25);
    const int64_t d = int64_t(rng() >> (2 + rng() % 61)) + 1;  // up to 2^62
    __int128 n = 0;
    for (int i = 0; i < 3; ++i) n += static_cast<__int128>(a[i]) * b[i];
    n *= static_cast<__int128>(1) << shift;
    const __int128 q = n >= 0 ? (n + d / 2) / d : -((-n + d / 2) / d);
    ASSERT_EQ(ml::scan::mul_add3_div_round_low_portable(a, b, shift, d), uint64_t(q)) << it;
    ASSERT_EQ(ml::scan::mul_add3_div_round_low(a, b, shift, d), uint64_t(q)) << it;
  }
  // Sums that fit int64, up to its limits, and divisors about the 64-bit path's bound 2^(62 - shift):
  // both sides of it, and quotients whose low 64 bits wrap.
  for (int it = 0; it < 200000; ++it) {
    int64_t a[3], b[3];
    for (int i = 0; i < 3; ++i) {
      a[i] = int64_t(rng() >> (33 + rng() % 31)) * ((rng() & 1) ? 1 : -1);
      b[i] = int64_t(rng() >> (33 + rng() % 31)) * ((rng() & 1) ? 1 : -1);
    }
    if (it % 5 == 0) a[0] = b[0] = INT32_MAX, a[1] = b[1] = INT32_MIN, a[2] = (it & 8) ? 1 : -1;
    const int shift = it % 25;
    const int bound = 62 - shift, e = std::max(0, bound - 3 + int(rng() % 6));
    const int64_t d = e >= 63 ? INT64_MAX : std::max<int64_t>(1, (int64_t(1) << e) + int64_t(rng() % 5) - 2);
    __int128 n = 0;
    for (int i = 0; i < 3; ++i) n += static_cast<__int128>(a[i]) * b[i];
    n *= static_cast<__int128>(1) << shift;
    const __int128 q = n >= 0 ? (n + d / 2) / d : -((-n + d / 2) / d);
    ASSERT_EQ(ml::scan::mul_add3_div_round_low(a, b, shift, d), uint64_t(q)) << it;
    const int64_t small_d = int64_t(rng() % 1000) + 1;  // large quotients: the low bits wrap
    const __int128 qs = n >= 0 ? (n + small_d / 2) / small_d : -((-n + small_d / 2) / small_d);
    ASSERT_EQ(ml::scan::mul_add3_div_round_low(a, b, shift, small_d), uint64_t(qs)) << it;
    ASSERT_EQ(ml::scan::mul_add3_div_round_low_portable(a, b, shift, small_d), uint64_t(qs)) << it;
  }
}

// The portable 128-by-64-bit division against __int128: random and extreme divisors (1, a single
// top bit, all ones) and numerators up to the largest allowed high word (v - 1).
TEST(ScanlineWide, Divide128By64MatchesInt128) {
  std::mt19937_64 rng(12);
  const uint64_t edges[] = {1, 2, 3, 0xFFFFFFFFu, uint64_t(1) << 32, (uint64_t(1) << 32) + 1,
                            uint64_t(1) << 63, ~uint64_t(0), (uint64_t(1) << 63) - 1};
  for (int it = 0; it < 200000; ++it) {
    uint64_t v = it < 9 * 4 ? edges[it / 4] : rng() >> (rng() % 64);
    if (v == 0) v = 1;
    uint64_t u1 = 0;
    switch (it % 4) {
      case 0: u1 = 0; break;
      case 1: u1 = v - 1; break;
      default: u1 = rng() % v; break;
    }
    const uint64_t u0 = (it % 7 == 0) ? ~uint64_t(0) : rng();
    const unsigned __int128 n = (static_cast<unsigned __int128>(u1) << 64) | u0;
    uint64_t r = 0;
    const uint64_t q = ml::scan::udiv_128_64(u1, u0, v, &r);
    ASSERT_EQ(q, uint64_t(n / v)) << it << " " << u1 << " " << u0 << " " << v;
    ASSERT_EQ(r, uint64_t(n % v)) << it;
  }
}

// Where a run's surface loses to a rival: the hosts' division gives the boards' stepped sample, for
// leads lost at once, exactly on a sample (ties either way), between samples, at the last sample, past
// it, and far past it (the division's quotient beyond int32).
TEST(ScanlineMath, LeadLostByDivisionMatchesSteps) {
  const struct { int64_t lead, step; } cases[] = {
      {-1, -1}, {0, -1}, {1, -1}, {6, -3}, {7, -3}, {8, -3}, {9, -3}, {100, -1}, {99, -100}, {100, -100},
      {101, -100}, {int64_t(1) << 46, -1}, {(int64_t(1) << 46) - 1, -(int64_t(1) << 47)},
  };
  for (const auto& c : cases)
    for (bool ties : {false, true})
      for (int32_t stop : {0, 1, 2, 3, 5, 50, 101, 1000}) {
        EXPECT_EQ(ml::scan::lead_lost_divided(c.lead, c.step, ties, 0, stop),
                  ml::scan::lead_lost_stepped(c.lead, c.step, ties, 0, stop))
            << c.lead << " " << c.step << " " << ties << " " << stop;
        EXPECT_EQ(ml::scan::lead_lost_divided(c.lead, c.step, ties, 7, stop + 7),
                  ml::scan::lead_lost_stepped(c.lead, c.step, ties, 7, stop + 7));
      }
  std::mt19937_64 rng(11);
  for (int i = 0; i < 20000; ++i) {
    const int64_t step = -int64_t(1 + rng() % (uint64_t(1) << (1 + rng() % 47)));
    // leads around a multiple of the step, so that exact crossings and ties come up often
    const int64_t lead = -step * int64_t(rng() % 600) + int64_t(rng() % 5) - 2;
    const bool ties = rng() & 1;
    const int32_t from = int32_t(rng() % 2000), stop = from + int32_t(rng() % 700) - 1;
    ASSERT_EQ(ml::scan::lead_lost_divided(lead, step, ties, from, stop),
              ml::scan::lead_lost_stepped(lead, step, ties, from, stop))
        << lead << " " << step << " " << ties << " " << from << " " << stop;
  }
}

TEST(ScanlineMath, NormalsRenormalizeWithNewton) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int it = 0; it < 2000; ++it) {
    int16_t n[3][3];
    double d[3][3];
    for (int j = 0; j < 3; ++j) {
      double v[3] = {0.4 * u(rng), 0.4 * u(rng), 1};  // neighbouring normals of a tessellated smooth surface
      const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      for (int k = 0; k < 3; ++k) { d[j][k] = v[k] / l; n[j][k] = int16_t(std::lround(d[j][k] * 16384)); }
    }
    int32_t w[3] = {int32_t(rng() % 30000), int32_t(rng() % 30000), 0};
    w[2] = 65536 - w[0] - w[1];
    const ml::Vec3i r = ml::scan::interpolate_normal(n, w);
    double ref[3] = {0, 0, 0};
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) ref[k] += d[j][k] * w[j] / 65536.0;
    const double l = std::sqrt(ref[0] * ref[0] + ref[1] * ref[1] + ref[2] * ref[2]);
    EXPECT_NEAR(r.x / 16384.0, ref[0] / l, 4e-3);
    EXPECT_NEAR(r.y / 16384.0, ref[1] / l, 4e-3);
    EXPECT_NEAR(r.z / 16384.0, ref[2] / l, 4e-3);
  }
}

// ---- streaming, arena, stats -----------------------------------------------------------------------

BuiltScene sphere_scene(int stacks = 24, int slices = 48) {
  BuiltScene b;
  Material m;
  scantest::build({m}, {sphere(1000, stacks, slices)}, &b);
  EXPECT_TRUE(b.status.ok()) << b.status.message;
  return b;
}

TEST(ScanlineRender, RowsArriveOnceInOrder) {
  BuiltScene b = sphere_scene();
  const ml::Camera cam = camera_at({0, 300, 3000}, {0, 0, 0}, 97, 61);
  for (ml::ShadingMode mode : {ml::ShadingMode::Flat, ml::ShadingMode::Gouraud, ml::ShadingMode::Ids,
                               ml::ShadingMode::Lines}) {
    for (int aa : {1, 2, 3, 8}) {
      Result r;
      render(b.scene, cam, options(mode, aa), &r);
      ASSERT_TRUE(r.status.ok()) << r.status.message;
      EXPECT_EQ(r.sink.begins, 1);
      EXPECT_EQ(r.sink.ends, 1);
      EXPECT_EQ(r.sink.fills, 0);
      EXPECT_EQ(r.sink.bad_calls, 0);
      ASSERT_EQ(r.sink.rows.size(), 61u);
      for (int y = 0; y < 61; ++y) EXPECT_EQ(r.sink.rows[size_t(y)], y);
      EXPECT_EQ(r.stats.pixel_writes, uint64_t(97 * 61));
      EXPECT_GT(r.stats.triangles_drawn, 0u);
      EXPECT_GT(r.stats.geometry_samples, 0u);
    }
  }
}

TEST(ScanlineRender, ArenaTooSmallNamesBytesAndNeverTouchesSink) {
  BuiltScene b = sphere_scene();
  const ml::Camera cam = camera_at({0, 300, 3000}, {0, 0, 0}, 80, 60);
  for (int aa : {1, 3, 8}) {  // aa = 8: 421 sample rows, more than one counting block
    const ml::RenderOptions o = options(ml::ShadingMode::Gouraud, aa);
    const size_t need = ml::render_arena_bytes(b.scene, cam, o);
    ASSERT_GT(need, 0u);
    for (size_t give : {size_t(0), size_t(64), need / 2, need - 8}) {
      std::vector<uint64_t> storage(need / 8 + 2);
      ml::Arena arena(storage.data(), give);
      RecordingSink sink;
      ml::Stats stats;
      const ml::Status s = ml::render(b.scene, cam, o, arena, sink, &stats);
      EXPECT_EQ(s.code, ml::StatusCode::ArenaTooSmall) << give;
      EXPECT_EQ(s.value, need) << give;
      EXPECT_EQ(sink.calls(), 0u);
    }
    Result r;
    render(b.scene, cam, o, &r);
    ASSERT_TRUE(r.status.ok());
    EXPECT_LE(r.stats.peak_arena_bytes, need);
    EXPECT_GT(r.stats.peak_arena_bytes, 0u);
    // The memory target: 16 B n + 64 B m_max + 16 B width, plus the band buffer the display lends.
    EXPECT_LE(r.stats.peak_arena_bytes, 16u * r.stats.n + 64u * r.stats.m_max + 16u * 80u +
                                            ml::BandOutput::arena_bytes(o.output, cam.width, cam.height));
    EXPECT_LT(r.stats.m_max, r.stats.n);
  }
}

TEST(ScanlineRender, InvalidOptions) {
  BuiltScene b = sphere_scene(4, 8);
  const ml::Camera cam = camera_at({0, 0, 3000}, {0, 0, 0}, 16, 16);
  for (int aa : {0, 9}) {
    Result r;
    std::vector<uint64_t> storage(1 << 16);
    ml::Arena arena(storage.data(), storage.size() * 8);
    const ml::Status s = ml::render(b.scene, cam, options(ml::ShadingMode::Flat, aa), arena, r.sink, &r.stats);
    EXPECT_EQ(s.code, ml::StatusCode::InvalidArgument);
    EXPECT_EQ(r.sink.calls(), 0u);
  }
}

// ---- coverage and depth ------------------------------------------------------------------------------

TEST(ScanlineCoverage, RandomTrianglesMatchViewCoverage) {
  std::mt19937 rng(17);
  const ml::Camera cam = camera_at({0, 0, 4000}, {0, 0, 0}, 64, 48, 50);
  int checked = 0;
  for (int it = 0; it < 150; ++it) {
    Prim p;
    // Mix of sizes: tiny, normal, huge (far off screen), and partly behind the eye.
    const int scale = (it % 4 == 0) ? 40 : (it % 4 == 1) ? 2000 : (it % 4 == 2) ? 30000 : 8000;
    std::uniform_int_distribution<int32_t> c(-scale, scale);
    std::uniform_int_distribution<int32_t> z(it % 4 == 3 ? -12000 : -2000, it % 4 == 3 ? 12000 : 2000);
    for (int k = 0; k < 3; ++k) p.pos.push_back({c(rng) / (it % 4 == 0 ? 1 : 1), c(rng), std::clamp(z(rng), -32000, 32000)});
    for (auto& v : p.pos) for (auto& a : v) a = std::clamp(a, -32000, 32000);
    p.tris.push_back({0, 1, 2});
    Material m;
    m.double_sided = (it % 2) == 0;
    BuiltScene b;
    scantest::build({m}, {p}, &b);
    ASSERT_TRUE(b.status.ok()) << b.status.message;
    std::vector<int> count;
    const std::vector<uint32_t> expect = coverage_ids(b.scene, cam, &count);
    Result r;
    render(b.scene, cam, options(ml::ShadingMode::Ids), &r);
    ASSERT_TRUE(r.status.ok()) << r.status.message;
    for (int y = 0; y < cam.height; ++y)
      for (int x = 0; x < cam.width; ++x) {
        ASSERT_EQ(r.sink.at(x, y), expect[size_t(y) * 64 + size_t(x)]) << "it " << it << " at " << x << "," << y;
        checked += expect[size_t(y) * 64 + size_t(x)] != 0;
      }
  }
  EXPECT_GT(checked, 1000);
}

TEST(ScanlineCoverage, MeshTilingTheScreenCoversEveryPixelOnce) {
  // A jittered grid far larger than the view, facing the camera: every pixel centre is covered by
  // exactly one triangle, and the scanline id is that triangle.
  std::mt19937 rng(23);
  Prim p;
  const int n = 24;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const int jit = (i > 0 && i < n && j > 0 && j < n) ? 1 : 0;
      p.pos.push_back({-6000 + j * 500 + jit * int32_t(rng() % 301) - jit * 150,
                       -6000 + i * 500 + jit * int32_t(rng() % 301) - jit * 150, int32_t(rng() % 400) - 200});
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const uint32_t a = uint32_t(i * (n + 1) + j), b2 = a + uint32_t(n + 1);
      p.tris.push_back({a, a + 1, b2 + 1});
      p.tris.push_back({a, b2 + 1, b2});
    }
  Material m;
  m.double_sided = true;
  BuiltScene b;
  scantest::build({m}, {p}, &b);
  ASSERT_TRUE(b.status.ok());
  const ml::Camera cam = camera_at({300, 200, 5000}, {0, 0, 0}, 120, 90, 100);
  std::vector<int> count;
  const std::vector<uint32_t> expect = coverage_ids(b.scene, cam, &count);
  Result r;
  render(b.scene, cam, options(ml::ShadingMode::Ids), &r);
  ASSERT_TRUE(r.status.ok());
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      ASSERT_EQ(count[size_t(y) * 120 + size_t(x)], 1) << x << "," << y;
      ASSERT_NE(r.sink.at(x, y), 0u);
      ASSERT_EQ(r.sink.at(x, y), expect[size_t(y) * 120 + size_t(x)]) << x << "," << y;
    }
  EXPECT_EQ(r.stats.geometry_samples, uint64_t(120 * 90));
}

TEST(ScanlineDepth, NearestSurfaceWinsAgainstDoubleReference) {
  // Random interpenetrating triangles; compare with double-precision interpolation of
  // ScreenVertex::depth (linear in screen space) where the gap is clear of rounding.
  std::mt19937 rng(29);
  const ml::Camera cam = camera_at({0, 0, 6000}, {0, 0, 0}, 80, 60, 100);
  ml::View view;
  ASSERT_TRUE(ml::make_view(cam, &view).ok());
  size_t decisive = 0;
  for (int it = 0; it < 20; ++it) {
    Prim p;
    std::uniform_int_distribution<int32_t> c(-3000, 3000);
    for (int t = 0; t < 8; ++t) {
      for (int k = 0; k < 3; ++k) p.pos.push_back({c(rng), c(rng), c(rng)});
      p.tris.push_back({uint32_t(3 * t), uint32_t(3 * t + 1), uint32_t(3 * t + 2)});
    }
    Material m;
    m.double_sided = true;
    BuiltScene b;
    scantest::build({m}, {p}, &b);
    ASSERT_TRUE(b.status.ok());
    Result r;
    render(b.scene, cam, options(ml::ShadingMode::Ids), &r);
    ASSERT_TRUE(r.status.ok());
    for (int y = 0; y < 60; ++y)
      for (int x = 0; x < 80; ++x) {
        double best = -1, second = -1;
        uint32_t best_id = 0;
        for (uint32_t id = 0; id < b.scene.triangle_count; ++id) {
          ml::Vec3i w[3];
          ml::triangle_world(b.scene, id, w);
          ml::ScreenTriangle pieces[ml::kMaxClipTriangles];
          const int np = ml::project_triangle(view, w, pieces);
          for (int k = 0; k < np; ++k) {
            ml::TriangleSetup s;
            ml::setup_triangle(pieces[k], 80, 60, &s);
            if (!ml::covers_pixel(s, x, y)) continue;
            const ml::ScreenTriangle& t = pieces[k];
            const double px = x * 256 + 128, py = y * 256 + 128;
            double l[3];
            for (int j = 0; j < 3; ++j) {
              const auto& P = t.v[(j + 1) % 3];
              const auto& Q = t.v[(j + 2) % 3];
              l[j] = (double(Q.x) - P.x) * (py - P.y) - (double(Q.y) - P.y) * (px - P.x);
            }
            const double d = (l[0] * t.v[0].depth + l[1] * t.v[1].depth + l[2] * t.v[2].depth) / double(t.area2);
            if (d > best) { second = best; best = d; best_id = id + 1; }
            else if (d > second) second = d;
          }
        }
        if (best < 0 || (second >= 0 && best - second < 2.0)) continue;
        ++decisive;
        ASSERT_EQ(r.sink.at(x, y), best_id) << "it " << it << " at " << x << "," << y;
      }
  }
  EXPECT_GT(decisive, 5000u);
}

// Appends a primitive of one triangle (at pos) with a double-sided material of its own, colour (r, g, b):
// triangle i has material i.
void add_triangle(uint8_t r, uint8_t g, uint8_t b, const std::vector<std::array<int32_t, 3>>& pos,
                  std::vector<Material>* mats, std::vector<Prim>* prims) {
  Material m;
  m.double_sided = true;
  m.rgba[0] = r, m.rgba[1] = g, m.rgba[2] = b;
  Prim p;
  p.material = uint32_t(mats->size());
  p.pos = pos;
  p.tris.push_back({0, 1, 2});
  mats->push_back(m);
  prims->push_back(p);
}

// A projected piece with its coverage edge functions (view.h, fill rule included) and unlit colour.
struct ReferencePiece {
  ml::ScreenTriangle t;
  ml::EdgeFunction e[3];
  ml::Pixel colour;
};

// Every piece of the scene's triangles; triangle i has material i.
std::vector<ReferencePiece> reference_pieces(const BuiltScene& b, const std::vector<Material>& mats,
                                             const ml::View& view) {
  std::vector<ReferencePiece> pieces;
  for (uint32_t id = 0; id < b.scene.triangle_count; ++id) {
    ml::Vec3i wp[3];
    ml::triangle_world(b.scene, id, wp);
    ml::ScreenTriangle pc[ml::kMaxClipTriangles];
    const int np = ml::project_triangle(view, wp, pc);
    const uint8_t* rgba = mats[id].rgba;
    for (int k = 0; k < np; ++k) {
      ReferencePiece p{pc[k], {}, (uint32_t(rgba[0]) << 16) | (uint32_t(rgba[1]) << 8) | rgba[2]};
      for (int i = 0; i < 3; ++i) {
        const ml::ScreenVertex &P = pc[k].v[i], &Q = pc[k].v[(i + 1) % 3];
        p.e[i] = ml::edge_function(P.x, P.y, Q.x, Q.y);
      }
      pieces.push_back(p);
    }
  }
  return pieces;
}

// The colour of lattice sample (sx, sy) of an aa x aa lattice (q = aa - 1: at (256 sx / q, 256 sy / q)
// subpixels, E * q exact in int64) from double-precision depths; false when the two nearest pieces
// there are too close in depth to tell.
bool reference_sample(const std::vector<ReferencePiece>& pieces, int32_t sx, int32_t sy, int32_t q,
                      ml::Pixel* colour) {
  double best = -1, second = -1;
  for (const ReferencePiece& p : pieces) {
    bool in = true;
    for (const ml::EdgeFunction& e : p.e) in = in && e.a * 256 * sx + e.b * 256 * sy + e.c * q >= 0;
    if (!in) continue;
    const double fx = 256.0 * sx / q, fy = 256.0 * sy / q;
    double l[3];
    for (int j = 0; j < 3; ++j) {
      const auto& P = p.t.v[(j + 1) % 3];
      const auto& Q = p.t.v[(j + 2) % 3];
      l[j] = (double(Q.x) - P.x) * (fy - P.y) - (double(Q.y) - P.y) * (fx - P.x);
    }
    const double d = (l[0] * p.t.v[0].depth + l[1] * p.t.v[1].depth + l[2] * p.t.v[2].depth) / double(p.t.area2);
    if (d > best) { second = best; best = d; *colour = p.colour; }
    else if (d > second) second = d;
  }
  return second < 0 || best - second >= 2.0;
}

// Every pixel whose aa x aa lattice samples all have a clear winner (or none) must be the rounded mean
// of those samples' colours (unlit; triangle i has material i). Returns the pixels compared; *mixed
// counts those of more than one colour.
size_t expect_supersampled_matches_double_reference(const BuiltScene& b, const std::vector<Material>& mats,
                                                    const ml::Camera& cam, int aa, size_t* mixed) {
  const int32_t q = aa - 1;
  ml::View view;
  EXPECT_TRUE(ml::make_view(cam, &view).ok());
  Result r;
  const ml::RenderOptions o = options(ml::ShadingMode::Unlit, aa);
  render(b.scene, cam, o, &r);
  EXPECT_TRUE(r.status.ok()) << r.status.message;
  if (!r.status.ok()) return 0;
  const std::vector<ReferencePiece> pieces = reference_pieces(b, mats, view);
  size_t decisive = 0;
  for (int py = 0; py < cam.height; ++py)
    for (int px = 0; px < cam.width; ++px) {
      uint32_t sum[3] = {0, 0, 0};
      bool clear = true;
      std::set<ml::Pixel> colours;
      for (int32_t sy = py * q; sy <= py * q + q && clear; ++sy)
        for (int32_t sx = px * q; sx <= px * q + q && clear; ++sx) {
          ml::Pixel colour = o.background;
          clear = reference_sample(pieces, sx, sy, q, &colour);
          for (int ch = 0; ch < 3; ++ch) sum[ch] += (colour >> (16 - 8 * ch)) & 0xFF;
          colours.insert(colour);
        }
      if (!clear) continue;
      const uint32_t l2 = uint32_t(aa * aa);
      const ml::Pixel expect = ((sum[0] + l2 / 2) / l2 << 16) | ((sum[1] + l2 / 2) / l2 << 8) | (sum[2] + l2 / 2) / l2;
      ++decisive;
      *mixed += colours.size() > 1;
      if (r.sink.at(px, py) != expect) {
        ADD_FAILURE() << "aa " << aa << " at " << px << "," << py << ": " << std::hex << r.sink.at(px, py)
                      << ", expected " << expect;
        return decisive;
      }
    }
  return decisive;
}

// Scenes of one-triangle primitives, add_scene(rng, &mats, &prims) making each; scene it is checked
// at 2 + it % 3 samples a side (expect_supersampled_matches_double_reference). Returns the pixels
// compared; *mixed counts those of more than one colour.
template <typename AddScene>
size_t expect_scenes_match_double_reference(uint32_t seed, int scenes, AddScene add_scene, size_t* mixed) {
  std::mt19937 rng(seed);
  const ml::Camera cam = camera_at({0, 0, 6000}, {0, 0, 0}, 80, 60, 100);
  size_t decisive = 0;
  for (int it = 0; it < scenes; ++it) {
    SCOPED_TRACE("scene " + std::to_string(it));
    std::vector<Material> mats;
    std::vector<Prim> prims;
    add_scene(rng, &mats, &prims);
    BuiltScene b;
    scantest::build(mats, prims, &b);
    EXPECT_TRUE(b.status.ok());
    if (!b.status.ok()) return decisive;
    decisive += expect_supersampled_matches_double_reference(b, mats, cam, 2 + it % 3, mixed);
  }
  return decisive;
}

// Supersampled: random interpenetrating triangles of distinct unlit colours, where the nearest piece
// changes inside spans (the sweep resolves each winner's samples as one run up to where a rival's depth
// overtakes it).
TEST(ScanlineDepth, SupersampledNearestSurfaceMatchesDoubleReference) {
  size_t mixed = 0;
  const size_t decisive = expect_scenes_match_double_reference(
      31, 12,
      [](std::mt19937& rng, std::vector<Material>* mats, std::vector<Prim>* prims) {
        std::uniform_int_distribution<int32_t> c(-3000, 3000);
        for (int t = 0; t < 8; ++t) {
          const uint8_t blue = uint8_t(rng() % 256);
          std::vector<std::array<int32_t, 3>> pos;
          for (int k = 0; k < 3; ++k) pos.push_back({c(rng), c(rng), c(rng)});
          add_triangle(uint8_t(30 * t + 10), uint8_t(250 - 29 * t), blue, pos, mats, prims);
        }
      },
      &mixed);
  EXPECT_GT(decisive, 30000u);
  EXPECT_GT(mixed, 1000u);
}

// Layers of small triangles behind large ones, as in a room seen down its rows: the sweep drops a span
// that the winning span hides to its end (hidden_behind), so such spans must be hidden at every
// sample. Some small triangles are slanted through the large ones' depths or poke out past their
// edges, and so are seen in part.
TEST(ScanlineDepth, LayeredHiddenSpansMatchDoubleReference) {
  size_t mixed = 0;
  const size_t decisive = expect_scenes_match_double_reference(
      47, 6,
      [](std::mt19937& rng, std::vector<Material>* mats, std::vector<Prim>* prims) {
        std::uniform_int_distribution<int32_t> spot(-2600, 2600), size(150, 700), slant(-900, 900);
        for (int t = 0; t < 64; ++t) {
          const uint8_t blue = uint8_t(rng() % 256);
          std::vector<std::array<int32_t, 3>> pos;
          if (t < 4) {  // a large near triangle
            const int32_t x = spot(rng) / 2, y = spot(rng) / 2, z = 1500 + 200 * t;
            pos = {{x - 2500, y - 1800, z}, {x + 2500, y - 1600, z + slant(rng) / 3}, {x, y + 2400, z}};
          } else {  // a small one behind, at its own depth, some slanted
            const int32_t x = spot(rng), y = spot(rng), z = -2000 + 45 * t, d = size(rng);
            const int32_t tilt = t % 5 == 0 ? 6 * slant(rng) : slant(rng) / 8;
            pos = {{x - d, y - d, z}, {x + d, y - d / 2, z + tilt}, {x, y + d, z - tilt}};
          }
          add_triangle(uint8_t(4 * t), uint8_t(255 - 3 * t), blue, pos, mats, prims);
        }
      },
      &mixed);
  EXPECT_GT(decisive, 25000u);
  EXPECT_GT(mixed, 2000u);
}

// ---- transparency -----------------------------------------------------------------------------------

TEST(ScanlineBlend, FrontToBackMatchesDoubleReference) {
  // Four overlapping quads at different depths, three BLEND with various alphas and one opaque at
  // the back half; Unlit colours so the reference is pure compositing.
  std::vector<Material> mats(4);
  const uint8_t cols[4][4] = {{255, 40, 40, 100}, {40, 255, 40, 160}, {40, 40, 255, 60}, {250, 250, 20, 255}};
  std::vector<Prim> prims;
  for (int i = 0; i < 4; ++i) {
    std::memcpy(mats[size_t(i)].rgba, cols[i], 4);
    mats[size_t(i)].mode = i < 3 ? ml::AlphaMode::Blend : ml::AlphaMode::Opaque;
    Prim p;
    p.material = uint32_t(i);
    const int32_t x0 = -2000 + i * 500, z = 600 - i * 400;
    p.pos = {{x0, -1500 + i * 300, z}, {x0 + 2200, -1500 + i * 300, z}, {x0 + 2200, 1500, z}, {x0, 1500, z}};
    p.tris = {{0, 1, 2}, {0, 2, 3}};
    prims.push_back(p);
  }
  BuiltScene b;
  scantest::build(mats, prims, &b);
  ASSERT_TRUE(b.status.ok());
  const ml::Camera cam = camera_at({200, 100, 7000}, {0, 0, 0}, 96, 72, 100);
  Result r;
  render(b.scene, cam, options(ml::ShadingMode::Unlit), &r);
  ASSERT_TRUE(r.status.ok());
  ml::View view;
  ASSERT_TRUE(ml::make_view(cam, &view).ok());
  int blended = 0;
  for (int y = 0; y < 72; ++y)
    for (int x = 0; x < 96; ++x) {
      // Layers covering the pixel centre (quads are parallel, so order by material = depth order).
      double acc[3] = {0, 0, 0}, t = 1;
      int layers = 0;
      for (int i = 0; i < 4; ++i) {
        bool cov = false;
        for (int tri = 0; tri < 2; ++tri) {
          const uint32_t id = uint32_t(2 * i + tri);
          ml::Vec3i w[3];
          ml::triangle_world(b.scene, id, w);
          ml::ScreenTriangle pieces[ml::kMaxClipTriangles];
          const int np = ml::project_triangle(view, w, pieces);
          for (int k = 0; k < np; ++k) {
            ml::TriangleSetup s;
            ml::setup_triangle(pieces[k], 96, 72, &s);
            cov = cov || ml::covers_pixel(s, x, y);
          }
        }
        if (!cov) continue;
        ++layers;
        const double a = cols[i][3] / 255.0;
        for (int c = 0; c < 3; ++c) acc[c] += t * a * cols[i][c];
        t *= 1 - a;
      }
      const uint32_t bg[3] = {0x10, 0x20, 0x30};
      const ml::Pixel got = r.sink.at(x, y);
      const uint32_t g[3] = {ml::red_of(got), ml::green_of(got), ml::blue_of(got)};
      for (int c = 0; c < 3; ++c) {
        const double ref = acc[c] + t * bg[c];
        ASSERT_LE(std::fabs(g[c] - ref), 1.0) << x << "," << y << " channel " << c;
      }
      blended += layers >= 2;
    }
  EXPECT_GT(blended, 200);
}

TEST(ScanlineBlend, MaskCutsOutBelowCutoff) {
  std::vector<Material> mats(2);
  mats[0].mode = ml::AlphaMode::Mask;
  mats[0].rgba[3] = 100;
  mats[0].cutoff = 128;  // below: cut out
  mats[1].mode = ml::AlphaMode::Mask;
  mats[1].rgba[3] = 200;  // above: opaque
  Prim a = cube(500), c = cube(500);
  c.material = 1;
  for (auto& v : c.pos) v[0] += 2000;
  BuiltScene b;
  scantest::build(mats, {a, c}, &b);
  ASSERT_TRUE(b.status.ok());
  const ml::Camera cam = camera_at({1000, 800, 5000}, {1000, 0, 0}, 80, 60);
  Result r;
  render(b.scene, cam, options(ml::ShadingMode::Ids), &r);
  ASSERT_TRUE(r.status.ok());
  std::set<uint32_t> seen(r.sink.image.begin(), r.sink.image.end());
  for (uint32_t id : seen) EXPECT_TRUE(id == 0 || id > 12) << id;
  EXPECT_GT(seen.size(), 1u);
  EXPECT_EQ(r.stats.triangles_culled >= 12u, true);
}

// ---- hidden lines -------------------------------------------------------------------------------------

double seg_dist(double px, double py, double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  const double ex = ax + t * dx - px, ey = ay + t * dy - py;
  return std::sqrt(ex * ex + ey * ey);
}

TEST(ScanlineLines, CubeShowsExactlyTheVisibleEdges) {
  BuiltScene b;
  scantest::build({Material{}}, {cube(1000)}, &b);
  ASSERT_TRUE(b.status.ok());
  const ml::Camera cam = camera_at({2600, 2100, 3900}, {0, 0, 0}, 160, 120, 100);
  Result r;
  render(b.scene, cam, options(ml::ShadingMode::Lines), &r);
  ASSERT_TRUE(r.status.ok());
  EXPECT_EQ(r.stats.shading_calls, 0u);
  ml::View view;
  ASSERT_TRUE(ml::make_view(cam, &view).ok());
  // Visible edges: edges of front-facing triangles (diagonals included); hidden: the others.
  struct Seg { double ax, ay, bx, by; };
  std::vector<Seg> visible, hidden;
  std::map<std::pair<uint32_t, uint32_t>, int> front_count;
  for (uint32_t id = 0; id < 12; ++id) {
    ml::Vec3i w[3];
    ml::triangle_world(b.scene, id, w);
    ml::ScreenTriangle pieces[ml::kMaxClipTriangles];
    ASSERT_EQ(ml::project_triangle(view, w, pieces), 1);
    const auto& t = pieces[0];
    for (int i = 0; i < 3; ++i) {
      const auto& P = t.v[i];
      const auto& Q = t.v[(i + 1) % 3];
      Seg s{P.x / 256.0, P.y / 256.0, Q.x / 256.0, Q.y / 256.0};
      (t.front_facing ? visible : hidden).push_back(s);
    }
  }
  auto near_any = [](const std::vector<Seg>& segs, double x, double y, double d) {
    for (const Seg& s : segs)
      if (seg_dist(x, y, s.ax, s.ay, s.bx, s.by) <= d) return true;
    return false;
  };
  int lines = 0;
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 160; ++x) {
      const ml::Pixel p = r.sink.at(x, y);
      ASSERT_TRUE(p == 0xFFFFFF || p == 0x102030);
      if (p != 0xFFFFFF) continue;
      ++lines;
      // Every line pixel lies on a visible edge (within the 1-pixel one-sided rule).
      ASSERT_TRUE(near_any(visible, x + 0.5, y + 0.5, 1.5)) << x << "," << y;
    }
  // Every visible edge is drawn: points along it (away from its ends) have a line pixel within 1.5 px.
  for (const Seg& s : visible) {
    const double len = std::hypot(s.bx - s.ax, s.by - s.ay);
    for (double t = 0.1; t <= 0.9; t += 2.0 / std::max(len, 1.0)) {
      const double px = s.ax + t * (s.bx - s.ax), py = s.ay + t * (s.by - s.ay);
      bool found = false;
      for (int dy = -2; dy <= 2 && !found; ++dy)
        for (int dx = -2; dx <= 2 && !found; ++dx) {
          const int qx = int(std::floor(px)) + dx, qy = int(std::floor(py)) + dy;
          if (qx < 0 || qy < 0 || qx >= 160 || qy >= 120) continue;
          if (r.sink.at(qx, qy) == 0xFFFFFF && std::hypot(qx + 0.5 - px, qy + 0.5 - py) <= 1.5) found = true;
        }
      ASSERT_TRUE(found) << "visible edge not drawn near " << px << "," << py;
    }
  }
  // Hidden edges leave no trace away from visible ones.
  for (const Seg& s : hidden) {
    for (double t = 0.05; t <= 0.95; t += 0.01) {
      const double px = s.ax + t * (s.bx - s.ax), py = s.ay + t * (s.by - s.ay);
      if (near_any(visible, px, py, 3.0)) continue;
      const int qx = int(std::floor(px)), qy = int(std::floor(py));
      if (qx < 0 || qy < 0 || qx >= 160 || qy >= 120) continue;
      ASSERT_NE(r.sink.at(qx, qy), 0xFFFFFFu) << "hidden edge drawn at " << qx << "," << qy;
    }
  }
  EXPECT_GT(lines, 300);
}

// ---- antialiasing and shading reuse ------------------------------------------------------------------

TEST(ScanlineAa, ReproducibleWithSeedAndSmoothEdges) {
  BuiltScene b = sphere_scene();
  const ml::Camera cam = camera_at({0, 500, 3200}, {0, 0, 0}, 90, 70);
  Result a, a2, c;
  render(b.scene, cam, options(ml::ShadingMode::Gouraud, 4, 7), &a);
  render(b.scene, cam, options(ml::ShadingMode::Gouraud, 4, 7), &a2);
  render(b.scene, cam, options(ml::ShadingMode::Gouraud, 4, 8), &c);
  ASSERT_TRUE(a.status.ok() && a2.status.ok() && c.status.ok());
  EXPECT_EQ(a.sink.image, a2.sink.image);
  EXPECT_EQ(a.stats.shading_calls, a2.stats.shading_calls);
  EXPECT_NE(a.stats.shading_calls, c.stats.shading_calls);  // the seed drives the stochastic choice
  EXPECT_EQ(a.stats.geometry_samples, c.stats.geometry_samples);
  EXPECT_EQ(a.stats.samples_per_pixel, 16u);
  // Silhouette pixels blend sphere and background: some pixels are strictly between.
  Result one;
  render(b.scene, cam, options(ml::ShadingMode::Unlit, 1), &one);
  Result aa;
  render(b.scene, cam, options(ml::ShadingMode::Unlit, 3), &aa);
  std::set<ml::Pixel> c1(one.sink.image.begin(), one.sink.image.end()),
      c3(aa.sink.image.begin(), aa.sink.image.end());
  EXPECT_EQ(c1.size(), 2u);
  EXPECT_GT(c3.size(), 6u);
}

// Flat and Unlit surfaces have one colour each: keepObj's reuse is exact, so no stochastic or forced
// re-shading runs (docs/scanline.md, one colour a surface). Neither the picture nor the number of
// shading calls depends on the seed then (at a Gouraud surface both do: ReproducibleWithSeed...).
TEST(ScanlineAa, OneColourSurfacesIgnoreTheSeed) {
  BuiltScene b = sphere_scene();
  const ml::Camera cam = camera_at({0, 500, 3200}, {0, 0, 0}, 90, 70);
  for (ml::ShadingMode mode : {ml::ShadingMode::Flat, ml::ShadingMode::Unlit}) {
    for (int aa : {2, 3, 4}) {
      Result a, c;
      render(b.scene, cam, options(mode, aa, 7), &a);
      render(b.scene, cam, options(mode, aa, 8), &c);
      ASSERT_TRUE(a.status.ok() && c.status.ok());
      EXPECT_EQ(a.sink.image, c.sink.image) << int(mode) << " aa " << aa;
      EXPECT_EQ(a.stats.shading_calls, c.stats.shading_calls) << int(mode) << " aa " << aa;
    }
  }
}

// The scanline renderer's own entry (what a firmware image of this renderer alone links) gives
// render()'s frame, stats and arena size, whatever options.renderer says.
TEST(ScanlineRender, OwnEntryMatchesRender) {
  BuiltScene b = sphere_scene();
  const ml::Camera cam = camera_at({0, 500, 3200}, {0, 0, 0}, 64, 48);
  for (ml::ShadingMode mode : {ml::ShadingMode::Flat, ml::ShadingMode::Ids}) {
    Result whole;
    render(b.scene, cam, options(mode, mode == ml::ShadingMode::Ids ? 1 : 3), &whole);
    ASSERT_TRUE(whole.status.ok());
    ml::RenderOptions other = options(mode, mode == ml::ShadingMode::Ids ? 1 : 3);
    other.renderer = ml::RendererKind::Tiler;  // ignored by the entry
    const size_t bytes = ml::render_scanline_arena_bytes(b.scene, cam, other);
    EXPECT_EQ(bytes, whole.bytes);
    std::vector<uint64_t> storage(bytes / 8 + 2);
    ml::Arena arena(storage.data(), bytes);
    Result one;
    one.status = ml::render_scanline(b.scene, cam, other, arena, one.sink, &one.stats);
    ASSERT_TRUE(one.status.ok());
    EXPECT_EQ(one.sink.image, whole.sink.image);
    EXPECT_EQ(one.stats.shading_calls, whole.stats.shading_calls);
    EXPECT_EQ(one.stats.sink_calls, whole.stats.sink_calls);
    EXPECT_EQ(one.stats.samples_per_pixel, whole.stats.samples_per_pixel);
  }
}

TEST(ScanlineAa, ShadingReuseOnSmoothModel) {
  BuiltScene b = sphere_scene(32, 64);
  const ml::Camera cam = camera_at({0, 500, 2600}, {0, 0, 0}, 160, 120);
  Result r1, r3;
  render(b.scene, cam, options(ml::ShadingMode::Gouraud, 1), &r1);
  render(b.scene, cam, options(ml::ShadingMode::Gouraud, 3), &r3);
  ASSERT_TRUE(r1.status.ok() && r3.status.ok());
  // 1x1: one shading call per covered pixel.
  EXPECT_EQ(r1.stats.shading_calls, r1.stats.geometry_samples);
  // 3x3: (l-1)^2 = 4 shared samples per pixel, about four times the 1x1 geometry samples.
  EXPECT_GT(r3.stats.geometry_samples, 3 * r1.stats.geometry_samples);
  const double ratio = double(r3.stats.shading_calls) / double(r3.stats.geometry_samples);
  EXPECT_LE(ratio, 0.5) << r3.stats.shading_calls << " / " << r3.stats.geometry_samples;
  EXPECT_GT(ratio, 0.2);
  // The 3x3 image stays close to the 1x1 one inside the sphere.
  int close = 0, total = 0;
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 160; ++x) {
      const ml::Pixel p = r1.sink.at(x, y), q = r3.sink.at(x, y);
      if (p == 0x102030) continue;
      ++total;
      close += std::abs(int(ml::green_of(p)) - int(ml::green_of(q))) <= 12;
    }
  EXPECT_GT(close, total * 9 / 10);
}

}  // namespace

namespace {

// At l > 1 the samples sit at k / (l - 1) pixel; a white single triangle over black must average
// exactly the samples where src/view's edge functions (scaled by l - 1) are >= 0.
TEST(ScanlineAa, SupersampledCoverageIsExactOnTheLattice) {
  std::mt19937 rng(31);
  const ml::Camera cam = camera_at({0, 0, 4000}, {0, 0, 0}, 40, 30, 50);
  ml::View view;
  ASSERT_TRUE(ml::make_view(cam, &view).ok());
  for (int it = 0; it < 40; ++it) {
    const int l = 2 + it % 7;
    const int q = l - 1;
    Prim p;
    std::uniform_int_distribution<int32_t> c(-1500, 1500);
    for (int k = 0; k < 3; ++k) p.pos.push_back({c(rng), c(rng), c(rng) / 4});
    p.tris.push_back({0, 1, 2});
    Material m;
    m.double_sided = true;
    for (int k = 0; k < 3; ++k) m.rgba[k] = 255;
    BuiltScene b;
    scantest::build({m}, {p}, &b);
    ASSERT_TRUE(b.status.ok());
    ml::RenderOptions o = options(ml::ShadingMode::Unlit, l);
    o.background = 0;
    Result r;
    render(b.scene, cam, o, &r);
    ASSERT_TRUE(r.status.ok());
    ml::Vec3i w[3];
    ml::triangle_world(b.scene, 0, w);
    ml::ScreenTriangle pieces[ml::kMaxClipTriangles];
    const int np = ml::project_triangle(view, w, pieces);
    std::vector<ml::TriangleSetup> setups(static_cast<size_t>(np));
    for (int k = 0; k < np; ++k) ml::setup_triangle(pieces[k], 40, 30, &setups[size_t(k)]);
    for (int y = 0; y < 30; ++y)
      for (int x = 0; x < 40; ++x) {
        int covered = 0;
        for (int j = 0; j <= q; ++j)
          for (int i = 0; i <= q; ++i) {
            const int64_t X = int64_t(x) * q + i, Y = int64_t(y) * q + j;
            bool in = false;
            for (const auto& s : setups) {
              bool all = true;
              for (const auto& e : s.edge) all = all && e.a * 256 * X + e.b * 256 * Y + e.c * q >= 0;
              in = in || all;
            }
            covered += in;
          }
        const uint32_t expect = uint32_t((covered * 255 + l * l / 2) / (l * l));
        ASSERT_EQ(ml::red_of(r.sink.at(x, y)), expect) << "l=" << l << " at " << x << "," << y;
      }
  }
}

struct RefusingSink : RecordingSink {
  bool flush(const ml::Flush& b) override {
    RecordingSink::flush(b);
    return b.y < 3;
  }
};

TEST(ScanlineRender, SinkRefusalAbortsWithSinkFailed) {
  BuiltScene b = sphere_scene(8, 16);
  const ml::Camera cam = camera_at({0, 0, 3000}, {0, 0, 0}, 32, 24);
  ml::RenderOptions o = options(ml::ShadingMode::Flat);
  o.output.band_rows = 1;  // a band a row: the refusal comes at row 3
  const size_t bytes = ml::render_arena_bytes(b.scene, cam, o);
  std::vector<uint64_t> storage(bytes / 8 + 1);
  ml::Arena arena(storage.data(), bytes);
  RefusingSink sink;
  ml::Stats stats;
  EXPECT_EQ(ml::render(b.scene, cam, o, arena, sink, &stats).code, ml::StatusCode::SinkFailed);
  EXPECT_EQ(sink.rows.size(), 4u);
  EXPECT_EQ(sink.ends, 0);
}

}  // namespace

namespace {

// Random cameras (inside and outside the geometry, near plane cutting through it), every mode and aa:
// the render succeeds within the arena it asked for and the sink contract holds (sanitizers watch
// for overflow and out-of-bounds access).
TEST(ScanlineRender, RandomCamerasKeepTheContract) {
  std::vector<Material> mats(3);
  mats[1].mode = ml::AlphaMode::Blend;
  mats[1].rgba[3] = 90;
  mats[2].double_sided = true;
  Prim s = sphere(1500, 12, 24), c = cube(900), g;
  c.material = 1;
  for (auto& v : c.pos) v[0] += 1200;
  g.material = 2;
  g.pos = {{-8000, -1600, -8000}, {8000, -1600, -8000}, {8000, -1600, 8000}, {-8000, -1600, 8000}};
  g.tris = {{0, 2, 1}, {0, 3, 2}};
  BuiltScene b;
  scantest::build(mats, {s, c, g}, &b);
  ASSERT_TRUE(b.status.ok()) << b.status.message;
  std::mt19937 rng(41);
  std::uniform_int_distribution<int32_t> pos(-6000, 6000);
  const ml::ShadingMode modes[] = {ml::ShadingMode::Unlit, ml::ShadingMode::Flat, ml::ShadingMode::Gouraud,
                                   ml::ShadingMode::Ids, ml::ShadingMode::Lines};
  for (int it = 0; it < 60; ++it) {
    const int w = 8 + int(rng() % 60), h = 6 + int(rng() % 50);
    ml::Camera cam = camera_at({pos(rng), pos(rng), pos(rng)}, {pos(rng) / 4, pos(rng) / 4, pos(rng) / 4}, w, h,
                               1 + int32_t(rng() % 200));
    const ml::RenderOptions o = options(modes[it % 5], 1 + int(rng() % 8), rng());
    Result r;
    render(b.scene, cam, o, &r);
    ASSERT_TRUE(r.status.ok()) << it << ": " << r.status.message;
    ASSERT_EQ(r.sink.rows.size(), size_t(h));
    for (int y = 0; y < h; ++y) ASSERT_EQ(r.sink.rows[size_t(y)], y);
    EXPECT_EQ(r.sink.bad_calls, 0);
    EXPECT_LE(r.stats.peak_arena_bytes, r.bytes);
    for (ml::Pixel p : r.sink.image) ASSERT_EQ(p >> 24, 0u);  // every pixel written with a 24-bit value
  }
}

TEST(ScanlineMath, TexcoordsInterpolateLinearly) {
  const int32_t uv[3][2] = {{0, 0}, {65536 * 4, 0}, {0, -65536 * 2}};
  const int32_t w[3] = {32768, 16384, 16384};
  int32_t out[2];
  ml::scan::interpolate_uv(uv, w, out);
  EXPECT_EQ(out[0], 65536);
  EXPECT_EQ(out[1], -32768);
}

}  // namespace

namespace {

// A random piece in area2 > 0 order: tiny, pixel-sized, screen-sized or reaching into the guard band.
// Every third one has its vertices on samples (multiples of 256 subpixels; pixel centres at aa == 1),
// so that edges pass exactly through samples and the fill rule decides them.
ml::ScreenTriangle random_piece(std::mt19937& rng, int it, int width, int height, int aa) {
  const int32_t reach[] = {300, 3000, 40000, int32_t(ml::kGuardBandPixels) * 256};
  const int32_t r = reach[it % 4];
  std::uniform_int_distribution<int32_t> dx(-r, r), dy(-r, r);
  const int32_t cx = std::uniform_int_distribution<int32_t>(0, width * 256)(rng);
  const int32_t cy = std::uniform_int_distribution<int32_t>(0, height * 256)(rng);
  for (;;) {
    ml::ScreenTriangle t{};
    for (int k = 0; k < 3; ++k) {
      t.v[k].x = cx + dx(rng);
      t.v[k].y = cy + dy(rng);
      if (it % 7 == 0 && k == 2) t.v[k].y = t.v[0].y;  // horizontal edges
      if (it % 3 == 0) {
        const int32_t o = aa == 1 ? 128 : 0;
        t.v[k].x = int32_t(ml::floor_shift(t.v[k].x, 8) * 256 + o);
        t.v[k].y = int32_t(ml::floor_shift(t.v[k].y, 8) * 256 + o);
      }
    }
    const int64_t a2 = (int64_t(t.v[1].x) - t.v[0].x) * (int64_t(t.v[2].y) - t.v[0].y) -
                       (int64_t(t.v[1].y) - t.v[0].y) * (int64_t(t.v[2].x) - t.v[0].x);
    if (a2 == 0) continue;
    if (a2 < 0) std::swap(t.v[1], t.v[2]);
    t.area2 = a2 < 0 ? -a2 : a2;
    return t;
  }
}

ml::scan::ActiveTri active_from(const ml::ScreenTriangle& t, const ml::scan::LatticeBox& box,
                                const ml::scan::Lattice& lat) {
  ml::scan::ActiveTri a{};
  for (int k = 0; k < 3; ++k) {
    a.vx[k] = t.v[k].x;
    a.vy[k] = t.v[k].y;
  }
  a.box_x0 = uint16_t(box.x0);
  a.box_x1 = uint16_t(box.x1);
  ml::scan::start_span(&a, lat, box.y0);
  return a;
}

}  // namespace

// Spans stepped row to row by walking the edge functions equal the spans found by division, on every
// row of random pieces at every sampling rate, also when rows are skipped; at 1x1 both equal the
// coverage of src/view sample by sample.
TEST(ScanlineSpans, SteppedSpansEqualDividedSpansAndViewCoverage) {
  std::mt19937 rng(41);
  int rows = 0, covered = 0;
  for (int it = 0; it < 4000; ++it) {
    const int width = 1 + int(rng() % 90), height = 1 + int(rng() % 70);
    const int aa = 1 + int(rng() % 8);
    const ml::scan::Lattice lat = ml::scan::make_lattice(width, height, aa);
    const ml::ScreenTriangle t = random_piece(rng, it, width, height, aa);
    ml::scan::LatticeBox box;
    if (!ml::scan::lattice_box(t, lat, &box)) continue;
    ml::scan::ActiveTri a = active_from(t, box, lat);
    ml::TriangleSetup setup;
    ml::setup_triangle(t, width, height, &setup);
    for (int32_t y = box.y0; y <= box.y1; y += (it % 5 == 0) ? 1 + int32_t(rng() % 4) : 1) {
      int32_t s0 = -1, s1 = -2, d0 = -1, d1 = -2;
      const bool stepped = ml::scan::step_span(&a, lat, y, &s0, &s1);
      const bool divided = ml::scan::row_span(a, lat, y, &d0, &d1);
      const bool divided_in_box = divided && std::max(d0, box.x0) <= std::min(d1, box.x1);
      ASSERT_EQ(stepped, divided_in_box) << "it " << it << " row " << y;
      if (stepped) {
        ASSERT_EQ(s0, std::max(d0, box.x0)) << "it " << it << " row " << y;
        ASSERT_EQ(s1, std::min(d1, box.x1)) << "it " << it << " row " << y;
        // Inside the box's rows and columns the divided span never leaves the box.
        ASSERT_EQ(s0, d0);
        ASSERT_EQ(s1, d1);
      }
      ++rows;
      if (aa == 1) {
        for (int32_t x = 0; x < width; ++x) {
          const bool in = stepped && x >= s0 && x <= s1;
          ASSERT_EQ(in, ml::covers_pixel(setup, x, y)) << "it " << it << " at " << x << "," << y;
          covered += in;
        }
      }
    }
  }
  EXPECT_GT(rows, 20000);
  EXPECT_GT(covered, 10000);
}

// Gouraud weights from the piece's reciprocal equal round(E 2^16 / (area2 den)) by division at every
// covered sample of random pieces, huge ones (numerators pre-shifted) included.
TEST(ScanlineMath, WeightsByReciprocalEqualWeightsByDivision) {
  std::mt19937 rng(43);
  int checked = 0;
  for (int it = 0; it < 3000; ++it) {
    const int width = 1 + int(rng() % 60), height = 1 + int(rng() % 40);
    const int aa = 1 + int(rng() % 8);
    const ml::scan::Lattice lat = ml::scan::make_lattice(width, height, aa);
    const ml::ScreenTriangle t = random_piece(rng, it, width, height, aa);
    ml::scan::LatticeBox box;
    if (!ml::scan::lattice_box(t, lat, &box)) continue;
    ml::scan::ActiveTri a = active_from(t, box, lat);
    ml::scan::prepare_weights(&a, lat);
    for (int32_t y = box.y0; y <= box.y1; ++y) {
      int32_t x0, x1;
      if (!ml::scan::row_span(a, lat, y, &x0, &x1)) continue;
      for (int32_t x = x0; x <= x1; x += 1 + (x1 - x0) / 7) {
        int32_t w[3];
        ml::scan::sample_weights(a, lat, x, y, w);
        // The reference: unbiased edge functions at the sample, divided.
        const int64_t u = int64_t(x) * 256 + lat.ox, v = int64_t(y) * 256 + lat.oy;
        int64_t e[3];
        for (int j = 0; j < 3; ++j) {
          const int p = (j + 1) % 3, q = (j + 2) % 3;
          e[j] = (int64_t(a.vy[p]) - a.vy[q]) * (u - int64_t(a.vx[p]) * lat.den) +
                 (int64_t(a.vx[q]) - a.vx[p]) * (v - int64_t(a.vy[p]) * lat.den);
          ASSERT_GE(e[j], 0);
        }
        const int64_t total = e[0] + e[1] + e[2];
        ASSERT_EQ(total, t.area2 * lat.den);
        const int shift = std::max(0, ml::bit_length(uint64_t(total)) - 46);
        const int64_t den = std::max<int64_t>(1, total >> shift);
        ASSERT_EQ(w[1], ml::div_round((e[1] >> shift) << 16, den)) << "it " << it;
        ASSERT_EQ(w[2], ml::div_round((e[2] >> shift) << 16, den)) << "it " << it;
        ASSERT_EQ(w[0] + w[1] + w[2], 65536);
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 20000);
}

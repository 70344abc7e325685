// Woo & Chall's scanline renderer in integers. The algorithm, formats and memory formula are
// described in docs/scanline.md; this file follows the paper's sections in order.
#include "scanline/scanline.h"

#include <string.h>

#include "core/band.h"
#include "core/build.h"
#include "scanline/internal.h"
#include "scanline/sort.h"
#include "scanline/wide.h"
#include "shade/shade.h"
#include "texture/mapping.h"
#include "texture/pager.h"
#include "texture/sampler.h"
#include "view/vertex_cache.h"

namespace ml {
namespace scan {

// ---- sample lattice and per-piece geometry (§3.2, §4) -----------------------------------------

Lattice make_lattice(int width, int height, int aa) {
  Lattice lat;
  lat.l = aa;
  if (aa <= 1) {
    lat.l = 1;
    lat.den = 1;
    lat.ox = lat.oy = kSubpixelHalf;
    lat.q = 1;
    lat.nx = width;
    lat.ny = height;
  } else {
    lat.den = aa - 1;
    lat.ox = lat.oy = 0;
    lat.q = aa - 1;
    lat.nx = width * lat.q + 1;
    lat.ny = height * lat.q + 1;
  }
  return lat;
}

// Lattice rows/columns whose sample coordinate lies in [lo, hi] subpixels (o = origin offset).
static inline int64_t lattice_first(int64_t lo, const Lattice& lat, int32_t o) {
  return floor_shift(lo * lat.den - o + (kSubpixelOne - 1), kSubpixelBits);  // ceil((lo den - o) / 256)
}
static inline int64_t lattice_last(int64_t hi, const Lattice& lat, int32_t o) {
  return floor_shift(hi * lat.den - o, kSubpixelBits);
}

bool lattice_box(const ScreenTriangle& t, const Lattice& lat, LatticeBox* b) {
  // Screen coordinates are below 2^22 and den at most 7: the lattice indices fit int32 on the way.
  const int32_t ax = t.v[0].x, bx = t.v[1].x, cx = t.v[2].x, ay = t.v[0].y, by = t.v[1].y, cy = t.v[2].y;
  const int32_t x0 = min_of(ax, min_of(bx, cx)), x1 = max_of(ax, max_of(bx, cx));
  const int32_t y0 = min_of(ay, min_of(by, cy)), y1 = max_of(ay, max_of(by, cy));
  b->y0 = max_of(int32_t(0), int32_t(lattice_first(y0, lat, lat.oy)));
  b->y1 = min_of(lat.ny - 1, int32_t(lattice_last(y1, lat, lat.oy)));
  if (b->y0 > b->y1) return false;
  b->x0 = max_of(int32_t(0), int32_t(lattice_first(x0, lat, lat.ox)));
  b->x1 = min_of(lat.nx - 1, int32_t(lattice_last(x1, lat, lat.ox)));
  return b->x0 <= b->x1;
}

// Edge i (v_i -> v_{i+1}) of the piece on sample row y, scaled by den: E*den = k X + r, exact in int64
// (|E*den| < 2^50 inside the guard band). The edge function is view.h's, top-left rule included.
struct LatticeEdge {
  int64_t k, r;
};
static inline LatticeEdge lattice_row(const EdgeFunction& e, const Lattice& lat, int32_t y) {
  // E(x, y) * den at x = (256 X + ox) / den, y = (256 Y + oy) / den.
  return LatticeEdge{e.a * kSubpixelOne,
                     e.b * (int64_t(y) * kSubpixelOne + lat.oy) + e.a * lat.ox + e.c * lat.den};
}
static inline LatticeEdge lattice_edge(const ActiveTri& t, const Lattice& lat, int i, int32_t y) {
  const int j = i == 2 ? 0 : i + 1;
  return lattice_row(edge_function(t.vx[i], t.vy[i], t.vx[j], t.vy[j]), lat, y);
}

bool row_span(const ActiveTri& t, const Lattice& lat, int32_t y, int32_t* min_x, int32_t* max_x) {
  int64_t lo = 0, hi = lat.nx - 1;
  for (int i = 0; i < 3; ++i) {
    const LatticeEdge e = lattice_edge(t, lat, i, y);
    if (e.k > 0) {
      const int64_t first = -div_floor(e.r, e.k);  // k X >= -r
      if (first > lo) lo = first;
    } else if (e.k < 0) {
      const int64_t last = div_floor(e.r, -e.k);
      if (last < hi) hi = last;
    } else if (e.r < 0) {
      return false;
    }
    if (lo > hi) return false;
  }
  *min_x = int32_t(lo);
  *max_x = int32_t(hi);
  return true;
}

// Pixels [x0, x1] of a row set to c. On 64-bit hosts two at a time (a row's runs and gaps between
// pieces are most of its samples); the boards store one at a time (no unaligned 64-bit stores there).
static inline void fill_pixels(Pixel* row, int32_t x0, int32_t x1, Pixel c) {
#if UINTPTR_MAX > 0xFFFFFFFFu
  const uint64_t two = c | (uint64_t(c) << 32);
  int32_t x = x0;
  for (; x < x1; x += 2) memcpy(row + x, &two, sizeof two);
  if (x == x1) row[x] = c;
#else
  for (int32_t x = x0; x <= x1; ++x) row[x] = c;
#endif
}

// Edge p -> q's function times den at column x of sample row `row` (256 Y + oy), the fill rule folded
// in: lattice_row(edge_function(p, q)) at X, written relative to p, which takes fewer products:
// a (256 X + ox - den p.x) + b (row - den p.y), minus den off a top-left edge (edge_plane's a and b).
static int64_t edge_value(int32_t px, int32_t py, int32_t qx, int32_t qy, const Lattice& lat, int64_t row, int32_t x) {
  const EdgeFunction plane = edge_plane(px, py, qx, qy);
  const int64_t v = plane.a * (int64_t(x) * kSubpixelOne + lat.ox - int64_t(lat.den) * px) +
                    plane.b * (row - int64_t(lat.den) * py);
  return is_top_left(plane.a, plane.b) ? v : v - lat.den;
}

void start_span(ActiveTri* t, const Lattice& lat, int32_t y) {
  [[maybe_unused]] const int64_t row = int64_t(y) * kSubpixelOne + lat.oy;
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    const int j = i == 2 ? 0 : i + 1;
    // A left edge (E grows with X) starts at the box's left side, a right edge at its right side.
    t->edge_x[i] = int16_t(t->vy[i] > t->vy[j] ? t->box_x0 : t->box_x1);
#if ML_CARRY_EDGE_VALUES
    t->edge_v[i] = edge_value(t->vx[i], t->vy[i], t->vx[j], t->vy[j], lat, row, t->edge_x[i]);
#endif
  }
#if ML_CARRY_EDGE_VALUES
  t->edge_row = y;
#endif
}

// Edge p -> q of step_span, its function `v` at boundary column *col of this row: walks the column to
// the row's crossing and narrows [*left, *right]; false when the edge is horizontal and the row lies
// outside it. *value: v at the column reached.
static inline bool walk_edge(int32_t py, int32_t qy, int64_t v, int32_t lo, int32_t hi, int16_t* col, int64_t* value,
                             int32_t* left, int32_t* right) {
  const int64_t k = (int64_t(py) - qy) * kSubpixelOne;  // edge_plane's a, per sample
  int32_t x = *col;
  if (k > 0) {
    // Left edge: the first column in [lo, hi + 1] from which E >= 0.
    while (x > lo && v - k >= 0) { --x; v -= k; }
    while (x <= hi && v < 0) { ++x; v += k; }
    *left = max_of(*left, x);
  } else if (k < 0) {
    // Right edge: the last column in [lo - 1, hi] up to which E >= 0.
    while (x < hi && v + k >= 0) { ++x; v += k; }
    while (x >= lo && v < 0) { --x; v -= k; }
    *right = min_of(*right, x);
  } else if (v < 0) {
    *value = v;
    return false;  // horizontal edge with the row outside it
  }
  *col = int16_t(x);
  *value = v;
  return true;
}

// Edge p -> q of stepped_span: its function at boundary column *col of this row, carried from the
// last row stepped (*value, `rows` rows up) or evaluated, then walked.
static inline bool step_edge(int32_t px, int32_t py, int32_t qx, int32_t qy, const Lattice& lat, int64_t row,
                             int64_t rows, int32_t lo, int32_t hi, int16_t* col, int64_t* value, int32_t* left,
                             int32_t* right) {
#if ML_CARRY_EDGE_VALUES
  (void)lat, (void)row, (void)py;
  const int64_t v = *value + (int64_t(qx) - px) * kSubpixelOne * rows;  // edge_plane's b, a row down
#else
  (void)rows;
  const int64_t v = edge_value(px, py, qx, qy, lat, row, *col);
#endif
  return walk_edge(py, qy, v, lo, hi, col, value, left, right);
}

// step_span, inline in the renderer's row loop on 64-bit hosts (the call and its saved registers cost
// about a sixth of a stepped span).
ML_HOST_INLINE static inline bool stepped_span(ActiveTri* t, const Lattice& lat, int32_t y, int32_t* min_x, int32_t* max_x) {
  const int32_t lo = t->box_x0, hi = t->box_x1;
  const int64_t row = int64_t(y) * kSubpixelOne + lat.oy;
#if ML_CARRY_EDGE_VALUES
  const int64_t rows = y - t->edge_row;
  t->edge_row = y;
  int64_t* v = t->edge_v;
#else
  const int64_t rows = 0;
  int64_t v[3];  // the values reached (unused)
#endif
  int32_t left = lo, right = hi;
  // Every edge is stepped, even past an empty one, so that each keeps its column for the next row.
  const bool e0 = step_edge(t->vx[0], t->vy[0], t->vx[1], t->vy[1], lat, row, rows, lo, hi, &t->edge_x[0], &v[0], &left, &right);
  const bool e1 = step_edge(t->vx[1], t->vy[1], t->vx[2], t->vy[2], lat, row, rows, lo, hi, &t->edge_x[1], &v[1], &left, &right);
  const bool e2 = step_edge(t->vx[2], t->vy[2], t->vx[0], t->vy[0], lat, row, rows, lo, hi, &t->edge_x[2], &v[2], &left, &right);
  if (!(e0 && e1 && e2) || left > right) return false;
  *min_x = left;
  *max_x = right;
  return true;
}

bool step_span(ActiveTri* t, const Lattice& lat, int32_t y, int32_t* min_x, int32_t* max_x) {
  return stepped_span(t, lat, y, min_x, max_x);
}

// The plane (no fill rule) of the edge opposite vertex j, v_{j+1} -> v_{j+2}: vertex j's barycentric
// weight times area2.
static inline EdgeFunction opposite_plane(const ActiveTri& t, int j) {
  const int p = j == 2 ? 0 : j + 1;
  const int q = p == 2 ? 0 : p + 1;
  return edge_plane(t.vx[p], t.vy[p], t.vx[q], t.vy[q]);
}

static inline int64_t triangle_area2(const ActiveTri& t) {
  return (int64_t(t.vx[1]) - t.vx[0]) * (int64_t(t.vy[2]) - t.vy[0]) -
         (int64_t(t.vy[1]) - t.vy[0]) * (int64_t(t.vx[2]) - t.vx[0]);
}

// The weights' divisor for a sum of edge functions `total` > 0 is total >> weight_shift(total): kept
// below 2^46 (so that a numerator << 16 fits), at least 1.
static inline int weight_shift(uint64_t total) { return max_of(0, bit_length(total) - kReciprocalDivisorBits); }
static inline uint64_t weight_divisor(uint64_t total, int shift) { return max_of<uint64_t>(1, total >> shift); }

void depth_plane(ActiveTri* t, const uint32_t depth[3], const Lattice& lat) {
  // Barycentric weight of vertex j = E_opp(j) / area2 with E_opp(j) the unbiased edge v_{j+1} -> v_{j+2}
  // (edge index j+1). depth = sum d_j E_opp(j) / area2, a plane in (X, Y):
  //   z0 = sum d_j E_opp(j)(X=0,Y=0) * den, gx = sum d_j a_opp(j) * 256, gy = sum d_j b_opp(j) * 256,
  // all over area2 * den, times 2^16 (Q16).
  int64_t d[3], cz[3], ca[3], cb[3];
  ML_HOST_UNROLL for (int j = 0; j < 3; ++j) {
    const EdgeFunction e = opposite_plane(*t, j);
    d[j] = depth[j];
    ca[j] = e.a;
    cb[j] = e.b;
    cz[j] = lattice_row(e, lat, 0).r;  // E * den at sample (0, 0)
  }
  const int64_t den = triangle_area2(*t) * lat.den;
  t->z_row = mul_add3_div_round_low(d, cz, 16, den);
  t->gx = mul_add3_div_round_low(d, ca, 16 + kSubpixelBits, den);
  t->gy = mul_add3_div_round_low(d, cb, 16 + kSubpixelBits, den);
}

void prepare_weights(ActiveTri* t, const Lattice& lat) {
  const uint64_t total = uint64_t(triangle_area2(*t) * lat.den);
  t->weight_shift = uint8_t(weight_shift(total));
  t->weight_recip = make_reciprocal(weight_divisor(total, t->weight_shift));
}

namespace {
// The weights of a piece at its covered samples from the edge values there, e[j] for the edge opposite
// vertex j (j = 1, 2), scaled by den. At a covered sample the three are >= 0 and sum to area2 * den
// (the edge functions of a triangle add up to its doubled area everywhere): the divisor
// prepare_weights made the reciprocal for. Numerators are kept below 2^46 so that << 16 fits; w =
// round(e 2^16 / total) (div_round of non-negatives). A value below 0 (not at a covered sample) is kept
// in range.
class WeightDivider {
 public:
  WeightDivider(const ActiveTri& t, const Lattice& lat)
      : total_(uint64_t(triangle_area2(t) * lat.den)), shift_(t.weight_shift),
        d_(weight_divisor(total_, shift_)), half_(d_ / 2), recip_(t.weight_recip) {}
  [[gnu::always_inline]] void weights(const int64_t e[3], int32_t w[3]) const {
    ML_HOST_UNROLL for (int j = 1; j < 3; ++j) {
      const uint64_t ej = min_of(uint64_t(max_of(e[j], int64_t(0))), total_) >> shift_;  // <= d: quotients <= 2^16
      w[j] = int32_t(divide_by_reciprocal((ej << kWeightBits) + half_, d_, recip_));
    }
    w[0] = kWeightOne - w[1] - w[2];
  }

 private:
  uint64_t total_;
  int shift_;
  uint64_t d_, half_;
  uint32_t recip_;
};
}  // namespace

void sample_weights(const ActiveTri& t, const Lattice& lat, int32_t x, int32_t y, int32_t w[3]) {
  int64_t e[3];  // e[j]: the plane of the edge opposite vertex j at the sample, scaled by den
  for (int j = 1; j < 3; ++j) {
    const LatticeEdge r = lattice_row(opposite_plane(t, j), lat, y);
    e[j] = r.k * x + r.r;
  }
  WeightDivider(t, lat).weights(e, w);
}

void smooth_run(const ActiveTri& t, const Lattice& lat, int32_t x0, int32_t x1, int32_t y, Pixel* out) {
  int64_t e[3], k[3];  // sample_weights' edge values, stepped along the row (e = k x + r: the same values)
  for (int j = 1; j < 3; ++j) {
    const LatticeEdge r = lattice_row(opposite_plane(t, j), lat, y);
    e[j] = r.k * x0 + r.r;
    k[j] = r.k;
  }
  const WeightDivider divider(t, lat);
  for (int32_t x = x0; x <= x1; ++x, e[1] += k[1], e[2] += k[2]) {
    int32_t w[3];
    divider.weights(e, w);
    out[x] = blend_colors_inline(t.color, w);
  }
}

Vec3i interpolate_normal(const int16_t n[3][3], const int32_t w[3], int steps) {
  int64_t acc[3] = {0, 0, 0};
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) acc[k] += int64_t(n[j][k]) * w[j];
  Vec3i v{int32_t(shift_round(acc[0], kWeightBits)), int32_t(shift_round(acc[1], kWeightBits)),
          int32_t(shift_round(acc[2], kWeightBits))};
  for (int i = 0; i < steps; ++i) v = newton_renormalize_q14(v);
  return v;
}

void interpolate_uv(const int32_t uv[3][2], const int32_t w[3], int32_t out[2]) {
  for (int k = 0; k < 2; ++k) {
    int64_t acc = 0;
    for (int j = 0; j < 3; ++j) acc += int64_t(uv[j][k]) * w[j];
    out[k] = int32_t(shift_round(acc, kWeightBits));
  }
}

// ---- setup shared by scanline_arena_bytes and scanline_render ----------------------------------

namespace {

constexpr Pixel kLineColor = 0xFFFFFF;
constexpr int kShadeTolerance = 32;           // per channel, forces supersampled shading (§3.4.2)
constexpr uint32_t kValid = 1u << 24;         // keep_rgb: holds a shaded colour
constexpr uint32_t kForce = 1u << 25;         // keep_rgb: supersample shading in this pixel

struct Setup {
  View view;
  Lattice lat;
  int width = 0, height = 0;
  bool colour = true;  // not Ids / Lines
  bool accumulate = false;  // l > 1 colour: per-pixel sums
  size_t band_bytes = 0;    // band buffers (core/band.h)
  size_t pager_bytes = 0;   // texture pager (texture/pager.h); 0 without texels or in Ids/Lines mode
};

Status make_setup(const Scene& scene, const Camera& camera, const RenderOptions& options, Setup* s) {
  if (options.aa < 1 || options.aa > kMaxSamplesPerAxis) return error(StatusCode::InvalidArgument, "aa must be 1..8");
  if (scene.triangle_count >= kMaxScanlineTriangles) return error(StatusCode::Unsupported, "too many triangles");
  Status st = make_view(camera, &s->view);
  if (!st.ok()) return st;
  st = BandOutput::check(options.output);
  if (!st.ok()) return st;
  s->band_bytes = BandOutput::arena_bytes(options.output, camera.width, camera.height);
  s->width = camera.width;
  s->height = camera.height;
  s->colour = options.shading != ShadingMode::Ids && options.shading != ShadingMode::Lines;
  s->lat = make_lattice(camera.width, camera.height, s->colour ? options.aa : 1);
  s->accumulate = s->colour && s->lat.l > 1;
  s->pager_bytes = s->colour ? TexturePager::arena_bytes(scene, options.texture_pool_bytes) : 0;
  return ok_status();
}

// False when the piece certainly covers no sample of its box: boxes of a few samples are tested
// exactly (the edge functions of step_span), so slivers between samples never enter the ySortList.
constexpr int32_t kSmallBoxSamples = 4;
bool may_cover(const ScreenTriangle& t, const Lattice& lat, const LatticeBox& b) {
  if ((b.x1 - b.x0 + 1) * (b.y1 - b.y0 + 1) > kSmallBoxSamples) return true;
  EdgeFunction f[3];
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    const int j = i == 2 ? 0 : i + 1;
    f[i] = edge_function(t.v[i].x, t.v[i].y, t.v[j].x, t.v[j].y);
  }
  for (int32_t y = b.y0; y <= b.y1; ++y) {
    LatticeEdge r[3];
    for (int i = 0; i < 3; ++i) r[i] = lattice_row(f[i], lat, y);
    for (int32_t x = b.x0; x <= b.x1; ++x)
      if (r[0].k * x + r[0].r >= 0 && r[1].k * x + r[1].r >= 0 && r[2].k * x + r[2].r >= 0) return true;
  }
  return false;
}

// The piece project_triangle makes of an unclipped triangle at these positions, as far as pass 1 looks
// at it (x and y, in area2 > 0 order): 0 when it is degenerate.
int positions_piece(const int32_t x[3], const int32_t y[3], ScreenTriangle* t) {
  const int64_t area2 = (int64_t(x[1]) - x[0]) * (int64_t(y[2]) - y[0]) - (int64_t(y[1]) - y[0]) * (int64_t(x[2]) - x[0]);
  if (area2 == 0) return 0;
  const int b = area2 > 0 ? 1 : 2, c = area2 > 0 ? 2 : 1;  // project_triangle swaps 1 and 2 when < 0
  t->v[0].x = x[0]; t->v[0].y = y[0];
  t->v[1].x = x[b]; t->v[1].y = y[b];
  t->v[2].x = x[c]; t->v[2].y = y[c];
  return 1;
}

// ySortList reference: triangle id, whether it faces away (so activation need not test it again) and
// the piece index from project_triangle.
inline uint32_t make_ref(uint32_t id, int facing, int piece) {
  return (id << 4) | (facing < 0 ? 8u : 0u) | uint32_t(piece);
}

// Whether the view transforms of the ySortList pass and of activation come from a vertex cache
// (view/vertex_cache.h): a vertex of a mesh is shared by about six triangles, and every triangle the
// pass keeps is transformed again when it activates. The same values as view_triangle's: the same image.
inline bool holds(const VertexCache* cache) { return kVertexCacheBuilt && cache && cache->entries() > 0; }
// Whether a batch's triangles share their vertices enough for the cache: a vertex used by three
// triangles or more on average (vertices <= triangles; a mesh's look-ups miss one in four or five). A
// batch of boxes with a vertex per corner and face (24 for 12 triangles: office(8)'s, where two look-ups
// in three miss) loses more to the look-ups than the cache saves.
inline bool shares_vertices(const Batch& b) { return b.vertex_count <= b.triangle_count; }
// The cache's entries for the scene: none when no batch shares its vertices (or in a build without it).
uint32_t cache_entries(const Scene& scene) {
  bool any = false;
  for (uint32_t b = 0; b < scene.batch_count && !any; ++b) any = shares_vertices(scene.batches[b]);
  return kVertexCacheBuilt && any ? VertexCache::entries_for(scene.vertex_count) : 0;
}

// Calls f(ref, min_y, max_y) for every piece that can cover a sample; returns the triangles that
// gave none (culled: back-facing, cut out, behind the eye, off screen, degenerate). cache: null, or a
// vertex cache for the view transforms (which f may drop).
template <typename F>
uint32_t for_each_piece(const Scene& scene, const Setup& s, VertexCache* cache, F f) {
  uint32_t culled = 0;
  bool cached = false;  // the batch's view transforms from the cache
  const Lattice& lat = s.lat;
  uint32_t batch = 0xFFFFFFFFu;
  const Material* material = nullptr;
  bool hidden = false;
  for (uint32_t id = 0; id < scene.triangle_count; ++id) {
    const Triangle tri = triangle_at(scene, id);
    if (tri.batch != batch) {  // a batch's triangles are consecutive: one look-up each
      batch = tri.batch;
      material = &batch_material(scene, batch);
      hidden = material_hidden(*material);
      cached = holds(cache) && shares_vertices(scene.batches[batch]);
    }
    const Material& m = *material;
    if (hidden) { ++culled; continue; }
    Vec3i world[3];
    int32_t x[3], y[3];
    vertices_world(scene, tri.batch, tri.v, world);  // (a linear read: cheaper than the cache's look-ups)
    // Back faces are culled in world space before projecting (exact, as the tiler does).
    const int facing = triangle_facing(s.view, world);
    if (facing == 0 || (facing < 0 && !m.double_sided)) { ++culled; continue; }
    ScreenTriangle pieces[kMaxClipTriangles];
    ViewTriangle viewed;
    if (cached && holds(cache)) cache->view(tri.batch, tri.v, &viewed);  // (f may have dropped it)
    else view_triangle(s.view, world, &viewed);
    int count;
    if (viewed.unclipped) {
      // The common case needs only the positions here (activation projects again): ordered as
      // project_triangle orders them, so the piece is the same.
      unclipped_positions(s.view, viewed, x, y);
      count = positions_piece(x, y, &pieces[0]);
    } else {
      count = project_triangle(s.view, viewed, facing, pieces);
    }
    bool any = false;
    for (int k = 0; k < count; ++k) {
      LatticeBox b;
      if (!lattice_box(pieces[k], lat, &b) || !may_cover(pieces[k], lat, b)) continue;
      f(make_ref(id, facing, k), uint16_t(b.y0), uint16_t(b.y1));
      any = true;
    }
    if (!any) ++culled;
  }
  return culled;
}

inline size_t round8(size_t v) { return (v + 7) & ~size_t(7); }

// Sorting the ySortList and finding m_max take a temporary: two arrays of 4 B a sample row (a histogram
// for m_max, then bucket offsets for sorting by minY without comparisons) or, when those would be
// larger, a sorted copy of max_y (2 B a piece) after a quicksort. The row arrays are also taken when
// they fit in the row buffers the rows phase allocates anyway (keepObj, sums, band): the temporary is
// released before those, so the peak stays the same.
inline size_t row_arrays_bytes(const Lattice& lat) { return (size_t(lat.ny) + 1) * 8; }

// A yActiveList slot's texel table (texture/sampler.h) for its colour, valid while the pager's table
// generation stays the same; untabled counts the samples shaded without one.
struct SlotLut {
  const Pixel* lut;
  Pixel colour, lut_colour;
  uint32_t generation, untabled;
};

// A yActiveList slot's texture planes, or on 64-bit hosts until its first textured sample the
// triangle's view they are made from: planes are made only for triangles some sample shows (about one
// in nine of the duck's activated textured triangles never is). No larger than the planes alone.
union TexSlot {
  TexturePlanes planes;
  ViewTriangle view;
};
static_assert(sizeof(TexSlot) == sizeof(TexturePlanes), "the view in the planes' place");

struct Sizes {
  size_t ysort, drawn, temp, yactive, ord, xactive, keep, acc, band;
  size_t pager, texslots;  // texture pool and per-slot texture state (0 untextured)
  bool by_rows;            // the ySortList is sorted by rows (temp: two row arrays), else quicksorted
  size_t phase1() const { return 7 + pager + ysort + drawn + temp; }
  size_t phase2() const { return 7 + pager + ysort + drawn + yactive + ord + xactive + keep + acc + band + texslots; }
  size_t need() const { return max_of(phase1(), phase2()); }
};

Sizes sizes_for(const Scene& scene, const Setup& s, uint32_t n, uint32_t m) {
  Sizes z;
  z.ysort = round8(size_t(n) * sizeof(YSortEntry));
  z.drawn = round8(((size_t(scene.triangle_count) + 31) / 32) * 4);
  z.yactive = round8(size_t(m) * sizeof(ActiveTri));
  z.ord = round8(size_t(m) * 4);
  z.xactive = round8(size_t(m) * 4);
  z.keep = 2 * round8(size_t(s.width) * 4);
  z.acc = s.accumulate ? round8(size_t(s.width) * 8) : 0;
  z.band = s.band_bytes;
  z.by_rows = row_arrays_bytes(s.lat) <= max_of(size_t(n) * 2, z.keep + z.acc + z.band);
  z.temp = round8(z.by_rows ? row_arrays_bytes(s.lat) : size_t(n) * 2);
  z.pager = s.pager_bytes;
  z.texslots = s.pager_bytes ? round8(size_t(m) * sizeof(TexSlot)) + round8(size_t(m) * 4) +
                                   round8(size_t(m) * sizeof(SlotLut))
                             : 0;
  return z;
}

// n and m_max without any arena: a difference array over blocks of kBlockRows sample rows on the
// stack (1 KiB), one projection pass per block.
constexpr int kBlockRows = 255;
void count_n_m(const Scene& scene, const Setup& s, uint32_t* n_out, uint32_t* m_out) {
  uint32_t n = 0, m = 0;
  for (int32_t base = 0; base < s.lat.ny; base += kBlockRows) {
    int32_t diff[kBlockRows + 1];
    for (int i = 0; i <= kBlockRows; ++i) diff[i] = 0;
    const int32_t end = base + kBlockRows;  // exclusive
    uint32_t count = 0;
    for_each_piece(scene, s, nullptr, [&](uint32_t, uint16_t y0, uint16_t y1) {
      ++count;
      if (y1 < base || y0 >= end) return;
      diff[max_of<int32_t>(y0, base) - base] += 1;
      if (y1 + 1 < end) diff[y1 + 1 - base] -= 1;
    });
    n = count;
    int32_t run = 0;
    for (int i = 0; i < kBlockRows; ++i) {
      run += diff[i];
      if (uint32_t(run) > m) m = uint32_t(run);
    }
  }
  *n_out = n;
  *m_out = m;
}

// m_max from the ySortList sorted by min_y and its max_y values sorted (temp): at each activation,
// active = activated so far - finished before this row.
// m_max from a histogram of the rows: +1 where a piece starts, -1 after it ends; rows[ny + 1].
uint32_t m_from_rows(const YSortEntry* ys, uint32_t n, int32_t ny, int32_t* rows) {
  for (int32_t y = 0; y <= ny; ++y) rows[y] = 0;
  for (uint32_t i = 0; i < n; ++i) {
    ++rows[ys[i].min_y];
    --rows[ys[i].max_y + 1];
  }
  int32_t run = 0, m = 0;
  for (int32_t y = 0; y < ny; ++y) {
    run += rows[y];
    m = max_of(m, run);
  }
  return uint32_t(m);
}

// Sorts ys by min_y in place (American flag sort: bucket offsets, then each entry swapped straight into
// its bucket). start[ny + 1] and next[ny] are scratch. Counts element moves in *work.
void bucket_sort_rows(YSortEntry* ys, uint32_t n, int32_t ny, uint32_t* start, uint32_t* next, uint64_t* work) {
  for (int32_t y = 0; y <= ny; ++y) start[y] = 0;
  for (uint32_t i = 0; i < n; ++i) ++start[ys[i].min_y + 1];
  for (int32_t y = 0; y < ny; ++y) {
    start[y + 1] += start[y];
    next[y] = start[y];
  }
  uint64_t w = 0;
  for (int32_t y = 0; y < ny; ++y) {
    while (next[y] < start[y + 1]) {
      YSortEntry e = ys[next[y]];
      while (e.min_y != y) {  // follow the cycle: e goes to its bucket, the entry there comes out
        const YSortEntry out = ys[next[e.min_y]];
        ys[next[e.min_y]++] = e;
        e = out;
        w += 2;
      }
      ys[next[y]++] = e;
      ++w;
    }
  }
  *work += w;
}

uint32_t m_from_sorted(const YSortEntry* ys, uint16_t* max_ys, uint32_t n, uint64_t* work) {
  quick_sort(max_ys, n, [](uint16_t v) { return v; }, work);
  uint32_t m = 0, j = 0;
  for (uint32_t i = 0; i < n; ++i) {
    while (j < n && max_ys[j] < ys[i].min_y) ++j;
    const uint32_t active = i + 1 - j;
    if (active > m) m = active;
  }
  return m;
}

// ---- the render ---------------------------------------------------------------------------------


struct Renderer {
  const Scene* scene;
  const RenderOptions* opt;
  Setup s;
  Light light;
  Stats* stats;
  Sink* sink;
  Arena* arena;
  BandOutput out;
  Rng rng{1};
  uint32_t p_threshold = 0;  // shade stochastically when rng < threshold: P = 1 / (l + 1)
  // Whether a surface's colour can vary over it (Gouraud). In Flat and Unlit modes a surface is one
  // triangle of one colour (textured ones are shaded at every sample anyway), so keepObj's reuse is
  // exact and §3.4.2's stochastic and forced re-shading could only give the same colour again: they
  // are skipped, and a run of one such surface is emitted in bulk (single_run_constant).
  bool varying = false;

  YSortEntry* ys = nullptr;
  uint32_t n = 0, ys_next = 0;
  uint32_t* drawn = nullptr;
  ActiveTri* act = nullptr;
  uint32_t* ord = nullptr;   // live slots sorted by min_x
  uint32_t* xact = nullptr;
  uint32_t live = 0, high = 0;
  uint32_t free_head = 0xFFFFFFFFu;  // finished slots, linked through ActiveTri::id
  uint32_t* keep_surface = nullptr;  // keepObj: surface key per pixel column (0 = none); output row
  uint32_t* keep_rgb = nullptr;      // keepObj: last colour | kValid | kForce
  uint64_t* acc = nullptr;           // l > 1: per-pixel channel sums, 21 bits each
  Pixel bg = 0;

  VertexCache* vertices = nullptr;  // activation's view transforms (for_each_piece's cache), or null

  // textures: the pager, and per yActiveList slot the texture (kNone: untextured; kTexReady: planes
  // set up) and its perspective planes, set up at the slot's first shading call
  TexturePager pager;
  uint32_t* tex_of = nullptr;
  TexSlot* tex_slots = nullptr;
  TextureLevels levels;  // the mip levels sampled
  SlotLut* tex_lut = nullptr;
  static constexpr uint32_t kTexReady = 0x80000000u;
  static constexpr uint32_t kTexturedChunk = 64;  // samples a supersampled textured run makes at once
  [[no_unique_address]] BatchTextures batch_textures;  // the activated triangles' textures (boards: empty)
#if UINTPTR_MAX > 0xFFFFFFFFu
  KeptSampling kept_sampling;  // small triangles' spans' sampling (texture_run, 64-bit hosts)
  // A row's small textured triangles' spans, waiting to be sampled in one call (sample_small_spans):
  // a span is a few samples, and a call and its set-up each cost about as much. All of one texture
  // and mip level, whose bytes stay put while they wait: any other use of the pager samples them first.
  struct PendingSpans {
    static constexpr uint32_t kMax = 32;
    SmallSpan span[kMax];
    uint32_t count = 0, texture = kNone, level = 0;
    const uint8_t* bytes = nullptr;  // the level's
  } pending;
#endif

  // per sample row (l > 1)
  int32_t cur_px = 0;
  int32_t cur_right = 0;  // cur_px's right border sample
  Pixel last_colour = 0;  // emit_sample, emit_run: last_packed = pack(last_colour)
  uint64_t last_packed = 0;
  uint64_t cur_sum = 0;
  int32_t row_kind = 0;  // 0 interior, 1 top of frame, 2 shared border, 3 bottom of frame
  // The row is its pixel row's first (keepObj's keys all 0 when it starts). Runs come in sample order
  // and write only the columns they reach, so right of a run's first column the keys are still 0.
  bool empty_keys = false;

  // --- activation (§3.1, §4.1) ---
  void activate(const YSortEntry& e, int32_t y) {
#if UINTPTR_MAX > 0xFFFFFFFFu
    if (texturing()) activate_as<true>(e, y);
    else activate_as<false>(e, y);
#else
    activate_as<false>(e, y);
#endif
  }
  uint32_t take_slot() {
    if (free_head == 0xFFFFFFFFu) return high++;
    const uint32_t slot = free_head;
    free_head = act[slot].id;
    return slot;
  }
  // kKeepView: the triangle's view kept in its slot for its texture planes (64-bit hosts).
  template <bool kKeepView>
  void activate_as(const YSortEntry& e, int32_t y) {
    const uint32_t id = e.ref >> 4;
    const int k = int(e.ref & 7);
    ScreenTriangle pieces[kMaxClipTriangles];
    // Deterministic: the same pieces as the ySortList pass, which also found the facing. (Its view
    // transform kept for a textured triangle's planes, below.)
    uint32_t slot = kKeepView ? take_slot() : 0;
    // Kept in the slot for its texture planes, made at its first textured sample (planes_of).
    ViewTriangle own;
    ViewTriangle& viewed = kKeepView ? tex_slots[slot].view : own;
    const Triangle tri = triangle_at(*scene, id);
    if (holds(vertices) && shares_vertices(scene->batches[tri.batch])) {
      vertices->view(tri.batch, tri.v, &viewed);
    } else {
      Vec3i world[3];
      triangle_world(*scene, id, world);
      view_triangle(s.view, world, &viewed);
    }
    project_triangle(s.view, viewed, (e.ref & 8) ? -1 : 1, pieces);
    const ScreenTriangle& t = pieces[k];
    if (!kKeepView) slot = take_slot();
    ActiveTri& a = act[slot];
    uint8_t flags = 0;
    ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
      a.vx[i] = t.v[i].x;
      a.vy[i] = t.v[i].y;
    }
    if (t.front_facing) flags |= kFront;
    if (texturing()) {
      tex_of[slot] = batch_textures.of_triangle(*scene, id);
      tex_lut[slot] = SlotLut{nullptr, 0, 0, ~0u, 0};
      pager.add_user(tex_of[slot]);
#if UINTPTR_MAX == 0xFFFFFFFFu
      // The texture planes now, from the view transform at hand (planes_of would make it again).
      if (tex_of[slot] != kNone) {
        triangle_texture_planes(*scene, s.view, id, tex_of[slot], s.lat.den, s.lat.ox, s.lat.oy, &tex_slots[slot].planes,
                                &viewed);
        tex_of[slot] |= kTexReady;
      }
#endif
    }
    const Material& mat = triangle_material(*scene, id);
    if (mat.alpha_mode == uint8_t(AlphaMode::Blend) && s.colour) flags |= kBlend;
    const uint32_t depth[3] = {t.v[0].depth, t.v[1].depth, t.v[2].depth};
    depth_plane(&a, depth, s.lat);
    a.z_row += a.gy * uint64_t(int64_t(y));
    a.id = id;
    a.max_y = e.max_y;
    a.min_x = kNoSpan;
    a.max_x = 0;
    LatticeBox box;
    lattice_box(t, s.lat, &box);
    a.box_x0 = uint16_t(box.x0);
    a.box_x1 = uint16_t(box.x1);
    start_span(&a, s.lat, y);
    // Unclipped pieces keep the original vertices (possibly reordered): colours can wait until the
    // first shading call. Clipped pieces blend vertex colours by their weights now.
    uint8_t perm = 0;
    for (int j = 0; j < 3 && perm != 0xFF; ++j) {
      int which = -1;
      ML_HOST_UNROLL for (int c = 0; c < 3; ++c)
        if (t.v[j].weight[c] == kWeightOne) which = c;
      if (which < 0) perm = 0xFF;
      else perm = uint8_t(perm | (which << (2 * j)));
    }
    a.perm = perm;
    a.flags = flags;
    if (perm == 0xFF && s.colour) {
      TriangleColors colors;
      shade_triangle(*scene, light, opt->shading, id, t.front_facing, &colors);
      ML_HOST_UNROLL for (int j = 0; j < 3; ++j)
        a.color[j] = colors.smooth ? blend_vertex_color(colors, t.v[j]) : colors.flat;
      a.flags |= kColorsReady;
      if (colors.smooth) a.flags |= kSmooth;
    }
    ord[live++] = slot;
  }

  void ensure_colors(ActiveTri& a) {
    if (!(a.flags & kColorsReady)) make_colors(a);
  }
  // Out of line: once a piece, off the per-run paths.
  [[gnu::noinline]] void make_colors(ActiveTri& a) {
    TriangleColors colors;
    shade_triangle(*scene, light, opt->shading, a.id, (a.flags & kFront) != 0, &colors);
    if (colors.smooth) {
      for (int j = 0; j < 3; ++j) a.color[j] = colors.vertex[(a.perm >> (2 * j)) & 3];
      a.flags |= kSmooth;
    } else {
      a.color[0] = colors.flat;
    }
    a.flags |= kColorsReady;
  }

  // A Gouraud piece's weight reciprocal (prepare_weights), made at its first smooth sample: one a
  // piece, no division a sample.
  void ready_weights(ActiveTri& a) {
    if (a.flags & kWeightsReady) return;
    prepare_weights(&a, s.lat);
    a.flags |= kWeightsReady;
  }
  // One shading call (§4.4): the colour of piece `a` at sample (x, y).
  Pixel shade(ActiveTri& a, int32_t x, int32_t y) {
    ++stats->shading_calls;
    ensure_colors(a);
    Pixel c = a.color[0];
    if (a.flags & kSmooth) {
      ready_weights(a);
      int32_t w[3];
      sample_weights(a, s.lat, x, y, w);
      c = blend_colors(a.color, w);
    }
    if (texturing()) {
      const uint32_t slot = uint32_t(&a - act);
      if (tex_of[slot] != kNone) return texture(slot, a.id, x, y, c);
    }
    return c;
  }

  // §5: the texel at sample (x, y) modulates the shaded colour (the colour alone when the pager
  // falls back). Texture coordinates come from the whole triangle, as in the tiler.
  Pixel texture(uint32_t slot, uint32_t id, int32_t x, int32_t y, Pixel c) {
    const uint32_t texture = tex_of[slot] & ~kTexReady;
    TexturePlanes& planes = planes_of(slot, id);
    const uint8_t* bytes = texture_bytes(texture, planes.level, false, y);
    if (!bytes) return c;
    const TextureTexels& t = level_texels(texture, planes.level);
#if UINTPTR_MAX > 0xFFFFFFFFu
    if (planes.exact && !(act[slot].flags & kSmooth)) {  // a small triangle's sample as its spans take them
      Pixel out;
      sample_row(kept_sampling.for_texture(pager, t, texture, bytes, planes, c), x, y, 1, &out);
      return out;
    }
#endif
    int32_t uv[2];
    texture_uv(planes, x, y, uv);
    if (act[slot].flags & kSmooth) return sample_texture(t, bytes, uv, c, planes.exact);
    // A flat piece's samples keep the texel table the pager has cached for its colour (the same
    // colours as without it; looked up again when the pager makes a table). Without one, the pager
    // makes one once the slot has shaded as many samples as a run it would make one for.
    SlotLut& l = tex_lut[slot];
    if (l.generation != pager.lut_generation() || l.colour != c) {
      l.lut = pager.texel_lut(texture, c, bytes, 0, &l.lut_colour);
      l.colour = c;
      l.generation = pager.lut_generation();
      l.untabled = 0;
    }
    if (!l.lut || l.lut_colour != c) {
      ++l.untabled;  // samples shaded without a table of their own colour
      if (l.untabled >= TexturePager::kLutMinSamples && !planes.exact) {
        l.lut = pager.texel_lut(texture, c, bytes, l.untabled, &l.lut_colour);
        l.generation = pager.lut_generation();
      }
    }
    if (l.lut) return sample_texture(t, bytes, l.lut, l.lut_colour, uv, c, planes.exact);
    return sample_texture(t, bytes, uv, c, planes.exact);
  }
  TexturePlanes& planes_of(uint32_t slot, uint32_t id) {
    uint32_t& t = tex_of[slot];
    if (!(t & kTexReady)) make_planes(slot, id);
    return tex_slots[slot].planes;
  }
  // The slot's texture planes: on 64-bit hosts from the view its activation kept (the planes take
  // its place), on the boards from the triangle (activation makes them there).
  void make_planes(uint32_t slot, uint32_t id) {
    uint32_t& t = tex_of[slot];
#if UINTPTR_MAX > 0xFFFFFFFFu
    const ViewTriangle viewed = tex_slots[slot].view;
    triangle_texture_planes(*scene, s.view, id, t, s.lat.den, s.lat.ox, s.lat.oy, &tex_slots[slot].planes, &viewed);
#else
    triangle_texture_planes(*scene, s.view, id, t, s.lat.den, s.lat.ox, s.lat.oy, &tex_slots[slot].planes);
#endif
    t |= kTexReady;
  }
  // Samples [x0, x1] of row y of textured piece `a` in a flat colour, into out: one texture_row,
  // or for a small triangle with kWait (one sample a pixel, out = keep_surface + x0) a span sampled
  // with the row's others (the same colours as shade() sample by sample). False when the piece is
  // smooth (left to shade()).
  template <bool kWait>
  bool texture_run(ActiveTri& a, int32_t x0, int32_t x1, int32_t y, Pixel* out) {
    ensure_colors(a);
    if (a.flags & kSmooth) return false;
    const uint32_t slot = slot_of(a), texture = tex_of[slot] & ~kTexReady, n = uint32_t(x1 - x0 + 1);
    stats->shading_calls += n;
    TexturePlanes& planes = planes_of(slot, a.id);
    const uint8_t* bytes = texture_bytes(texture, planes.level, kWait && planes.exact, y);
    if (!bytes) {
      for (uint32_t i = 0; i < n; ++i) out[i] = a.color[0];
      return true;
    }
    // The slot's table, looked up once for its rows: again only when the pager has made one since,
    // or for a run long enough to have a table of the colour made. A small triangle's is the
    // texture's white one (TexturePager::white_lut).
    const Pixel c = a.color[0];
    if (planes.exact) {
#if UINTPTR_MAX > 0xFFFFFFFFu
      if (!kWait) {  // kept from small triangle to small triangle
        sample_row(kept_sampling.for_texture(pager, level_texels(texture, planes.level), texture, bytes, planes, c), x0,
                   y, int32_t(n), out);
        return true;
      }
      // Sampled with the row's others (sample_small_spans).
      if (pending.count == 0) pending.texture = texture, pending.level = planes.level, pending.bytes = bytes;
      pending.span[pending.count++] = SmallSpan{&planes, c, x0, int32_t(n)};
      a.flags |= kSmallTextured;
#else
      const Pixel* white = pager.white_lut(texture, bytes);
      texture_row(planes, level_texels(texture, planes.level), bytes, white, 0xFFFFFF, c, x0, y, int32_t(n), out,
                  pager.lanes_for(texture, white, 0xFFFFFF, c, true));
#endif
      return true;
    }
    SlotLut& l = tex_lut[slot];
    if (l.generation != pager.lut_generation() || l.colour != c || !l.lut ||
        (l.lut_colour != c && n >= TexturePager::kLutMinSamples)) {
      l.lut = pager.texel_lut(texture, c, bytes, n, &l.lut_colour);
      l.colour = c;
      l.generation = pager.lut_generation();
      l.untabled = 0;
    }
    texture_row(planes, level_texels(texture, planes.level), bytes, l.lut, l.lut_colour, c, x0, y, int32_t(n), out,
                pager.lanes_for(texture, l.lut, l.lut_colour, c, false));
    return true;
  }
  // The bytes of the texture's mip level `level` (TexturePager::get's, moved to the level). The
  // waiting small spans are sampled first, unless this is for another small span of their texture and
  // level (it joins them: their bytes are its).
  ML_HOST_INLINE const uint8_t* texture_bytes(uint32_t texture, uint32_t level, bool small, int32_t y) {
#if UINTPTR_MAX > 0xFFFFFFFFu
    if (small && pending.count != 0 && pending.texture == texture && pending.level == level &&
        pending.count < PendingSpans::kMax)
      return pending.bytes;
    sample_small_spans(y);
#else
    (void)small, (void)y;
#endif
    return levels.bytes(*scene, texture, level, pager.get(texture));
  }
  const TextureTexels& level_texels(uint32_t texture, uint32_t level) { return levels.texels(*scene, texture, level); }
#if UINTPTR_MAX > 0xFFFFFFFFu
  // texture_run's answer for a span of a small triangle of the waiting spans' texture, its planes
  // and colour made (the common case: texture_run took one of its spans before), without its checks.
  bool join_small_span(ActiveTri& a, int32_t x0, int32_t x1) {
    if (!(a.flags & kSmallTextured)) return false;
    const uint32_t slot = slot_of(a);
    if (pending.count == 0 || pending.count == PendingSpans::kMax || tex_of[slot] != (pending.texture | kTexReady) ||
        tex_slots[slot].planes.level != pending.level)
      return false;
    stats->shading_calls += uint64_t(x1 - x0 + 1);
    pending.span[pending.count++] = SmallSpan{&tex_slots[slot].planes, a.color[0], x0, x1 - x0 + 1};
    return true;
  }
#endif
  // The waiting spans of row y sampled, into the row.
  void sample_small_spans(int32_t y) {
#if UINTPTR_MAX > 0xFFFFFFFFu
    if (pending.count == 0) return;
    const SmallSpan& first = pending.span[0];
    const TextureSampling& sampling =
        kept_sampling.for_texture(pager, level_texels(pending.texture, pending.level), pending.texture, pending.bytes,
                                  *first.planes, first.colour);
    sample_spans(sampling, pending.span, pending.count, y, keep_surface);
    pending.count = 0;
#else
    (void)y;
#endif
  }
  // Whether this frame textures at all (never in a build without textures: its paths compile away),
  // and whether the piece in `slot` is textured.
  bool texturing() const { return kTextures && tex_of != nullptr; }
  bool textured(uint32_t slot) const { return texturing() && tex_of[slot] != kNone; }
  uint32_t slot_of(const ActiveTri& a) const { return uint32_t(&a - act); }

  void mark_drawn(ActiveTri& a) {
    if (a.flags & kWon) return;
    a.flags |= kWon;
    uint32_t& word = drawn[a.id >> 5];
    const uint32_t bit = 1u << (a.id & 31);
    if (!(word & bit)) { word |= bit; ++stats->triangles_drawn; }
  }

  uint32_t surface_key(const ActiveTri& a) const {
    // Woo's keepObj keys on the surface, not the triangle: for Gouraud shading the smooth surface is
    // the batch (one glTF primitive); flat colours are per triangle, so there the triangle is the key.
    if (opt->shading == ShadingMode::Gouraud) {
      const uint32_t batch = triangle_at(*scene, a.id).batch;
      return 0x80000000u | (batch << 1) | ((a.flags & kFront) ? 1u : 0u);
    }
    return a.id + 1;
  }

  // --- per-sample output for l > 1: shared border samples feed both pixels -----------------------
  static uint64_t pack(Pixel c) {
    return (uint64_t((c >> 16) & 0xFF) << 42) | (uint64_t((c >> 8) & 0xFF) << 21) | uint64_t(c & 0xFF);
  }
  Pixel finish(uint64_t sum) const {
    const uint32_t l2 = uint32_t(s.lat.l * s.lat.l);
    const uint32_t r = uint32_t((sum >> 42) & 0x1FFFFF), g = uint32_t((sum >> 21) & 0x1FFFFF),
                   b = uint32_t(sum & 0x1FFFFF);
    return rgb((r + l2 / 2) / l2, (g + l2 / 2) / l2, (b + l2 / 2) / l2);
  }
  void commit(int32_t px, uint64_t sum) {
    switch (row_kind) {
      case 0: acc[px] += sum; break;
      case 1: acc[px] = sum; break;
      case 2: keep_surface[px] = finish(acc[px] + sum); acc[px] = sum; break;
      default: keep_surface[px] = finish(acc[px] + sum); break;
    }
  }
  // commit(px, sum) for px in [px0, px1), the row kind decided once; sum is q + 1 samples of colour c
  // (packed: pc). A pixel whose l^2 samples all have colour c (background, a surface's inside: most
  // pixels) is c exactly, without the mean's divisions.
  // (Unrolled on hosts, as single_run_constant's column loop: the bundled scene at 3 x 3, 14.11 M -> 13.86 M
  // instructions a frame.)
  void commit_same(int32_t px0, int32_t px1, uint64_t sum, Pixel c, uint64_t pc) {
    const uint64_t all_c = pc * uint64_t(s.lat.l * s.lat.l);
    switch (row_kind) {
      case 0: ML_HOST_UNROLL_8 for (int32_t px = px0; px < px1; ++px) acc[px] += sum; break;
      case 1: for (int32_t px = px0; px < px1; ++px) acc[px] = sum; break;
      case 2:
        ML_HOST_UNROLL_8 for (int32_t px = px0; px < px1; ++px) {
          const uint64_t total = acc[px] + sum;
          keep_surface[px] = total == all_c ? c : finish(total);
          acc[px] = sum;
        }
        break;
      default:
        ML_HOST_UNROLL_8 for (int32_t px = px0; px < px1; ++px) {
          const uint64_t total = acc[px] + sum;
          keep_surface[px] = total == all_c ? c : finish(total);
        }
        break;
    }
  }
  // Samples [x0, x1] of the current row all have colour c (x0 is the next sample in order).
  void emit_run(int32_t x0, int32_t x1, Pixel c) {
    if (!s.accumulate) {
      fill_pixels(keep_surface, x0, x1, c);
      return;
    }
    if (c != last_colour) { last_colour = c; last_packed = pack(c); }  // runs of one colour are common
    const uint64_t pc = last_packed;
    const int32_t q = s.lat.q;
    while (x0 <= x1 && cur_px < s.width) {
      if (x1 < cur_right) { cur_sum += pc * uint64_t(x1 - x0 + 1); return; }
      cur_sum += pc * uint64_t(cur_right - x0 + 1);
      commit(cur_px, cur_sum);
      cur_sum = pc;  // the border sample is also the next pixel's left sample
      x0 = cur_right + 1;
      next_pixel();
      // Pixels the run covers whole get the same sum: committed in one loop.
      const int32_t whole = min_of((x1 - x0 + 1) / q, s.width - cur_px);
      if (whole > 0) {
        commit_same(cur_px, cur_px + whole, pc * uint64_t(q + 1), c, pc);
        cur_px += whole - 1;
        cur_right += (whole - 1) * q;
        x0 = cur_right + 1;
        next_pixel();
      }
    }
  }
  // One covered sample x, the next in order (l > 1).
  void emit_sample(int32_t x, Pixel c) {
    if (c != last_colour) { last_colour = c; last_packed = pack(c); }  // runs of one colour are common
    const uint64_t pc = last_packed;
    cur_sum += pc;
    if (x < cur_right) return;
    commit(cur_px, cur_sum);  // x is cur_px's right border, shared with the next pixel
    cur_sum = pc;
    next_pixel();
  }
  // Pixel column keepObj uses for sample x (x / q, the last column for the right border): x is the
  // sample about to be emitted, so it lies in cur_px or on its right border.
  int32_t pixel_of(int32_t x) const { return x == cur_right && cur_px + 1 < s.width ? cur_px + 1 : cur_px; }
  void next_pixel() {
    ++cur_px;
    cur_right += s.lat.q;
  }

  // Whether any channel of a and b differs by more than kShadeTolerance (§3.4.2).
  static bool differs(uint32_t a, uint32_t b) {
    if (((a ^ b) & 0xFFFFFF) == 0) return false;  // the common case: the same colour
    constexpr uint32_t t = kShadeTolerance;
    const int32_t dr = int32_t((a >> 16) & 0xFF) - int32_t((b >> 16) & 0xFF);
    const int32_t dg = int32_t((a >> 8) & 0xFF) - int32_t((b >> 8) & 0xFF);
    const int32_t db = int32_t(a & 0xFF) - int32_t(b & 0xFF);
    // |d| > t exactly when d + t, as unsigned, exceeds 2t.
    return (uint32_t(dr + int32_t(t)) > 2 * t) | (uint32_t(dg + int32_t(t)) > 2 * t) |
           (uint32_t(db + int32_t(t)) > 2 * t);
  }

  // Colour of one covered sample (§3, §3.4). k entries in xact; their z_run are already one step ahead.
  Pixel resolve_colour(int32_t x, int32_t y, uint32_t k, uint32_t best) {
    ActiveTri& front = act[best];
    if (front.flags & kBlend) return composite(x, y, k);
    mark_drawn(front);
    if (s.lat.l == 1) return shade(front, x, y);
    return keep_or_shade(front, x, y, surface_key(front));
  }

  // keepObj (§3.4.1–3.4.2) for opaque surface `front` at sample x (l > 1): the colour kept in the
  // pixel when the surface is the same, not forced, and the stochastic draw says so; else a shading
  // call, compared with the pixel and its neighbours.
  Pixel keep_or_shade(ActiveTri& front, int32_t x, int32_t y, uint32_t key) {
    const int32_t c = pixel_of(x);
    if (!varying) {  // one colour a surface (a triangle): the kept colour is the piece's own
      if (keep_surface[c] == key && !textured(slot_of(front))) {
        ensure_colors(front);  // the colour may have been shaded for another piece of the triangle
        return front.color[0];
      }
      keep_surface[c] = key;
      return shade(front, x, y);
    }
    const uint32_t kr = keep_rgb[c];
    // Adaptive-stochastic shading (§3.4.2): the generator is drawn only for a kept, unforced surface.
    // Textured surfaces are shaded at every sample: the l x l samples filter the texels (§5).
    if (keep_surface[c] == key && !(kr & kForce) && !textured(slot_of(front)) && rng.next() >= p_threshold)
      return kr & 0xFFFFFF;
    return shade_kept(front, x, y, c, key);
  }

  // A shading call for keepObj column c: compared with the pixel's kept colour and its neighbours'; a
  // difference forces shading of their later samples.
  [[gnu::always_inline]] Pixel shade_kept(ActiveTri& front, int32_t x, int32_t y, int32_t c, uint32_t key) {
    return keep_shaded(shade(front, x, y), c, key);
  }
  // shade_kept's keeping of colour col, shaded for a sample of pixel c of surface `key`.
  [[gnu::always_inline]] Pixel keep_shaded(Pixel col, int32_t c, uint32_t key) {
    uint32_t& kr = keep_rgb[c];
    const bool differ = ((kr & kValid) && differs(kr, col)) ||  // the first that differs decides
                        (c > 0 && (keep_rgb[c - 1] & kValid) && differs(keep_rgb[c - 1], col)) ||
                        (c + 1 < s.width && (keep_rgb[c + 1] & kValid) && differs(keep_rgb[c + 1], col));
    uint32_t force = kr & kForce;
    if (differ) {
      force = kForce;
      if (c > 0) keep_rgb[c - 1] |= kForce;
      if (c + 1 < s.width) keep_rgb[c + 1] |= kForce;
    }
    kr = col | kValid | force;
    keep_surface[c] = key;
    return col;
  }

  // Samples [x0, x1] of the row where opaque piece `a` is the only active span (the common case):
  // no nearest-surface search, the same per-sample results as the general sweep. The common run
  // inline (one sample a pixel, an untextured piece of one colour whose colours are made); the others
  // out of line (other_run), so that the common one pays for no saved registers or stack frame.
  ML_HOST_INLINE void single_run(ActiveTri& a, int32_t x0, int32_t x1, int32_t y) {
    stats->geometry_samples += uint64_t(x1 - x0 + 1);
    mark_drawn(a);
    a.z_run += a.gx * uint64_t(int64_t(x1 - x0));  // as if stepped sample by sample
#if UINTPTR_MAX > 0xFFFFFFFFu  // the boards: other_run alone (flash)
    if (opt->shading != ShadingMode::Ids && !textured(slot_of(a))) {
      if (!s.accumulate && (a.flags & (kColorsReady | kSmooth)) == kColorsReady) {
        stats->shading_calls += uint64_t(x1 - x0 + 1);  // shade()'s answer, counted as its calls
        fill_pixels(keep_surface, x0, x1, a.color[0]);
        return;
      }
      if (s.accumulate && !varying) return single_run_constant(a, x0, x1);
    } else if (join_small_span(a, x0, x1)) {  // a small triangle's later span: no call (texture_run)
      return;
    }
#endif
    other_run(a, x0, x1, y);
  }
  ML_HOST_NOINLINE void other_run(ActiveTri& a, int32_t x0, int32_t x1, int32_t y) {
    if (opt->shading == ShadingMode::Ids) {
      fill_pixels(keep_surface, x0, x1, a.id + 1);
      return;
    }
    if (!s.accumulate) {
      const bool has_texture = textured(slot_of(a));
      if (has_texture && texture_run<true>(a, x0, x1, y, keep_surface + x0)) return;
      ensure_colors(a);
      if (!has_texture && !(a.flags & kSmooth)) {  // one colour: shade()'s answer, counted as its calls
        stats->shading_calls += uint64_t(x1 - x0 + 1);
        fill_pixels(keep_surface, x0, x1, a.color[0]);
        return;
      }
      if (!has_texture) {  // Gouraud: shade()'s colours, the row's weights stepped (smooth_run)
        stats->shading_calls += uint64_t(x1 - x0 + 1);
        ready_weights(a);
        smooth_run(a, s.lat, x0, x1, y, keep_surface);
        return;
      }
      for (int32_t x = x0; x <= x1; ++x) keep_surface[x] = shade(a, x, y);
      return;
    }
    if (!varying && !textured(slot_of(a))) single_run_constant(a, x0, x1);
    else single_run_supersampled(a, x0, x1, y);
  }

  // single_run at l > 1 for a surface of one colour: keepObj's shading call in each pixel column the
  // surface enters (the column of sample x is x / q, the last one for the frame's right border), then
  // the samples emitted in bulk. The same colours and calls as sample by sample: a column's key is
  // checked before any of its samples, and a commit only overwrites columns the run has left.
  ML_HOST_INLINE void single_run_constant(ActiveTri& a, int32_t x0, int32_t x1) {
    const uint32_t key = surface_key(a);
    ensure_colors(a);
    const int32_t q = s.lat.q, last = s.width - 1;
    const int32_t c1 = min_of(x1 / q, last);
    uint32_t* const surface = keep_surface;
    int32_t c = min_of(x0 / q, last);
    uint32_t calls = surface[c] != key;  // shade(): the colour is a.color[0]
    surface[c] = key;
    if (empty_keys) {
      // Every column right of the first is still empty (key 0, never a surface's): one call each.
      calls += uint32_t(c1 - c);
      fill_pixels(surface, c + 1, c1, key);
    } else {
      // (Unrolled by 2 on hosts: runs are a few columns; by 4 or 8 GCC's remainder code costs more.)
      ML_HOST_UNROLL_2 for (++c; c <= c1; ++c) {
        calls += surface[c] != key;
        surface[c] = key;
      }
    }
    stats->shading_calls += calls;
    emit_run(x0, x1, a.color[0]);
  }

  // single_run at l > 1: keep_or_shade and emit_sample for each sample, with the pixel cursor, the
  // running sum and the generator in locals (stores into the keepObj arrays would otherwise make the
  // compiler reload them at every sample).
  void single_run_supersampled(ActiveTri& a, int32_t x0, int32_t x1, int32_t y) {
#if UINTPTR_MAX > 0xFFFFFFFFu
    if (textured(slot_of(a))) return single_run_supersampled_as<true>(a, x0, x1, y);
#endif
    single_run_supersampled_as<false>(a, x0, x1, y);
  }
  // kTextured (64-bit hosts): a textured piece, its samples' colours made a chunk at a time through
  // texture_run's loops when it has one colour (the same colours as shade()'s, sample by sample), kept
  // as shade_kept keeps them.
  template <bool kTextured>
  void single_run_supersampled_as(ActiveTri& a, int32_t x0, int32_t x1, int32_t y) {
    const uint32_t key = surface_key(a);
    const int32_t last_px = s.width - 1, q = s.lat.q;
    const uint32_t p = p_threshold;
    const uint32_t* const surface = keep_surface;
    const uint32_t* const kept = keep_rgb;
    const bool tex = textured(slot_of(a));  // shaded at every sample, as in keep_or_shade
    Pixel chunk[kTextured ? kTexturedChunk : 1];
    bool chunked = kTextured;                // until texture_run leaves a smooth piece to shade()
    int32_t chunk_x = x0, chunk_end = x0 - 1;  // chunk holds samples chunk_x .. chunk_end
    int32_t px = cur_px, right = cur_right;
    uint64_t sum = cur_sum;
    for (int32_t x = x0; x <= x1; ++x) {
      const int32_t c = x == right && px < last_px ? px + 1 : px;
      const uint32_t kr = kept[c];
      Pixel col;
      if constexpr (kTextured) {
        if (chunked && x > chunk_end) {
          chunk_x = x;
          chunk_end = min_of(x1, x + int32_t(kTexturedChunk) - 1);
          chunked = texture_run<false>(a, x, chunk_end, y, chunk);
        }
      }
      if (kTextured && chunked) col = keep_shaded(chunk[x - chunk_x], c, key);
      else if (surface[c] == key && !(kr & kForce) && !tex && rng.next() >= p) col = kr & 0xFFFFFF;
      else col = shade_kept(a, x, y, c, key);
      if (col != last_colour) { last_colour = col; last_packed = pack(col); }
      sum += last_packed;
      if (x == right) {  // x is px's right border, shared with the next pixel
        commit(px, sum);
        sum = last_packed;
        ++px;
        right += q;
      }
    }
    cur_px = px;
    cur_right = right;
    cur_sum = sum;
  }

  // Front-to-back compositing (§3, pseudo-code "Do until visible surface is opaque or background").
  Pixel composite(int32_t x, int32_t y, uint32_t k) {
    int64_t t = int64_t(1) << 24;  // transmittance, Q24
    int64_t accum[3] = {0, 0, 0};  // Q24 * 255
    bool have_prev = false;
    int64_t prev_z = 0;
    uint32_t prev_id = 0;
    while (t > 0) {
      int32_t pick = -1;
      int64_t pz = 0;
      for (uint32_t j = 0; j < k; ++j) {
        const ActiveTri& a = act[xact[j]];
        const int64_t z = int64_t(a.z_run - a.gx);
        if (have_prev && (z > prev_z || (z == prev_z && a.id <= prev_id))) continue;  // already used
        if (pick < 0 || z > pz || (z == pz && a.id < act[xact[pick]].id)) { pick = int32_t(j); pz = z; }
      }
      if (pick < 0) break;
      ActiveTri& a = act[xact[pick]];
      have_prev = true;
      prev_z = pz;
      prev_id = a.id;
      mark_drawn(a);
      const Pixel col = shade(a, x, y);
      const int64_t alpha = (a.flags & kBlend) ? triangle_material(*scene, a.id).base_color[3] : 255;
      for (int c = 0; c < 3; ++c) accum[c] += t * alpha * int64_t((col >> (16 - 8 * c)) & 0xFF);
      t = (t * (255 - alpha) + 127) / 255;
    }
    uint32_t ch[3];
    for (int c = 0; c < 3; ++c) {
      const int64_t total = accum[c] + t * 255 * int64_t((bg >> (16 - 8 * c)) & 0xFF);
      ch[c] = uint32_t(min_of<int64_t>(255, (total + (int64_t(255) << 23)) / (int64_t(255) << 24)));
    }
    if (s.lat.l > 1) {
      const int32_t c = pixel_of(x);
      keep_surface[c] = 0xFFFFFFFFu;  // never reused: the stack of surfaces may change
      keep_rgb[c] = rgb(ch[0], ch[1], ch[2]) | kValid | (keep_rgb[c] & kForce);
    }
    return rgb(ch[0], ch[1], ch[2]);
  }

  // --- one sample row -------------------------------------------------------------------------------
  void start_row(int32_t y) {
    cur_px = 0;
    cur_right = s.lat.q;
    cur_sum = 0;
    if (!s.accumulate) return;
    const int32_t q = s.lat.q;
    empty_keys = y == 0 || (y - 1) % q == 0;
    if (y == 0) row_kind = 1;
    else if (y == s.lat.ny - 1) row_kind = 3;
    else if (y % q == 0) row_kind = 2;
    else row_kind = 0;
  }

  // Returns the pixel row finished by sample row y, or -1.
  int32_t finished_row(int32_t y) const {
    if (!s.accumulate) return y;
    if (y == 0) return -1;
    if (y % s.lat.q == 0) return y / s.lat.q - 1;
    return -1;
  }

  void sweep(int32_t y) {
    const Lattice& lat = s.lat;
    const ShadingMode mode = opt->shading;
    uint32_t k = 0, i = 0;
    int32_t x = 0;
    uint32_t left_id = 0;  // Lines: visible id of the previous sample
    // Where the next span in order starts (pieces without a span sort last, at kNoSpan >= nx).
    int32_t next = i < live ? int32_t(act[ord[i]].min_x) : lat.nx;
    while (x < lat.nx) {
      if (k == 0) {
        const int32_t stop = min_of(next, lat.nx);
        if (stop > x) {
          if (mode == ShadingMode::Lines) {
            lines_run(x, stop - 1, y, left_id);
            left_id = 0;
          } else {
            emit_run(x, stop - 1, bg);
          }
          x = stop;
          if (x >= lat.nx) break;
        }
      }
      while (next == x) {
        ActiveTri& a = act[ord[i]];
        a.z_run = depth_at(a, x);
        xact[k++] = ord[i];
        ++i;
        next = i < live ? int32_t(act[ord[i]].min_x) : lat.nx;
      }
      // Nearest surface; drop finished spans; step z (§4.2: z_{i+1} = z_i + dz).
      int32_t best = -1;
      int64_t best_z = 0;
      uint32_t best_id = 0;
      for (uint32_t j = 0; j < k;) {
        ActiveTri& a = act[xact[j]];
        if (a.max_x < x) { xact[j] = xact[--k]; continue; }
        const int64_t z = int64_t(a.z_run);
        a.z_run += a.gx;
        if (best < 0 || z > best_z || (z == best_z && a.id < best_id)) {
          best = int32_t(xact[j]);
          best_z = z;
          best_id = a.id;
        }
        ++j;
      }
      if (best < 0) continue;  // every span ended: the k == 0 branch handles x
      if (mode != ShadingMode::Lines && !(act[best].flags & kBlend)) {
        // Until the next span starts, the opaque nearest piece keeps every sample it still wins: a run
        // of one surface, resolved in bulk (a single sample costs less sample by sample, below).
        // A span starting inside the winner's that the winner hides to its end is dropped for the rest
        // of the row: it neither stops the run nor joins the active spans that every later search,
        // lead and depth step goes through (office(8): most of its hundreds of spans a row). Tested
        // only where the winner has rivals: with the winner alone it cost the other scenes more.
        while (k >= 2 && next <= int32_t(act[best].max_x) && hidden_behind(act[best], act[ord[i]], next)) {
          ++i;
          next = i < live ? int32_t(act[ord[i]].min_x) : lat.nx;
        }
        int32_t end = min_of(int32_t(act[best].max_x), min_of(next, lat.nx) - 1);
        if (k > 1) end = winner_end(uint32_t(best), k, x, end);
        if (k == 1 || end > x) {
          for (uint32_t j = 0; k > 1 && j < k; ++j)
            if (xact[j] != uint32_t(best)) act[xact[j]].z_run += act[xact[j]].gx * uint64_t(int64_t(end - x));
          single_run(act[best], x, end, y);
          x = end + 1;
          continue;
        }
      }
      ++stats->geometry_samples;
      if (mode == ShadingMode::Ids) {
        mark_drawn(act[best]);
        keep_surface[x] = best_id + 1;
      } else if (mode == ShadingMode::Lines) {
        mark_drawn(act[best]);
        lines_run(x, x, y, left_id, best_id + 1);
        left_id = best_id + 1;
      } else {
        const Pixel c = resolve_colour(x, y, k, uint32_t(best));
        if (s.accumulate) emit_sample(x, c);
        else keep_surface[x] = c;
      }
      ++x;
    }
  }

  // Whether opaque piece b, holding sample x, holds every sample of r's span from x on and is nearer
  // there than r (ties to the smaller id, as in the sweep): r is then never seen on this row, nor
  // behind b in a blend. Their depth difference is affine in the column, so its two ends decide; where
  // both spans hold a sample their depths are true values, exact in int64 (winner_end).
  static bool hidden_behind(const ActiveTri& b, const ActiveTri& r, int32_t x) {
    if ((b.flags & kBlend) || b.max_x < r.max_x) return false;
    const auto lead = [&](int32_t at) { return int64_t(depth_at(b, at) - depth_at(r, at)); };
    const int64_t first = lead(x), last = lead(r.max_x);
    return b.id < r.id ? first >= 0 && last >= 0 : first > 0 && last > 0;
  }

  // The last sample in [x, end] up to which piece `best`, nearest at x, stays nearest among the k
  // active spans (ties to the smaller id, as in the sweep). Where both spans hold x and x + 1 the depths
  // are true values in [0, 2^46], so their differences and steps are exact in int64 (z_run is one step
  // ahead, at x + 1).
  int32_t winner_end(uint32_t best, uint32_t k, int32_t x, int32_t end) const {
    const ActiveTri& b = act[best];
    for (uint32_t j = 0; j < k && end > x; ++j) {
      const ActiveTri& r = act[xact[j]];
      const int32_t stop = min_of(end, int32_t(r.max_x));
      if (xact[j] == best || stop <= x) continue;
      const int64_t step = int64_t(b.gx - r.gx);
      if (step >= 0) continue;  // the lead never shrinks
      const int32_t lost = lead_lost(int64_t(b.z_run - r.z_run), step, r.id < b.id, x + 1, stop);
      if (lost <= stop) end = lost - 1;
    }
    return end;
  }

  // Hidden-line mode (§6): a pixel is on a line where the visible surface differs from the one to
  // its left or above. keep_surface holds the previous row's ids, keep_rgb the output row.
  void lines_run(int32_t x0, int32_t x1, int32_t y, uint32_t left_id, uint32_t id = 0) {
    for (int32_t x = x0; x <= x1; ++x) {
      const uint32_t up = keep_surface[x];
      const bool line = (x > 0 && id != left_id) || (y > 0 && id != up);
      keep_rgb[x] = line ? kLineColor : bg;
      keep_surface[x] = id;
      left_id = id;
    }
  }

  // Steps every active span to row y and orders the pieces by span start (§3.3). The previous row's
  // order is kept: pieces that had a span and still have one are nearly sorted already; pieces whose
  // span starts on this row (new or no span before) are sorted on their own and merged in; pieces
  // with no span on this row go last, in any order (the sweep never reaches them).
  void order_row(int32_t y) {
    auto key = [this](uint32_t slot) { return act[slot].min_x; };
    uint32_t kept = 0, fresh = 0, none = 0;
    for (uint32_t r = 0; r < live; ++r) {
      const uint32_t slot = ord[r];
      ActiveTri& a = act[slot];
      const bool had = a.min_x != kNoSpan;
      int32_t x0, x1;
      if (!stepped_span(&a, s.lat, y, &x0, &x1)) {
        a.min_x = kNoSpan;
        a.max_x = 0;
        xact[live - 1 - none++] = slot;
        continue;
      }
      a.min_x = uint16_t(x0);
      a.max_x = uint16_t(x1);
      if (had) ord[kept++] = slot;  // r >= kept: in place, order kept
      else xact[fresh++] = slot;
    }
    sort_kept_and_fresh(ord, kept, xact, fresh, key, &stats->sort_instructions);
    for (uint32_t i = 0; i < none; ++i) ord[kept + fresh + i] = xact[live - none + i];
  }

  Status run() {
    const Lattice& lat = s.lat;
    Pixel* out_row = s.colour || opt->shading == ShadingMode::Ids ? keep_surface : keep_rgb;
    for (int32_t x = 0; x < s.width; ++x) { keep_surface[x] = 0; keep_rgb[x] = 0; }
    Status st = out.begin(opt->output, s.width, s.height, *arena, *sink);
    if (!st.ok()) return st;
    for (int32_t y = 0; y < lat.ny; ++y) {
      // Compaction (§3.1): finished pieces leave the order; their slots go to the free stack.
      uint32_t w = 0;
      for (uint32_t r = 0; r < live; ++r) {
        const uint32_t slot = ord[r];
        ActiveTri& a = act[slot];
        if (a.max_y < y) {
          if (texturing()) pager.drop_user(tex_of[slot] & ~kTexReady);
          a.id = free_head;
          free_head = slot;
        } else {
          a.z_row += a.gy;
          ord[w++] = slot;
        }
      }
      live = w;
      while (ys_next < n && ys[ys_next].min_y == y) activate(ys[ys_next++], y);
      if (live > stats->m_max) stats->m_max = live;
      start_row(y);
      if (live == 0) {
        // Empty row: nothing but background (ySortList tells where the next triangle starts).
        if (opt->shading == ShadingMode::Lines) lines_run(0, lat.nx - 1, y, 0);
        else emit_run(0, lat.nx - 1, bg);
      } else {
        order_row(y);
        sweep(y);
        sample_small_spans(y);
      }
      pager.rows_done(uint32_t(y));  // frees the textures whose last row this was
      const int32_t py = finished_row(y);
      if (py >= 0) {
        st = emit_row(py, out_row);
        if (!st.ok()) return st;
        // keepObj's arrays start each pixel row empty; at l = 1 the row is only the output, every pixel
        // written again by the next row (at 1024 wide a 4 KB memset a row: 2CylinderEngine's frame
        // 175.9 M -> 172.7 M instructions).
        if (s.accumulate) {
          if (varying) {
            for (int32_t x = 0; x < s.width; ++x) { keep_surface[x] = 0; keep_rgb[x] &= ~kForce; }
          } else {  // kForce is never read when surfaces have one colour
            memset(keep_surface, 0, size_t(s.width) * sizeof(keep_surface[0]));
          }
        }
      }
    }
    return out.end();
  }

  // Packs a finished pixel row into its band; the band leaves when its last row is in.
  Status emit_row(int32_t py, const Pixel* row) {
    const int band = py / out.band_rows();
    if (py == out.band_top(band)) {
      const Status st = out.start_band(band);
      if (!st.ok()) return st;
    }
    out.put_row(0, py, row, s.width);
    stats->pixel_writes += uint32_t(s.width);
    if (py + 1 < out.band_top(band) + out.band_height(band)) return ok_status();
    ++stats->bands;
    ++stats->render_bands;
    return out.finish_band();
  }
};

}  // namespace
}  // namespace scan

using namespace scan;

size_t scanline_arena_bytes(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  Setup s;
  if (!make_setup(scene, camera, options, &s).ok()) return 0;
  uint32_t n = 0, m = 0;
  count_n_m(scene, s, &n, &m);
  return sizes_for(scene, s, n, m).need();
}

size_t scanline_spare_bytes(const Scene& scene) {
  const uint32_t entries = cache_entries(scene);
  return entries ? VertexCache::arena_bytes(entries) : 0;
}

Status scanline_render(const Scene& scene, const Camera& camera, const RenderOptions& options, Arena& arena,
                       Sink& sink, Stats* stats) {
  Renderer r;
  r.scene = &scene;
  r.opt = &options;
  r.stats = stats;
  r.sink = &sink;
  r.arena = &arena;
  Status st = make_setup(scene, camera, options, &r.s);
  if (!st.ok()) return st;
  const Setup& s = r.s;
  stats->width = uint32_t(s.width);
  stats->height = uint32_t(s.height);
  stats->samples_per_pixel = uint32_t(s.lat.l * s.lat.l);
  stats->triangles_in = scene.triangle_count;
  r.light = make_light(s.view);
  r.rng = Rng(options.seed);
  r.p_threshold = s.lat.l > 1 ? uint32_t(0xFFFFFFFFu / uint32_t(s.lat.l + 1)) : 0;  // (l-1)/(l^2-1)
  r.varying = options.shading == ShadingMode::Gouraud;
  r.bg = options.shading == ShadingMode::Ids ? 0 : (options.background & 0xFFFFFF);

  const size_t start = arena.used();
  size_t peak = 0;
  size_t cache_bytes = 0;  // the vertex cache's, at the end of the arena while it is held
  auto note = [&]() { peak = max_of(peak, arena.used() - start + cache_bytes); };
  auto too_small = [&]() {
    uint32_t n = 0, m = 0;
    count_n_m(scene, s, &n, &m);
    return error(StatusCode::ArenaTooSmall, "arena too small for the scanline renderer",
                 start + sizes_for(scene, s, n, m).need());
  };

  if (s.colour) {  // (a scene without texels: nothing; a build without textures: their fallbacks counted)
    st = r.pager.begin(scene, options.texture_source, options.texture_pool_bytes, arena, stats);
    if (!st.ok()) { arena.release_to(start); return too_small(); }
  }
  // Build ySortList straight into the free part of the arena, then claim exactly what it used. Where
  // the build has it (core/build.h ML_VERTEX_CACHE) a vertex cache takes the end of the free part
  // (scanline_spare_bytes) and keeps it while the list and then the frame's arrays leave it room: it is
  // dropped, never a failure, once they need its bytes (the same frame, slower).
  arena.allocate(0, 8);
  const size_t free_bytes = arena.size() - arena.used();
  YSortEntry* ys_space = reinterpret_cast<YSortEntry*>(arena.allocate(0, 8));
  VertexCache cache;
  if (kVertexCacheBuilt && cache_entries(scene) > 0) {
    cache_bytes = cache.init_at_end(ys_space, free_bytes, scene, s.view, cache_entries(scene));
    r.vertices = &cache;
  }
  const auto keep_cache_if = [&](bool room) {
    if (room || cache_bytes == 0) return;
    cache.drop();
    cache_bytes = 0;
  };
  size_t cap = (free_bytes - cache_bytes) / sizeof(YSortEntry);
  uint32_t n = 0;
  stats->triangles_culled = for_each_piece(scene, s, r.vertices, [&](uint32_t ref, uint16_t y0, uint16_t y1) {
    if (n == cap && cache_bytes) {  // the list reaches the cache
      peak = max_of(peak, arena.used() - start + size_t(n) * sizeof(YSortEntry) + cache_bytes);
      keep_cache_if(false);
      cap = free_bytes / sizeof(YSortEntry);
    }
    if (n < cap) ys_space[n] = YSortEntry{ref, y0, y1};
    ++n;
    // §5: last row; ref: make_ref
    if (r.pager.active()) r.pager.plan(r.batch_textures.of_triangle(scene, ref >> 4), y1);
  });
  r.pager.finish_plan();
  Sizes z = sizes_for(scene, s, n, 0);
  peak = max_of(peak, arena.used() - start + min_of<size_t>(n, cap) * sizeof(YSortEntry) + cache_bytes);
  keep_cache_if(arena.size() - start >= z.phase1() + cache_bytes);
  if (arena.size() - start < z.phase1()) { arena.release_to(start); return too_small(); }
  YSortEntry* ys = static_cast<YSortEntry*>(arena.allocate(z.ysort, 8));
  r.drawn = static_cast<uint32_t*>(arena.allocate(z.drawn, 8));
  for (size_t i = 0; i < z.drawn / 4; ++i) r.drawn[i] = 0;
  // §3.3: sort ySortList on min_y (top row first: our y grows downwards), and find m_max.
  const size_t mark = arena.used();
  void* temp = arena.allocate(z.temp, 8);
  note();
  uint32_t m;
  if (z.by_rows) {
    int32_t* rows = static_cast<int32_t*>(temp);
    m = m_from_rows(ys, n, s.lat.ny, rows);
    bucket_sort_rows(ys, n, s.lat.ny, reinterpret_cast<uint32_t*>(rows), reinterpret_cast<uint32_t*>(rows) + s.lat.ny + 1,
                     &stats->sort_instructions);
  } else {
    quick_sort(ys, n, [](const YSortEntry& e) { return e.min_y; }, &stats->sort_instructions);
    uint16_t* max_ys = static_cast<uint16_t*>(temp);
    for (uint32_t i = 0; i < n; ++i) max_ys[i] = ys[i].max_y;
    m = m_from_sorted(ys, max_ys, n, &stats->sort_instructions);
  }
  arena.release_to(mark);
  z = sizes_for(scene, s, n, m);
  keep_cache_if(arena.size() - start >= z.need() + cache_bytes);
  if (arena.size() - start < z.need()) { arena.release_to(start); return error(StatusCode::ArenaTooSmall,
      "arena too small for the scanline renderer", start + z.need()); }
  r.ys = ys;
  r.n = n;
  r.act = static_cast<ActiveTri*>(arena.allocate(z.yactive, 8));
  r.ord = static_cast<uint32_t*>(arena.allocate(z.ord, 8));
  r.xact = static_cast<uint32_t*>(arena.allocate(z.xactive, 8));
  r.keep_surface = static_cast<uint32_t*>(arena.allocate(z.keep / 2, 8));
  r.keep_rgb = static_cast<uint32_t*>(arena.allocate(z.keep / 2, 8));
  if (z.acc) r.acc = static_cast<uint64_t*>(arena.allocate(z.acc, 8));
  if (z.texslots) {
    r.tex_slots = static_cast<TexSlot*>(arena.allocate(round8(size_t(m) * sizeof(TexSlot)), 8));
    r.tex_lut = static_cast<SlotLut*>(arena.allocate(round8(size_t(m) * sizeof(SlotLut)), 8));
    r.tex_of = static_cast<uint32_t*>(arena.allocate(round8(size_t(m) * 4), 8));
  }
  stats->n = n;
  st = r.run();  // takes the band buffers
  note();
  stats->peak_arena_bytes = uint32_t(peak);
  arena.release_to(start);
  return st;
}

}  // namespace ml

// Internals of the scanline renderer shared with its tests. Formats (docs/scanline.md):
// - Sample lattice: sample (X, Y) lies at subpixel ((256 X + ox) / den, (256 Y + oy) / den).
//   aa = 1: den = 1, ox = oy = 128 (pixel centres, as src/view and the tiler);
//   aa = l > 1: den = l - 1, ox = oy = 0, so samples sit at k / (l - 1) pixel and those on pixel
//   borders are shared with the neighbours (Woo & Chall §3.4). Edge functions are evaluated as
//   E * den, exactly, in int64.
// - Depth: Q16 of ScreenVertex::depth, as a plane z(X, Y) = z0 + gx X + gy Y held modulo 2^64
//   (uint64 wrap-around): the true value inside the triangle is in [0, 2^46], so the wrapped sum is
//   exact whatever the size of the intermediate terms.
#pragma once
#include <stdint.h>

#include "core/fixed.h"
#include "core/sink.h"
#include "view/view.h"

namespace ml {
namespace scan {

struct Lattice {
  int l;            // samples per pixel per axis actually used (Ids and Lines modes use 1)
  int32_t den;      // 1 or l - 1
  int32_t ox, oy;   // sample origin offset, in subpixels * den
  int32_t nx, ny;   // sample columns and rows
  int32_t q;        // samples per pixel step (1 when l == 1, else l - 1)
};

Lattice make_lattice(int width, int height, int aa);

// ySortList element (§3.1): 8 bytes.
struct YSortEntry {
  uint32_t ref;     // triangle id * 16 + 8 when it faces away + piece index (scanline.cpp, make_ref)
  uint16_t min_y;   // first and last sample row the piece's bounding box touches
  uint16_t max_y;
};
static_assert(sizeof(YSortEntry) == 8, "YSortEntry layout");

// yActiveList element: the piece's screen-space parameters (§4) and its span on the current row.
enum : uint8_t {
  kWeightsReady = 1,    // weight_recip and weight_shift are set
  kSmallTextured = 2,   // a small textured piece of one colour, its planes and colours made (texture_run)
  kFront = 8,
  kColorsReady = 16,
  kSmooth = 32,
  kBlend = 64,
  kWon = 128,           // won at least one sample (Stats::triangles_drawn)
};
// Span stepping carries each edge's function value from row to row on 64-bit hosts (one product by
// the rows stepped instead of its evaluation at the boundary column, two products and their terms:
// the duck's frame 3.4 % cheaper for 24 bytes an active piece); the boards evaluate it each row (their
// RAM: on a Cortex-M3 the carried value saved nothing, its 64-bit product costing as much).
#if UINTPTR_MAX > 0xFFFFFFFFu
#define ML_CARRY_EDGE_VALUES 1
#else
#define ML_CARRY_EDGE_VALUES 0
#endif

struct ActiveTri {
  uint64_t z_row;       // depth Q16 at X = 0 of the current row (mod 2^64)
  uint64_t gx, gy;      // depth Q16 per sample step in X and Y (mod 2^64)
  uint64_t z_run;       // depth Q16 at the sweep's current sample
  int32_t vx[3], vy[3]; // piece vertices, subpixels, area2 > 0 order
  uint32_t id;          // triangle id
  Pixel color[3];       // piece vertex colours (kColorsReady), color[0] = flat colour unless kSmooth
  uint16_t min_x, max_x;  // span on the current row; min_x = 0xFFFF when empty
  uint16_t max_y;
  uint8_t flags;
  uint8_t perm;         // unclipped piece: original vertex of piece vertex j in bits 2j..2j+1; 0xFF clipped
  uint16_t box_x0, box_x1;  // sample columns of the piece's bounding box, clipped to the screen
  int16_t edge_x[3];    // edge i's boundary column on the last row stepped (step_span)
  uint8_t weight_shift;   // kWeightsReady: the weights' numerators and divisor shift (prepare_weights)
  uint8_t pad;
  uint32_t weight_recip;  // kWeightsReady: the divisor's reciprocal (prepare_weights), for sample_weights
#if ML_CARRY_EDGE_VALUES
  int32_t edge_row;       // the sample row edge_v is at (start_span, then the last row stepped)
  // Edge i's function times den at column edge_x[i] of row edge_row, the fill rule folded in (E < 0
  // outside): a row later it is one addition away (step_span).
  int64_t edge_v[3];
#else
  uint32_t pad2;
#endif
};
static_assert(sizeof(ActiveTri) == (ML_CARRY_EDGE_VALUES ? 128 : 104), "ActiveTri layout");

constexpr uint16_t kNoSpan = 0xFFFF;

// The piece's depth (Q16, mod 2^64) at sample x of the current row: its true depth where its span
// holds x.
inline uint64_t depth_at(const ActiveTri& t, int32_t x) { return t.z_row + t.gx * uint64_t(int64_t(x)); }

// The piece's bounding box on the sample lattice, clipped to the screen. False when it holds no sample.
struct LatticeBox {
  int32_t x0, x1, y0, y1;
};
bool lattice_box(const ScreenTriangle& t, const Lattice& lat, LatticeBox* b);

// Span [min_x, max_x] of sample row Y for the piece: exactly the samples where all three edge
// functions of src/view (top-left rule folded in) are >= 0, clamped to [0, nx). Returns false if empty.
// The reference: one division per edge. The renderer steps spans with step_span instead.
bool row_span(const ActiveTri& t, const Lattice& lat, int32_t y, int32_t* min_x, int32_t* max_x);

// Starts span stepping at sample row y for a piece whose vertices and box_x0/box_x1 are set (no
// division): each edge's boundary column at a side of the box (and, ML_CARRY_EDGE_VALUES, its
// function there).
void start_span(ActiveTri* t, const Lattice& lat, int32_t y);

// The same span as row_span, found from the previous row's edge boundaries (edge_x) by walking the
// exact edge functions sample by sample: no division; each edge's function at its boundary column is
// carried from the last row stepped by one product (ML_CARRY_EDGE_VALUES; one row: b 256) or
// evaluated there. Rows must be stepped in increasing order from start_span's (any gaps allowed); the
// walk costs the boundaries' movement, at most the box width per edge and row.
bool step_span(ActiveTri* t, const Lattice& lat, int32_t y, int32_t* min_x, int32_t* max_x);

// Depth plane of a piece (vertices vx/vy in ActiveTri, depths d[3]): sets z_row for row 0, gx, gy.
void depth_plane(ActiveTri* t, const uint32_t depth[3], const Lattice& lat);

// Sets the reciprocal sample_weights divides by (core/fixed.h make_reciprocal of the piece's area2 * den,
// shifted below 2^46) and that shift: once per piece, so no sample measures the area's bit length.
void prepare_weights(ActiveTri* t, const Lattice& lat);

// Barycentric weights (Q16, summing to 65536) of the piece's vertices at a covered sample (X, Y):
// round(E_j 2^16 / (area2 den)) exactly, by t.weight_recip and t.weight_shift (prepare_weights): no
// division.
void sample_weights(const ActiveTri& t, const Lattice& lat, int32_t x, int32_t y, int32_t w[3]);
// The colours of covered samples x0 .. x1 of row y of a Gouraud piece (weights ready) into out[x0 ..
// x1]: blend_colors of its vertex colours by sample_weights at each, the same values, the edge values
// stepped along the row instead of evaluated at each sample.
void smooth_run(const ActiveTri& t, const Lattice& lat, int32_t x0, int32_t x1, int32_t y, Pixel* out);


// Where a nearer surface loses a run to a rival (the sweep's runs of one surface): the first sample t
// in [from, stop] where its depth lead `lead` at `from`, changing by step < 0 a sample, is lost (below
// 0, or 0 when the rival wins ties); stop + 1 if none. |lead|, |step| < 2^48. Stepped sample by sample
// (no division: the boards, where a 64-bit division is a library call), or by one division (64-bit
// hosts: a wall crossed at a shallow angle is hundreds of samples away). The same sample.
inline int32_t lead_lost_stepped(int64_t lead, int64_t step, bool rival_wins_ties, int32_t from, int32_t stop) {
  for (int32_t t = from; t <= stop; ++t, lead += step)
    if (lead < 0 || (lead == 0 && rival_wins_ties)) return t;
  return stop + 1;
}
inline int32_t lead_lost_divided(int64_t lead, int64_t step, bool rival_wins_ties, int32_t from, int32_t stop) {
  // lead + i step < 0 from i = floor(lead / -step) + 1 on; <= 0 from i = ceil(lead / -step).
  if (lead < 0 || (lead == 0 && rival_wins_ties)) return from;
  const int64_t i = rival_wins_ties ? (lead - step - 1) / -step : lead / -step + 1;
  return i > int64_t(stop) - from ? stop + 1 : from + int32_t(i);
}
// The form for this target.
inline int32_t lead_lost(int64_t lead, int64_t step, bool rival_wins_ties, int32_t from, int32_t stop) {
#if UINTPTR_MAX > 0xFFFFFFFFu
  return lead_lost_divided(lead, step, rival_wins_ties, from, stop);
#else
  return lead_lost_stepped(lead, step, rival_wins_ties, from, stop);
#endif
}

// Interpolated vertex normal (Q1.14 in, Q1.14 out) renormalized with Newton steps
// x1 = x0 (1.5 - 0.5 |x0|^2) (Woo & Chall §4.4, core/fixed.h newton_renormalize_q14), no sqrt.
Vec3i interpolate_normal(const int16_t n[3][3], const int32_t w[3], int steps = 2);

// Interpolated texture coordinates (Q16.16).
void interpolate_uv(const int32_t uv[3][2], const int32_t w[3], int32_t out[2]);

// Deterministic xorshift32 (seed 0 is mapped to a fixed non-zero state).
struct Rng {
  uint32_t s;
  explicit Rng(uint32_t seed) : s(seed ? seed : 0x9E3779B9u) {}
  uint32_t next() {
    s ^= s << 13;
    s ^= s >> 17;
    s ^= s << 5;
    return s;
  }
};

}  // namespace scan
}  // namespace ml

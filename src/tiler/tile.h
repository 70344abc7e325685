// tile_poly: Greene's hierarchical tiling of one convex polygon into the coverage pyramid.
//
// Per visited cell, each edge's values at the cell's corners (computed incrementally from the
// parent's corner, in the edge function's exact integer units) classify it as outside (reject: the
// polygon misses the cell, also when a conservative parent mask called the cell active), inside
// (dropped for the subtree) or crossing; a crossing edge's two perimeter intercepts are quantized
// to the table's k intervals (exact, by restoring division) and its triage mask looked up in
// tables/. Then, with S the screen mask and P the polygon mask:
//   W = Sv & Pc (newly covered subcells: written),  A = ~(W | Pv | Sc) (subdivided),
// and each subdivided child's status is propagated back into S. At the finest level the table
// resolves most samples and the rest are tested with the edge functions at the sample centres, so
// coverage there is exactly src/view's (fill rule included): watertight.
//
// Samples: sample (sx, sy) sits at subpixel (sx * pitch + pitch / 2, sy * pitch + pitch / 2); with
// one sample per pixel, pitch = 256 and samples are pixels. Cell corners are sample-area corners.
#pragma once
#include <stdint.h>

#include "core/build.h"
#include "core/options.h"
#include "tiler/pyramid.h"
#include "view/view.h"

namespace ml {

constexpr int kMaxPolyEdges = 6;  // triangles now; projected box silhouettes later

// A convex polygon as the intersection of edge half-planes E >= 0, with the bounding box of the
// samples it can cover (inclusive, clipped to the screen; empty when min > max).
struct ConvexPoly {
  int n = 0;
  EdgeFunction edge[kMaxPolyEdges];
  int32_t min_x = 0, min_y = 0, max_x = -1, max_y = -1;
};

// Copies a polygon's box alone (its edges untouched).
inline void copy_box(const ConvexPoly& from, ConvexPoly* to) {
  to->min_x = from.min_x;
  to->min_y = from.min_y;
  to->max_x = from.max_x;
  to->max_y = from.max_y;
}

// One-sample-per-pixel polygon of a set-up triangle.
void poly_from_setup(const TriangleSetup& setup, ConvexPoly* out);

// The polygon of a set-up triangle sampled factor x factor times a pixel (factor 1, 2, 4 or 8): the
// same edges, the box in samples (width and height in pixels; sample pitch 256 / factor subpixels).
// jittered: samples lie anywhere inside their sub-cells (core/jitter.h), so the box holds every
// sample whose cell meets the triangle's bounds.
void poly_in_samples(const ScreenTriangle& tri, const TriangleSetup& setup, int factor, int width,
                     int height, ConvexPoly* out, bool jittered = false);

// The sample lattice of sample_box (factor samples a pixel per axis: 1, 2, 4 or 8; jittered or
// regular) over a screen of width x height pixels, worked out once for the many boxes of a frame.
struct SampleGrid {
  int bits = kSubpixelBits;  // the sample pitch, 2^bits subpixels
  int32_t half = 0;          // a sample centre's offset in its cell (jittered: 0, anywhere in the cell)
  bool jittered = false;
  int32_t last_x = -1, last_y = -1;  // the screen's last sample column and row
};
inline SampleGrid sample_grid(int factor, int width, int height, bool jittered) {
  SampleGrid g;
  g.bits = kSubpixelBits - (factor == 8 ? 3 : factor == 4 ? 2 : factor == 2 ? 1 : 0);
  g.half = jittered ? 0 : (int32_t(1) << g.bits) / 2;
  g.jittered = jittered;
  g.last_x = width * factor - 1;
  g.last_y = height * factor - 1;
  return g;
}

// The box of poly_in_samples alone, from a triangle's extent in subpixels (its vertices' smallest and
// largest x and y, |values| < 2^30: projected vertices lie inside the guard band): the samples of grid g
// it can cover, clipped to the screen; empty when min > max. 32-bit arithmetic.
inline void grid_box(const SampleGrid& g, int32_t min_x, int32_t min_y, int32_t max_x, int32_t max_y,
                     ConvexPoly* out) {
  // Sample centres s * pitch + pitch / 2 inside [min, max] (setup_triangle's pixel box when factor is
  // 1); jittered samples anywhere in their cells [s * pitch, (s + 1) * pitch). The pitch is a power of
  // two: floors are arithmetic shifts.
  if (g.jittered) {
    out->min_x = max_of<int32_t>(0, min_x >> g.bits);
    out->min_y = max_of<int32_t>(0, min_y >> g.bits);
  } else {
    out->min_x = max_of<int32_t>(0, -((g.half - min_x) >> g.bits));
    out->min_y = max_of<int32_t>(0, -((g.half - min_y) >> g.bits));
  }
  out->max_x = min_of<int32_t>(g.last_x, (max_x - g.half) >> g.bits);
  out->max_y = min_of<int32_t>(g.last_y, (max_y - g.half) >> g.bits);
}
inline void sample_box(int32_t min_x, int32_t min_y, int32_t max_x, int32_t max_y, int factor, int width, int height,
                       bool jittered, ConvexPoly* out) {
  grid_box(sample_grid(factor, width, height, jittered), min_x, min_y, max_x, max_y, out);
}

// grid_box of a screen triangle's vertices (poly_in_samples's box).
inline void triangle_grid_box(const SampleGrid& g, const ScreenTriangle& tri, ConvexPoly* out) {
  int32_t min_x = tri.v[0].x, max_x = min_x, min_y = tri.v[0].y, max_y = min_y;
  for (int i = 1; i < 3; ++i) {
    min_x = min_of(min_x, tri.v[i].x);
    max_x = max_of(max_x, tri.v[i].x);
    min_y = min_of(min_y, tri.v[i].y);
    max_y = max_of(max_y, tri.v[i].y);
  }
  grid_box(g, min_x, min_y, max_x, max_y, out);
}
inline void triangle_sample_box(const ScreenTriangle& tri, int factor, int width, int height, bool jittered,
                                ConvexPoly* out) {
  triangle_grid_box(sample_grid(factor, width, height, jittered), tri, out);
}

// The edges of poly_in_samples alone (setup_triangle's): a caller that rejects most polygons by their
// box computes the edges of the others only.
void poly_edges(const ScreenTriangle& tri, ConvexPoly* out);

// Receives every block of samples that tiling (or the background pass) newly covers. Each sample is
// handed over at most once per frame. Returning false aborts the frame.
class CoverageWriter;

// Hands the set samples of an 8x8-sample mask at (x, y) to writer.write() as maximal runs per row,
// identical consecutive rows merged into one block.
bool write_mask_runs(uint64_t mask, int x, int y, CoverageWriter& writer);

class CoverageWriter {
 public:
  virtual ~CoverageWriter() = default;
  virtual bool write(int x, int y, int w, int h) = 0;
  // The newly covered samples of the 8x8-sample block at (x, y), as a mask (bit = row * 8 + col).
  // Inline, so no translation unit owns the vtable (the core builds without RTTI, tests with it).
  virtual bool write_block(uint64_t mask, int x, int y) { return write_mask_runs(mask, x, y, *this); }
};

// The triage mask of an edge crossing a square, from the edge's values at the corners in walk
// order (TL, TR, BR, BL): at least one must be > 0 and one < 0.
TriageMask edge_triage_mask(const int64_t corner[4]);

// The polygon's triage mask over the square [x0, x0 + side) x [y0, y0 + side) (subpixels, cut in
// 8x8 subcells). False when an edge puts the whole square outside (then *out is unspecified).
bool polygon_mask(const ConvexPoly& poly, int64_t x0, int64_t y0, int64_t side, TriageMask* out);

// Greene's compositing of a polygon mask p under a screen mask s (Table 4.1): w = subcells newly
// covered (written), a = subcells to subdivide, *s updated (w moved from vacant to covered).
//   w = Sv & Pc,  a = ~(w | Pv | Sc)
inline void composite(TriageMask* s, const TriageMask& p, uint64_t* w, uint64_t* a) {
  *w = s->v & p.c;
  s->c |= *w;
  s->v &= ~*w;
  *a = ~(*w | p.v | s->c);
}

enum class TileResult : uint8_t { Hidden, Tiled, Failed };

// Where HierTiler::box_visible last found an uncovered sample: samples [x0, x1] x [y0, y1] (inclusive;
// empty when x0 > x1), all uncovered. Kept on 64-bit hosts only; on the boards an empty base of
// HierTiler, so no bytes (four fields there move the tiler frame's later members past the offsets a
// Cortex-M0+ load reaches: 64 bytes more code).
template <bool kKept>
class BoxWitness {
 protected:
  bool witness_reached(const ConvexPoly&) const { return false; }
  void remember_witness(int32_t, int32_t, int32_t, int32_t) const {}
  void forget_witness() {}
};
template <>
class BoxWitness<true> {
 protected:
  // No witness reaches any box: its columns are INT32_MAX..INT32_MIN.
  bool witness_reached(const ConvexPoly& p) const {
    return p.min_x <= wx1_ && wx0_ <= p.max_x && p.min_y <= wy1_ && wy0_ <= p.max_y;
  }
  // Remembered by queries (const: they never change the pyramid).
  void remember_witness(int32_t x0, int32_t y0, int32_t x1, int32_t y1) const {
    wx0_ = x0, wy0_ = y0, wx1_ = x1, wy1_ = y1;
  }
  void forget_witness() { wx0_ = INT32_MAX, wx1_ = INT32_MIN; }

 private:
  mutable int32_t wx0_ = INT32_MAX, wy0_ = 0, wx1_ = INT32_MIN, wy1_ = 0;
};

// The covered blocks of finest-level parent (x, y), or all of them when an ancestor is covered
// (HierTiler::block_done); x = -1: none.
struct ParentCover {
  int x = -1, y = -1;
  uint64_t c = 0;
};

// The last ParentCover a small polygon looked up, kept for the next until a triage mask changes (the
// neighbouring triangles the BSP hands over one after another share parents). 64-bit hosts only: an
// empty base on the boards, as BoxWitness.
// With it, the last cell start_cell found no covered subcell above (its level, 0 for none, and position):
// the next start cell below it need not test those levels again (the BSP hands over neighbouring boxes).
template <bool kKept>
class KeptParent {
 protected:
  ParentCover* kept_parent() { return nullptr; }
  void forget_parent() {}
  int kept_path_level() const { return 0; }
  int32_t kept_path_x() const { return 0; }
  int32_t kept_path_y() const { return 0; }
  void keep_path(int, int32_t, int32_t) const {}
};
template <>
class KeptParent<true> {
 protected:
  ParentCover* kept_parent() { return &parent_; }
  void forget_parent() {
    parent_.x = -1;
    path_level_ = 0;
  }
  int kept_path_level() const { return path_level_; }
  int32_t kept_path_x() const { return path_x_; }
  int32_t kept_path_y() const { return path_y_; }
  // Kept by queries too (const: they never change the pyramid).
  void keep_path(int level, int32_t x, int32_t y) const {
    path_level_ = level;
    path_x_ = x;
    path_y_ = y;
  }

 private:
  ParentCover parent_;
  mutable int path_level_ = 0;
  mutable int32_t path_x_ = 0, path_y_ = 0;
};

// The small grid's blocks (tile_small) on 64-bit hosts: the tiler's, all zero between polygons, so a
// polygon clears none before placing its rows (it clears those it reads after). An empty base on the
// boards (their RAM), as BoxWitness.
constexpr int kZeroBlockCount = 64;  // tile_small's SmallGrid: 8 x 8 blocks
template <bool kKept>
class ZeroBlocks {
 protected:
  uint64_t* zero_blocks() { return nullptr; }
};
template <>
class ZeroBlocks<true> {
 protected:
  uint64_t* zero_blocks() { return blocks_; }

 private:
  uint64_t blocks_[kZeroBlockCount] = {};
};

class HierTiler : private BoxWitness<(UINTPTR_MAX > 0xFFFFFFFFu)>,
                  private KeptParent<(UINTPTR_MAX > 0xFFFFFFFFu)>,
                  private ZeroBlocks<(UINTPTR_MAX > 0xFFFFFFFFu)> {
 public:
  // pitch: subpixels per sample (256 / samples a pixel per axis). work: optional work image (pixels,
  // the screen's size); the pyramid's row 0 is the top of its row work_row0 (the band's top row).
  // cells_visited keeps counting across init calls (one frame, many bands).
  void init(Pyramid* pyramid, int32_t pitch, WorkImage* work, int work_row0 = 0);
  // Jittered samples (core/jitter.h) for f samples a pixel per axis and this seed, their offsets in
  // `table` (fill_jitter_table); f = 0: the regular grid. Coverage at the finest level is then
  // decided sample by sample at the jittered positions.
  void jitter(int f, uint32_t seed, const uint8_t* table) {
    jitter_f_ = f;
    jitter_seed_ = seed;
    jitter_table_ = table;
  }

  // Tiles one polygon, front to back: Hidden when the bounding-box test proves it invisible
  // (nothing visited), Failed when the writer refused a write.
  TileResult tile(const ConvexPoly& poly, CoverageWriter& writer);

  // Whether any sample the polygon covers is still uncovered. Never changes the pyramid.
  bool visible(const ConvexPoly& poly);

  // The bounding-box part of that test alone (no edges): false when every sample in the
  // polygon's box is covered. Never changes the pyramid. On 64-bit hosts it remembers where it last
  // found an uncovered sample (the witness) until the next tile(): a box reaching it is visible at once.
  bool box_visible(const ConvexPoly& poly);

  // Covers every remaining sample (the background polygon composited with the root mask).
  bool background(CoverageWriter& writer);

  uint64_t cells_visited = 0;

 private:
  friend bool polygon_mask(const ConvexPoly&, int64_t, int64_t, int64_t, TriageMask*);
  struct Edges {
    int n;
    int64_t a[kMaxPolyEdges], b[kMaxPolyEdges];
    int64_t e[kMaxPolyEdges];  // value at the cell's top-left corner

    // n, a and b of `cell` (the edges in use only: a whole copy is a memcpy of every slot).
    void copy_steps(const Edges& cell) {
      n = cell.n;
      for (int i = 0; i < n; ++i) {
        a[i] = cell.a[i];
        b[i] = cell.b[i];
      }
    }
    // This cell's edges (same n, a, b) at the top-left corner of subcell (col, row) of `cell`,
    // whose subcells are q subpixels wide.
    void at_subcell(const Edges& cell, int64_t q, int col, int row) {
      for (int i = 0; i < n; ++i) e[i] = cell.e[i] + cell.a[i] * (q * col) + cell.b[i] * (q * row);
    }
  };
  // The polygon's edges at the top-left corner of cell (mx, my) of `level` (start_cell's answer).
  void edges_at_cell(const ConvexPoly& poly, int level, int mx, int my, Edges* out) const;
  static bool edges_mask(const Edges& in, int64_t side, Edges* crossing, uint64_t* pc, uint64_t* pv);
  bool poly_mask(int level, const Edges& in, Edges* crossing, uint64_t* pc, uint64_t* pv) const;
  uint64_t exact_samples(const Edges& edges, uint64_t todo, int bx, int by) const;

  bool block_samples(const Edges& in, uint64_t* out) const;
  bool tile_cell(int level, int mx, int my, const Edges& in, CoverageWriter& writer);
  template <class Grid>
  bool tile_small(const ConvexPoly& poly, CoverageWriter& writer, TileResult* result, bool open);
  bool tile_wide(const ConvexPoly& poly, CoverageWriter& writer, TileResult* result, bool open);
  bool tile_in_block(const ConvexPoly& poly, CoverageWriter& writer, TileResult* result);
  bool cover_block(int bx, int by, uint64_t w, CoverageWriter& writer, bool parent_inline);
  uint64_t block_done(int bx, int by, ParentCover* parent) const;
  bool covered_above(int level, int mx, int my) const;
  bool query_cell(int level, int mx, int my, const Edges& in) const;
  bool background_cell(int level, int mx, int my, CoverageWriter& writer);
  bool start_cell(const ConvexPoly& poly, int* level, int* mx, int* my) const;
  uint64_t box_bits(int level, int mx, int my) const;
  uint64_t block_box(int bx, int by) const;
  bool box_uncovered(int level, int mx, int my) const;
  bool block_uncovered(uint64_t box, int bx, int by) const;
  void propagate_up(int level, int mx, int my);
  void block_to_parent(int bx, int by, uint64_t block);
  bool set_in_parent(int l, int mx, int my, bool all_covered, bool none_covered);
  void add_work(int level, int mx, int my);

  Pyramid* pyr_ = nullptr;
  int32_t pitch_ = 256;
  WorkImage* work_ = nullptr;
  int work_row0_ = 0;
  int jitter_f_ = 0;
  uint32_t jitter_seed_ = 0;
  const uint8_t* jitter_table_ = nullptr;
  // Sample box of the polygon being tiled or queried (inclusive).
  int32_t bx0_ = 0, by0_ = 0, bx1_ = -1, by1_ = -1;
  // Remembers samples [x0, x1] x [y0, y1], all uncovered, cut to the box (BoxWitness).
  void witness(int32_t x0, int32_t y0, int32_t x1, int32_t y1) const;
};

}  // namespace ml

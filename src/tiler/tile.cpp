#include "tiler/tile.h"

#include "core/build.h"
#include "core/jitter.h"
#include "tables/mask_tables.h"

namespace ml {

namespace {

constexpr uint64_t kAll = ~uint64_t(0);

// Table row of a side pair (s1 < s2), as the table header's layout.
constexpr int kSidePair[4][4] = {{-1, 0, 1, 2}, {0, -1, 3, 4}, {1, 3, -1, 5}, {2, 4, 5, -1}};

// floor(k * t) for the crossing at t = from / (from - to) along a side whose corner values have
// opposite classes (> 0 vs <= 0): exact restoring division, kMaskKBits steps, no divide. t = 1
// yields k - 1.
inline int quantize(int64_t from, int64_t to) {
  const int64_t num = from > 0 ? from : -from;
  const int64_t den = from > 0 ? from - to : to - from;
  int64_t r = num;
  int iv = 0;
  for (int i = 0; i < kMaskKBits; ++i) {
    r <<= 1;
    iv <<= 1;
    if (r >= den) {
      r -= den;
      iv |= 1;
    }
  }
  return iv;
}

// Writes the set bits of an 8x8 mask of q x q subcells at (x0, y0): maximal runs per row, and
// identical consecutive rows merged into one block.
bool emit_mask(uint64_t m, int x0, int y0, int q, CoverageWriter& writer) {
  while (m != 0) {
    const int row = __builtin_ctzll(m) >> 3;  // first row with a set bit; rows above are done
    const uint32_t byte = uint32_t(m >> (8 * row)) & 0xFFu;
    int rows = 1;
    while (row + rows < 8 && (uint32_t(m >> (8 * (row + rows))) & 0xFFu) == byte) ++rows;
    uint32_t b = byte;
    while (b != 0) {
      const int start = __builtin_ctz(b);
      const int len = __builtin_ctz(~(b >> start));
      if (!writer.write(x0 + start * q, y0 + row * q, len * q, rows * q)) return false;
      b &= ~(((1u << len) - 1u) << start);
    }
    m = row + rows >= 8 ? 0 : m & (~uint64_t(0) << (8 * (row + rows)));
  }
  return true;
}

// RowSpans::rows (the bounds stepped in registers) on 64-bit hosts only: on a Cortex-M0+ the second
// copy of the row loop is 664 bytes of flash it does not have.
constexpr bool kRowsInRegisters = UINTPTR_MAX > 0xFFFFFFFFu;

// Row r of an 8x8 mask is its byte r in memory on little-endian 64-bit hosts: tile_small stores a row's
// span there a byte a block (place_bytes), without the row's word (2CylinderEngine at 1024x768: 75.58 M ->
// 74.94 M instructions a frame). The boards keep the word (no flash for a second way).
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
constexpr bool kByteRows = UINTPTR_MAX > 0xFFFFFFFFu;
#else
constexpr bool kByteRows = false;
#endif

// A small polygon's coverage, row by row (HierTiler::tile_small, HierTiler::block_samples). For one
// edge crossing the box, the samples of box row j inside it are the columns col with E_j + A col >= 0,
// E_j = E_0 + B j (E at the row's first sample centre, A and B the steps between samples): from
// -floor(E_j / A) on when A > 0 (the edge bounds the row from the left), up to floor(E_j / -A) when
// A < 0 (from the right); with A = 0 the whole row or none. A row's samples are then one span, the
// largest left bound to the smallest right bound. Each floor is stepped exactly from row to row (a
// DDA: two 32-bit divisions an edge, then adds), so each sample gets exactly E >= 0 at its centre,
// the descent's coverage. The caller keeps every edge value and both steps below 2^30 (rows_fit), so
// a row's value and remainder sums stay below 2^31. On 64-bit hosts the rows of up to three bounds a
// side step each floor in 64-bit fixed point instead when that is exact (rows_fixed): one add a bound
// and row, the bounds compared before their shift (2CylinderEngine at 1024x768: 77.52 M -> 75.58 M
// instructions a frame, 320x240 54.40 M -> 54.11 M).
class RowSpans {
 public:
  void clear() {
    lower_n_ = upper_n_ = level_n_ = 0;
    if (kRowsInRegisters) max_d_ = 0;
  }
  void add(int32_t e0, int32_t step_col, int32_t step_row) {
    if (step_col == 0) {
      level_[level_n_++] = Level{e0, step_row};
      return;
    }
    Bound& b = step_col > 0 ? lower_[lower_n_++] : upper_[upper_n_++];
    b.d = step_col < 0 ? -step_col : step_col;
    if (!kRowsInRegisters) {
      split(e0, b.d, &b.q, &b.r);
      split(step_row, b.d, &b.step_q, &b.step_r);
      return;
    }
    // E_0 and B as they are until a loop steps the DDA (dda()): on 64-bit hosts most loops take them
    // whole, in fixed point (rows_fixed).
    b.q = e0;
    b.step_q = step_row;
    max_d_ = max_of(max_d_, b.d);
  }
  // The DDA's quotients and remainders of every bound, for row() (on 64-bit hosts, once before it).
  void dda() {
    if (!kRowsInRegisters) return;
    for (int i = 0; i < lower_n_; ++i) lower_[i].divide();
    for (int i = 0; i < upper_n_; ++i) upper_[i].divide();
  }
  // The current row's inside columns, [first, last] within [0, last_column] (none when first > last),
  // then on to the next row.
  void row(int32_t last_column, int32_t* first, int32_t* last) {
    int32_t lo = 0, hi = last_column;
    for (int i = 0; i < lower_n_; ++i) {
      lo = max_of(lo, -lower_[i].q);
      lower_[i].next_row();
    }
    for (int i = 0; i < upper_n_; ++i) {
      hi = min_of(hi, upper_[i].q);
      upper_[i].next_row();
    }
    for (int i = 0; i < level_n_; ++i) {
      if (level_[i].e < 0) hi = -1;
      level_[i].e += level_[i].step;
    }
    *first = lo;
    *last = hi;
  }
  // row() for rows 0..count-1 in turn, handing each row's span to emit(row, first + shift, last + shift)
  // when it is not empty (shift: the box's first column within its block, added once in the fixed-point
  // loops' start values, not once a row: 2CylinderEngine at 1024x768 68.41 M -> 68.32 M a frame, 320x240
  // 52.43 M -> 52.37 M): through rows() when kRowsInRegisters and in_registers(), else through the
  // arrays. Inlined (a call costs 2CylinderEngine at 1024x768 0.14 M).
  template <class Emit>
  [[gnu::always_inline]] void each_row(int count, int32_t shift, int32_t last_column, Emit emit) {
    if (kRowsInRegisters && in_registers()) return rows(count, shift, last_column, emit);
    dda();
    for (int y = 0; y < count; ++y) {
      int32_t first, last;
      row(last_column, &first, &last);
      if (first <= last) emit(y, first + shift, last + shift);
    }
  }
  // Whether the crossing edges are at most three left bounds and three right bounds and no level
  // one (triangles have two a side at most; a split piece clipped to its triangle, three):
  // rows() then steps them in locals, not through the arrays.
  bool in_registers() const { return lower_n_ <= 3 && upper_n_ <= 3 && level_n_ == 0; }
  // row() for rows 0..count-1 in turn, handing each row's span to emit(row, first, last) (none when
  // first > last). Only when in_registers(); one loop for each count of left and right bounds.
  template <class Emit>
  void rows(int count, int32_t shift, int32_t last_column, Emit emit) {
    const bool fixed = fixed_fits(count);
    switch (lower_n_ * 4 + upper_n_) {
      case 0: case 1: case 4: case 5: return rows_with<1, 1>(fixed, count, shift, last_column, emit);
      case 2: case 6: return rows_with<1, 2>(fixed, count, shift, last_column, emit);
      case 3: case 7: return rows_with<1, 3>(fixed, count, shift, last_column, emit);
      case 8: case 9: return rows_with<2, 1>(fixed, count, shift, last_column, emit);
      case 10: return rows_with<2, 2>(fixed, count, shift, last_column, emit);
      case 11: return rows_with<2, 3>(fixed, count, shift, last_column, emit);
      case 12: case 13: return rows_with<3, 1>(fixed, count, shift, last_column, emit);
      case 14: return rows_with<3, 2>(fixed, count, shift, last_column, emit);
      default: return rows_with<3, 3>(fixed, count, shift, last_column, emit);
    }
  }

 private:
  // floor(E_j / d) = q with remainder r (0 <= r < d), and its steps from row to row.
  struct Bound {
    int32_t d, q, r, step_q, step_r;
    // q = E_0 and step_q = B (add) to their quotients and remainders.
    void divide() {
      split(q, d, &q, &r);
      split(step_q, d, &step_q, &step_r);
    }
    void next_row() {
      q += step_q;
      r += step_r;
      if (r >= d) {
        r -= d;
        ++q;
      }
    }
  };

  template <int kLower, int kUpper, class Emit>
  void rows_with(bool fixed, int count, int32_t shift, int32_t last_column, Emit emit) {
    if (fixed) return rows_fixed<kLower, kUpper>(count, shift, last_column, emit);
    dda();
    rows_of<kLower, kUpper>(count, shift, last_column, emit);
  }

  // A bound in 64-bit fixed point, 32 fraction bits: y is stepped by `step` from row to row and the row's
  // bound is y >> 32 (rows_fixed).
  struct Fixed {
    int64_t y, step;
  };
  // Whether rows_fixed is exact for `count` rows: every divisor below 2^32 / count. (A divisor is an
  // edge's step times the pitch, at least 32: y stays below 2^59.)
  bool fixed_fits(int count) const { return uint64_t(uint32_t(max_d_)) * uint64_t(count) < (uint64_t(1) << 32); }
  // Y_j = floor(E_0 2^32 / d) + j floor(B 2^32 / d) + count lies in [E_j 2^32 / d, (floor(E_j / d) + 1) 2^32)
  // for rows j < count: each floor loses less than one unit, j + 1 <= count of them at row j, and
  // E_j 2^32 / d is at least 2^32 / d > count units below the next multiple of 2^32 (d count < 2^32,
  // fixed_fits). So Y_j >> 32 = floor(E_j / d) exactly. A lower bound keeps 2^32 - 1 - Y_j, whose integer
  // part is -floor(E_j / d): the row's first column, as the upper bound's is its last.
  // Both with `shift` (already shifted to the integer part) added.
  static Fixed fixed(const Bound& b, int count, bool lower, int64_t shift) {
    const int64_t y = floor_fraction(b.q, b.d) + count, step = floor_fraction(b.step_q, b.d);
    if (lower) return Fixed{int64_t(0xFFFFFFFFu) - y + shift, -step};
    return Fixed{y + shift, step};
  }
  // rows_of in fixed point: a row's bounds are the largest lower and the smallest upper y, whose integer
  // parts are its first and last columns plus shift (the shift keeps the order). Missing bounds bound
  // nothing (shift and last_column + shift).
  template <int kLower, int kUpper, class Emit>
  void rows_fixed(int count, int32_t shift, int32_t last_column, Emit emit) {
    const int64_t first_cap = int64_t(uint64_t(uint32_t(shift)) << 32);
    const int64_t last_cap = int64_t(uint64_t(uint32_t(last_column + shift)) << 32) + 0xFFFFFFFF;
    const Fixed lnone{first_cap, 0}, unone{last_cap, 0};
    Fixed l0 = lower_n_ > 0 ? fixed(lower_[0], count, true, first_cap) : lnone;
    Fixed l1 = kLower >= 2 ? fixed(lower_[1], count, true, first_cap) : lnone;
    Fixed l2 = kLower == 3 ? fixed(lower_[2], count, true, first_cap) : lnone;
    Fixed u0 = upper_n_ > 0 ? fixed(upper_[0], count, false, first_cap) : unone;
    Fixed u1 = kUpper >= 2 ? fixed(upper_[1], count, false, first_cap) : unone;
    Fixed u2 = kUpper == 3 ? fixed(upper_[2], count, false, first_cap) : unone;
    for (int y = 0; y < count; ++y) {
      int64_t lo = max_of(first_cap, l0.y), hi = min_of(last_cap, u0.y);
      l0.y += l0.step;
      u0.y += u0.step;
      if (kLower >= 2) {
        lo = max_of(lo, l1.y);
        l1.y += l1.step;
      }
      if (kLower == 3) {
        lo = max_of(lo, l2.y);
        l2.y += l2.step;
      }
      if (kUpper >= 2) {
        hi = min_of(hi, u1.y);
        u1.y += u1.step;
      }
      if (kUpper == 3) {
        hi = min_of(hi, u2.y);
        u2.y += u2.step;
      }
      const int32_t first = int32_t(lo >> 32), last = int32_t(hi >> 32);
      if (first <= last) emit(y, first, last);
    }
  }

  // rows() with kLower left and kUpper right bounds; a missing one (none of a side) is stood in for by
  // one that bounds nothing (q = 2^30 stays beyond every column: no steps).
  template <int kLower, int kUpper, class Emit>
  void rows_of(int count, int32_t shift, int32_t last_column, Emit emit) {
    const Bound none{1, int32_t(1) << 30, 0, 0, 0};
    Bound l0 = lower_n_ > 0 ? lower_[0] : none, l1 = kLower >= 2 ? lower_[1] : none;
    Bound l2 = kLower == 3 ? lower_[2] : none;
    Bound u0 = upper_n_ > 0 ? upper_[0] : none, u1 = kUpper >= 2 ? upper_[1] : none;
    Bound u2 = kUpper == 3 ? upper_[2] : none;
    for (int y = 0; y < count; ++y) {
      int32_t first = max_of(int32_t(0), -l0.q), last = min_of(last_column, u0.q);
      l0.next_row();
      u0.next_row();
      if (kLower >= 2) {
        first = max_of(first, -l1.q);
        l1.next_row();
      }
      if (kLower == 3) {
        first = max_of(first, -l2.q);
        l2.next_row();
      }
      if (kUpper >= 2) {
        last = min_of(last, u1.q);
        u1.next_row();
      }
      if (kUpper == 3) {
        last = min_of(last, u2.q);
        u2.next_row();
      }
      if (first <= last) emit(y, first + shift, last + shift);
    }
  }

  struct Level {
    int32_t e, step;
  };
  // floor(n 2^32 / d), d > 0 (|n| < 2^30, rows_fit: no overflow).
  static int64_t floor_fraction(int32_t n, int32_t d) {
    const int64_t x = int64_t(n) * (int64_t(1) << 32);
    return (x >= 0 ? x : x - (d - 1)) / d;
  }
  // n = q d + r with 0 <= r < d.
  static void split(int32_t n, int32_t d, int32_t* q, int32_t* r) {
    *q = n / d;
    *r = n % d;
    if (*r < 0) {
      --*q;
      *r += d;
    }
  }
  // No initializers: the arrays would be cleared by a memset each call.
  int lower_n_, upper_n_, level_n_;
  int32_t max_d_;  // the largest d of the bounds (64-bit hosts)
  Bound lower_[kMaxPolyEdges], upper_[kMaxPolyEdges];
  Level level_[kMaxPolyEdges];
};

// Boxes up to Grid::kSamples samples a side take the row-by-row path (HierTiler::tile_small), where a
// descent would triage at least two levels of masks. A row's span is a Word of the box's columns,
// placed at the box's column within its first block (up to 7 bits further); Placed::byte(i) is the
// row's part in block i.
// - 64-bit hosts: a 64-bit word and boxes up to 56 samples (8 x 8 blocks; bundled scene, 320x240,
//   16-row bands: 11.94 M instructions at 32, 11.44 M at 48, 11.36 M at 56), and wider boxes up to 120
//   samples in a 128-bit word (WideGrid; 2CylinderEngine, 1024x768: 81.42 M -> 79.99 M a frame; all
//   boxes in the wide word cost more: 81.50 M).
// - 32-bit boards: 32 samples (5 x 5 blocks; best of 16, 24, 32) in a 32-bit word placed as two
//   halves: 64-bit shifts cost a Cortex-M3 more than the wider path saves (mps2-an385 frame 10.58 M ->
//   10.61 M at 56), and the blocks' arrays stay at 400 bytes of stack (1 KB at 56). No wide grid.
#if UINTPTR_MAX == 0xFFFFFFFFu
struct SmallGrid {
  static constexpr int kSamples = 32;
  using Word = uint32_t;
  struct Placed {
    uint32_t low, high;  // bits 0..31 and 32..63 of span << s
    Placed(uint32_t span, int s) : low(span << s), high(s == 0 ? 0 : span >> (32 - s)) {}
    uint32_t byte(int i) const { return (i < 4 ? low >> (8 * i) : high) & 0xFFu; }
  };
};
using WideGrid = SmallGrid;
#else
template <class W, int kSide>
struct GridOf {
  static constexpr int kSamples = kSide;
  using Word = W;
  struct Placed {
    W bits;  // span << s
    Placed(W span, int s) : bits(span << s) {}
    uint32_t byte(int i) const { return uint32_t(bits >> (8 * i)) & 0xFFu; }
  };
};
using SmallGrid = GridOf<uint64_t, 56>;
// Placed a byte a block (kByteRows), a row needs no word: wide boxes up to 248 samples, their blocks'
// array 8 KB of stack (2CylinderEngine, 1024x768: 74.09 M -> 73.44 M a frame, the same at 504).
using WideGrid = GridOf<unsigned __int128, kByteRows ? 248 : 120>;
#endif
// A box inside one finest block tiled without the blocks' arrays (tile_in_block) on 64-bit hosts only:
// the boards' flash (bundled scene, 320x240: 6.97 M -> 6.81 M a frame; 2CylinderEngine 55.81 M ->
// 55.16 M).
constexpr bool kOneBlockPath = UINTPTR_MAX > 0xFFFFFFFFu;
// box_visible's witness (BoxWitness) on 64-bit hosts only: the boards' flash.
constexpr bool kWitness = UINTPTR_MAX > 0xFFFFFFFFu;
// cover_block's first step up inline (HierTiler::block_to_parent) on 64-bit hosts only, likewise.
constexpr bool kParentInline = UINTPTR_MAX > 0xFFFFFFFFu;
// tile_small's parent kept from polygon to polygon (KeptParent) on 64-bit hosts only, likewise.
constexpr bool kKeptParent = UINTPTR_MAX > 0xFFFFFFFFu;

// A row byte's columns c.. and ..c (looked up: a variable shift costs moves into the count register;
// 2CylinderEngine at 1024x768: 73.19 M -> 72.89 M instructions a frame).
constexpr uint8_t kFrom[8] = {0xFF, 0xFE, 0xFC, 0xF8, 0xF0, 0xE0, 0xC0, 0x80};
constexpr uint8_t kTo[8] = {0x01, 0x03, 0x07, 0x0F, 0x1F, 0x3F, 0x7F, 0xFF};

// Columns a..b (0 <= a <= b) of a row of masks kStride bytes apart, `row` its byte in the first: the
// end masks' bytes cut at a and b, any between full. Stored, not merged: each row of a mask is placed
// once, into a cleared mask.
template <int kStride>
inline void place_bytes(uint8_t* row, int32_t a, int32_t b) {
  uint8_t* at = row + (a >> 3) * kStride;
  const int n = (b >> 3) - (a >> 3);
  const uint32_t head = kFrom[a & 7], tail = kTo[b & 7];
  if (n == 0) {
    *at = uint8_t(head & tail);
    return;
  }
  *at = uint8_t(head);
  for (int i = 1; i < n; ++i) at[kStride * i] = 0xFFu;
  at[kStride * n] = uint8_t(tail);
}

// Bits first..last of a row (0 <= first <= last < the grid's kSamples).
template <class Word>
inline Word span_bits(int32_t first, int32_t last) {
  return ((Word(2) << last) - 1) & (~Word(0) << first);
}

// |v| < limit, one unsigned comparison (limit > 0).
inline bool within(int64_t v, int64_t limit) { return uint64_t(v) + uint64_t(limit - 1) < uint64_t(2 * limit - 1); }

// Whether RowSpans can step an edge whose values over the samples lie in [lo, hi] and whose steps
// between samples are a (columns) and b (rows): everything below 2^30.
inline bool rows_fit(int64_t lo, int64_t hi, int64_t a, int64_t b) {
  constexpr int64_t kLimit = int64_t(1) << 30;
  return -lo < kLimit && hi < kLimit && within(a, kLimit) && within(b, kLimit);
}

enum class SmallSetup : uint8_t { Ready, Outside, TooLarge };

// The row spans of the edges that cross the box [x0, x1] x [y0, y1] (samples of `pitch`
// subpixels); edges with the whole box inside are dropped.
SmallSetup small_edges(const ConvexPoly& poly, int32_t pitch, RowSpans* rows) {
  // Sample centres and box sides below 2^21 subpixels (the screen), so with |a|, |b| < 2^23 (checked;
  // src/view keeps them there) every product is a 32-by-32-bit one: one instruction on a Cortex-M3.
  constexpr int32_t kStepLimit = int32_t(1) << 23;
  const int32_t half = pitch / 2;
  const int32_t x0 = poly.min_x * pitch + half, y0 = poly.min_y * pitch + half;
  const int32_t w = (poly.max_x - poly.min_x) * pitch, h = (poly.max_y - poly.min_y) * pitch;
  rows->clear();
  for (int i = 0; i < poly.n; ++i) {
    const EdgeFunction& e = poly.edge[i];
    if (!within(e.a, kStepLimit) || !within(e.b, kStepLimit)) return SmallSetup::TooLarge;
    const int32_t a = int32_t(e.a), b = int32_t(e.b);
    // A linear function's extremes over the box: its value at x0, y0 plus the negative (positive) steps.
    const int64_t k0 = int64_t(a) * x0 + int64_t(b) * y0 + e.c;
    const int64_t aw = int64_t(a) * w, bh = int64_t(b) * h;
    const int64_t lo = k0 + (aw < 0 ? aw : 0) + (bh < 0 ? bh : 0);
    const int64_t hi = k0 + (aw > 0 ? aw : 0) + (bh > 0 ? bh : 0);
    if (hi < 0) return SmallSetup::Outside;
    if (lo >= 0) continue;
    if (!rows_fit(lo, hi, int64_t(a) * pitch, int64_t(b) * pitch)) return SmallSetup::TooLarge;
    rows->add(int32_t(k0), a * pitch, b * pitch);
  }
  return SmallSetup::Ready;
}

}  // namespace

bool write_mask_runs(uint64_t mask, int x, int y, CoverageWriter& writer) { return emit_mask(mask, x, y, 1, writer); }

void poly_from_setup(const TriangleSetup& setup, ConvexPoly* out) {
  out->n = 3;
  for (int i = 0; i < 3; ++i) out->edge[i] = setup.edge[i];
  out->min_x = setup.min_x;
  out->min_y = setup.min_y;
  out->max_x = setup.max_x;
  out->max_y = setup.max_y;
}

void poly_edges(const ScreenTriangle& tri, ConvexPoly* out) {
  out->n = 3;
  ML_HOST_UNROLL for (int i = 0; i < 3; ++i) {
    const ScreenVertex& p = tri.v[i];
    const ScreenVertex& q = tri.v[i == 2 ? 0 : i + 1];
    out->edge[i] = edge_function(p.x, p.y, q.x, q.y);
  }
}

void poly_in_samples(const ScreenTriangle& tri, const TriangleSetup& setup, int factor, int width,
                     int height, ConvexPoly* out, bool jittered) {
  poly_from_setup(setup, out);
  if (factor == 1) return;
  triangle_sample_box(tri, factor, width, height, jittered, out);
}

TriageMask edge_triage_mask(const int64_t corner[4]) {
  int enter = 0, exit = 0;
  for (int s = 0; s < 4; ++s) {
    const int64_t from = corner[s], to = corner[(s + 1) & 3];
    const bool p0 = from > 0, p1 = to > 0;
    if (p0 == p1) continue;
    const int g = s * kMaskK + quantize(from, to);
    if (p1) enter = g; else exit = g;
  }
  const int g1 = enter < exit ? enter : exit;
  const int g2 = enter < exit ? exit : enter;
  const MaskEntry& m = kMaskTable[kSidePair[g1 >> kMaskKBits][g2 >> kMaskKBits] * kMaskK * kMaskK +
                                  (g1 & (kMaskK - 1)) * kMaskK + (g2 & (kMaskK - 1))];
  // The stored entry's covered side is the perimeter arc from g1 to g2; ours runs from enter.
  return enter == g1 ? TriageMask{m.c, m.v} : TriageMask{m.v, m.c};
}

void HierTiler::init(Pyramid* pyramid, int32_t pitch, WorkImage* work, int work_row0) {
  pyr_ = pyramid;
  pitch_ = pitch;
  work_ = work;
  work_row0_ = work_row0;
  if (kWitness) forget_witness();
  if (kKeptParent) forget_parent();
}

bool HierTiler::poly_mask(int level, const Edges& in, Edges* crossing, uint64_t* pc,
                          uint64_t* pv) const {
  return edges_mask(in, int64_t(pitch_) << pyr_->layout.shift(level), crossing, pc, pv);
}

// The polygon's mask over a cell of `side` subpixels whose top-left corner values are in.e. False
// when some edge puts the whole cell outside.
bool HierTiler::edges_mask(const Edges& in, int64_t side, Edges* crossing, uint64_t* pc, uint64_t* pv) {
  uint64_t c = kAll, v = 0;
  int n = 0;
  for (int i = 0; i < in.n; ++i) {
    int64_t k[4];
    k[0] = in.e[i];
    k[1] = k[0] + in.a[i] * side;
    k[3] = k[0] + in.b[i] * side;
    k[2] = k[1] + in.b[i] * side;
    const int64_t lo = min_of(min_of(k[0], k[1]), min_of(k[2], k[3]));
    const int64_t hi = max_of(max_of(k[0], k[1]), max_of(k[2], k[3]));
    if (hi <= 0) return false;  // outside: no sample of the open cell has E >= 0
    if (lo >= 0) continue;      // inside the whole closed cell: irrelevant below
    const TriageMask m = edge_triage_mask(k);
    c &= m.c;
    v |= m.v;
    crossing->a[n] = in.a[i];
    crossing->b[n] = in.b[i];
    crossing->e[n] = in.e[i];
    ++n;
  }
  crossing->n = n;
  *pc = c;
  *pv = v;
  return v != kAll;
}

// Of the samples in `todo` of finest cell (bx, by), those inside every crossing edge: at the sub-cell
// centres, or at their jittered offsets (the pattern of their pixel, whose row counts from the band's
// top row; looked up once a pixel).
uint64_t HierTiler::exact_samples(const Edges& edges, uint64_t todo, int bx, int by) const {
  uint64_t in = 0;
  const int f = jitter_f_, fb = f == 8 ? 3 : f == 4 ? 2 : 1;  // f is 2, 4 or 8 when jittered
  int last_px = -1, last_py = -1;
  const uint8_t* offsets = nullptr;  // the pattern of pixel (last_px, last_py)
  while (todo != 0) {
    const int bit = __builtin_ctzll(todo);
    todo &= todo - 1;
    int64_t ox = pitch_ / 2, oy = pitch_ / 2;
    if (f != 0) {
      const int gx = bx * 8 + (bit & 7), gy = by * 8 + (bit >> 3);
      if ((gx >> fb) != last_px || (gy >> fb) != last_py) {
        last_px = gx >> fb;
        last_py = gy >> fb;
        offsets = jitter_table_ + (jitter_pattern(last_px, last_py + work_row0_, jitter_seed_) << (2 * fb + 1));
      }
      const uint8_t* o = offsets + ((((gy & (f - 1)) << fb) + (gx & (f - 1))) << 1);
      ox = o[0];
      oy = o[1];
    }
    const int64_t x = (bit & 7) * int64_t(pitch_) + ox, y = (bit >> 3) * int64_t(pitch_) + oy;
    bool inside = true;
    for (int i = 0; i < edges.n && inside; ++i)
      inside = edges.e[i] + edges.a[i] * x + edges.b[i] * y >= 0;
    if (inside) in |= uint64_t(1) << bit;
  }
  return in;
}

// The work image is in pixels: a cell of samples counts for every pixel it touches.
void HierTiler::add_work(int level, int mx, int my) {
  const int s = pyr_->layout.shift(level);
  const int f = kSubpixelOne / pitch_;  // samples per pixel per axis
  const int x0 = (mx << s) / f, y0 = work_row0_ + ((my << s) / f);
  const int x1 = min_of((((mx + 1) << s) + f - 1) / f, work_->width);
  const int y1 = min_of(min_of(work_row0_ + (((my + 1) << s) + f - 1) / f, work_row0_ + pyr_->layout.height / f),
                        work_->height);
  if (x1 <= x0 || y1 <= y0) return;
  const uint32_t add = uint32_t(65536 / (int64_t(x1 - x0) * (y1 - y0)));
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) work_->q16[size_t(y) * size_t(work_->width) + size_t(x)] += add;
}

// The samples of a finest cell (edge values at its top-left corner in `in`) inside every edge, row by
// row (RowSpans), exactly. False when an edge's values are too large for 32-bit rows.
bool HierTiler::block_samples(const Edges& in, uint64_t* out) const {
  const int64_t half = pitch_ / 2, span = int64_t(pitch_) * 7;  // first to last sample centre
  RowSpans rows;
  rows.clear();
  *out = 0;
  for (int i = 0; i < in.n; ++i) {
    const int64_t k0 = in.e[i] + (in.a[i] + in.b[i]) * half;
    const int64_t k1 = k0 + in.a[i] * span, k2 = k0 + in.b[i] * span, k3 = k1 + in.b[i] * span;
    const int64_t lo = min_of(min_of(k0, k1), min_of(k2, k3)), hi = max_of(max_of(k0, k1), max_of(k2, k3));
    if (hi < 0) return true;
    if (lo >= 0) continue;
    if (!rows_fit(lo, hi, in.a[i] * pitch_, in.b[i] * pitch_)) return false;
    rows.add(int32_t(k0), int32_t(in.a[i] * pitch_), int32_t(in.b[i] * pitch_));
  }
  rows.dda();
  for (int r = 0; r < 8; ++r) {
    int32_t first, last;
    rows.row(7, &first, &last);
    if (first <= last) *out |= uint64_t(span_bits<uint32_t>(first, last)) << (8 * r);
  }
  return true;
}

bool HierTiler::tile_cell(int level, int mx, int my, const Edges& in, CoverageWriter& writer) {
  ++cells_visited;
  if (work_) add_work(level, mx, my);
  const PyramidLayout& lay = pyr_->layout;
  uint64_t cover;
  if (level == lay.finest() && jitter_f_ == 0 && block_samples(in, &cover)) {
    // Inside the box only: a split piece's box bounds its slivers (as the descent's exact tests do).
    uint64_t& sc = pyr_->block(mx, my);
    const uint64_t w = cover & ~sc & box_bits(level, mx, my);
    if (w == 0) return true;
    sc |= w;
    return writer.write_block(w, mx << lay.shift(level), my << lay.shift(level));
  }
  Edges act;
  uint64_t pc, pv;
  if (!poly_mask(level, in, &act, &pc, &pv)) return true;
  const int s = lay.shift(level);
  if (level == lay.finest()) {
    uint64_t& sc = pyr_->block(mx, my);
    uint64_t w = pc & ~sc;
    const uint64_t todo = ~(sc | pc | pv) & box_bits(level, mx, my);  // no sample outside the box is covered
    if (todo != 0) w |= exact_samples(act, todo, mx, my);
    if (w == 0) return true;
    sc |= w;
    return writer.write_block(w, mx << s, my << s);
  }
  TriageMask& sm = pyr_->mask(level, mx, my);
  uint64_t w, a;
  composite(&sm, TriageMask{pc, pv}, &w, &a);
  if (w != 0 && !emit_mask(w, mx << s, my << s, 1 << (s - 3), writer)) return false;
  a &= box_bits(level, mx, my);  // conservative masks may call subcells beside the box active
  const int64_t q = int64_t(pitch_) << (s - 3);
  const bool child_finest = level + 1 == lay.finest();
  Edges child;  // same edges; at_subcell moves their values to each child's corner
  child.copy_steps(act);
  while (a != 0) {
    const int bit = __builtin_ctzll(a);
    a &= a - 1;
    const int col = bit & 7, row = bit >> 3;
    child.at_subcell(act, q, col, row);
    const int cx = mx * 8 + col, cy = my * 8 + row;
    if (!tile_cell(level + 1, cx, cy, child, writer)) return false;
    const uint64_t m = uint64_t(1) << bit;
    if (child_finest) {
      const uint64_t cb = pyr_->block(cx, cy);
      if (cb == kAll) sm.c |= m;
      if (cb != 0) sm.v &= ~m;
    } else {
      const TriageMask& cm = pyr_->mask(level + 1, cx, cy);
      if (cm.c == kAll) sm.c |= m;
      if (cm.v != kAll) sm.v &= ~m;
    }
  }
  return true;
}

bool HierTiler::query_cell(int level, int mx, int my, const Edges& in) const {
  Edges act;
  uint64_t pc, pv;
  if (!poly_mask(level, in, &act, &pc, &pv)) return false;
  const PyramidLayout& lay = pyr_->layout;
  if (level == lay.finest()) {
    const uint64_t sc = pyr_->block(mx, my);
    if ((pc & ~sc) != 0) return true;
    const uint64_t todo = ~(sc | pc | pv);
    return todo != 0 && exact_samples(act, todo, mx, my) != 0;
  }
  const TriageMask& sm = pyr_->mask(level, mx, my);
  // A subcell that is not covered holds at least one uncovered sample (propagation keeps it so).
  if ((pc & ~sm.c) != 0) return true;
  uint64_t a = ~(pv | sm.c | pc);
  const int64_t q = int64_t(pitch_) << (lay.shift(level) - 3);
  Edges child = act;  // same edges; at_subcell moves their values to each child's corner
  while (a != 0) {
    const int bit = __builtin_ctzll(a);
    a &= a - 1;
    const int col = bit & 7, row = bit >> 3;
    child.at_subcell(act, q, col, row);
    if (query_cell(level + 1, mx * 8 + col, my * 8 + row, child)) return true;
  }
  return false;
}

// The bits of an 8x8 mask in columns c0..c1 and rows r0..r1 (0 <= c0 <= c1 <= 7, 0 <= r0 <= r1 <= 7).
inline uint64_t range_mask(int c0, int c1, int r0, int r1) {
#if UINTPTR_MAX > 0xFFFFFFFFu
  // Looked up on 64-bit hosts, as place_bytes's bytes (2CylinderEngine at 1024x768: 72.84 M -> 72.75 M);
  // the boards keep the shifts (no flash for the tables). Rows r.. and ..r:
  static constexpr uint64_t kRowsFrom[8] = {kAll,       kAll << 8,  kAll << 16, kAll << 24,
                                            kAll << 32, kAll << 40, kAll << 48, kAll << 56};
  static constexpr uint64_t kRowsTo[8] = {kAll >> 56, kAll >> 48, kAll >> 40, kAll >> 32,
                                          kAll >> 24, kAll >> 16, kAll >> 8,  kAll};
  return (uint64_t(kFrom[c0] & kTo[c1]) * 0x0101010101010101u) & kRowsFrom[r0] & kRowsTo[r1];
#else
  const uint32_t row = (0xFFu >> (7 - c1)) & (0xFFu << c0);
  return (uint64_t(row) * 0x0101010101010101u) & (kAll >> (8 * (7 - r1))) & (kAll << (8 * r0));  // rows r0..r1
#endif
}

// The subcells of mask (mx, my) inside the box of subcells [x0, x1] x [y0, y1] (x0, y0 >= 0), which
// must overlap the mask: the box's first and last columns and rows cut it only in the masks that hold
// them, so there is nothing to clip.
inline uint64_t overlap_mask(int32_t x0, int32_t x1, int32_t y0, int32_t y1, int mx, int my) {
  return range_mask((x0 >> 3) == mx ? x0 & 7 : 0, (x1 >> 3) == mx ? x1 & 7 : 7, (y0 >> 3) == my ? y0 & 7 : 0,
                    (y1 >> 3) == my ? y1 & 7 : 7);
}

// Subcells (samples at the finest level) of a level-`level` cell that the polygon's box overlaps. Only
// for cells that overlap the box: the start cell encloses it, and every cell the descents visit below
// it was picked by these bits.
uint64_t HierTiler::box_bits(int level, int mx, int my) const {
  const int sub = pyr_->layout.shift(level) - 3;
  return overlap_mask(bx0_ >> sub, bx1_ >> sub, by0_ >> sub, by1_ >> sub, mx, my);
}

// box_bits of finest block (bx, by), without the level arithmetic on 64-bit hosts. The boards call
// box_bits: the mask inline costs a Cortex-M0+ about 400 bytes of flash.
inline uint64_t HierTiler::block_box(int bx, int by) const {
#if UINTPTR_MAX == 0xFFFFFFFFu
  return box_bits(pyr_->layout.finest(), bx, by);
#else
  return overlap_mask(bx0_, bx1_, by0_, by1_, bx, by);
#endif
}

// Whether block (bx, by) has an uncovered sample among `box` (its samples in the polygon's box); the
// first one becomes the witness.
inline bool HierTiler::block_uncovered(uint64_t box, int bx, int by) const {
  const uint64_t open = box & ~pyr_->block(bx, by);
  if (kWitness && open != 0) {
    const int bit = __builtin_ctzll(open);
    const int32_t x = bx * 8 + (bit & 7), y = by * 8 + (bit >> 3);
    witness(x, y, x, y);
  }
  return open != 0;
}

void HierTiler::witness(int32_t x0, int32_t y0, int32_t x1, int32_t y1) const {
  remember_witness(max_of(x0, bx0_), max_of(y0, by0_), min_of(x1, bx1_), min_of(y1, by1_));
}

// Whether the polygon's box holds an uncovered sample inside this (not covered) cell: a descent
// through the pyramid over the box, no edge arithmetic, first uncovered sample wins.
bool HierTiler::box_uncovered(int level, int mx, int my) const {
  const uint64_t box = box_bits(level, mx, my);
  const int s = pyr_->layout.shift(level) - 3;  // log2 of a subcell's side in samples
  if (level == pyr_->layout.finest()) return block_uncovered(box, mx, my);
  const TriageMask& m = pyr_->mask(level, mx, my);
  if (box & m.v) {  // a vacant subcell is wholly on screen: every sample in it is uncovered
    if (kWitness) {
      const int bit = __builtin_ctzll(box & m.v);
      const int32_t x = (mx * 8 + (bit & 7)) << s, y = (my * 8 + (bit >> 3)) << s;
      witness(x, y, x + (1 << s) - 1, y + (1 << s) - 1);
    }
    return true;
  }
  uint64_t a = box & ~(m.c | m.v);
  // Blocks (the finest level) are tested here: no recursive call a block.
  const bool child_finest = level + 1 == pyr_->layout.finest();
  while (a != 0) {
    const int bit = __builtin_ctzll(a);
    a &= a - 1;
    const int cx = mx * 8 + (bit & 7), cy = my * 8 + (bit >> 3);
    if (child_finest ? block_uncovered(block_box(cx, cy), cx, cy) : box_uncovered(level + 1, cx, cy)) return true;
  }
  return false;
}

// The smallest cell enclosing the polygon's sample box, or false when the box is empty or the
// pyramid proves every sample in it covered (an ancestor subcell on the path, or all subcells the
// box touches in the enclosing cell).
bool HierTiler::start_cell(const ConvexPoly& poly, int* level, int* mx, int* my) const {
  if (poly.min_x > poly.max_x || poly.min_y > poly.max_y) return false;
  const PyramidLayout& lay = pyr_->layout;
  const uint32_t d = uint32_t(poly.min_x ^ poly.max_x) | uint32_t(poly.min_y ^ poly.max_y);
  int m = (bit_length(d) + 2) / 3;
  if (m < 1) m = 1;
  const int target = lay.levels - m;
  // The levels above the kept path's cell (KeptParent) when the start cell lies in it: tested already.
  // Only for a path of two tests or more: with one the check costs what it saves (2CylinderEngine at
  // 1024x768: 68.95 M -> 68.70 M instructions a frame; for every path 68.76 M, and 320x240 52.45 M ->
  // 52.54 M; from three tests on 68.94 M).
  int l = 0;
  if (kKeptParent && target >= 2) {
    const int kept = min_of(target, kept_path_level()), up = 3 * (kept_path_level() - kept);
    if ((poly.min_x >> lay.shift(kept)) == (kept_path_x() >> up) && (poly.min_y >> lay.shift(kept)) == (kept_path_y() >> up))
      l = kept;
  }
  for (int sub = lay.shift(l) - 3; l < target; ++l, sub -= 3) {
    const int cx = poly.min_x >> sub, cy = poly.min_y >> sub;  // the level-(l + 1) cell on the path
    if ((pyr_->mask(l, cx >> 3, cy >> 3).c >> ((cy & 7) * 8 + (cx & 7))) & 1) return false;
  }
  const int s = lay.shift(target);
  if (kKeptParent && target >= 2) keep_path(target, poly.min_x >> s, poly.min_y >> s);
  *level = target;
  *mx = poly.min_x >> s;
  *my = poly.min_y >> s;
  return box_uncovered(target, *mx, *my);
}

// Carries a cell's new status to its ancestors (tiling may start below the root), on 64-bit hosts up to the
// first whose own status stays as it was (set_in_parent): the ones above it agree with it already (every
// mask's bits are its children's status, or the mask is stale, under a covered subcell, and never tiled).
// The kept parent (KeptParent) holds covered bits only: forgotten when one changes. 2CylinderEngine at
// 1024x768: most blocks a polygon starts are in a parent already started, so the walk stops at the parent.
void HierTiler::propagate_up(int level, int mx, int my) {
  const PyramidLayout& lay = pyr_->layout;
  for (int l = level; l > 0; --l, mx >>= 3, my >>= 3) {
    bool all_covered, none_covered;
    if (l == lay.finest()) {
      const uint64_t b = pyr_->block(mx, my);
      all_covered = b == kAll;
      none_covered = b == 0;
    } else {
      const TriageMask& m = pyr_->mask(l, mx, my);
      all_covered = m.c == kAll;
      none_covered = m.v == kAll;
    }
    if (!set_in_parent(l, mx, my, all_covered, none_covered)) return;
  }
}

// Cell (l, mx, my)'s status into its bit of the parent mask; whether the parent's own status (all covered,
// all vacant) changed, the only thing its parent reads of it. Coverage only grows: bits are only set in
// c and cleared in v. The boards report every step as a change (a walk to the root: the Cortex-M0+
// image's flash).
inline bool HierTiler::set_in_parent(int l, int mx, int my, bool all_covered, bool none_covered) {
  const uint64_t bit = uint64_t(1) << ((my & 7) * 8 + (mx & 7));
  TriageMask& parent = pyr_->mask(l - 1, mx >> 3, my >> 3);
  if (!kKeptParent) {
    if (all_covered) parent.c |= bit;
    if (!none_covered) parent.v &= ~bit;
    return true;
  }
  const bool was_covered = parent.c == kAll, was_vacant = parent.v == kAll;
  if (all_covered && !(parent.c & bit)) {
    forget_parent();  // a covered bit changes
    parent.c |= bit;
  }
  if (!none_covered) parent.v &= ~bit;
  return (parent.c == kAll) != was_covered || (parent.v == kAll) != was_vacant;
}

// Whether a cell's ancestor (a subcell of a coarser mask on its path) is covered: the cell's contents
// may then be stale.
inline bool HierTiler::covered_above(int level, int mx, int my) const {
  for (int l = 0, d = 3 * (level - 1); l < level; ++l, d -= 3) {
    const int cx = mx >> d, cy = my >> d;  // the level-(l + 1) cell on the path: a subcell of mask l
    if ((pyr_->mask(l, cx >> 3, cy >> 3).c >> ((cy & 7) * 8 + (cx & 7))) & 1) return true;
  }
  return false;
}

// The hierarchy costs a small polygon more than it saves: its coverage comes row by row from the
// edge functions (RowSpans), is gathered into the finest blocks the box touches, and only samples
// not yet covered there are written. False (nothing done) when the edges are too long for 32-bit
// rows; then the caller descends. On 64-bit hosts inlined in tile, as is cover_block in it (GCC's own
// choice flips with small changes to either: 2CylinderEngine at 1024x768 68.83 M a frame with
// block_to_parent out of both, 68.41 M in both).
template <class Grid>
ML_HOST_INLINE inline bool HierTiler::tile_small(const ConvexPoly& poly, CoverageWriter& writer, TileResult* result,
                                                 bool open) {
  constexpr int kBlocks = Grid::kSamples / 8 + 1;
  const int cx0 = poly.min_x >> 3, cy0 = poly.min_y >> 3;
  const int nx = (poly.max_x >> 3) - cx0 + 1, ny = (poly.max_y >> 3) - cy0 + 1;
  // The polygon's samples in each block, cover[i * kBlocks + j] for block (cx0 + i, cy0 + j): a block
  // column's masks are adjacent, so the box's row y lies at byte y + y0 of each column (kByteRows). On
  // 64-bit hosts the small grid's blocks are ZeroBlocks, zero already: the loop that reads them clears
  // them (2CylinderEngine at 1024x768: 68.32 M -> 67.86 M a frame, 320x240 52.37 M -> 52.22 M; most blocks
  // of a box stay empty). Otherwise only the nx x ny blocks in use are cleared (with the whole array
  // cleared, a memset of 200 bytes a call).
  constexpr bool kZeroed = kKeptParent && kBlocks * kBlocks == kZeroBlockCount;
  uint64_t own[kZeroed ? 1 : kBlocks * kBlocks];
  uint64_t* const cover = kZeroed ? zero_blocks() : own;
  // The blocks' covered samples (block_done) are asked of the first blocks, for the test below, then
  // only of the blocks the polygon reaches, as they are covered (the other blocks' writes change no bit
  // of them): most blocks of a small polygon's box miss it.
  ParentCover local;
  ParentCover* parent = kKeptParent ? kept_parent() : &local;
  auto done = [&](int bx, int by) { return block_done(bx, by, parent); };
  // Hidden unless a block holds an uncovered sample of the box (open: known to, the caller found one). The
  // box's columns in its first and last block columns, and its rows in its first and last block rows (the
  // blocks between are whole): a block's samples in the box are one product of the two.
  if (!open) {
    const uint32_t col_first = (0xFFu << (poly.min_x & 7)) & 0xFFu, col_last = 0xFFu >> (7 - (poly.max_x & 7));
    const uint64_t row_first = kAll << (8 * (poly.min_y & 7)), row_last = kAll >> (8 * (7 - (poly.max_y & 7)));
    for (int j = 0; j < ny && !open; ++j)
      for (int i = 0; i < nx && !open; ++i) {
        const uint64_t d = done(cx0 + i, cy0 + j);
        // The box holds samples of every block it touches: an empty block is open without its box bits.
        if (d == kAll) continue;
        const uint32_t cols = (i == 0 ? col_first : 0xFFu) & (i == nx - 1 ? col_last : 0xFFu);
        const uint64_t rows_in = (j == 0 ? row_first : kAll) & (j == ny - 1 ? row_last : kAll);
        open = d == 0 || ((cols * 0x0101010101010101u) & rows_in & ~d) != 0;
      }
    *result = TileResult::Hidden;
    if (!open) return true;
  }
  RowSpans rows;
  const SmallSetup setup = small_edges(poly, pitch_, &rows);
  if (setup == SmallSetup::TooLarge) return false;
  *result = TileResult::Tiled;
  if (setup == SmallSetup::Outside) return true;
  if (!kZeroed)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) cover[i * kBlocks + j] = 0;
  const int32_t last_column = poly.max_x - poly.min_x;
  const int s = poly.min_x & 7;  // the box's first column within its block
  const int y0 = poly.min_y & 7;  // the box's first row within its block
  // A row's span placed at its column in the blocks it reaches (row y of the box).
  uint8_t* const row0 = reinterpret_cast<uint8_t*>(cover) + y0;  // the box's first row, block column 0
  auto place = [cover, row0, s, y0](int y, int32_t first, int32_t last) {
    if (kByteRows) return place_bytes<kBlocks * 8>(row0 + y, first, last);
    const typename Grid::Placed row(span_bits<typename Grid::Word>(first, last), s);
    const int j = (y + y0) >> 3, shift = ((y + y0) & 7) * 8;
    for (int i = (first + s) >> 3; i <= (last + s) >> 3; ++i) cover[i * kBlocks + j] |= uint64_t(row.byte(i)) << shift;
  };
  rows.each_row(poly.max_y - poly.min_y + 1, kByteRows ? s : 0, last_column, place);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const uint64_t c = cover[i * kBlocks + j];
      if (c == 0) continue;
      if (kZeroed) cover[i * kBlocks + j] = 0;
      if (!cover_block(cx0 + i, cy0 + j, c & ~done(cx0 + i, cy0 + j), writer, true)) {
        if (kZeroed)
          for (int k = 0; k < kBlocks * kBlocks; ++k) cover[k] = 0;
        *result = TileResult::Failed;
        return true;
      }
    }
  return true;
}

// tile_small for boxes past SmallGrid's, out of line on 64-bit hosts: few polygons take it, and tile_small
// is inlined. (The boards have no wider grid: never called there.)
ML_HOST_NOINLINE inline bool HierTiler::tile_wide(const ConvexPoly& poly, CoverageWriter& writer, TileResult* result,
                                           bool open) {
  return tile_small<WideGrid>(poly, writer, result, open);
}

// Samples already covered in finest block (bx, by): all of them when an ancestor is covered. Blocks share
// their parent's ancestors (a small polygon's box has at most 3 x 3 parents): those are looked up once a
// parent, as the parent's covered blocks, kept in *parent.
inline uint64_t HierTiler::block_done(int bx, int by, ParentCover* parent) const {
  if ((bx >> 3) != parent->x || (by >> 3) != parent->y) {
    const int f = pyr_->layout.finest();
    parent->x = bx >> 3;
    parent->y = by >> 3;
    parent->c = covered_above(f - 1, parent->x, parent->y) ? kAll : pyr_->mask(f - 1, parent->x, parent->y).c;
  }
  return (parent->c >> ((by & 7) * 8 + (bx & 7))) & 1 ? kAll : pyr_->block(bx, by);
}

// Covers samples w (none of them covered yet) of finest block (bx, by), which the polygon reached, and
// writes them; false when the writer refused.
ML_HOST_INLINE inline bool HierTiler::cover_block(int bx, int by, uint64_t w, CoverageWriter& writer,
                                                 bool parent_inline) {
  const int f = pyr_->layout.finest();
  ++cells_visited;
  if (work_) add_work(f, bx, by);
  if (w == 0) return true;
  uint64_t& block = pyr_->block(bx, by);
  const bool was_empty = block == 0;
  block |= w;
  // The ancestors change only when the block stops being empty or becomes full (a block already
  // partly covered has cleared its vacant bit up the tree before).
  if (was_empty || block == kAll) {
    if (kParentInline && parent_inline) block_to_parent(bx, by, block);
    else propagate_up(f, bx, by);
  }
  return writer.write_block(w, bx << 3, by << 3);
}

// propagate_up from finest block (bx, by), now `block` (not empty), its first step inline: the call only
// when the parent's own status changes. On 64-bit hosts (the boards' flash), for tile_small's blocks
// (tile_in_block's one block: slower so). 2CylinderEngine at 1024x768: 68.70 M -> 68.41 M instructions
// a frame, 320x240 52.43 M -> 52.43 M, the bundled scene 5.93 M -> 5.82 M.
inline void HierTiler::block_to_parent(int bx, int by, uint64_t block) {
  if (set_in_parent(pyr_->layout.finest(), bx, by, block == kAll, false))
    propagate_up(pyr_->layout.finest() - 1, bx >> 3, by >> 3);
}

// tile_small for a box inside one finest block: one mask, no arrays.
bool HierTiler::tile_in_block(const ConvexPoly& poly, CoverageWriter& writer, TileResult* result) {
  const int bx = poly.min_x >> 3, by = poly.min_y >> 3;
  ParentCover local;
  const uint64_t done = block_done(bx, by, kKeptParent ? kept_parent() : &local);
  *result = TileResult::Hidden;
  if ((range_mask(poly.min_x & 7, poly.max_x & 7, poly.min_y & 7, poly.max_y & 7) & ~done) == 0) return true;
  RowSpans rows;
  const SmallSetup setup = small_edges(poly, pitch_, &rows);
  if (setup == SmallSetup::TooLarge) return false;
  *result = TileResult::Tiled;
  if (setup == SmallSetup::Outside) return true;
  const int s = poly.min_x & 7, y0 = poly.min_y & 7;
  uint64_t cover = 0;
  auto place = [&cover, s, y0](int y, int32_t first, int32_t last) {
    if (kByteRows) {
      reinterpret_cast<uint8_t*>(&cover)[y + y0] = uint8_t(kFrom[first] & kTo[last]);
      return;
    }
    cover |= uint64_t(span_bits<uint32_t>(first, last) << s) << ((y + y0) * 8);
  };
  rows.each_row(poly.max_y - poly.min_y + 1, kByteRows ? s : 0, poly.max_x - poly.min_x, place);
  if (cover != 0 && !cover_block(bx, by, cover & ~done, writer, false)) *result = TileResult::Failed;
  return true;
}

inline void HierTiler::edges_at_cell(const ConvexPoly& poly, int level, int mx, int my, Edges* out) const {
  const int s = pyr_->layout.shift(level);
  const int64_t x0 = int64_t(mx) * pitch_ << s, y0 = int64_t(my) * pitch_ << s;
  out->n = poly.n;
  for (int i = 0; i < poly.n; ++i) {
    out->a[i] = poly.edge[i].a;
    out->b[i] = poly.edge[i].b;
    out->e[i] = poly.edge[i].at(x0, y0);
  }
}

TileResult HierTiler::tile(const ConvexPoly& poly, CoverageWriter& writer) {
  // A box that reaches box_visible's witness, an uncovered sample, is open: tile_small skips its own test
  // of the box. A split piece's box was tested just before (TilerFrame::clip_to_whole), and often the
  // subtree's around a piece (2CylinderEngine at 1024x768: 69.75 M -> 69.18 M a frame).
  const bool open = kWitness && witness_reached(poly);
  if (kWitness) forget_witness();  // tiling covers samples (start_cell may find another below)
  bx0_ = poly.min_x;
  by0_ = poly.min_y;
  bx1_ = poly.max_x;
  by1_ = poly.max_y;
  if (poly.min_x > poly.max_x || poly.min_y > poly.max_y) return TileResult::Hidden;
  const int32_t w = poly.max_x - poly.min_x, h = poly.max_y - poly.min_y;
  if (jitter_f_ == 0 && w < WideGrid::kSamples && h < WideGrid::kSamples) {
    TileResult small;
    const bool one_block = kOneBlockPath && (poly.min_x ^ poly.max_x) < 8 && (poly.min_y ^ poly.max_y) < 8;
    const bool narrow = w < SmallGrid::kSamples && h < SmallGrid::kSamples;
    const bool tiled = one_block ? tile_in_block(poly, writer, &small)
                       : narrow  ? tile_small<SmallGrid>(poly, writer, &small, open)
                                 : tile_wide(poly, writer, &small, open);
    if (tiled) return small;
  }
  int level, mx, my;
  if (!start_cell(poly, &level, &mx, &my)) return TileResult::Hidden;
  if (kWitness) forget_witness();
  if (kKeptParent) forget_parent();  // the descent changes triage masks
  Edges edges;
  edges_at_cell(poly, level, mx, my, &edges);
  const bool ok = tile_cell(level, mx, my, edges, writer);
  propagate_up(level, mx, my);
  return ok ? TileResult::Tiled : TileResult::Failed;
}

bool HierTiler::box_visible(const ConvexPoly& poly) {
  // The witness inside the box: visible. Most subtree tests are of a node's near child, with nothing
  // tiled since its parent's (2CylinderEngine, one band: 320x240 63.65 M -> 62.45 M a frame).
  if (kWitness && witness_reached(poly)) return true;
  bx0_ = poly.min_x;
  by0_ = poly.min_y;
  bx1_ = poly.max_x;
  by1_ = poly.max_y;
  int level, mx, my;
  return start_cell(poly, &level, &mx, &my);
}

bool HierTiler::visible(const ConvexPoly& poly) {
  bx0_ = poly.min_x;
  by0_ = poly.min_y;
  bx1_ = poly.max_x;
  by1_ = poly.max_y;
  int level, mx, my;
  if (!start_cell(poly, &level, &mx, &my)) return false;
  Edges edges;
  edges_at_cell(poly, level, mx, my, &edges);
  return query_cell(level, mx, my, edges);
}

bool polygon_mask(const ConvexPoly& poly, int64_t x0, int64_t y0, int64_t side, TriageMask* out) {
  HierTiler::Edges in, crossing;
  in.n = poly.n;
  for (int i = 0; i < poly.n; ++i) {
    in.a[i] = poly.edge[i].a;
    in.b[i] = poly.edge[i].b;
    in.e[i] = poly.edge[i].at(x0, y0);
  }
  return HierTiler::edges_mask(in, side, &crossing, &out->c, &out->v);
}

bool HierTiler::background_cell(int level, int mx, int my, CoverageWriter& writer) {
  const PyramidLayout& lay = pyr_->layout;
  const int s = lay.shift(level);
  if (level == lay.finest()) {
    uint64_t& b = pyr_->block(mx, my);
    const uint64_t w = ~b;
    b = kAll;
    return w == 0 || writer.write_block(w, mx << s, my << s);
  }
  TriageMask& m = pyr_->mask(level, mx, my);
  if (m.v != 0 && !emit_mask(m.v, mx << s, my << s, 1 << (s - 3), writer)) return false;
  uint64_t a = ~(m.c | m.v);
  while (a != 0) {
    const int bit = __builtin_ctzll(a);
    a &= a - 1;
    if (!background_cell(level + 1, mx * 8 + (bit & 7), my * 8 + (bit >> 3), writer)) return false;
  }
  m.c = kAll;
  m.v = 0;
  return true;
}

bool HierTiler::background(CoverageWriter& writer) {
  if (kWitness) forget_witness();
  if (kKeptParent) forget_parent();
  return background_cell(0, 0, 0, writer);
}

}  // namespace ml

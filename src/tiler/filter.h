// The tiler's cosine-hump filter (Greene, SIGGRAPH '96 section 5): an antialiased pixel is the
// weighted sum of the samples of the 3 x 3 pixels around it, weights from tables/filter_tables.h
// (one pixel in radius, summing to exactly kFilterWeightOne). Samples arrive front to back, each
// once, as masks of newly covered samples of one source pixel in one colour; each mask adds, for
// each of the nine destination pixels around its source, the colour times the mask's weight (eight
// byte look-ups). A destination leaves, packed once, when its weights reach the whole kernel: every
// sample that counts for it is covered. Frame edges: the kernel keeps only on-screen samples and is
// normalised by their weight (one 32-bit division a border pixel).
//
// Bands: a band is tiled with the top half of the next band's first row below it (the halo: the
// samples within one pixel of its last row's centres), whose samples count only for the band's own
// pixels; what the band's own samples give the next band's first row is summed in a carry row that
// becomes that row's start. So every sample counts once for every pixel, whatever the band height,
// and the next band needs nothing above it.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "core/band.h"
#include "core/fixed.h"
#include "tables/filter_tables.h"
#include "core/stats.h"

namespace ml {

// The k x k samples at the top-left corner of an 8 x 8-sample mask (row r in bits 8r..8r+7; k = 1, 2,
// 4 or 8): one pixel's samples at k samples a pixel per axis, shifted to each pixel of the block.
constexpr uint64_t corner_samples(int k) {
  return ((uint64_t(1) << k) - 1) * (0x0101010101010101u >> (8 * (8 - k)));
}
static_assert(corner_samples(8) == ~uint64_t(0) && corner_samples(2) == 0x303u, "corner_samples");

// A destination pixel's running sums: colour channels times weights (< 255 * 2^16) and the weight
// so far. Border pixels start at the weight their off-screen neighbours would have given.
struct FilterSum {
  uint32_t r, g, b, weight;
};

// The colours of the samples being handed over: the piece being tiled, or the background.
class SourceColours {
 public:
  // True (and *c) when every sample has one colour.
  virtual bool flat(Pixel* c) = 0;
  // The colour of the samples of frame pixel (px, py).
  virtual Pixel colour_at(int px, int py) = 0;

 protected:
  ~SourceColours() = default;
};

// What the tiler's band writer hands newly covered samples to when a filter wider than the box makes
// the pixels (the cosine-hump filter below). An interface, so an image whose entry never makes one
// links none of its code or tables (render_tiler_box).
class SampleFilter {
 public:
  // sums: sums_count(width, band_rows) entries; width, height: the frame's pixels; f samples a pixel
  // per axis.
  virtual void init(FilterSum* sums, int width, int height, int f, int band_rows, BandOutput* out, Stats* stats) = 0;
  // The band's own rows [top, top + rows), tiled with the halo below them (sample row 0 is the top of
  // pixel row `top`).
  virtual void begin_band(int top, int rows) = 0;
  // Newly covered band samples: the rectangle [x, x + w) x [y, y + h), or the set bits of the 8 x 8
  // block at (x, y) (bit = row * 8 + col).
  virtual void add_samples(int x, int y, int w, int h, SourceColours& colours) = 0;
  virtual void add_block(uint64_t mask, int x, int y, SourceColours& colours) = 0;
  // The band's samples are all covered, with its halo: its own rows' pixels leave.
  virtual void end_band() = 0;

 protected:
  ~SampleFilter() = default;
};


class CosineFilter final : public SampleFilter {
 public:
  // Sums for bands of at most band_rows rows: the band's and the carry row.
  static size_t sums_count(int width, int band_rows) { return size_t(width) * size_t(band_rows + 1); }

  void init(FilterSum* sums, int width, int height, int f, int band_rows, BandOutput* out, Stats* stats) override;
  // The first row starts from the carry of the band above.
  void begin_band(int top, int rows) override;
  // Whole pixels of one colour as one rectangle, of varying colour one by one, partial pixels (the
  // halo's half row, blocks smaller than a pixel) as masks.
  void add_samples(int x, int y, int w, int h, SourceColours& colours) override;
  void add_block(uint64_t mask, int x, int y, SourceColours& colours) override;
  // Each pixel of the band's own rows whose weight is complete (every one but those add_flat_rect
  // wrote at once) leaves, packed once, a run of a row at a time (a one-pixel fill as each pixel's
  // weight came cost about 100 instructions a pixel).
  void end_band() override;

  // The samples of source pixel (px, py) set in `mask` (8 x 8 samples, bit = row * 8 + col) are
  // newly covered, in colour c.
  void add(int px, int py, uint64_t mask, Pixel c);
  // Pixels [x, x + w) x [y, y + h) of the band's own rows newly covered whole, in colour c: pixels
  // whose whole neighbourhood lies inside leave at once (none of their samples counted before, so
  // they are exactly c).
  void add_flat_rect(int x, int y, int w, int h, Pixel c);

  // Spreads an f x f sample mask of a pixel (bit = row * 8 + col, row and col < f) over the 8 x 8
  // samples of the tables: each sample stands for the (8 / f)^2 table samples of its area.
  static uint64_t expand(uint64_t mask, int f);

 private:
  struct Channels {
    uint32_t r, g, b;
  };
  static Channels channels(Pixel c) { return Channels{(c >> 16) & 0xFFu, (c >> 8) & 0xFFu, c & 0xFFu}; }
  // The sums of destination row py: a row of the band, or the carry row below it.
  FilterSum* row_at(int py) const {
    const int row = py - top_ < rows_ ? py - top_ : carry_;
    return sums_ + size_t(row) * size_t(width_);
  }
  // Destination rows a source row counts for: [top_, end): the carry row only for the band's own rows.
  int rows_end(int source_y) const { return min_of(top_ + rows_ + (source_y < top_ + rows_), height_); }
  // Weight w of colour ch for destination pixel s (it leaves at the band's end, end_band).
  static void add_weight(FilterSum& s, uint32_t w, const Channels& ch) {
    s.r += ch.r * w;
    s.g += ch.g * w;
    s.b += ch.b * w;
    s.weight += w;
  }
  // The colour of pixel (px, py), its weight complete.
  Pixel mean(const FilterSum& s, int px, int py) const;
  void start_row(int row, int py);
  // Weight of all on-screen samples around (px, py): kFilterWeightOne except at the frame's edges.
  uint32_t full_weight(int px, int py) const;
  bool on_border(int px, int py) const { return px == 0 || py == 0 || px == width_ - 1 || py == height_ - 1; }

  FilterSum* sums_ = nullptr;
  int width_ = 0, height_ = 0, top_ = 0, rows_ = 0;
  int f_ = 8;  // samples a pixel per axis
  int carry_ = 0;  // index of the carry row in sums_ (after the largest band's rows)
  BandOutput* out_ = nullptr;
  Stats* stats_ = nullptr;
};

}  // namespace ml

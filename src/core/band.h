// Band output: the renderers' side of the Sink contract (core/sink.h). Owns the band buffers (from
// the arena), packs pixels into the current band, flushes finished bands to the sink, and waits for
// a lent buffer before writing into it again. Both renderers render band by band, top to bottom.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "core/arena.h"
#include "core/options.h"
#include "core/pixel_format.h"
#include "core/sink.h"
#include "core/stats.h"
#include "core/status.h"

namespace ml {

// The band height render() uses for a frame: options.band_rows (0 = the whole frame), at most the
// frame height, rounded up to the format's row unit (Mono1 pages).
int band_rows_for(const OutputOptions& output, int height);

// The rows a renderer renders at once when it asks for `render_rows` (0: one band): whole bands,
// at least one, at most the frame's.
int render_rows_for(const OutputOptions& output, int height, int render_rows);
// The most rows the options let a renderer render at once (OutputOptions::render_rows, whole bands).
int render_rows_allowed(const OutputOptions& output, int height);

// Render bands of several bands on 64-bit hosts only: a board's RAM goes to the least arena, and its
// flash (the m0plus image is within a few hundred bytes of its budget) to other code.
constexpr bool kRenderBands = sizeof(void*) >= 8;

// Render bands: a renderer with arena to spare may render several bands at once (render_rows, the
// tiler: its per-band work is then done once for all of them). They are rendered into one buffer of
// that many rows, and each band of it is lent to the sink in place, top to bottom, as it would be
// from a buffer of its own; the sink sees the same bands either way. The next render band waits
// until every band of the last one is given back.
class BandOutput {
 public:
  // Arena bytes begin() takes at most (render_rows as begin's).
  static size_t arena_bytes(const OutputOptions& output, int width, int height, int render_rows = 0);
  // InvalidArgument for options that cannot work (buffers outside 1..kMaxBandBuffers, negative rows).
  static Status check(const OutputOptions& output);

  // Takes the band buffers from the arena (check arena_bytes first) and begins the frame.
  // render_rows: the rows rendered at once (render_rows_for; 0: one band at a time).
  Status begin(const OutputOptions& output, int width, int height, Arena& arena, Sink& sink, int render_rows = 0);

  // The render bands (one sink band each unless begin was given more render rows).
  int band_rows() const { return render_rows_; }
  // Whether a render band holds several of the sink's bands (one buffer, lent a band at a time).
  bool several() const { return kRenderBands && render_rows_ > band_rows_; }
  int band_count() const { return (height_ + render_rows_ - 1) / render_rows_; }
  int band_top(int band) const { return band * render_rows_; }
  int band_height(int band) const { return rows_from(band_top(band), render_rows_); }
  // The sink's bands in render band `band`.
  int sink_bands_in(int band) const { return several() ? (band_height(band) + band_rows_ - 1) / band_rows_ : 1; }

  // Makes the next buffer current for render band `band` (waiting for the sink to give it back).
  Status start_band(int band);
  // Pixel writes into the current band, in frame coordinates; each pixel of the band exactly once.
  void put_row(int x, int y, const Pixel* pixels, int n) {
    packer_.put_row(current_, stride_, x, y - top_, y, pixels, n);
  }
  // The pixels x of frame row y (0 <= x < width) for which has(x), each colour(x), put a run at a time
  // through `buffer` (of `capacity` pixels); returns how many. For the antialiasing filters' pixels,
  // which leave at the band's end but for those written whole before.
  template <class Has, class Colour>
  [[gnu::always_inline]] uint32_t put_row_runs(int y, int width, Pixel* buffer, int capacity, Has has, Colour colour) {
    uint32_t put = 0;
    for (int x = 0; x < width;) {
      if (!has(x)) {
        ++x;
        continue;
      }
      const int start = x;  // a run: pixels start .. x - 1
      for (; x < width && x - start < capacity && has(x); ++x) buffer[x - start] = colour(x);
      put_row(start, y, buffer, x - start);
      put += uint32_t(x - start);
    }
    return put;
  }
  void fill(int x, int y, int w, int h, Pixel value) {
    packer_.fill(current_, stride_, x, y - top_, y, w, h, value);
  }
  // The set bits of an 8x8 mask at (x, y): how many, or -1 when the format needs them run by run
  // (PixelPacker::fill_mask).
  bool mask_value_ready(Pixel value) const { return packer_.mask_value_ready(value); }
  ML_HOST_INLINE int fill_mask(uint64_t mask, int x, int y, Pixel value) {
    return packer_.fill_mask(current_, stride_, x, y - top_, mask, value);
  }
  // The set bits of an 8x8 mask at (x, y), pixels[8 r + c] for pixel (x + c, y + r)
  // (PixelPacker::put_mask); false when the format needs them run by run.
  bool put_mask(uint64_t mask, int x, int y, const Pixel* pixels) {
    return packer_.put_mask(current_, stride_, x, y - top_, mask, pixels);
  }
  // Pixel (x, y) in the band for writing colours directly, rows *pixel_stride apart; null when the
  // format does not store them as they are (PixelPacker::pixels_at).
  Pixel* pixels_at(int x, int y, uint32_t* pixel_stride) {
    return packer_.pixels_at(current_, stride_, x, y - top_, pixel_stride);
  }
  // Hands the finished render band to the sink, a band at a time.
  Status finish_band();
  // Waits until no buffer is lent, then ends the frame.
  Status end();

 private:
  Status wait_for(int buffer);
  // Lends the sink `rows` rows of the frame from row y, at bytes, as buffer `buffer`.
  Status flush(int y, int rows, uint8_t* bytes, int buffer);
  // Rows of a band of at most `rows` rows from frame row `top`.
  int rows_from(int top, int rows) const { return height_ - top < rows ? height_ - top : rows; }

  Sink* sink_ = nullptr;
  PixelPacker packer_;
  PixelFormat format_ = PixelFormat::Xrgb8888;
  int width_ = 0, height_ = 0, band_rows_ = 1, render_rows_ = 1, buffers_ = 1;
  uint32_t stride_ = 0;
  uint8_t* buffer_[kMaxBandBuffers] = {};
  uint8_t* current_ = nullptr;
  int current_index_ = 0, band_ = 0, top_ = 0;
};

}  // namespace ml

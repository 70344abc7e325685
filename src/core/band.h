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

class BandOutput {
 public:
  // Arena bytes init() takes at most.
  static size_t arena_bytes(const OutputOptions& output, int width, int height);
  // InvalidArgument for options that cannot work (buffers outside 1..kMaxBandBuffers, negative rows).
  static Status check(const OutputOptions& output);

  // Takes the band buffers from the arena (check arena_bytes first) and begins the frame.
  Status begin(const OutputOptions& output, int width, int height, Arena& arena, Sink& sink);

  int band_rows() const { return band_rows_; }
  int band_count() const { return (height_ + band_rows_ - 1) / band_rows_; }
  int band_top(int band) const { return band * band_rows_; }
  int band_height(int band) const {
    const int rest = height_ - band * band_rows_;
    return rest < band_rows_ ? rest : band_rows_;
  }

  // Makes the next buffer current for band `band` (waiting for the sink to give it back).
  Status start_band(int band);
  // Pixel writes into the current band, in frame coordinates; each pixel of the band exactly once.
  void put_row(int x, int y, const Pixel* pixels, int n) {
    packer_.put_row(current_, stride_, x, y - top_, y, pixels, n);
  }
  void fill(int x, int y, int w, int h, Pixel value) {
    packer_.fill(current_, stride_, x, y - top_, y, w, h, value);
  }
  // The set bits of an 8x8 mask at (x, y) (PixelPacker::fill_mask).
  void fill_mask(uint64_t mask, int x, int y, Pixel value) {
    packer_.fill_mask(current_, stride_, x, y - top_, y, mask, value);
  }
  // Hands the finished band to the sink.
  Status finish_band();
  // Waits until no buffer is lent, then ends the frame.
  Status end();

 private:
  Status wait_for(int buffer);

  Sink* sink_ = nullptr;
  PixelPacker packer_;
  int width_ = 0, height_ = 0, band_rows_ = 1, buffers_ = 1;
  uint32_t stride_ = 0;
  uint8_t* buffer_[kMaxBandBuffers] = {};
  uint8_t* current_ = nullptr;
  int current_index_ = 0, band_ = 0, top_ = 0;
};

}  // namespace ml

// The fuzzers' sink: checks the band contract (core/sink.h) on XRGB8888 frames — bands top to
// bottom, full width, each once — and that no pixel is left unwritten. Unwritten pixels show as
// poison: the caller fills the arena with kPoison, every band is poisoned again after it is read, and
// a written pixel's top byte is 0. Any breach aborts (a finding).
#pragma once
#include <stdlib.h>
#include <string.h>

#include <algorithm>

#include "core/sink.h"

namespace fuzz {

constexpr uint8_t kPoison = 0xA5;

class CheckingSink : public ml::Sink {
 public:
  bool begin_frame(const ml::FrameInfo& frame) override {
    if (frame.format != ml::PixelFormat::Xrgb8888 || frame.band_rows < 1) abort();
    frame_ = frame;
    next_row_ = 0;
    return true;
  }
  bool flush(const ml::Flush& band) override {
    const int rows = std::min(frame_.band_rows, frame_.height - next_row_);
    if (band.x != 0 || band.y != next_row_ || band.width != frame_.width || band.height != rows) abort();
    for (int r = 0; r < band.height; ++r)
      for (int x = 0; x < band.width; ++x)
        if (band.bytes[size_t(r) * band.stride + size_t(x) * 4 + 3] != 0) abort();  // never written
    memset(const_cast<uint8_t*>(band.bytes), kPoison, size_t(band.stride) * size_t(band.height));
    next_row_ += rows;
    flush_ready(band.buffer);
    return true;
  }
  bool end_frame() override {
    if (next_row_ != frame_.height) abort();
    return true;
  }

 private:
  ml::FrameInfo frame_;
  int next_row_ = 0;
};

}  // namespace fuzz

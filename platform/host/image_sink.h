// In-memory image sink that checks the Sink contract (core/sink.h): begin_frame once, every pixel of
// the screen written exactly once, then end_frame. The CLI renders into it before writing PNGs; tests
// use it to check renderers. Violations are recorded (first one kept as a message) and, in strict
// mode, also refused so the render aborts with SinkFailed.
#pragma once
#include <stdint.h>

#include <string>
#include <vector>

#include "core/sink.h"

namespace mlhost {

class ImageSink : public ml::Sink {
 public:
  explicit ImageSink(bool strict = false) : strict_(strict) {}

  bool begin_frame(int width, int height) override;
  bool write_block(int x, int y, int w, int h, const ml::Pixel* pixels, int stride) override;
  bool fill_block(int x, int y, int w, int h, ml::Pixel value) override;
  bool end_frame() override;

  // True when the frame was begun and ended once and every pixel written exactly once.
  bool contract_ok() const { return error_.empty() && ended_ && unwritten_ == 0 && overwritten_ == 0; }
  // First violation, or why contract_ok() is false ("" when it holds).
  std::string contract_error() const;

  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<ml::Pixel>& pixels() const { return pixels_; }
  ml::Pixel at(int x, int y) const { return pixels_[size_t(y) * size_t(width_) + size_t(x)]; }
  // Times pixel (x, y) was written (1 when the contract holds).
  uint8_t writes_at(int x, int y) const { return writes_[size_t(y) * size_t(width_) + size_t(x)]; }

  uint64_t pixel_writes() const { return pixel_writes_; }
  uint64_t calls() const { return calls_; }
  // Whether every call so far was a whole row (x == 0, w == width, h == 1) arriving top to bottom.
  bool rows_in_order() const { return rows_in_order_; }

 private:
  bool record(int x, int y, int w, int h);
  void fail(const std::string& message);

  bool strict_;
  int width_ = 0, height_ = 0;
  std::vector<ml::Pixel> pixels_;
  std::vector<uint8_t> writes_;  // saturating count per pixel
  uint64_t pixel_writes_ = 0, calls_ = 0;
  uint64_t unwritten_ = 0, overwritten_ = 0;
  int begins_ = 0;
  bool ended_ = false;
  bool rows_in_order_ = true;
  int next_row_ = 0;
  std::string error_;
};

}  // namespace mlhost

#include "platform/host/image_sink.h"

#include <stddef.h>

namespace mlhost {

void ImageSink::fail(const std::string& message) {
  if (error_.empty()) error_ = message;
}

bool ImageSink::begin_frame(int width, int height) {
  ++begins_;
  if (begins_ > 1) {
    fail("begin_frame called twice");
    return !strict_;
  }
  if (width <= 0 || height <= 0) {
    fail("begin_frame with an empty screen");
    return false;
  }
  width_ = width;
  height_ = height;
  const size_t n = size_t(width) * size_t(height);
  pixels_.assign(n, 0);
  writes_.assign(n, 0);
  unwritten_ = n;
  return true;
}

bool ImageSink::record(int x, int y, int w, int h) {
  ++calls_;
  if (begins_ != 1 || ended_) {
    fail(begins_ == 0 ? "write before begin_frame" : "write after end_frame");
    return false;
  }
  if (w <= 0 || h <= 0 || x < 0 || y < 0 || x > width_ - w || y > height_ - h) {
    fail("block " + std::to_string(w) + "x" + std::to_string(h) + " at (" + std::to_string(x) + "," +
         std::to_string(y) + ") outside the " + std::to_string(width_) + "x" + std::to_string(height_) +
         " screen");
    return false;
  }
  if (rows_in_order_) {
    if (x == 0 && w == width_ && h == 1 && y == next_row_) {
      ++next_row_;
    } else {
      rows_in_order_ = false;
    }
  }
  bool ok = true;
  for (int j = y; j < y + h; ++j) {
    for (int i = x; i < x + w; ++i) {
      uint8_t& c = writes_[size_t(j) * size_t(width_) + size_t(i)];
      if (c == 0) {
        --unwritten_;
      } else {
        if (c == 1) ++overwritten_;
        fail("pixel (" + std::to_string(i) + "," + std::to_string(j) + ") written twice");
        ok = false;
      }
      if (c < 255) ++c;
    }
  }
  pixel_writes_ += uint64_t(w) * uint64_t(h);
  return ok || !strict_;
}

bool ImageSink::write_block(int x, int y, int w, int h, const ml::Pixel* pixels, int stride) {
  if (!record(x, y, w, h)) return false;
  if (w <= 0 || h <= 0 || x < 0 || y < 0 || x > width_ - w || y > height_ - h) return true;
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      pixels_[size_t(y + j) * size_t(width_) + size_t(x + i)] = pixels[size_t(j) * size_t(stride) + size_t(i)];
    }
  }
  return true;
}

bool ImageSink::fill_block(int x, int y, int w, int h, ml::Pixel value) {
  if (!record(x, y, w, h)) return false;
  if (w <= 0 || h <= 0 || x < 0 || y < 0 || x > width_ - w || y > height_ - h) return true;
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) pixels_[size_t(y + j) * size_t(width_) + size_t(x + i)] = value;
  }
  return true;
}

bool ImageSink::end_frame() {
  if (begins_ != 1 || ended_) {
    fail(ended_ ? "end_frame called twice" : "end_frame without begin_frame");
    return !strict_;
  }
  ended_ = true;
  if (unwritten_ != 0) {
    fail(std::to_string(unwritten_) + " pixel(s) never written");
    return !strict_;
  }
  return true;
}

std::string ImageSink::contract_error() const {
  if (!error_.empty()) return error_;
  if (begins_ == 0) return "frame never begun";
  if (!ended_) return "end_frame never called";
  if (unwritten_ != 0) return std::to_string(unwritten_) + " pixel(s) never written";
  if (overwritten_ != 0) return std::to_string(overwritten_) + " pixel(s) written more than once";
  return "";
}

}  // namespace mlhost

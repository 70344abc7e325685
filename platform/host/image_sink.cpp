#include "platform/host/image_sink.h"

#include <stddef.h>
#include <string.h>

#include "core/pixel_format.h"

namespace mlhost {

namespace {

std::string rect(const ml::Flush& b) {
  return std::to_string(b.width) + "x" + std::to_string(b.height) + " at (" + std::to_string(b.x) + "," +
         std::to_string(b.y) + ")";
}

// Whether a stored value is the poison the sink left in a lent buffer (a pixel never written).
bool is_poison(ml::PixelFormat format, const uint8_t* band, uint32_t stride, int x, int row) {
  if (format == ml::PixelFormat::Id32)
    return ml::load_pixel(format, band, stride, x, row) == 0xA5A5A5A5u;
  if (format == ml::PixelFormat::Xrgb8888) return band[uint32_t(row) * stride + uint32_t(x) * 4 + 3] == kPoisonByte;
  return false;
}

}  // namespace

std::string BandContract::begin(const ml::FrameInfo& frame) {
  if (begun_) return "begin_frame called twice";
  begun_ = true;
  frame_ = frame;
  if (frame.width <= 0 || frame.height <= 0) return "begin_frame with an empty screen";
  if (frame.band_rows <= 0) return "begin_frame with bands of no rows";
  if (frame.buffers < 1 || frame.buffers > ml::kMaxBandBuffers) return "begin_frame with a bad buffer count";
  return "";
}

std::string BandContract::check(const ml::Flush& b) {
  if (!begun_) return "flush before begin_frame";
  if (ended_) return "flush after end_frame";
  const int rows = frame_.height - next_row_ < frame_.band_rows ? frame_.height - next_row_ : frame_.band_rows;
  if (next_row_ >= frame_.height) return "band " + rect(b) + " after the last row";
  if (b.x != 0 || b.width != frame_.width || b.y != next_row_ || b.height != rows)
    return "band " + rect(b) + " where the next band is " + std::to_string(frame_.width) + "x" +
           std::to_string(rows) + " at (0," + std::to_string(next_row_) + ")";
  if (b.bytes == nullptr || b.stride < ml::format_stride(frame_.format, frame_.width))
    return "band " + rect(b) + " with a short stride or no bytes";
  next_row_ += rows;
  return "";
}

std::string BandContract::end() const {
  if (!begun_) return "end_frame without begin_frame";
  if (next_row_ != frame_.height)
    return std::to_string(frame_.height - next_row_) + " row(s) never flushed";
  return "";
}

void ImageSink::fail(const std::string& message) {
  if (error_.empty()) error_ = message;
}

bool ImageSink::begin_frame(const ml::FrameInfo& frame) {
  ++begins_;
  const std::string e = contract_.begin(frame);
  if (!e.empty()) {
    fail(e);
    return begins_ == 1 && frame.width > 0 && frame.height > 0 ? !strict_ : false;
  }
  frame_ = frame;
  const size_t n = size_t(frame.width) * size_t(frame.height);
  pixels_.assign(n, 0);
  stored_.assign(n, 0);
  writes_.assign(n, 0);
  unwritten_ = n;
  return true;
}

bool ImageSink::flush(const ml::Flush& b) {
  ++flushes_;
  const std::string e = contract_.check(b);
  if (!e.empty()) {
    fail(e);
    flush_ready(b.buffer);
    return false;
  }
  for (int r = 0; r < b.height; ++r)
    for (int x = 0; x < b.width; ++x) {
      const size_t at = size_t(b.y + r) * size_t(frame_.width) + size_t(x);
      if (is_poison(frame_.format, b.bytes, b.stride, x, r)) {
        fail("pixel (" + std::to_string(x) + "," + std::to_string(b.y + r) + ") never written");
        continue;
      }
      stored_[at] = ml::load_pixel(frame_.format, b.bytes, b.stride, x, r);
      pixels_[at] = ml::expand_stored(frame_.format, stored_[at]);
      if (writes_[at]++ == 0) --unwritten_;
    }
  pixel_writes_ += uint64_t(b.width) * uint64_t(b.height);
  counters.bytes += uint64_t(ml::format_band_bytes(frame_.format, b.width, b.height));  // no windows: memory
  // The bytes are ours until flush_ready: poison them so a pixel skipped next time shows.
  const int unit = ml::format_row_unit(frame_.format);
  memset(const_cast<uint8_t*>(b.bytes), kPoisonByte, size_t(b.stride) * size_t((b.height + unit - 1) / unit));
  flush_ready(b.buffer);
  return error_.empty() || !strict_;
}

bool ImageSink::end_frame() {
  if (ended_) {
    fail("end_frame called twice");
    return !strict_;
  }
  ended_ = true;
  const std::string e = contract_.end();
  if (!e.empty()) {
    fail(e);
    return !strict_;
  }
  for (int i = 0; i < ml::kMaxBandBuffers; ++i)
    if (lent(i)) fail("end_frame with a buffer still lent");
  return error_.empty() || !strict_;
}

std::string ImageSink::contract_error() const {
  if (!error_.empty()) return error_;
  if (begins_ == 0) return "frame never begun";
  if (!ended_) return "end_frame never called";
  if (unwritten_ != 0) return std::to_string(unwritten_) + " pixel(s) never written";
  return "";
}

}  // namespace mlhost

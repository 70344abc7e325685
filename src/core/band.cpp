#include "core/band.h"

namespace ml {

namespace {

constexpr size_t kBandAlign = 4;  // Id32 and Xrgb8888 rows are read as 32-bit words

Status sink_error(const char* message) { return error(StatusCode::SinkFailed, message); }

}  // namespace

int band_rows_for(const OutputOptions& output, int height) {
  int rows = output.band_rows <= 0 || output.band_rows > height ? height : output.band_rows;
  const int unit = format_row_unit(output.format);
  rows = (rows + unit - 1) / unit * unit;
  return rows < 1 ? 1 : rows;
}

Status BandOutput::check(const OutputOptions& output) {
  if (output.buffers < 1 || output.buffers > kMaxBandBuffers)
    return error(StatusCode::InvalidArgument, "band buffers must be 1 or 2");
  if (output.band_rows < 0) return error(StatusCode::InvalidArgument, "band rows must not be negative");
  return ok_status();
}

size_t BandOutput::arena_bytes(const OutputOptions& output, int width, int height) {
  if (width < 1 || height < 1) return 0;
  const int buffers = output.buffers < 1 ? 1 : (output.buffers > kMaxBandBuffers ? kMaxBandBuffers : output.buffers);
  return size_t(buffers) *
         arena_worst_case(format_band_bytes(output.format, width, band_rows_for(output, height)), kBandAlign);
}

Status BandOutput::begin(const OutputOptions& output, int width, int height, Arena& arena, Sink& sink) {
  sink_ = &sink;
  width_ = width;
  height_ = height;
  band_rows_ = band_rows_for(output, height);
  buffers_ = output.buffers;
  stride_ = format_stride(output.format, width);
  packer_.init(output.format, output.dither);
  const uint32_t bytes = format_band_bytes(output.format, width, band_rows_);
  for (int i = 0; i < buffers_; ++i) {
    buffer_[i] = static_cast<uint8_t*>(arena.allocate(bytes, kBandAlign));
    if (!buffer_[i]) return error(StatusCode::ArenaTooSmall, "arena too small for the band buffers");
    sink.flush_ready(i);
  }
  current_index_ = buffers_ - 1;  // start_band(0) moves to buffer 0
  FrameInfo frame;
  frame.width = width;
  frame.height = height;
  frame.format = output.format;
  frame.band_rows = band_rows_;
  frame.buffers = buffers_;
  sink.counters = DisplayCounters{};
  if (!sink.begin_frame(frame)) return sink_error("the display refused the frame");
  return ok_status();
}

Status BandOutput::wait_for(int buffer) {
  while (sink_->lent(buffer))
    if (!sink_->wait_for_flush()) return sink_error("the display never gave a band buffer back");
  return ok_status();
}

Status BandOutput::start_band(int band) {
  current_index_ = (current_index_ + 1) % buffers_;
  const Status s = wait_for(current_index_);
  if (!s.ok()) return s;
  current_ = buffer_[current_index_];
  band_ = band;
  top_ = band_top(band);
  return ok_status();
}

Status BandOutput::finish_band() {
  Flush f;
  f.x = 0;
  f.y = top_;
  f.width = width_;
  f.height = band_height(band_);
  f.stride = stride_;
  f.bytes = current_;
  f.buffer = current_index_;
  sink_->lend(current_index_);
  if (!sink_->flush(f)) {
    sink_->flush_ready(current_index_);
    return sink_error("the display refused a band");
  }
  return ok_status();
}

Status BandOutput::end() {
  for (int i = 0; i < buffers_; ++i) {
    const Status s = wait_for(i);
    if (!s.ok()) return s;
  }
  if (!sink_->end_frame()) return sink_error("the display refused the frame end");
  return ok_status();
}

}  // namespace ml

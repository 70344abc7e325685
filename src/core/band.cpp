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

int render_rows_for(const OutputOptions& output, int height, int render_rows) {
  const int rows = band_rows_for(output, height);
  if (render_rows <= rows) return rows;
  const int bands = (height + rows - 1) / rows;
  const int wanted = render_rows / rows + (render_rows % rows != 0);  // no overflow near INT_MAX
  return (wanted < bands ? wanted : bands) * rows;
}

int render_rows_allowed(const OutputOptions& output, int height) {
  const int wanted = output.render_rows > 0 ? output.render_rows : output.buffers > 1 ? 0 : height;
  return render_rows_for(output, height, wanted);
}

Status BandOutput::check(const OutputOptions& output) {
  if (output.buffers < 1 || output.buffers > kMaxBandBuffers)
    return error(StatusCode::InvalidArgument, "band buffers must be 1 or 2");
  if (output.band_rows < 0) return error(StatusCode::InvalidArgument, "band rows must not be negative");
  if (output.render_rows < 0) return error(StatusCode::InvalidArgument, "render rows must not be negative");
  return ok_status();
}

size_t BandOutput::arena_bytes(const OutputOptions& output, int width, int height, int render_rows) {
  if (width < 1 || height < 1) return 0;
  const int rows = band_rows_for(output, height), render = kRenderBands ? render_rows_for(output, height, render_rows) : rows;
  // Render bands of several bands: one buffer of the render rows (at most the frame's).
  if (render > rows) return arena_worst_case(format_band_bytes(output.format, width, render < height ? render : height), kBandAlign);
  const int buffers = output.buffers < 1 ? 1 : (output.buffers > kMaxBandBuffers ? kMaxBandBuffers : output.buffers);
  return size_t(buffers) * arena_worst_case(format_band_bytes(output.format, width, rows), kBandAlign);
}

Status BandOutput::begin(const OutputOptions& output, int width, int height, Arena& arena, Sink& sink,
                         int render_rows) {
  sink_ = &sink;
  format_ = output.format;
  width_ = width;
  height_ = height;
  band_rows_ = band_rows_for(output, height);
  render_rows_ = kRenderBands ? render_rows_for(output, height, render_rows) : band_rows_;
  buffers_ = output.buffers;
  stride_ = format_stride(output.format, width);
  packer_.init(output.format, output.dither);
  const uint32_t bytes = format_band_bytes(output.format, width, several() ? rows_from(0, render_rows_) : band_rows_);
  for (int i = 0; i < buffers_; ++i) {
    sink.flush_ready(i);
    if (several() && i > 0) continue;
    buffer_[i] = static_cast<uint8_t*>(arena.allocate(bytes, kBandAlign));
    if (!buffer_[i]) return error(StatusCode::ArenaTooSmall, "arena too small for the band buffers");
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
  band_ = band;
  top_ = band_top(band);
  if (several()) {  // the one buffer: every band of it back from the sink
    current_ = buffer_[0];
    for (int i = 0; i < buffers_; ++i) {
      const Status s = wait_for(i);
      if (!s.ok()) return s;
    }
    return ok_status();
  }
  current_index_ = (current_index_ + 1) % buffers_;
  const Status s = wait_for(current_index_);
  if (!s.ok()) return s;
  current_ = buffer_[current_index_];
  return ok_status();
}

Status BandOutput::finish_band() {
  if (!several()) return flush(top_, band_height(band_), current_, current_index_);
  // Each band of the render band in place, lent as the buffers in turn.
  const int end = top_ + band_height(band_);
  for (int y = top_; y < end; y += band_rows_) {
    current_index_ = (current_index_ + 1) % buffers_;
    Status s = wait_for(current_index_);
    if (s.ok()) s = flush(y, rows_from(y, band_rows_), current_ + format_band_bytes(format_, width_, y - top_), current_index_);
    if (!s.ok()) return s;
  }
  return ok_status();
}

Status BandOutput::flush(int y, int rows, uint8_t* bytes, int buffer) {
  Flush f;
  f.x = 0;
  f.y = y;
  f.width = width_;
  f.height = rows;
  f.stride = stride_;
  f.bytes = bytes;
  f.buffer = buffer;
  sink_->lend(buffer);
  if (!sink_->flush(f)) {
    sink_->flush_ready(buffer);
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

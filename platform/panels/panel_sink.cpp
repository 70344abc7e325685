#include "platform/panels/panel_sink.h"

#include "core/pixel_format.h"

namespace mlpanels {

bool PanelSink::init() {
  ml::DisplayCounters scratch;
  Bus bus(*transport_, max_transfer_, &scratch);
  const bool ok = panel_.init(bus);
  init_bytes_ = scratch.bytes;
  return ok ? true : fail("the panel did not take its init sequence");
}

bool PanelSink::begin_frame(const ml::FrameInfo& frame) {
  error_ = "";
  in_frame_ = false;
  if (frame.width != panel_.width() || frame.height != panel_.height())
    return fail("the frame size is not the panel's");
  if (frame.format != panel_.format()) return fail("the frame's pixel format is not the panel's");
  if (frame.band_rows < 1 || frame.band_rows % ml::format_row_unit(frame.format) != 0)
    return fail("band height does not suit the panel");
  in_frame_ = true;
  return true;
}

bool PanelSink::flush(const ml::Flush& band) {
  struct Release {  // the buffer goes back whatever happens: nothing keeps reading it
    PanelSink* sink;
    int buffer;
    ~Release() { sink->flush_ready(buffer); }
  } release{this, band.buffer};

  if (!in_frame_) return fail("flush outside a frame");
  if (!band.bytes) return fail("flush without bytes");
  const uint32_t row_bytes = panel_.row_bytes(band.width);
  if (band.stride < row_bytes) return fail("band stride shorter than a row");
  Bus bus(*transport_, max_transfer_, &counters);
  if (!panel_.begin_window(bus, band.x, band.y, band.width, band.height))
    return fail("the band does not fit the panel's addressing");
  const int rows = panel_.packed_rows(band.height);
  if (band.stride == row_bytes) {  // contiguous: one stream, chunked by the bus
    if (!bus.data(band.bytes, size_t(row_bytes) * size_t(rows))) return fail("the transport refused data");
    return true;
  }
  for (int r = 0; r < rows; ++r)
    if (!bus.data(band.bytes + size_t(r) * band.stride, row_bytes)) return fail("the transport refused data");
  return true;
}

bool PanelSink::end_frame() {
  if (!in_frame_) return fail("end of a frame that was not begun");
  in_frame_ = false;
  return true;
}

}  // namespace mlpanels

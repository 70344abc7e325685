// Helpers for the panel tests: every panel/rotation pair, a test pattern, and a driver that packs a
// frame into bands and flushes them into a sink the way the renderers do.
#pragma once
#include <stdint.h>

#include <algorithm>
#include <ostream>
#include <string>
#include <vector>

#include "core/pixel_format.h"
#include "core/sink.h"
#include "platform/host/panel_emulator.h"
#include "platform/panels/panel.h"

namespace panel_test {

struct PanelCase {
  const char* name;
  int rotation;
};

inline void PrintTo(const PanelCase& c, std::ostream* os) { *os << c.name << " at " << c.rotation; }

inline std::vector<PanelCase> all_cases() {
  std::vector<PanelCase> out;
  for (const char* name : {"ili9341", "st7789", "st7789-240"})
    for (int r : {0, 90, 180, 270}) out.push_back({name, r});
  for (const char* name : {"ssd1306", "ssd0323"})
    for (int r : {0, 180}) out.push_back({name, r});
  return out;
}

inline std::string case_name(const PanelCase& c) {
  std::string s = std::string(c.name) + "_r" + std::to_string(c.rotation);
  for (char& ch : s)
    if (ch == '-') ch = '_';
  return s;
}

// A pattern with distinct values along both axes, so any mirroring, transposition or offset shows.
inline std::vector<ml::Pixel> pattern(int w, int h, uint32_t seed = 0) {
  std::vector<ml::Pixel> p(size_t(w) * size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint32_t v = uint32_t(x) * 2654435761u ^ uint32_t(y) * 40503u ^ seed * 97u;
      v ^= v >> 13;
      const uint32_t r = (uint32_t(x) * 255 / uint32_t(w) + (v & 7)) & 255;
      const uint32_t g = (uint32_t(y) * 255 / uint32_t(h) + (v >> 5 & 15)) & 255;
      p[size_t(y) * size_t(w) + size_t(x)] = ml::rgb(r, g, v >> 11 & 255);
    }
  return p;
}

// What the panel should show for `image`: each pixel quantized to the format (no dither) and expanded.
inline std::vector<ml::Pixel> expected_picture(ml::PixelFormat f, const std::vector<ml::Pixel>& image, int w) {
  std::vector<ml::Pixel> out(image.size());
  for (size_t i = 0; i < image.size(); ++i)
    out[i] = ml::expand_stored(f, ml::quantize_pixel(f, image[i], false, int(i % size_t(w)), int(i / size_t(w))));
  return out;
}

// Packs `image` into bands of `band_rows` (stride = the packed row plus `pad` bytes) and sends the
// frame through `sink` as a renderer would. False as soon as the sink refuses.
inline bool send_frame(ml::Sink& sink, ml::PixelFormat f, const std::vector<ml::Pixel>& image, int w, int h,
                       int band_rows, uint32_t pad = 0) {
  ml::FrameInfo info;
  info.width = w;
  info.height = h;
  info.format = f;
  info.band_rows = band_rows;
  info.buffers = 1;
  sink.counters = ml::DisplayCounters{};
  if (!sink.begin_frame(info)) return false;
  ml::PixelPacker packer;
  packer.init(f, false);
  const uint32_t stride = ml::format_stride(f, w) + pad;
  const int unit = ml::format_row_unit(f);
  for (int top = 0; top < h; top += band_rows) {
    const int rows = h - top < band_rows ? h - top : band_rows;
    std::vector<uint8_t> band(size_t(stride) * size_t((rows + unit - 1) / unit), 0xA5);
    if (f == ml::PixelFormat::Mono1 || f == ml::PixelFormat::Grey4)
      std::fill(band.begin(), band.end(), 0);
    for (int r = 0; r < rows; ++r)
      packer.put_row(band.data(), stride, 0, r, top + r, &image[size_t(top + r) * size_t(w)], w);
    ml::Flush fl;
    fl.x = 0;
    fl.y = top;
    fl.width = w;
    fl.height = rows;
    fl.stride = stride;
    fl.bytes = band.data();
    fl.buffer = 0;
    sink.lend(0);
    if (!sink.flush(fl)) return false;
    if (sink.lent(0)) return false;  // a synchronous sink gives the buffer back inside flush()
  }
  return sink.end_frame();
}

// Bytes of one address window on the bus: CASET(1+4) RASET(1+4) RAMWR(1); SSD 3 + 3.
inline uint64_t window_bytes(const mlpanels::Panel& p) {
  return p.format() == ml::PixelFormat::Rgb565Be ? 11 : 6;
}

inline int bits_per_pixel(ml::PixelFormat f) { return ml::format_bits_per_pixel(f); }

}  // namespace panel_test

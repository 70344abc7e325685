// The Sink: the display seam. Where finished pixels go: an SPI panel, a Linux framebuffer, a PNG
// file, an in-memory image. The shape is Zephyr's display_write(x, y, desc, buf) with LVGL's
// flush_cb + lv_display_flush_ready: the caller states the display's pixel format (OutputOptions in
// core/options.h), the renderer packs every pixel once, in that format, into band buffers lent from
// the arena, and hands each finished band to the sink as one rectangle of bytes.
//
// Frame contract (both renderers):
//   begin_frame(frame) once; then flush() of consecutive bands top to bottom, each the full frame
//   width and `band_rows` rows high (the last band may be lower), so every pixel leaves exactly once
//   and a panel needs one address window per band; then end_frame() once, after every lent buffer
//   has been given back. A sink returning false aborts the render with StatusCode::SinkFailed (then
//   end_frame is not called; the sink may have shown part of the frame).
//
// Buffer lending: the bytes of a flush belong to the sink from the flush() call until the sink calls
// flush_ready(f.buffer): inside flush() (a synchronous sink: copy or send, then release) or later,
// from a DMA-complete interrupt. The renderer renders the next band into the other buffer meanwhile
// (two buffers when the arena allows; the tiler rendering several bands at once into one buffer lends
// them in place and renders nothing until all are back, core/band.h) and writes into a lent buffer
// again only after its release;
// while it waits it calls wait_for_flush(). render() returns only when no buffer is lent.
#pragma once
#include <stddef.h>
#include <stdint.h>

namespace ml {

// A colour as the renderer computes it: 0x00RRGGBB, or in id mode the visible triangle's id + 1
// (0 = background).
using Pixel = uint32_t;

inline Pixel rgb(uint32_t r, uint32_t g, uint32_t b) { return (r << 16) | (g << 8) | b; }
inline uint32_t red_of(Pixel p) { return (p >> 16) & 0xFF; }
inline uint32_t green_of(Pixel p) { return (p >> 8) & 0xFF; }
inline uint32_t blue_of(Pixel p) { return p & 0xFF; }

// The byte layouts a display takes (core/pixel_format.h packs them).
enum class PixelFormat : uint8_t {
  Rgb565Be,  // 2 bytes a pixel, RGB565 high byte first: SPI panels' wire order (ILI9341, ST7789)
  Rgb565Le,  // 2 bytes a pixel, RGB565 low byte first: 16-bit Linux framebuffers
  Xrgb8888,  // 4 bytes a pixel, the 32-bit word 0x00RRGGBB little-endian (bytes B, G, R, 0)
  Grey8,     // 1 byte a pixel, luma 0..255
  Grey4,     // 2 pixels a byte, left pixel in the high nibble, luma 0..15 (SSD0323, SSD1322)
  Mono1,     // SSD1306 pages: a byte is 8 pixels of one column, bit 0 on top; a row of bytes is a
             // page of 8 pixel rows, so band heights are multiples of 8
  Id32,      // id mode: 4 bytes a pixel, native-endian uint32 (triangle id + 1, 0 = background)
};

// What begin_frame announces.
struct FrameInfo {
  int width = 0, height = 0;  // pixels
  PixelFormat format = PixelFormat::Xrgb8888;
  int band_rows = 0;          // rows of every band but possibly the last
  int buffers = 1;            // band buffers in rotation (1 or 2)
};

// One finished band: `height` rows of `width` pixels at (x, y), packed; row r (for Mono1: page r)
// starts at bytes + r * stride.
struct Flush {
  int x = 0, y = 0, width = 0, height = 0;
  uint32_t stride = 0;        // bytes from one row (Mono1: one page of 8 rows) to the next
  const uint8_t* bytes = nullptr;
  int buffer = 0;             // which band buffer: pass it to flush_ready()
};

// What reached the display in a frame, counted by the sink (a panel driver counts command bytes and
// window commands too; a framebuffer the bytes it stores). render() resets them before
// begin_frame and copies them into Stats::display_bytes and display_windows.
struct DisplayCounters {
  uint64_t bytes = 0;     // bytes on the bus or into the framebuffer, commands included
  uint32_t windows = 0;   // address-window commands (CASET/RASET pairs, SSD column/page windows);
                          // 0 for memory: framebuffers, files, images
};

constexpr int kMaxBandBuffers = 2;

class Sink {
 public:
  virtual ~Sink() = default;
  virtual bool begin_frame(const FrameInfo& frame) { (void)frame; return true; }
  // Hands over one finished band (see the lending rules above).
  virtual bool flush(const Flush& band) = 0;
  // Called while the renderer waits for a lent buffer. A sink with transfers in flight waits for
  // progress (polls its DMA, sleeps until an interrupt) and returns true; false means the buffer will
  // never come back and fails the frame. The default suits synchronous sinks, which never lend past
  // flush().
  virtual bool wait_for_flush() { return false; }
  virtual bool end_frame() { return true; }

  // The completion call: the sink no longer reads buffer `buffer`. Safe from an interrupt handler
  // (each flag is written by one side at a time: set by the renderer while clear, cleared here).
  void flush_ready(int buffer) {
    if (buffer >= 0 && buffer < kMaxBandBuffers) lent_[buffer] = 0;
  }
  bool lent(int buffer) const { return buffer >= 0 && buffer < kMaxBandBuffers && lent_[buffer] != 0; }
  // Marks a buffer lent just before the renderer flushes it.
  void lend(int buffer) { lent_[buffer] = 1; }

  DisplayCounters counters;

 private:
  volatile uint8_t lent_[kMaxBandBuffers] = {0, 0};
};

}  // namespace ml

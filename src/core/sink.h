// The Sink: where finished pixels go (a PNG file, an in-memory image, a framebuffer, an SPI panel).
// Renderers never keep a framebuffer; they hand pixels to the Sink as soon as they are final.
//
// Pixel values are 32-bit: in colour mode 0x00RRGGBB; in id mode (ShadingMode::Ids) the visible
// triangle's id + 1 (0 = background). Sinks convert to their own format (RGB565, 4-bit grey, ...).
//
// Contract: a renderer calls begin_frame once, then writes every pixel of the w x h screen exactly once
// (the tiler as blocks, runs and single pixels in any order; the scanline renderer as whole rows, top to
// bottom), then end_frame. A sink returning false aborts the render with StatusCode::SinkFailed.
#pragma once
#include <stdint.h>

namespace ml {

using Pixel = uint32_t;

inline Pixel rgb(uint32_t r, uint32_t g, uint32_t b) { return (r << 16) | (g << 8) | b; }
inline uint32_t red_of(Pixel p) { return (p >> 16) & 0xFF; }
inline uint32_t green_of(Pixel p) { return (p >> 8) & 0xFF; }
inline uint32_t blue_of(Pixel p) { return p & 0xFF; }

class Sink {
 public:
  virtual ~Sink() = default;
  virtual bool begin_frame(int width, int height) { (void)width; (void)height; return true; }
  // Writes a w x h block at (x, y); pixels are row-major with the given stride (in pixels).
  virtual bool write_block(int x, int y, int w, int h, const Pixel* pixels, int stride) = 0;
  // Fills a w x h block at (x, y) with one value.
  virtual bool fill_block(int x, int y, int w, int h, Pixel value) = 0;
  virtual bool end_frame() { return true; }
};

}  // namespace ml

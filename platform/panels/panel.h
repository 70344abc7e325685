// Panel drivers written once against Transport: the init sequence, the pixel format the controller
// takes, the logical size for the chosen rotation, and "address a window, then stream its bytes".
//
//   panel          controller RAM   format     rotations         notes
//   ili9341        240x320          Rgb565Be   0, 90, 180, 270   MADCTL MX/MY/MV + BGR
//   st7789         240x320          Rgb565Be   0, 90, 180, 270   MADCTL MX/MY/MV, INVON
//   st7789-240     240x320 (240x240 glass)     0, 90, 180, 270   80-row RAM offset at 0 and 90
//   ssd1306        128x64 (8 pages) Mono1      0, 180            horizontal addressing, 0x21/0x22
//   ssd0323        128x80 (128x64 glass) Grey4 0, 180            0x15 byte columns, 0x75 rows, 0xA0
//
// No heap, no exceptions, no floats: shared with bare-metal firmware.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include "core/sink.h"
#include "platform/panels/transport.h"

namespace mlpanels {

enum class PanelKind : uint8_t { Ili9341, St7789, St7789_240, Ssd1306, Ssd0323 };

// A Transport with byte counting and chunking: data goes out in pieces of at most max_transfer
// bytes (0 = unlimited). Every byte (commands and parameters included) is added to counters->bytes.
class Bus {
 public:
  Bus(Transport& transport, size_t max_transfer, ml::DisplayCounters* counters)
      : transport_(&transport), max_(max_transfer), counters_(counters) {}
  bool command(const uint8_t* bytes, size_t n);
  bool data(const uint8_t* bytes, size_t n);
  bool set_reset(bool high) { return transport_->set_reset(high); }
  void delay_ms(uint32_t ms) { transport_->delay_ms(ms); }
  void count_window() {
    if (counters_) ++counters_->windows;
  }

 private:
  Transport* transport_;
  size_t max_;
  ml::DisplayCounters* counters_;
};

class Panel {
 public:
  // Sets up the driver for `kind` mounted at `rotation` degrees (0, 90, 180, 270). False when the
  // panel does not support that rotation.
  bool configure(PanelKind kind, int rotation);

  PanelKind kind() const { return kind_; }
  int rotation() const { return rotation_; }
  const char* name() const;
  ml::PixelFormat format() const { return format_; }
  // The frame size a renderer draws for this panel and rotation.
  int width() const { return width_; }
  int height() const { return height_; }
  // Where logical pixel (0, 0) sits in the controller's column/row address space (the ST7789
  // 240x240 module's 80-row offset).
  int column_offset() const { return column_offset_; }
  int row_offset() const { return row_offset_; }
  // MADCTL (ILI9341/ST7789) or remap byte (SSD1306 segment remap and COM scan; SSD0323 0xA0).
  uint8_t orientation_byte() const { return orientation_; }

  // Hardware reset, then the controller's init sequence.
  bool init(Bus& bus) const;
  // Addresses the rectangle (one window command: CASET+RASET+RAMWR, SSD1306 0x21+0x22, SSD0323
  // 0x15+0x75) so the following data bytes fill it row by row. Mono1: y and h in pixel rows,
  // multiples of 8 (h may end at the frame bottom). Grey4: x and w even.
  bool begin_window(Bus& bus, int x, int y, int w, int h) const;
  // Bytes of one packed row of a window w pixels wide (Mono1: one page of the window).
  uint32_t row_bytes(int w) const;
  // Rows of packed bytes in a window h pixel rows high (Mono1: pages).
  int packed_rows(int h) const;

 private:
  PanelKind kind_ = PanelKind::Ili9341;
  int rotation_ = 0;
  ml::PixelFormat format_ = ml::PixelFormat::Rgb565Be;
  int width_ = 240, height_ = 320;
  int column_offset_ = 0, row_offset_ = 0;
  uint8_t orientation_ = 0;
};

// Looks a panel up by name: "ili9341", "st7789" (240x320), "st7789-240" (240x240 module),
// "ssd1306" (128x64), "ssd0323" (128x64). False for an unknown name or unsupported rotation.
bool make_panel(const char* name, int rotation, Panel* out);
// The names make_panel accepts, space-separated (for usage messages).
const char* panel_names();

// MADCTL bits (ILI9341 and ST7789).
constexpr uint8_t kMadctlMY = 0x80, kMadctlMX = 0x40, kMadctlMV = 0x20, kMadctlBGR = 0x08;

}  // namespace mlpanels

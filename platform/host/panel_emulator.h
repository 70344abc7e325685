// Host emulation of the panels in platform/panels: a Transport that decodes the byte stream and the
// D/C line the way each controller does, into the controller's own RAM, and shows what a person sees
// with the panel mounted at the given rotation.
//
// Modelled per controller:
//   ILI9341 / ST7789: SWRESET, SLPIN/SLPOUT, NORON, INVOFF/INVON, DISPOFF/DISPON, COLMOD (16-bit only
//     takes pixels), MADCTL (MY, MX, MV, BGR), CASET/RASET, RAMWR with auto-increment within the
//     window; 240x320 RAM. Glass wiring per module: ILI9341 BGR glass with columns right to left;
//     ST7789 RGB IPS glass (needs INVON) seen with RAM (0, 0) at the bottom right; the 240x240 ST7789
//     module shows RAM rows 0..239.
//   SSD1306: the datasheet command set with parameter counts, horizontal addressing (0x20 0x00),
//     column/page windows 0x21/0x22, segment remap A0/A1 (applies to data written after it), COM scan
//     C0/C8, charge pump 8D, display on/off; 128x64 in 8 pages.
//   SSD0323: the datasheet command set with parameter counts, 0x15 column window in bytes, 0x75 row
//     window, 0xA0 remap (column remap, nibble remap, vertical increment, COM remap); 128x80 RAM of
//     which rows 0..63 are shown. Start line and display offset are accepted, not modelled.
// Stricter than the silicon: an unknown command, a command whose parameters did not all arrive,
// data with no command taking it, pixel data before RAMWR (TFT), beyond the window's last pixel, or
// bytes while RESET is low are errors: the first is kept as a message and the call returns false.
#pragma once
#include <stddef.h>
#include <stdint.h>

#include <memory>
#include <string>
#include <vector>

#include "core/sink.h"
#include "platform/panels/panel.h"
#include "platform/panels/panel_sink.h"
#include "platform/panels/transport.h"

namespace mlpanels {

class PanelEmulator : public Transport {
 public:
  // `rotation`: how the panel is mounted (0, 90, 180, 270 degrees).
  PanelEmulator(PanelKind kind, int rotation);

  bool write_command(const uint8_t* bytes, size_t n) override;
  bool write_data(const uint8_t* bytes, size_t n) override;
  bool set_reset(bool high) override;
  void delay_ms(uint32_t ms) override { delayed_ms_ += ms; }

  // What a person sees: width() x height() pixels, 0x00RRGGBB (black while the display is off).
  int width() const;
  int height() const;
  std::vector<ml::Pixel> picture() const;

  // The controller's RAM as stored values: TFT RGB565 words at (column, row) of 240x320; SSD1306 bits
  // at (segment, COM row) of 128x64; SSD0323 grey levels at (pixel column, row) of 128x80.
  int ram_width() const { return ram_w_; }
  int ram_height() const { return ram_h_; }
  uint32_t ram(int x, int y) const { return ram_[size_t(y) * size_t(ram_w_) + size_t(x)]; }

  bool ok() const { return errors_ == 0; }
  const std::string& error() const { return error_; }  // the first error
  uint64_t error_count() const { return errors_; }

  bool display_on() const;  // DISPON / 0xAF (SSD1306: and the charge pump on), awake
  uint64_t bytes() const { return bytes_; }          // every byte on either D/C level
  uint64_t commands() const { return commands_; }    // opcodes decoded
  uint64_t windows() const { return windows_; }      // complete column + row window pairs
  uint64_t data_bytes() const { return data_bytes_; }  // bytes stored into RAM
  uint64_t delayed_ms() const { return delayed_ms_; }
  void reset_counts() { bytes_ = commands_ = windows_ = data_bytes_ = 0; }

 private:
  enum class Chip : uint8_t { Tft, Ssd1306, Ssd0323 };
  bool fail(const std::string& message);
  void power_on_state();
  bool take_opcode(uint8_t op);        // starts a command
  bool take_parameter(uint8_t byte);   // one parameter of the current command
  bool execute();                      // all parameters in
  bool tft_pixel_byte(uint8_t byte);
  bool ssd_data_byte(uint8_t byte);
  void window_part(bool column);
  ml::Pixel glass(int gx, int gy) const;  // what glass pixel (gx, gy) shows
  int glass_width() const;
  int glass_height() const;

  PanelKind kind_;
  Chip chip_;
  int rotation_;
  int ram_w_ = 0, ram_h_ = 0;
  std::vector<uint32_t> ram_;

  // command decoding
  int op_ = -1;            // current command, -1 none
  int expected_ = 0;       // parameters it takes (-1: a RAM data stream, RAMWR)
  int got_ = 0;
  uint8_t params_[16] = {};

  // controller registers
  bool in_reset_ = false, sleeping_ = true, display_ = false, inverted_ = false;
  uint8_t madctl_ = 0, colmod_ = 0x66;
  int col_start_ = 0, col_end_ = 0, row_start_ = 0, row_end_ = 0;
  int col_ = 0, row_ = 0;
  bool writing_ = false;   // TFT: after RAMWR
  int pending_ = -1;       // TFT: first byte of a pixel
  bool past_end_ = false;  // the window's last pixel was written
  bool column_set_ = false, row_set_ = false;
  // SSD
  int address_mode_ = 2;   // SSD1306: 0 horizontal, 1 vertical, 2 page
  bool charge_pump_ = false, entire_on_ = false, seg_remap_ = false, com_reverse_ = false;
  bool display_mode_off_ = false;  // SSD0323 0xA6: all pixels off
  uint8_t remap_ = 0;      // SSD0323 0xA0 parameter

  std::string error_;
  uint64_t errors_ = 0;
  uint64_t bytes_ = 0, commands_ = 0, windows_ = 0, data_bytes_ = 0, delayed_ms_ = 0;
};

// A panel, its emulator and the sink that drives it, initialized: render into `sink`, look at
// `emulator.picture()`.
struct EmulatedPanel {
  EmulatedPanel(const Panel& p, size_t max_transfer)
      : panel(p), emulator(p.kind(), p.rotation()), sink(panel, emulator, max_transfer) {}
  Panel panel;
  PanelEmulator emulator;
  PanelSink sink;
};

// Opens panel `name` (make_panel names) mounted at `rotation` on an emulated bus and runs its init
// sequence. nullptr with a one-line message on an unknown name, unsupported rotation or init error.
std::unique_ptr<EmulatedPanel> open_emulated_panel(const std::string& name, int rotation, std::string* error,
                                                   size_t max_transfer = 4096);

}  // namespace mlpanels

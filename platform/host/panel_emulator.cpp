#include "platform/host/panel_emulator.h"

#include <stdio.h>

#include "core/pixel_format.h"

namespace mlpanels {

namespace {

constexpr int kStream = -1;  // RAMWR: data until the next command

std::string hex(int v) {
  char text[8];
  snprintf(text, sizeof text, "0x%02X", unsigned(v) & 0xFFu);
  return text;
}

// Parameters an opcode takes, or -2 for an unknown opcode.
int tft_parameters(uint8_t op) {
  switch (op) {
    case 0x00: case 0x01: case 0x10: case 0x11: case 0x13: case 0x20: case 0x21: case 0x28: case 0x29:
      return 0;
    case 0x2A: case 0x2B: return 4;
    case 0x2C: return kStream;
    case 0x36: case 0x3A: return 1;
    default: return -2;
  }
}

int ssd1306_parameters(uint8_t op) {
  if (op <= 0x1F || (op >= 0x40 && op <= 0x7F) || (op >= 0xB0 && op <= 0xB7)) return 0;
  switch (op) {
    case 0x20: return 1;
    case 0x21: case 0x22: return 2;
    case 0x26: case 0x27: return 6;
    case 0x29: case 0x2A: return 5;
    case 0x2E: case 0x2F: return 0;
    case 0x81: case 0x8D: return 1;
    case 0xA0: case 0xA1: return 0;
    case 0xA3: return 2;
    case 0xA4: case 0xA5: case 0xA6: case 0xA7: return 0;
    case 0xA8: return 1;
    case 0xAE: case 0xAF: return 0;
    case 0xC0: case 0xC8: return 0;
    case 0xD3: case 0xD5: case 0xD9: case 0xDA: case 0xDB: return 1;
    case 0xE3: return 0;
    default: return -2;
  }
}

int ssd0323_parameters(uint8_t op) {
  switch (op) {
    case 0x15: case 0x75: return 2;
    case 0x81: return 1;
    case 0x84: case 0x85: case 0x86: return 0;
    case 0xA0: case 0xA1: case 0xA2: return 1;
    case 0xA4: case 0xA5: case 0xA6: case 0xA7: return 0;
    case 0xA8: case 0xAD: return 1;
    case 0xAE: case 0xAF: return 0;
    case 0xB0: case 0xB1: case 0xB2: case 0xB3: case 0xB4: return 1;
    case 0xB8: return 8;
    case 0xBC: case 0xBE: case 0xBF: return 1;
    case 0xE3: return 0;
    default: return -2;
  }
}

uint32_t swap_red_blue(uint32_t v) { return (v & 31) << 11 | (v & 0x7E0) | (v >> 11 & 31); }

}  // namespace

PanelEmulator::PanelEmulator(PanelKind kind, int rotation) : kind_(kind), rotation_(rotation) {
  switch (kind) {
    case PanelKind::Ssd1306: chip_ = Chip::Ssd1306; ram_w_ = 128; ram_h_ = 64; break;
    case PanelKind::Ssd0323: chip_ = Chip::Ssd0323; ram_w_ = 128; ram_h_ = 80; break;
    default: chip_ = Chip::Tft; ram_w_ = 240; ram_h_ = 320; break;
  }
  if (rotation != 0 && rotation != 90 && rotation != 180 && rotation != 270) {
    fail("rotation must be 0, 90, 180 or 270");
    rotation_ = 0;
  }
  ram_.assign(size_t(ram_w_) * size_t(ram_h_), 0);
  power_on_state();
}

bool PanelEmulator::fail(const std::string& message) {
  if (errors_++ == 0) error_ = message;
  return false;
}

void PanelEmulator::power_on_state() {
  op_ = -1;
  expected_ = got_ = 0;
  sleeping_ = chip_ == Chip::Tft;
  display_ = inverted_ = false;
  madctl_ = 0;
  colmod_ = 0x66;
  writing_ = false;
  pending_ = -1;
  past_end_ = false;
  column_set_ = row_set_ = false;
  address_mode_ = 2;
  charge_pump_ = entire_on_ = seg_remap_ = com_reverse_ = display_mode_off_ = false;
  remap_ = 0;
  col_ = row_ = 0;
  switch (chip_) {
    case Chip::Tft: col_start_ = 0; col_end_ = 239; row_start_ = 0; row_end_ = 319; break;
    case Chip::Ssd1306: col_start_ = 0; col_end_ = 127; row_start_ = 0; row_end_ = 7; break;
    case Chip::Ssd0323: col_start_ = 0; col_end_ = 63; row_start_ = 0; row_end_ = 79; break;
  }
}

bool PanelEmulator::set_reset(bool high) {
  if (!high) {
    in_reset_ = true;
    return true;
  }
  if (in_reset_) power_on_state();  // rising edge: hardware reset
  in_reset_ = false;
  return true;
}

bool PanelEmulator::write_command(const uint8_t* bytes, size_t n) {
  bytes_ += n;
  if (in_reset_) return fail("bytes sent while RESET is low");
  for (size_t i = 0; i < n; ++i) {
    // SSD controllers take command parameters with D/C low too.
    const bool parameter = chip_ != Chip::Tft && op_ >= 0 && got_ < expected_;
    if (!(parameter ? take_parameter(bytes[i]) : take_opcode(bytes[i]))) return false;
  }
  return true;
}

bool PanelEmulator::write_data(const uint8_t* bytes, size_t n) {
  bytes_ += n;
  if (in_reset_) return fail("bytes sent while RESET is low");
  for (size_t i = 0; i < n; ++i) {
    const uint8_t b = bytes[i];
    if (chip_ == Chip::Tft) {
      if (op_ >= 0 && expected_ == kStream) {
        if (!tft_pixel_byte(b)) return false;
      } else if (op_ >= 0 && got_ < expected_) {
        if (!take_parameter(b)) return false;
      } else {
        return fail("data byte with no command taking it (pixel data before RAMWR?)");
      }
    } else {
      if (op_ >= 0 && got_ < expected_)
        return fail("parameters missing for command " + hex(op_) + " (display data arrived)");
      if (!ssd_data_byte(b)) return false;
    }
  }
  return true;
}

bool PanelEmulator::take_opcode(uint8_t op) {
  if (op_ >= 0 && expected_ != kStream && got_ < expected_)
    return fail("parameters missing for command " + hex(op_));
  if (pending_ >= 0) return fail("half a pixel before command " + hex(op));
  writing_ = false;
  ++commands_;
  int count = -2;
  switch (chip_) {
    case Chip::Tft: count = tft_parameters(op); break;
    case Chip::Ssd1306: count = ssd1306_parameters(op); break;
    case Chip::Ssd0323: count = ssd0323_parameters(op); break;
  }
  if (count == -2) {
    op_ = -1;
    return fail("unknown command " + hex(op));
  }
  op_ = op;
  expected_ = count;
  got_ = 0;
  if (count == 0 || count == kStream) return execute();
  return true;
}

bool PanelEmulator::take_parameter(uint8_t byte) {
  params_[got_++] = byte;
  if (got_ == expected_) return execute();
  return true;
}

void PanelEmulator::window_part(bool column) {
  (column ? column_set_ : row_set_) = true;
  if (column_set_ && row_set_) {
    ++windows_;
    column_set_ = row_set_ = false;
  }
}

bool PanelEmulator::execute() {
  const int op = op_;
  const uint8_t* p = params_;
  if (expected_ != kStream) op_ = -1;
  if (chip_ == Chip::Tft) {
    switch (op) {
      case 0x01: power_on_state(); return true;  // SWRESET
      case 0x10: sleeping_ = true; return true;
      case 0x11: sleeping_ = false; return true;
      case 0x20: inverted_ = false; return true;
      case 0x21: inverted_ = true; return true;
      case 0x28: display_ = false; return true;
      case 0x29: display_ = true; return true;
      case 0x36: madctl_ = p[0]; return true;
      case 0x3A: colmod_ = p[0]; return true;
      case 0x2A:
      case 0x2B: {
        const int s = p[0] << 8 | p[1], e = p[2] << 8 | p[3];
        if (s > e) return fail(std::string(op == 0x2A ? "CASET" : "RASET") + " start after end");
        if (op == 0x2A) col_start_ = s, col_end_ = e;
        else row_start_ = s, row_end_ = e;
        window_part(op == 0x2A);
        return true;
      }
      case 0x2C: {  // RAMWR
        const bool mv = madctl_ & kMadctlMV;
        const int cols = mv ? 320 : 240, rows = mv ? 240 : 320;
        if (col_end_ >= cols || row_end_ >= rows) return fail("window outside the controller's RAM");
        if ((colmod_ & 7) != 5) return fail("RAMWR while COLMOD is not 16 bits a pixel");
        writing_ = true;
        col_ = col_start_;
        row_ = row_start_;
        past_end_ = false;
        return true;
      }
      default: return true;  // NOP, NORON
    }
  }
  if (chip_ == Chip::Ssd1306) {
    switch (op) {
      case 0x20:
        if (p[0] > 2) return fail("invalid addressing mode");
        address_mode_ = p[0];
        return true;
      case 0x21:
        if (p[0] > 127 || p[1] > 127 || p[0] > p[1]) return fail("invalid column window");
        col_start_ = col_ = p[0];
        col_end_ = p[1];
        past_end_ = false;
        window_part(true);
        return true;
      case 0x22:
        if (p[0] > 7 || p[1] > 7 || p[0] > p[1]) return fail("invalid page window");
        row_start_ = row_ = p[0];
        row_end_ = p[1];
        past_end_ = false;
        window_part(false);
        return true;
      case 0x8D: charge_pump_ = (p[0] & 0x04) != 0; return true;
      case 0xA0: seg_remap_ = false; return true;
      case 0xA1: seg_remap_ = true; return true;
      case 0xA4: entire_on_ = false; return true;
      case 0xA5: entire_on_ = true; return true;
      case 0xA6: inverted_ = false; return true;
      case 0xA7: inverted_ = true; return true;
      case 0xAE: display_ = false; return true;
      case 0xAF: display_ = true; return true;
      case 0xC0: com_reverse_ = false; return true;
      case 0xC8: com_reverse_ = true; return true;
      default: return true;
    }
  }
  switch (op) {  // SSD0323
    case 0x15:
      if (p[0] > 63 || p[1] > 63 || p[0] > p[1]) return fail("invalid column window");
      col_start_ = col_ = p[0];
      col_end_ = p[1];
      row_ = row_start_;
      past_end_ = false;
      window_part(true);
      return true;
    case 0x75:
      if (p[0] > 79 || p[1] > 79 || p[0] > p[1]) return fail("invalid row window");
      row_start_ = row_ = p[0];
      row_end_ = p[1];
      col_ = col_start_;
      past_end_ = false;
      window_part(false);
      return true;
    case 0xA0: remap_ = p[0]; return true;
    case 0xA4: case 0xA5: case 0xA6: case 0xA7: entire_on_ = op == 0xA5; inverted_ = op == 0xA7;
      display_mode_off_ = op == 0xA6;
      return true;
    case 0xAE: display_ = false; return true;
    case 0xAF: display_ = true; return true;
    default: return true;
  }
}

bool PanelEmulator::tft_pixel_byte(uint8_t byte) {
  if (!writing_) return fail("pixel data before RAMWR");
  if (pending_ < 0) {
    pending_ = byte;
    return true;
  }
  const uint32_t value = uint32_t(pending_) << 8 | byte;
  pending_ = -1;
  if (past_end_) return fail("pixel data beyond the window's last pixel");
  int u = col_, v = row_;
  if (madctl_ & kMadctlMV) u = row_, v = col_;
  if (madctl_ & kMadctlMX) u = 239 - u;
  if (madctl_ & kMadctlMY) v = 319 - v;
  ram_[size_t(v) * 240 + size_t(u)] = value;
  data_bytes_ += 2;
  if (++col_ > col_end_) {
    col_ = col_start_;
    if (++row_ > row_end_) past_end_ = true;
  }
  return true;
}

bool PanelEmulator::ssd_data_byte(uint8_t byte) {
  if (past_end_) return fail("display data beyond the window's last byte");
  if (chip_ == Chip::Ssd1306) {
    if (address_mode_ != 0) return fail("display data in an addressing mode other than horizontal");
    const int s = seg_remap_ ? 127 - col_ : col_;
    for (int b = 0; b < 8; ++b) ram_[size_t(row_ * 8 + b) * 128 + size_t(s)] = byte >> b & 1u;
    data_bytes_ += 1;
    if (++col_ > col_end_) {
      col_ = col_start_;
      if (++row_ > row_end_) past_end_ = true;
    }
    return true;
  }
  const int column = (remap_ & 1) ? 63 - col_ : col_;
  const int high = 2 * column + ((remap_ & 2) ? 0 : 1);
  const int low = 2 * column + ((remap_ & 2) ? 1 : 0);
  ram_[size_t(row_) * 128 + size_t(high)] = byte >> 4;
  ram_[size_t(row_) * 128 + size_t(low)] = byte & 15u;
  data_bytes_ += 1;
  if (remap_ & 4) {  // vertical address increment
    if (++row_ > row_end_) {
      row_ = row_start_;
      if (++col_ > col_end_) past_end_ = true;
    }
  } else if (++col_ > col_end_) {
    col_ = col_start_;
    if (++row_ > row_end_) past_end_ = true;
  }
  return true;
}

bool PanelEmulator::display_on() const {
  switch (chip_) {
    case Chip::Tft: return display_ && !sleeping_ && !in_reset_;
    case Chip::Ssd1306: return display_ && charge_pump_ && !in_reset_;
    case Chip::Ssd0323: return display_ && !in_reset_;
  }
  return false;
}

int PanelEmulator::glass_width() const { return chip_ == Chip::Tft ? 240 : 128; }
int PanelEmulator::glass_height() const {
  switch (kind_) {
    case PanelKind::Ili9341: case PanelKind::St7789: return 320;
    case PanelKind::St7789_240: return 240;
    default: return 64;
  }
}

int PanelEmulator::width() const { return rotation_ % 180 ? glass_height() : glass_width(); }
int PanelEmulator::height() const { return rotation_ % 180 ? glass_width() : glass_height(); }

ml::Pixel PanelEmulator::glass(int gx, int gy) const {
  switch (kind_) {
    case PanelKind::Ili9341:
    case PanelKind::St7789:
    case PanelKind::St7789_240: {
      const int u = 239 - gx;
      const int v = kind_ == PanelKind::Ili9341 ? gy : glass_height() - 1 - gy;
      uint32_t value = ram_[size_t(v) * 240 + size_t(u)];
      const bool bgr = (madctl_ & kMadctlBGR) != 0;
      if (kind_ == PanelKind::Ili9341 ? !bgr : bgr) value = swap_red_blue(value);  // glass order
      if (kind_ == PanelKind::Ili9341 ? inverted_ : !inverted_) value ^= 0xFFFF;    // IPS glass
      return ml::expand_stored(ml::PixelFormat::Rgb565Be, value);
    }
    case PanelKind::Ssd1306: {
      const int r = com_reverse_ ? gy : 63 - gy;
      uint32_t bit = entire_on_ ? 1 : ram_[size_t(r) * 128 + size_t(127 - gx)];
      if (inverted_) bit ^= 1;
      return ml::expand_stored(ml::PixelFormat::Mono1, bit);
    }
    case PanelKind::Ssd0323: {
      const int r = (remap_ & 0x10) ? gy : 63 - gy;
      uint32_t level = ram_[size_t(r) * 128 + size_t(gx)];
      if (entire_on_) level = 15;
      if (display_mode_off_) level = 0;
      if (inverted_) level = 15 - level;
      return ml::expand_stored(ml::PixelFormat::Grey4, level);
    }
  }
  return 0;
}

std::vector<ml::Pixel> PanelEmulator::picture() const {
  const int w = width(), h = height(), gw = glass_width(), gh = glass_height();
  std::vector<ml::Pixel> out(size_t(w) * size_t(h), 0);
  if (!display_on()) return out;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      int gx = x, gy = y;
      switch (rotation_) {
        case 90: gx = gw - 1 - y; gy = x; break;
        case 180: gx = gw - 1 - x; gy = gh - 1 - y; break;
        case 270: gx = y; gy = gh - 1 - x; break;
        default: break;
      }
      out[size_t(y) * size_t(w) + size_t(x)] = glass(gx, gy);
    }
  return out;
}

std::unique_ptr<EmulatedPanel> open_emulated_panel(const std::string& name, int rotation, std::string* error,
                                                   size_t max_transfer) {
  Panel panel;
  if (!make_panel(name.c_str(), rotation, &panel)) {
    Panel probe;
    if (error)
      *error = make_panel(name.c_str(), 0, &probe)
                   ? "panel " + name + " does not support rotation " + std::to_string(rotation)
                   : "unknown panel '" + name + "' (known: " + panel_names() + ")";
    return nullptr;
  }
  auto out = std::make_unique<EmulatedPanel>(panel, max_transfer);
  if (!out->sink.init() || !out->emulator.ok()) {
    if (error) *error = "emulated " + name + " rejected its init sequence: " + out->emulator.error();
    return nullptr;
  }
  out->emulator.reset_counts();
  return out;
}

}  // namespace mlpanels

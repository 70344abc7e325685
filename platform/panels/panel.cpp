#include "platform/panels/panel.h"

namespace mlpanels {

namespace {

// ILI9341 / ST7789 commands.
constexpr uint8_t kSwReset = 0x01, kSleepOut = 0x11, kNormalOn = 0x13, kInvertOn = 0x21, kDisplayOn = 0x29;
constexpr uint8_t kColumnSet = 0x2A, kRowSet = 0x2B, kMemoryWrite = 0x2C, kMadctl = 0x36, kColmod = 0x3A;
constexpr uint8_t kColmod16 = 0x55;  // 16 bits a pixel on both interfaces

// SSD1306 init (datasheet application note order): display off, clock, multiplex 64, offset 0,
// start line 0, charge pump on, horizontal addressing, (remap and COM scan per rotation), COM pins,
// contrast, pre-charge, VCOMH, scroll off, display from RAM, normal, display on.
constexpr uint8_t kSsd1306InitHead[] = {0xAE, 0xD5, 0x80, 0xA8, 0x3F, 0xD3, 0x00, 0x40, 0x8D, 0x14, 0x20, 0x00};
constexpr uint8_t kSsd1306InitTail[] = {0xDA, 0x12, 0x81, 0xCF, 0xD9, 0xF1, 0xDB, 0x40, 0x2E, 0xA4, 0xA6, 0xAF};

// SSD0323 init: display off, full column and row windows, contrast, half current, (remap per
// rotation), start line, display offset, multiplex 64, phase length, row period, clock, VSL, VCOMH,
// pre-charge voltage, grey scale table, master configuration, normal display, display on.
constexpr uint8_t kSsd0323InitHead[] = {0xAE, 0x15, 0x00, 0x3F, 0x75, 0x00, 0x3F, 0x81, 0x33, 0x85};
constexpr uint8_t kSsd0323InitTail[] = {0xA1, 0x00, 0xA2, 0x4C, 0xA8, 0x3F, 0xB1, 0x22, 0xB2, 0x46,
                                        0xB3, 0x41, 0xBF, 0x0D, 0xBE, 0x02, 0xBC, 0x10, 0xB8, 0x01,
                                        0x11, 0x22, 0x32, 0x43, 0x54, 0x65, 0x76, 0xAD, 0x02, 0xA4, 0xAF};

bool streq(const char* a, const char* b) {
  while (*a && *a == *b) ++a, ++b;
  return *a == *b;
}

bool is_tft(PanelKind kind) {
  return kind == PanelKind::Ili9341 || kind == PanelKind::St7789 || kind == PanelKind::St7789_240;
}

// An ILI9341/ST7789 command: the opcode with D/C low, its parameters with D/C high.
bool tft_command(Bus& bus, uint8_t op, const uint8_t* params = nullptr, size_t n = 0) {
  if (!bus.command(&op, 1)) return false;
  return n == 0 || bus.data(params, n);
}

bool tft_window(Bus& bus, int x0, int y0, int x1, int y1) {
  const uint8_t cols[4] = {uint8_t(x0 >> 8), uint8_t(x0), uint8_t(x1 >> 8), uint8_t(x1)};
  const uint8_t rows[4] = {uint8_t(y0 >> 8), uint8_t(y0), uint8_t(y1 >> 8), uint8_t(y1)};
  return tft_command(bus, kColumnSet, cols, 4) && tft_command(bus, kRowSet, rows, 4) &&
         tft_command(bus, kMemoryWrite);
}

}  // namespace

bool Bus::command(const uint8_t* bytes, size_t n) {
  while (n > 0) {
    const size_t m = max_ != 0 && n > max_ ? max_ : n;
    if (!transport_->write_command(bytes, m)) return false;
    if (counters_) counters_->bytes += m;
    bytes += m;
    n -= m;
  }
  return true;
}

bool Bus::data(const uint8_t* bytes, size_t n) {
  while (n > 0) {
    const size_t m = max_ != 0 && n > max_ ? max_ : n;
    if (!transport_->write_data(bytes, m)) return false;
    if (counters_) counters_->bytes += m;
    bytes += m;
    n -= m;
  }
  return true;
}

bool Panel::configure(PanelKind kind, int rotation) {
  if (rotation != 0 && rotation != 90 && rotation != 180 && rotation != 270) return false;
  const bool quarter = rotation == 90 || rotation == 270;
  kind_ = kind;
  rotation_ = rotation;
  column_offset_ = row_offset_ = 0;
  switch (kind) {
    case PanelKind::Ili9341: {
      // Common ILI9341 modules: BGR glass, columns wired right to left.
      static constexpr uint8_t kMad[4] = {kMadctlMX | kMadctlBGR, kMadctlMV | kMadctlBGR, kMadctlMY | kMadctlBGR,
                                          kMadctlMX | kMadctlMY | kMadctlMV | kMadctlBGR};
      format_ = ml::PixelFormat::Rgb565Be;
      width_ = quarter ? 320 : 240;
      height_ = quarter ? 240 : 320;
      orientation_ = kMad[rotation / 90];
      return true;
    }
    case PanelKind::St7789:
    case PanelKind::St7789_240: {
      // ST7789 modules: RGB glass seen from the side where RAM (0, 0) is the bottom right corner.
      static constexpr uint8_t kMad[4] = {kMadctlMX | kMadctlMY, kMadctlMY | kMadctlMV, 0, kMadctlMX | kMadctlMV};
      format_ = ml::PixelFormat::Rgb565Be;
      const int tall = kind == PanelKind::St7789 ? 320 : 240;
      width_ = quarter ? tall : 240;
      height_ = quarter ? 240 : tall;
      orientation_ = kMad[rotation / 90];
      if (kind == PanelKind::St7789_240) {
        // The 240x240 glass shows RAM rows 0..239; mirrored row order puts them at addresses 80..319.
        if (rotation == 0) row_offset_ = 80;
        if (rotation == 90) column_offset_ = 80;
      }
      return true;
    }
    case PanelKind::Ssd1306:
    case PanelKind::Ssd0323:
      if (quarter) return false;  // pages / byte columns cannot be transposed by the controller
      width_ = 128;
      height_ = 64;
      if (kind == PanelKind::Ssd1306) {
        format_ = ml::PixelFormat::Mono1;
        orientation_ = rotation == 0 ? 0xA1 : 0xA0;  // segment remap; COM scan C8 / C0 follows
      } else {
        format_ = ml::PixelFormat::Grey4;
        // 0xA0 remap: bit 0 column address remap, bit 1 nibble remap (high nibble left), bit 4 COM
        // remap, bit 6 COM split odd/even (the module's wiring).
        orientation_ = rotation == 0 ? 0x52 : 0x41;
      }
      return true;
  }
  return false;
}

const char* Panel::name() const {
  switch (kind_) {
    case PanelKind::Ili9341: return "ili9341";
    case PanelKind::St7789: return "st7789";
    case PanelKind::St7789_240: return "st7789-240";
    case PanelKind::Ssd1306: return "ssd1306";
    case PanelKind::Ssd0323: return "ssd0323";
  }
  return "?";
}

bool Panel::init(Bus& bus) const {
  // Hardware reset (a transport without a RESET line ignores these).
  if (!bus.set_reset(true)) return false;
  bus.delay_ms(1);
  if (!bus.set_reset(false)) return false;
  bus.delay_ms(10);
  if (!bus.set_reset(true)) return false;
  bus.delay_ms(120);
  if (is_tft(kind_)) {
    if (!tft_command(bus, kSwReset)) return false;
    bus.delay_ms(150);
    if (!tft_command(bus, kSleepOut)) return false;
    bus.delay_ms(120);
    const uint8_t colmod = kColmod16;
    if (!tft_command(bus, kColmod, &colmod, 1)) return false;
    if (!tft_command(bus, kMadctl, &orientation_, 1)) return false;
    if (kind_ != PanelKind::Ili9341 && !tft_command(bus, kInvertOn)) return false;  // IPS glass
    if (!tft_command(bus, kNormalOn)) return false;
    bus.delay_ms(10);
    if (!tft_command(bus, kDisplayOn)) return false;
    bus.delay_ms(20);
    return true;
  }
  if (kind_ == PanelKind::Ssd1306) {
    const uint8_t remap[2] = {orientation_, uint8_t(orientation_ == 0xA1 ? 0xC8 : 0xC0)};
    if (!bus.command(kSsd1306InitHead, sizeof kSsd1306InitHead) || !bus.command(remap, 2) ||
        !bus.command(kSsd1306InitTail, sizeof kSsd1306InitTail))
      return false;
    bus.delay_ms(100);
    return true;
  }
  const uint8_t remap[2] = {0xA0, orientation_};
  if (!bus.command(kSsd0323InitHead, sizeof kSsd0323InitHead) || !bus.command(remap, 2) ||
      !bus.command(kSsd0323InitTail, sizeof kSsd0323InitTail))
    return false;
  bus.delay_ms(100);
  return true;
}

uint32_t Panel::row_bytes(int w) const {
  if (format_ == ml::PixelFormat::Mono1) return uint32_t(w);
  if (format_ == ml::PixelFormat::Grey4) return uint32_t(w + 1) / 2;
  return uint32_t(w) * 2;
}

int Panel::packed_rows(int h) const { return format_ == ml::PixelFormat::Mono1 ? (h + 7) / 8 : h; }

bool Panel::begin_window(Bus& bus, int x, int y, int w, int h) const {
  if (w < 1 || h < 1 || x < 0 || y < 0 || x + w > width_ || y + h > height_) return false;
  bool ok = false;
  switch (kind_) {
    case PanelKind::Ili9341:
    case PanelKind::St7789:
    case PanelKind::St7789_240:
      ok = tft_window(bus, x + column_offset_, y + row_offset_, x + w - 1 + column_offset_, y + h - 1 + row_offset_);
      break;
    case PanelKind::Ssd1306: {
      if (y % 8 != 0 || (h % 8 != 0 && y + h != height_)) return false;
      const uint8_t cmd[6] = {0x21, uint8_t(x), uint8_t(x + w - 1), 0x22, uint8_t(y / 8), uint8_t((y + h + 7) / 8 - 1)};
      ok = bus.command(cmd, 6);
      break;
    }
    case PanelKind::Ssd0323: {
      if (x % 2 != 0 || w % 2 != 0) return false;
      const uint8_t cmd[6] = {0x15, uint8_t(x / 2), uint8_t((x + w) / 2 - 1), 0x75, uint8_t(y), uint8_t(y + h - 1)};
      ok = bus.command(cmd, 6);
      break;
    }
  }
  if (ok) bus.count_window();
  return ok;
}

bool make_panel(const char* name, int rotation, Panel* out) {
  if (!name || !out) return false;
  PanelKind kind;
  if (streq(name, "ili9341")) kind = PanelKind::Ili9341;
  else if (streq(name, "st7789")) kind = PanelKind::St7789;
  else if (streq(name, "st7789-240")) kind = PanelKind::St7789_240;
  else if (streq(name, "ssd1306")) kind = PanelKind::Ssd1306;
  else if (streq(name, "ssd0323")) kind = PanelKind::Ssd0323;
  else return false;
  return out->configure(kind, rotation);
}

const char* panel_names() { return "ili9341 st7789 st7789-240 ssd1306 ssd0323"; }

}  // namespace mlpanels

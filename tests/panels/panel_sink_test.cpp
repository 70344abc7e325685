// PanelSink + panel drivers against the host emulator with synthetic bands: every panel and rotation
// shows the frame exactly, bytes and windows are counted, chunking does not change the picture, and
// the emulator rejects malformed streams.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/pixel_format.h"
#include "platform/host/panel_emulator.h"
#include "platform/panels/panel.h"
#include "platform/panels/panel_sink.h"
#include "tests/panels/panel_test_util.h"

namespace {

using mlpanels::Panel;
using mlpanels::PanelEmulator;
using mlpanels::PanelKind;
using panel_test::PanelCase;

class PanelCases : public ::testing::TestWithParam<PanelCase> {};

// Logical sizes and formats per panel and rotation.
TEST(PanelDrivers, SizesFormatsAndRotations) {
  Panel p;
  ASSERT_TRUE(mlpanels::make_panel("ili9341", 0, &p));
  EXPECT_EQ(p.width(), 240);
  EXPECT_EQ(p.height(), 320);
  EXPECT_EQ(p.format(), ml::PixelFormat::Rgb565Be);
  ASSERT_TRUE(mlpanels::make_panel("ili9341", 90, &p));
  EXPECT_EQ(p.width(), 320);
  EXPECT_EQ(p.height(), 240);
  ASSERT_TRUE(mlpanels::make_panel("st7789-240", 0, &p));
  EXPECT_EQ(p.width(), 240);
  EXPECT_EQ(p.height(), 240);
  EXPECT_EQ(p.row_offset(), 80);
  ASSERT_TRUE(mlpanels::make_panel("st7789-240", 90, &p));
  EXPECT_EQ(p.column_offset(), 80);
  ASSERT_TRUE(mlpanels::make_panel("st7789-240", 180, &p));
  EXPECT_EQ(p.row_offset() + p.column_offset(), 0);
  ASSERT_TRUE(mlpanels::make_panel("st7789", 270, &p));
  EXPECT_EQ(p.width(), 320);
  ASSERT_TRUE(mlpanels::make_panel("ssd1306", 180, &p));
  EXPECT_EQ(p.format(), ml::PixelFormat::Mono1);
  EXPECT_EQ(p.width(), 128);
  EXPECT_EQ(p.height(), 64);
  ASSERT_TRUE(mlpanels::make_panel("ssd0323", 0, &p));
  EXPECT_EQ(p.format(), ml::PixelFormat::Grey4);
  EXPECT_FALSE(mlpanels::make_panel("ssd1306", 90, &p));
  EXPECT_FALSE(mlpanels::make_panel("ssd0323", 270, &p));
  EXPECT_FALSE(mlpanels::make_panel("ili9341", 45, &p));
  EXPECT_FALSE(mlpanels::make_panel("hd44780", 0, &p));
  EXPECT_FALSE(mlpanels::make_panel(nullptr, 0, &p));
}

TEST(PanelEmulatorFactory, OpensEveryPanelAndReportsBadNames) {
  for (const PanelCase& c : panel_test::all_cases()) {
    std::string error;
    auto e = mlpanels::open_emulated_panel(c.name, c.rotation, &error);
    ASSERT_TRUE(e) << error;
    EXPECT_TRUE(e->emulator.ok()) << e->emulator.error();
    EXPECT_TRUE(e->emulator.display_on()) << c.name;
    EXPECT_EQ(e->emulator.width(), e->panel.width());
    EXPECT_EQ(e->emulator.height(), e->panel.height());
    EXPECT_GT(e->sink.init_bytes(), 0u);
  }
  std::string error;
  EXPECT_FALSE(mlpanels::open_emulated_panel("nope", 0, &error));
  EXPECT_NE(error.find("unknown panel"), std::string::npos) << error;
  EXPECT_FALSE(mlpanels::open_emulated_panel("ssd1306", 90, &error));
  EXPECT_NE(error.find("rotation"), std::string::npos) << error;
}

TEST_P(PanelCases, SyntheticFrameShowsExactly) {
  const PanelCase c = GetParam();
  std::string error;
  auto e = mlpanels::open_emulated_panel(c.name, c.rotation, &error);
  ASSERT_TRUE(e) << error;
  const int w = e->panel.width(), h = e->panel.height();
  const ml::PixelFormat f = e->panel.format();
  for (uint32_t seed : {1u, 2u}) {  // two frames: the second must overwrite the first everywhere
    const auto image = panel_test::pattern(w, h, seed);
    ASSERT_TRUE(panel_test::send_frame(e->sink, f, image, w, h, 16)) << e->sink.error() << " / " << e->emulator.error();
    ASSERT_TRUE(e->emulator.ok()) << e->emulator.error();
    const auto want = panel_test::expected_picture(f, image, w);
    const auto got = e->emulator.picture();
    ASSERT_EQ(got.size(), want.size());
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < got.size(); ++i)
      if (got[i] != want[i] && bad++ == 0) first = i;
    EXPECT_EQ(bad, 0u) << "first at (" << first % size_t(w) << ", " << first / size_t(w) << "): got " << std::hex
                       << got[first] << " want " << want[first];
  }
}

TEST_P(PanelCases, CountsBytesAndWindows) {
  const PanelCase c = GetParam();
  std::string error;
  auto e = mlpanels::open_emulated_panel(c.name, c.rotation, &error);
  ASSERT_TRUE(e) << error;
  const int w = e->panel.width(), h = e->panel.height();
  const ml::PixelFormat f = e->panel.format();
  for (int band_rows : {8, 16, 64}) {
    e->emulator.reset_counts();
    ASSERT_TRUE(panel_test::send_frame(e->sink, f, panel_test::pattern(w, h), w, h, band_rows));
    const uint64_t bands = uint64_t((h + band_rows - 1) / band_rows);
    const uint64_t pixel_bytes = uint64_t(w) * uint64_t(h) * uint64_t(panel_test::bits_per_pixel(f)) / 8;
    EXPECT_EQ(e->sink.counters.windows, bands);
    EXPECT_EQ(e->emulator.windows(), bands);
    EXPECT_EQ(e->sink.counters.bytes, pixel_bytes + bands * panel_test::window_bytes(e->panel));
    EXPECT_EQ(e->emulator.bytes(), e->sink.counters.bytes);
    EXPECT_EQ(e->emulator.data_bytes(), pixel_bytes);
    EXPECT_EQ(e->emulator.commands(), bands * (f == ml::PixelFormat::Rgb565Be ? 3 : 2));
    EXPECT_LE(double(e->sink.counters.bytes), 1.05 * double(pixel_bytes));
  }
}

// Transport wrapper that records the largest write and forwards to the emulator.
class CheckingTransport : public mlpanels::Transport {
 public:
  explicit CheckingTransport(mlpanels::Transport& inner) : inner_(inner) {}
  bool write_command(const uint8_t* b, size_t n) override { note(n); return inner_.write_command(b, n); }
  bool write_data(const uint8_t* b, size_t n) override { note(n); return inner_.write_data(b, n); }
  bool set_reset(bool high) override { return inner_.set_reset(high); }
  void delay_ms(uint32_t ms) override { inner_.delay_ms(ms); }
  size_t largest = 0;
  uint64_t writes = 0;

 private:
  void note(size_t n) {
    if (n > largest) largest = n;
    ++writes;
  }
  mlpanels::Transport& inner_;
};

TEST_P(PanelCases, ChunkingAndStrideGiveTheSamePicture) {
  const PanelCase c = GetParam();
  Panel panel;
  ASSERT_TRUE(mlpanels::make_panel(c.name, c.rotation, &panel));
  const int w = panel.width(), h = panel.height();
  const auto image = panel_test::pattern(w, h, 7);
  const auto want = panel_test::expected_picture(panel.format(), image, w);
  for (size_t max : {size_t(0), size_t(1), size_t(3), size_t(64), size_t(4096)}) {
    for (uint32_t pad : {0u, 5u}) {
      PanelEmulator emu(panel.kind(), c.rotation);
      CheckingTransport wire(emu);
      mlpanels::PanelSink sink(panel, wire, max);
      ASSERT_TRUE(sink.init()) << emu.error();
      ASSERT_TRUE(panel_test::send_frame(sink, panel.format(), image, w, h, 24 - 24 % ml::format_row_unit(panel.format()), pad))
          << "max " << max << " pad " << pad << ": " << sink.error() << " / " << emu.error();
      EXPECT_TRUE(emu.ok()) << emu.error();
      if (max != 0) {
        EXPECT_LE(wire.largest, max);
      }
      EXPECT_TRUE(emu.picture() == want) << "max " << max << " pad " << pad;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllPanels, PanelCases, ::testing::ValuesIn(panel_test::all_cases()),
                         [](const ::testing::TestParamInfo<PanelCase>& info) { return panel_test::case_name(info.param); });

TEST(PanelSinkFrames, RefusesFramesThatAreNotThePanels) {
  std::string error;
  auto e = mlpanels::open_emulated_panel("ili9341", 90, &error);
  ASSERT_TRUE(e) << error;
  ml::FrameInfo f;
  f.width = 320;
  f.height = 240;
  f.format = ml::PixelFormat::Rgb565Be;
  f.band_rows = 16;
  EXPECT_TRUE(e->sink.begin_frame(f));
  EXPECT_TRUE(e->sink.end_frame());
  ml::FrameInfo portrait = f;
  portrait.width = 240;
  portrait.height = 320;
  EXPECT_FALSE(e->sink.begin_frame(portrait));
  EXPECT_STRNE(e->sink.error(), "");
  ml::FrameInfo le = f;
  le.format = ml::PixelFormat::Rgb565Le;
  EXPECT_FALSE(e->sink.begin_frame(le));
  auto mono = mlpanels::open_emulated_panel("ssd1306", 0, &error);
  ASSERT_TRUE(mono) << error;
  ml::FrameInfo m;
  m.width = 128;
  m.height = 64;
  m.format = ml::PixelFormat::Mono1;
  m.band_rows = 12;  // not whole pages
  EXPECT_FALSE(mono->sink.begin_frame(m));
  m.band_rows = 16;
  EXPECT_TRUE(mono->sink.begin_frame(m));
  // A band outside the panel is refused and its buffer is still given back.
  std::vector<uint8_t> bytes(128 * 2, 0);
  ml::Flush fl;
  fl.y = 64;
  fl.width = 128;
  fl.height = 16;
  fl.stride = 128;
  fl.bytes = bytes.data();
  fl.buffer = 1;
  mono->sink.lend(1);
  EXPECT_FALSE(mono->sink.flush(fl));
  EXPECT_FALSE(mono->sink.lent(1));
  // Flush outside a frame.
  EXPECT_TRUE(mono->sink.end_frame());
  fl.y = 0;
  EXPECT_FALSE(mono->sink.flush(fl));
}

TEST(PanelSinkFrames, PartialWindowLandsWhereAddressed) {
  // A rectangle that is not a full-width band: the window addressing alone places it.
  std::string error;
  auto e = mlpanels::open_emulated_panel("st7789-240", 90, &error);
  ASSERT_TRUE(e) << error;
  const int w = 240, h = 240;
  const auto image = panel_test::pattern(w, h, 3);
  ASSERT_TRUE(panel_test::send_frame(e->sink, ml::PixelFormat::Rgb565Be, image, w, h, 40));
  ml::FrameInfo info;
  info.width = w;
  info.height = h;
  info.format = ml::PixelFormat::Rgb565Be;
  info.band_rows = 16;
  ASSERT_TRUE(e->sink.begin_frame(info));
  const uint8_t white[2] = {0xFF, 0xFF};
  std::vector<uint8_t> block;
  for (int i = 0; i < 10 * 6; ++i) block.insert(block.end(), white, white + 2);
  ml::Flush fl;
  fl.x = 100;
  fl.y = 50;
  fl.width = 10;
  fl.height = 6;
  fl.stride = 20;
  fl.bytes = block.data();
  ASSERT_TRUE(e->sink.flush(fl)) << e->sink.error() << e->emulator.error();
  const auto pic = e->emulator.picture();
  auto want = panel_test::expected_picture(ml::PixelFormat::Rgb565Be, image, w);
  for (int y = 50; y < 56; ++y)
    for (int x = 100; x < 110; ++x) want[size_t(y) * w + size_t(x)] = 0xFFFFFF;
  EXPECT_TRUE(pic == want);
}

// ---- the emulator's decoding errors ----

TEST(PanelEmulatorErrors, UnknownCommand) {
  PanelEmulator tft(PanelKind::Ili9341, 0);
  const uint8_t op = 0xD9;  // not in the modelled set
  EXPECT_FALSE(tft.write_command(&op, 1));
  EXPECT_NE(tft.error().find("unknown command 0xD9"), std::string::npos) << tft.error();
  PanelEmulator oled(PanelKind::Ssd0323, 0);
  const uint8_t bad = 0x24;
  EXPECT_FALSE(oled.write_command(&bad, 1));
  EXPECT_NE(oled.error().find("unknown command"), std::string::npos);
  PanelEmulator mono(PanelKind::Ssd1306, 0);
  const uint8_t nope = 0x9F;
  EXPECT_FALSE(mono.write_command(&nope, 1));
  EXPECT_FALSE(mono.ok());
}

TEST(PanelEmulatorErrors, MissingParameters) {
  PanelEmulator tft(PanelKind::St7789, 0);
  const uint8_t caset = 0x2A, params[2] = {0, 0}, ramwr = 0x2C;
  EXPECT_TRUE(tft.write_command(&caset, 1));
  EXPECT_TRUE(tft.write_data(params, 2));
  EXPECT_FALSE(tft.write_command(&ramwr, 1));
  EXPECT_NE(tft.error().find("parameters missing for command 0x2A"), std::string::npos) << tft.error();
  PanelEmulator oled(PanelKind::Ssd1306, 0);
  const uint8_t window[2] = {0x21, 0x00};  // 0x21 takes two
  const uint8_t pixels[1] = {0xFF};
  EXPECT_TRUE(oled.write_command(window, 2));
  EXPECT_FALSE(oled.write_data(pixels, 1));
  EXPECT_NE(oled.error().find("parameters missing"), std::string::npos) << oled.error();
}

TEST(PanelEmulatorErrors, PixelsBeforeRamwrAndOutsideTheWindow) {
  std::string error;
  auto e = mlpanels::open_emulated_panel("ili9341", 0, &error);
  ASSERT_TRUE(e) << error;
  const uint8_t px[2] = {0x12, 0x34};
  EXPECT_FALSE(e->emulator.write_data(px, 2));
  EXPECT_NE(e->emulator.error().find("before RAMWR"), std::string::npos) << e->emulator.error();

  auto f = mlpanels::open_emulated_panel("ili9341", 0, &error);
  ASSERT_TRUE(f) << error;
  mlpanels::Bus bus(f->emulator, 0, nullptr);
  ASSERT_TRUE(f->panel.begin_window(bus, 10, 10, 2, 2));
  const uint8_t four[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_TRUE(f->emulator.write_data(four, 8));
  EXPECT_TRUE(f->emulator.ok());
  EXPECT_FALSE(f->emulator.write_data(px, 2));
  EXPECT_NE(f->emulator.error().find("beyond the window"), std::string::npos) << f->emulator.error();

  // A window past the RAM for the current MADCTL.
  auto g = mlpanels::open_emulated_panel("ili9341", 0, &error);
  ASSERT_TRUE(g) << error;
  const uint8_t caset = 0x2A, cols[4] = {0, 0, 0x01, 0x3F}, raset = 0x2B, rows[4] = {0, 0, 0, 9}, ramwr = 0x2C;
  ASSERT_TRUE(g->emulator.write_command(&caset, 1) && g->emulator.write_data(cols, 4));
  ASSERT_TRUE(g->emulator.write_command(&raset, 1) && g->emulator.write_data(rows, 4));
  EXPECT_FALSE(g->emulator.write_command(&ramwr, 1));
  EXPECT_NE(g->emulator.error().find("outside the controller's RAM"), std::string::npos) << g->emulator.error();

  // SSD1306: more bytes than the page window holds.
  auto s = mlpanels::open_emulated_panel("ssd1306", 0, &error);
  ASSERT_TRUE(s) << error;
  mlpanels::Bus sbus(s->emulator, 0, nullptr);
  ASSERT_TRUE(s->panel.begin_window(sbus, 0, 0, 4, 8));
  const uint8_t five[5] = {1, 2, 3, 4, 5};
  EXPECT_FALSE(s->emulator.write_data(five, 5));
  EXPECT_NE(s->emulator.error().find("beyond the window"), std::string::npos) << s->emulator.error();
}

TEST(PanelEmulatorErrors, HalfPixelResetAndColmod) {
  std::string error;
  auto e = mlpanels::open_emulated_panel("st7789", 0, &error);
  ASSERT_TRUE(e) << error;
  mlpanels::Bus bus(e->emulator, 0, nullptr);
  ASSERT_TRUE(e->panel.begin_window(bus, 0, 0, 1, 1));
  const uint8_t one = 0xAB, nop = 0x00;
  EXPECT_TRUE(e->emulator.write_data(&one, 1));
  EXPECT_FALSE(e->emulator.write_command(&nop, 1));
  EXPECT_NE(e->emulator.error().find("half a pixel"), std::string::npos);

  PanelEmulator raw(PanelKind::Ili9341, 0);
  raw.set_reset(false);
  EXPECT_FALSE(raw.write_command(&nop, 1));
  EXPECT_NE(raw.error().find("RESET"), std::string::npos);

  PanelEmulator cold(PanelKind::Ili9341, 0);  // never got COLMOD: 18-bit default
  const uint8_t ramwr = 0x2C;
  EXPECT_FALSE(cold.write_command(&ramwr, 1));
  EXPECT_NE(cold.error().find("COLMOD"), std::string::npos);
  EXPECT_FALSE(cold.display_on());
}

TEST(PanelEmulatorModel, MadctlMapsIntoNativeRam) {
  // At rotation 90 the ILI9341 (MADCTL MV|BGR) stores logical (x, y) at RAM column y, row x.
  std::string error;
  auto e = mlpanels::open_emulated_panel("ili9341", 90, &error);
  ASSERT_TRUE(e) << error;
  EXPECT_EQ(e->panel.orientation_byte(), mlpanels::kMadctlMV | mlpanels::kMadctlBGR);
  mlpanels::Bus bus(e->emulator, 0, nullptr);
  ASSERT_TRUE(e->panel.begin_window(bus, 300, 7, 1, 1));
  const uint8_t px[2] = {0xF8, 0x00};
  ASSERT_TRUE(e->emulator.write_data(px, 2));
  EXPECT_EQ(e->emulator.ram(7, 300), 0xF800u);
  EXPECT_EQ(e->emulator.picture()[7 * 320 + 300], 0xFF0000u);  // red, upright
}

TEST(PanelEmulatorModel, St7789At240UsesTheRowOffset) {
  std::string error;
  auto e = mlpanels::open_emulated_panel("st7789-240", 0, &error);
  ASSERT_TRUE(e) << error;
  mlpanels::Bus bus(e->emulator, 0, nullptr);
  ASSERT_TRUE(e->panel.begin_window(bus, 0, 0, 1, 1));
  const uint8_t px[2] = {0x07, 0xE0};
  ASSERT_TRUE(e->emulator.write_data(px, 2));
  // MADCTL MX|MY: address (0, 80) is RAM column 239, row 239, the glass's last visible row.
  EXPECT_EQ(e->emulator.ram(239, 239), 0x07E0u);
  EXPECT_EQ(e->emulator.picture()[0], 0x00FF00u);
}

}  // namespace

namespace {

// Logs every byte with its D/C level, the RESET edges and the delays.
class LogTransport : public mlpanels::Transport {
 public:
  struct Byte {
    bool data;
    uint8_t value;
  };
  bool write_command(const uint8_t* b, size_t n) override {
    writes.push_back(std::vector<uint8_t>(b, b + n));
    for (size_t i = 0; i < n; ++i) bytes.push_back({false, b[i]});
    return true;
  }
  bool write_data(const uint8_t* b, size_t n) override {
    for (size_t i = 0; i < n; ++i) bytes.push_back({true, b[i]});
    return true;
  }
  bool set_reset(bool high) override {
    resets.push_back(high);
    return true;
  }
  void delay_ms(uint32_t ms) override { total_delay += ms; }
  std::vector<Byte> bytes;
  std::vector<std::vector<uint8_t>> writes;  // command writes
  std::vector<bool> resets;
  uint64_t total_delay = 0;
};

// The opcodes (D/C low bytes) of a TFT stream, in order.
std::vector<uint8_t> opcodes(const LogTransport& t) {
  std::vector<uint8_t> out;
  for (const auto& b : t.bytes)
    if (!b.data) out.push_back(b.value);
  return out;
}

TEST(PanelInit, TftSequence) {
  for (const char* name : {"ili9341", "st7789"}) {
    Panel p;
    ASSERT_TRUE(mlpanels::make_panel(name, 270, &p));
    LogTransport log;
    mlpanels::PanelSink sink(p, log, 0);
    ASSERT_TRUE(sink.init());
    ASSERT_EQ(log.resets, (std::vector<bool>{true, false, true}));
    const auto ops = opcodes(log);
    std::vector<uint8_t> want = {0x01, 0x11, 0x3A, 0x36};
    if (std::string(name) == "st7789") want.push_back(0x21);
    want.push_back(0x13);
    want.push_back(0x29);
    EXPECT_EQ(ops, want) << name;
    // COLMOD 0x55 and the rotation's MADCTL as data bytes after their opcodes.
    bool colmod = false, madctl = false;
    for (size_t i = 0; i + 1 < log.bytes.size(); ++i) {
      if (!log.bytes[i].data && log.bytes[i].value == 0x3A) colmod = log.bytes[i + 1].data && log.bytes[i + 1].value == 0x55;
      if (!log.bytes[i].data && log.bytes[i].value == 0x36)
        madctl = log.bytes[i + 1].data && log.bytes[i + 1].value == p.orientation_byte();
    }
    EXPECT_TRUE(colmod && madctl) << name;
    EXPECT_GE(log.total_delay, 120u + 150u + 120u);
    EXPECT_EQ(sink.init_bytes(), log.bytes.size());
  }
}

TEST(PanelInit, OledFramesUseOnlyWindowCommands) {
  // QEMU's lm3s6965evb SSD0323 honours only 0x15, 0x75 and 0xA0: a frame must need nothing else.
  for (const char* name : {"ssd0323", "ssd1306"}) {
    Panel p;
    ASSERT_TRUE(mlpanels::make_panel(name, 0, &p));
    LogTransport log;
    mlpanels::PanelSink sink(p, log, 0);
    ASSERT_TRUE(sink.init());
    bool remap_sent = false;
    for (const auto& w : log.writes)
      for (size_t i = 0; i + 1 < w.size(); ++i)
        if (w[i] == 0xA0 && w[i + 1] == p.orientation_byte()) remap_sent = true;
    if (std::string(name) == "ssd0323") {
      EXPECT_TRUE(remap_sent);
    }
    log.writes.clear();
    ASSERT_TRUE(panel_test::send_frame(sink, p.format(), panel_test::pattern(128, 64), 128, 64, 16));
    ASSERT_EQ(log.writes.size(), 4u);
    for (const auto& w : log.writes) {
      ASSERT_EQ(w.size(), 6u);
      EXPECT_EQ(w[0], std::string(name) == "ssd0323" ? 0x15 : 0x21);
      EXPECT_EQ(w[3], std::string(name) == "ssd0323" ? 0x75 : 0x22);
    }
    EXPECT_EQ(log.writes[1][4], std::string(name) == "ssd0323" ? 16 : 2);  // second band's first row / page
  }
}

}  // namespace

namespace {

// One TFT command with its parameters.
bool tft(PanelEmulator& e, uint8_t op, std::initializer_list<uint8_t> params = {}) {
  const std::vector<uint8_t> p(params);
  return e.write_command(&op, 1) && (p.empty() || e.write_data(p.data(), p.size()));
}

TEST(PanelEmulatorModel, GlassColourOrderAndInversion) {
  std::string error;
  auto e = mlpanels::open_emulated_panel("ili9341", 0, &error);
  ASSERT_TRUE(e) << error;
  mlpanels::Bus bus(e->emulator, 0, nullptr);
  ASSERT_TRUE(e->panel.begin_window(bus, 0, 0, 1, 1));
  const uint8_t red[2] = {0xF8, 0x00};
  ASSERT_TRUE(e->emulator.write_data(red, 2));
  EXPECT_EQ(e->emulator.picture()[0], 0xFF0000u);
  // Without the BGR bit the ILI9341's BGR glass shows red as blue.
  ASSERT_TRUE(tft(e->emulator, 0x36, {mlpanels::kMadctlMX}));
  EXPECT_EQ(e->emulator.picture()[0], 0x0000FFu);
  ASSERT_TRUE(tft(e->emulator, 0x36, {e->panel.orientation_byte()}));
  ASSERT_TRUE(tft(e->emulator, 0x21));  // INVON
  EXPECT_EQ(e->emulator.picture()[0], 0x00FFFFu);
  ASSERT_TRUE(tft(e->emulator, 0x28));  // DISPOFF
  EXPECT_FALSE(e->emulator.display_on());
  EXPECT_EQ(e->emulator.picture()[0], 0u);

  // The ST7789's IPS glass needs INVON: without it every colour shows inverted.
  auto s = mlpanels::open_emulated_panel("st7789", 0, &error);
  ASSERT_TRUE(s) << error;
  mlpanels::Bus sbus(s->emulator, 0, nullptr);
  ASSERT_TRUE(s->panel.begin_window(sbus, 0, 0, 1, 1));
  ASSERT_TRUE(s->emulator.write_data(red, 2));
  EXPECT_EQ(s->emulator.picture()[0], 0xFF0000u);
  ASSERT_TRUE(tft(s->emulator, 0x20));  // INVOFF
  EXPECT_EQ(s->emulator.picture()[0], 0x00FFFFu);
}

TEST(PanelEmulatorModel, Ssd1306NeedsChargePumpAndDisplayOn) {
  PanelEmulator e(PanelKind::Ssd1306, 0);
  const uint8_t on[1] = {0xAF};
  ASSERT_TRUE(e.write_command(on, 1));
  EXPECT_FALSE(e.display_on());  // charge pump still off
  const uint8_t pump[2] = {0x8D, 0x14};
  ASSERT_TRUE(e.write_command(pump, 2));
  EXPECT_TRUE(e.display_on());
  // Page addressing mode (the reset default) is not modelled for data.
  const uint8_t px = 0xFF;
  EXPECT_FALSE(e.write_data(&px, 1));
  EXPECT_NE(e.error().find("addressing mode"), std::string::npos) << e.error();
  // Entire display on lights every pixel whatever the RAM holds.
  PanelEmulator f(PanelKind::Ssd1306, 180);
  const uint8_t all[4] = {0x8D, 0x14, 0xA5, 0xAF};
  ASSERT_TRUE(f.write_command(all, 4));
  for (ml::Pixel p : f.picture()) ASSERT_EQ(p, 0xFFFFFFu);
}

TEST(PanelEmulatorModel, Ssd0323VerticalIncrementAndRemap) {
  PanelEmulator e(PanelKind::Ssd0323, 0);
  // Vertical address increment (remap bit 2) with nibble remap: bytes go down a column first.
  const uint8_t setup[] = {0xA0, 0x56, 0x15, 0x02, 0x03, 0x75, 0x00, 0x01, 0xAF};
  ASSERT_TRUE(e.write_command(setup, sizeof setup));
  const uint8_t data[4] = {0x12, 0x34, 0x56, 0x78};
  ASSERT_TRUE(e.write_data(data, 4));
  EXPECT_EQ(e.ram(4, 0), 1u);  // byte column 2, row 0: pixels 4 (high nibble) and 5
  EXPECT_EQ(e.ram(5, 0), 2u);
  EXPECT_EQ(e.ram(4, 1), 3u);  // next byte went down to row 1
  EXPECT_EQ(e.ram(6, 0), 5u);  // then column 3, row 0
  EXPECT_EQ(e.ram(7, 1), 8u);
  EXPECT_FALSE(e.write_data(data, 1));  // window full
  // Column remap without nibble remap mirrors the pixels: byte column a lands at 126 - 2a, 127 - 2a.
  PanelEmulator m(PanelKind::Ssd0323, 180);
  const uint8_t mirror[] = {0xA0, 0x41, 0x15, 0x00, 0x00, 0x75, 0x05, 0x05};
  ASSERT_TRUE(m.write_command(mirror, sizeof mirror));
  const uint8_t one = 0x9A;
  ASSERT_TRUE(m.write_data(&one, 1));
  EXPECT_EQ(m.ram(127, 5), 9u);
  EXPECT_EQ(m.ram(126, 5), 10u);
}

}  // namespace

// maskline show: the emulated panels show what `render` draws in the panel's format, bit for bit;
// bus bytes and windows in --stats; animation; and one-line errors for bad or missing displays.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "platform/host/png_io.h"
#include "tests/cli/cli_runner.h"

namespace {

using clitest::run_cli;
using clitest::RunResult;
using clitest::expect_one_line_error;
using clitest::json_int;

using CliShow = clitest::TempDirTest;

std::vector<uint32_t> png(const std::string& file, int* w, int* h) {
  std::vector<uint32_t> px;
  EXPECT_EQ(mlhost::read_png(file, w, h, &px, false), "") << file;
  return px;
}

// The emulator decodes the bytes on the bus into exactly the picture `render` gives in the panel's
// format, for every panel and both renderers; the bus carries one window a band and little else.
TEST_F(CliShow, EmulatedPanelsShowTheRenderedFrameExactly) {
  struct Case {
    const char* panel;
    const char* size;
    const char* format;
    int bytes_per_pixel_x8;  // bits per pixel
  };
  for (const Case& c : {Case{"ili9341", "320x240", "rgb565", 16}, Case{"st7789", "240x320", "rgb565", 16},
                        Case{"ssd0323", "128x64", "grey4", 4}, Case{"ssd1306", "128x64", "mono1", 1}}) {
    for (const char* renderer : {"tiler", "scanline"}) {
      const std::string what = std::string(c.panel) + " " + renderer;
      const RunResult shown = run_cli({"show", "--display", std::string("emu:") + c.panel, "--size", c.size,
                                       "--renderer", renderer, "-o", path("shown.png"), "--stats"});
      ASSERT_EQ(shown.exit_code, 0) << what << ": " << shown.describe();
      const RunResult drawn = run_cli({"render", "--size", c.size, "--renderer", renderer, "--format", c.format,
                                       "-o", path("drawn.png")});
      ASSERT_EQ(drawn.exit_code, 0) << what << ": " << drawn.describe();
      int w1 = 0, h1 = 0, w2 = 0, h2 = 0;
      const auto a = png(path("shown.png"), &w1, &h1);
      const auto b = png(path("drawn.png"), &w2, &h2);
      EXPECT_EQ(w1, w2) << what;
      EXPECT_EQ(h1, h2) << what;
      EXPECT_TRUE(a == b) << what << ": the emulated panel differs from the render";
      const long long pixels = json_int(shown.out, "width") * json_int(shown.out, "height");
      EXPECT_EQ(json_int(shown.out, "display_windows"), json_int(shown.out, "bands")) << what;
      EXPECT_LE(json_int(shown.out, "display_bytes") * 8, pixels * c.bytes_per_pixel_x8 * 105 / 100) << what;
      EXPECT_GE(json_int(shown.out, "display_bytes") * 8, pixels * c.bytes_per_pixel_x8) << what;
    }
  }
}

TEST_F(CliShow, RotationFollowsTheSizeAndTheDefaultIsThePanelsOwn) {
  const RunResult portrait = run_cli({"show", "--display", "emu:ili9341", "-o", path("p.png")});
  ASSERT_EQ(portrait.exit_code, 0) << portrait.describe();
  EXPECT_NE(portrait.out.find("240x320 at rotation 0"), std::string::npos) << portrait.out;
  const RunResult landscape = run_cli({"show", "--display", "emu:ili9341", "--size", "320x240", "-o", path("l.png")});
  ASSERT_EQ(landscape.exit_code, 0) << landscape.describe();
  EXPECT_NE(landscape.out.find("320x240 at rotation 90"), std::string::npos) << landscape.out;
  int w = 0, h = 0;
  png(path("l.png"), &w, &h);
  EXPECT_EQ(w, 320);
  EXPECT_EQ(h, 240);
  const RunResult flipped = run_cli({"show", "--display", "emu:ili9341,rotation=270", "-o", path("f.png")});
  ASSERT_EQ(flipped.exit_code, 0) << flipped.describe();
  EXPECT_NE(flipped.out.find("at rotation 270"), std::string::npos) << flipped.out;
}

TEST_F(CliShow, AnimationWritesEveryFrameAndReportsTheRate) {
  const RunResult r = run_cli({"show", "--display", "emu:ssd0323", "--frames", "3", "--orbit", "40", "--zoom", "2",
                               "-o", path("f%d.png")});
  ASSERT_EQ(r.exit_code, 0) << r.describe();
  EXPECT_NE(r.out.find("3 frames in"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frames per second"), std::string::npos) << r.out;
  int w = 0, h = 0;
  const auto f0 = png(path("f0.png"), &w, &h);
  EXPECT_EQ(w, 256);
  EXPECT_EQ(h, 128);
  const auto f2 = png(path("f2.png"), &w, &h);
  EXPECT_FALSE(f0 == f2) << "the camera did not turn";
}

TEST_F(CliShow, BadOrMissingDisplaysGiveOneLine) {
  expect_one_line_error(run_cli({"show"}), 2, "no --display");
  expect_one_line_error(run_cli({"show", "--display", "bogus"}), 2, "malformed spec");
  expect_one_line_error(run_cli({"show", "--display", "vga:1"}), 2, "unknown kind");
  expect_one_line_error(run_cli({"show", "--display", "emu:nopanel"}), 1, "unknown panel");
  expect_one_line_error(run_cli({"show", "--display", "emu:ili9341", "--size", "100x100"}), 1, "size that fits no rotation");
  expect_one_line_error(run_cli({"show", "--display", "emu:ili9341,rotation=45"}), 1, "bad rotation");
  expect_one_line_error(run_cli({"show", "--display", "emu:ili9341", "--format", "grey4"}), 2, "format the panel does not take");
  expect_one_line_error(run_cli({"show", "--display", "fb:/dev/nonexistent-fb"}), 1, "missing framebuffer");
  expect_one_line_error(run_cli({"show", "--display", "fb:/dev/null"}), 1, "not a framebuffer");
  expect_one_line_error(run_cli({"show", "--display", "spi:ili9341,device=/dev/spidev9.9"}), 1, "missing spidev");
  expect_one_line_error(run_cli({"show", "--display", "spi:ili9341,speed=fast"}), 1, "bad spi option");
}

}  // namespace

// The host's checking sink and PNG files: the contract checks the CLI and the renderer tests rely on.
#include <gtest/gtest.h>

#include "core/pixel_format.h"
#include "platform/host/format_names.h"
#include "platform/host/image_sink.h"
#include "platform/host/png_stream_sink.h"
#include "platform/host/png_io.h"
#include "platform/host/stats_json.h"
#include "tests/cli/cli_runner.h"

namespace {

// A band of packed pixels, as a renderer would flush it.
struct Band {
  ml::PixelFormat format;
  int width, rows;
  std::vector<uint8_t> bytes;
  Band(ml::PixelFormat f, int w, int r) : format(f), width(w), rows(r), bytes(ml::format_band_bytes(f, w, r)) {}
  void fill(ml::Pixel p) {
    ml::PixelPacker packer;
    packer.init(format, false);
    packer.fill(bytes.data(), ml::format_stride(format, width), 0, 0, 0, width, rows, p);
  }
  ml::Flush at(int y, int height = -1) const {
    ml::Flush f;
    f.y = y;
    f.width = width;
    f.height = height < 0 ? rows : height;
    f.stride = ml::format_stride(format, width);
    f.bytes = bytes.data();
    return f;
  }
};

ml::FrameInfo frame(int w, int h, int band_rows, ml::PixelFormat f = ml::PixelFormat::Xrgb8888) {
  ml::FrameInfo info;
  info.width = w;
  info.height = h;
  info.band_rows = band_rows;
  info.format = f;
  return info;
}

TEST(CliImageSink, AcceptsBandsTopToBottomAndDecodes) {
  mlhost::ImageSink sink;
  ASSERT_TRUE(sink.begin_frame(frame(5, 5, 2)));
  Band band(ml::PixelFormat::Xrgb8888, 5, 2);
  band.fill(0x123456);
  EXPECT_TRUE(sink.flush(band.at(0)));
  EXPECT_FALSE(sink.lent(0));  // released before returning
  band.fill(0xABCDEF);
  EXPECT_TRUE(sink.flush(band.at(2)));
  band.fill(0x000001);
  EXPECT_TRUE(sink.flush(band.at(4, 1)));
  EXPECT_TRUE(sink.end_frame());
  EXPECT_TRUE(sink.contract_ok()) << sink.contract_error();
  EXPECT_EQ(sink.at(4, 1), 0x123456u);
  EXPECT_EQ(sink.at(0, 3), 0xABCDEFu);
  EXPECT_EQ(sink.at(2, 4), 0x000001u);
  EXPECT_EQ(sink.pixel_writes(), 25u);
  EXPECT_EQ(sink.flushes(), 3u);
  EXPECT_EQ(sink.counters.bytes, 100u);
  EXPECT_EQ(sink.counters.windows, 0u);  // memory has no address windows
}

TEST(CliImageSink, ReportsBandsOutOfOrderGapsAndUnwrittenPixels) {
  Band band(ml::PixelFormat::Xrgb8888, 4, 2);
  band.fill(1);
  mlhost::ImageSink skip;
  skip.begin_frame(frame(4, 4, 2));
  EXPECT_FALSE(skip.flush(band.at(2)));
  EXPECT_NE(skip.contract_error().find("next band is 4x2 at (0,0)"), std::string::npos) << skip.contract_error();

  mlhost::ImageSink gap;
  gap.begin_frame(frame(4, 4, 2));
  gap.flush(band.at(0));
  gap.end_frame();
  EXPECT_FALSE(gap.contract_ok());
  EXPECT_NE(gap.contract_error().find("2 row(s) never flushed"), std::string::npos) << gap.contract_error();

  // The sink poisons a band after reading it: a pixel left alone before the next flush shows.
  mlhost::ImageSink poison;
  poison.begin_frame(frame(4, 4, 2));
  band.fill(1);  // the sinks above poisoned it
  EXPECT_TRUE(poison.flush(band.at(0)));
  ml::PixelPacker packer;
  packer.init(ml::PixelFormat::Xrgb8888, false);
  packer.fill(band.bytes.data(), 16, 0, 0, 2, 4, 1, 7);
  packer.fill(band.bytes.data(), 16, 0, 1, 3, 3, 1, 7);  // misses pixel (3, 3)
  poison.flush(band.at(2));
  poison.end_frame();
  EXPECT_FALSE(poison.contract_ok());
  EXPECT_NE(poison.contract_error().find("(3,3) never written"), std::string::npos) << poison.contract_error();

  mlhost::ImageSink strict(true);
  strict.begin_frame(frame(2, 2, 1));
  EXPECT_FALSE(strict.flush(band.at(1, 1)));  // refused: the render aborts
}

TEST(CliImageSink, DecodesEveryFormat) {
  for (ml::PixelFormat f : {ml::PixelFormat::Rgb565Be, ml::PixelFormat::Rgb565Le, ml::PixelFormat::Grey8,
                            ml::PixelFormat::Grey4, ml::PixelFormat::Mono1, ml::PixelFormat::Id32}) {
    mlhost::ImageSink sink;
    const int rows = ml::format_row_unit(f) * 2;
    ASSERT_TRUE(sink.begin_frame(frame(7, rows, rows, f)));
    Band band(f, 7, rows);
    band.fill(0xFFFFFF);
    EXPECT_TRUE(sink.flush(band.at(0)));
    EXPECT_TRUE(sink.end_frame());
    EXPECT_TRUE(sink.contract_ok()) << sink.contract_error();
    EXPECT_EQ(sink.at(6, rows - 1), 0xFFFFFFu) << mlhost::format_name(f);
    EXPECT_EQ(sink.counters.bytes, ml::format_band_bytes(f, 7, rows));
  }
}

TEST(CliPngStream, WritesBandsAsTheyComeAndChecksTheirOrder) {
  const std::string dir = clitest::make_temp_dir();
  Band band(ml::PixelFormat::Rgb565Be, 3, 2);
  {
    mlhost::PngStreamSink sink(dir + "/s.png");
    ASSERT_TRUE(sink.begin_frame(frame(3, 3, 2, ml::PixelFormat::Rgb565Be)));
    band.fill(0xFF0000);
    EXPECT_TRUE(sink.flush(band.at(0)));
    band.fill(0x0000FF);
    EXPECT_TRUE(sink.flush(band.at(2, 1)));
    EXPECT_TRUE(sink.end_frame());
    EXPECT_EQ(sink.error(), "");
  }
  int w = 0, h = 0;
  std::vector<uint32_t> back;
  ASSERT_EQ(mlhost::read_png(dir + "/s.png", &w, &h, &back, false), "");
  ASSERT_EQ(back.size(), 9u);
  EXPECT_EQ(back[0], 0xFF0000u);
  EXPECT_EQ(back[8], 0x0000FFu);
  mlhost::PngStreamSink bad(dir + "/b.png");
  ASSERT_TRUE(bad.begin_frame(frame(3, 3, 2, ml::PixelFormat::Rgb565Be)));
  EXPECT_FALSE(bad.flush(band.at(1)));
  EXPECT_NE(bad.error().find("next band"), std::string::npos) << bad.error();
  mlhost::PngStreamSink nowhere("/nonexistent-dir/x.png");
  EXPECT_FALSE(nowhere.begin_frame(frame(3, 3, 2)));
  EXPECT_NE(nowhere.error().find("/nonexistent-dir/x.png"), std::string::npos);
  clitest::remove_tree(dir);
}

TEST(CliPng, RgbAndIdImagesRoundTrip) {
  const std::string dir = clitest::make_temp_dir();
  const std::vector<uint32_t> colour = {0x102030, 0xFFFFFF, 0x000000, 0xABCDEF, 0x00FF00, 0x123456};
  ASSERT_EQ(mlhost::write_png_rgb(dir + "/c.png", 3, 2, colour), "");
  int w = 0, h = 0;
  std::vector<uint32_t> back;
  ASSERT_EQ(mlhost::read_png(dir + "/c.png", &w, &h, &back, false), "");
  EXPECT_EQ(w, 3);
  EXPECT_EQ(h, 2);
  EXPECT_EQ(back, colour);
  const std::vector<uint32_t> ids = {0, 1, 256, 65537, 0x01020304, 0xFFFFFFFF};
  ASSERT_EQ(mlhost::write_png_rgba_le(dir + "/i.png", 2, 3, ids), "");
  ASSERT_EQ(mlhost::read_png(dir + "/i.png", &w, &h, &back, true), "");
  EXPECT_EQ(back, ids);
  EXPECT_NE(mlhost::write_png_rgb("/nonexistent-dir/x.png", 3, 2, colour), "");
  clitest::remove_tree(dir);
}

TEST(CliPng, WorkHeatmapIsMonotoneFromBlackToWhite) {
  const std::vector<uint32_t> work = {0, 1 << 14, 1 << 16, 1 << 18, 1 << 22};
  const auto px = mlhost::work_heatmap(work);
  EXPECT_EQ(px.front(), 0u);
  EXPECT_EQ(px.back(), 0xFFFFFFu);
  auto brightness = [](ml::Pixel p) { return ml::red_of(p) + ml::green_of(p) + ml::blue_of(p); };
  for (size_t i = 1; i < px.size(); ++i) {
    EXPECT_GE(brightness(px[i]) + 1, brightness(px[i - 1])) << i;  // the ramp never gets darker
    EXPECT_NE(px[i], px[i - 1]) << i;                              // distinct work, distinct colour
  }
}

TEST(CliStatsJson, CarriesRunInfoAndDerivedRatios) {
  ml::Stats s;
  s.cells_visited = 300;
  s.pixel_writes = 1200;
  mlhost::RunInfo run;
  run.width = 40;
  run.height = 30;
  run.renderer = "tiler";
  run.shading = "flat";
  run.scene = "a \"quoted\" name";
  run.bsp_split_ratio = 1.25;
  const std::string j = mlhost::stats_json(s, run);
  EXPECT_EQ(j.front(), '{');
  EXPECT_EQ(j.back(), '}');
  EXPECT_NE(j.find("\"size\":\"40x30\""), std::string::npos) << j;
  EXPECT_NE(j.find("\"cells_visited_per_pixel\":0.25"), std::string::npos) << j;
  EXPECT_NE(j.find("\"bsp_split_ratio\":1.25"), std::string::npos) << j;
  EXPECT_NE(j.find("\"pixel_writes\":1200"), std::string::npos) << j;
  EXPECT_NE(j.find("a \\\"quoted\\\" name"), std::string::npos) << j;
  EXPECT_EQ(j.find('\n'), std::string::npos);
}

}  // namespace

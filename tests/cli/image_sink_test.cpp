// The host's checking sink and PNG files: the contract checks the CLI and the renderer tests rely on.
#include <gtest/gtest.h>

#include "platform/host/image_sink.h"
#include "platform/host/png_io.h"
#include "platform/host/stats_json.h"
#include "tests/cli/cli_runner.h"

namespace {

TEST(CliImageSink, AcceptsEveryPixelOnceInAnyShape) {
  mlhost::ImageSink sink;
  ASSERT_TRUE(sink.begin_frame(5, 3));
  const ml::Pixel block[4] = {1, 2, 3, 4};
  EXPECT_TRUE(sink.write_block(0, 0, 2, 2, block, 2));
  EXPECT_TRUE(sink.fill_block(2, 0, 3, 2, 9));
  EXPECT_TRUE(sink.fill_block(0, 2, 5, 1, 7));
  EXPECT_TRUE(sink.end_frame());
  EXPECT_TRUE(sink.contract_ok()) << sink.contract_error();
  EXPECT_EQ(sink.at(1, 1), 4u);
  EXPECT_EQ(sink.at(4, 1), 9u);
  EXPECT_EQ(sink.at(3, 2), 7u);
  EXPECT_EQ(sink.pixel_writes(), 15u);
  EXPECT_FALSE(sink.rows_in_order());
}

TEST(CliImageSink, ReportsDoubleWritesGapsAndOutOfBounds) {
  mlhost::ImageSink twice;
  twice.begin_frame(4, 4);
  twice.fill_block(0, 0, 4, 4, 1);
  twice.fill_block(1, 2, 1, 1, 2);
  twice.end_frame();
  EXPECT_FALSE(twice.contract_ok());
  EXPECT_NE(twice.contract_error().find("(1,2) written twice"), std::string::npos) << twice.contract_error();
  EXPECT_EQ(twice.writes_at(1, 2), 2);

  mlhost::ImageSink gap;
  gap.begin_frame(4, 4);
  gap.fill_block(0, 0, 4, 3, 1);
  gap.end_frame();
  EXPECT_FALSE(gap.contract_ok());
  EXPECT_NE(gap.contract_error().find("4 pixel(s) never written"), std::string::npos) << gap.contract_error();

  mlhost::ImageSink outside;
  outside.begin_frame(4, 4);
  EXPECT_FALSE(outside.fill_block(3, 3, 2, 1, 1));
  EXPECT_FALSE(outside.contract_ok());

  mlhost::ImageSink strict(true);
  strict.begin_frame(2, 1);
  EXPECT_TRUE(strict.fill_block(0, 0, 1, 1, 1));
  EXPECT_FALSE(strict.fill_block(0, 0, 1, 1, 1));  // refused: the render aborts
}

TEST(CliImageSink, TracksRowsArrivingTopToBottom) {
  mlhost::ImageSink rows;
  rows.begin_frame(3, 2);
  const ml::Pixel row[3] = {1, 2, 3};
  rows.write_block(0, 0, 3, 1, row, 3);
  rows.write_block(0, 1, 3, 1, row, 3);
  rows.end_frame();
  EXPECT_TRUE(rows.contract_ok());
  EXPECT_TRUE(rows.rows_in_order());
  mlhost::ImageSink reversed;
  reversed.begin_frame(3, 2);
  reversed.write_block(0, 1, 3, 1, row, 3);
  reversed.write_block(0, 0, 3, 1, row, 3);
  EXPECT_FALSE(reversed.rows_in_order());
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

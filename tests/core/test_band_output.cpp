// The band seam (core/band.h, core/sink.h) under a display that sends asynchronously: buffers stay
// lent after flush() and come back later, as from a DMA-complete interrupt. The renderers must never
// write into a lent buffer, must use both buffers when given two, and must return only when every
// buffer is back.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/band.h"
#include "render/render.h"
#include "tiler/tiler.h"
#include "tests/tiler/tiler_test_util.h"

namespace {

// Keeps up to `depth` bands in flight; wait_for_flush() completes the oldest. Each band's bytes are
// copied at flush() and compared when released: any change means the renderer wrote while lent.
class AsyncSink : public mlhost::ImageSink {
 public:
  explicit AsyncSink(size_t depth) : depth_(depth) {}
  bool flush(const ml::Flush& band) override {
    InFlight f{band, std::vector<uint8_t>(band.bytes, band.bytes + band.stride * size_t(band.height))};
    buffers_used |= 1u << band.buffer;
    in_flight_.push_back(f);
    if (in_flight_.size() > depth_) complete_oldest();
    max_in_flight = std::max(max_in_flight, in_flight_.size());
    return true;
  }
  bool wait_for_flush() override {
    ++waits;
    if (in_flight_.empty()) return false;
    complete_oldest();
    return true;
  }
  bool end_frame() override {
    ended_with_lent = lent(0) || lent(1);
    return ImageSink::end_frame();
  }
  size_t max_in_flight = 0;
  int waits = 0;
  uint32_t buffers_used = 0;
  bool changed_while_lent = false, ended_with_lent = false;

 private:
  struct InFlight {
    ml::Flush band;
    std::vector<uint8_t> copy;
  };
  void complete_oldest() {
    InFlight f = in_flight_.front();
    in_flight_.erase(in_flight_.begin());
    if (!std::equal(f.copy.begin(), f.copy.end(), f.band.bytes)) changed_while_lent = true;
    // Decode and check the band as a synchronous sink would, then release it.
    ImageSink::flush(f.band);
  }
  size_t depth_;
  std::vector<InFlight> in_flight_;
};

TEST(BandOutput, AsyncDisplayNeverSeesItsBufferChangeAndGetsTwoInFlight) {
  std::mt19937 rng(9);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 80, 120));
  const ml::Camera cam = tiler_test::test_camera(96, 70);
  // The tiler also renders 16 rows (two bands) at once and the whole frame at once, each band lent in
  // place from the one buffer (core/band.h's render bands).
  for (auto [kind, at_once] : {std::pair<ml::RendererKind, int>{ml::RendererKind::Tiler, 0}, {ml::RendererKind::Tiler, 16},
                               {ml::RendererKind::Tiler, 72}, {ml::RendererKind::Scanline, 0}}) {
    for (int buffers : {1, 2}) {
      ml::RenderOptions o;
      o.renderer = kind;
      o.shading = ml::ShadingMode::Ids;
      o.output.band_rows = 8;
      o.output.buffers = buffers;
      o.output.render_rows = at_once;
      const size_t more = at_once ? ml::tiler_render_rows_bytes(cam, o, at_once) : 0;
      std::vector<uint8_t> mem(ml::render_arena_bytes(ts.scene, cam, o) + more, mlhost::kPoisonByte);
      ml::Arena arena(mem.data(), mem.size());
      AsyncSink sink{size_t(buffers)};
      ml::Stats stats;
      const ml::Status s = ml::render(ts.scene, cam, o, arena, sink, &stats);
      ASSERT_TRUE(s.ok()) << s.message;
      EXPECT_TRUE(sink.contract_ok()) << sink.contract_error();
      EXPECT_FALSE(sink.changed_while_lent);
      EXPECT_FALSE(sink.ended_with_lent);
      EXPECT_EQ(stats.bands, 9u);
      if (ml::kRenderBands) {
        EXPECT_EQ(stats.render_bands, at_once == 16 ? 5u : at_once ? 1u : 9u);
      }
      EXPECT_EQ(sink.buffers_used, buffers == 2 ? 3u : 1u);
      EXPECT_EQ(sink.max_in_flight, size_t(buffers));
      EXPECT_GT(sink.waits, 0);
    }
  }
}

// A display that never gives a buffer back fails the frame instead of hanging it.
TEST(BandOutput, DisplayThatNeverReleasesFailsTheFrame) {
  struct Hoarder : ml::Sink {
    bool flush(const ml::Flush&) override { return true; }
  };
  std::mt19937 rng(10);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 20, 120));
  const ml::Camera cam = tiler_test::test_camera(40, 40);
  ml::RenderOptions o;
  o.output.band_rows = 8;
  std::vector<uint8_t> mem(ml::render_arena_bytes(ts.scene, cam, o));
  ml::Arena arena(mem.data(), mem.size());
  Hoarder sink;
  EXPECT_EQ(ml::render(ts.scene, cam, o, arena, sink, nullptr).code, ml::StatusCode::SinkFailed);
}

// Scanline bands: any band height gives the one-band image.
TEST(BandOutput, ScanlineBandSplitGivesTheSameImage) {
  std::mt19937 rng(11);
  tiler_test::TestScene ts;
  ts.build(tiler_test::random_scene(rng, 80, 120));
  const ml::Camera cam = tiler_test::test_camera(97, 61);
  for (ml::ShadingMode mode : {ml::ShadingMode::Ids, ml::ShadingMode::Gouraud}) {
    std::vector<ml::Pixel> reference;
    for (int rows : {0, 1, 5, 16, 60}) {
      ml::RenderOptions o;
      o.renderer = ml::RendererKind::Scanline;
      o.shading = mode;
      o.aa = mode == ml::ShadingMode::Ids ? 1 : 3;
      o.output.band_rows = rows;
      std::vector<uint8_t> mem(ml::render_arena_bytes(ts.scene, cam, o), mlhost::kPoisonByte);
      ml::Arena arena(mem.data(), mem.size());
      mlhost::ImageSink sink;
      ml::Stats stats;
      ASSERT_TRUE(ml::render(ts.scene, cam, o, arena, sink, &stats).ok());
      ASSERT_TRUE(sink.contract_ok()) << sink.contract_error();
      if (rows == 0) reference = sink.pixels();
      else EXPECT_EQ(sink.pixels(), reference) << "band rows " << rows;
    }
  }
}

}  // namespace

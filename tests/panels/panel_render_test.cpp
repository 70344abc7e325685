// Real renders through PanelSink into the emulated panels: the picture each panel shows equals the
// renderer's Xrgb8888 frame quantized to the panel's format, bit for bit, for every panel, rotation
// and both renderers; and the bus carries at most 5% more than the pixels themselves.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/arena.h"
#include "core/pixel_format.h"
#include "platform/host/panel_emulator.h"
#include "platform/host/scene_load.h"
#include "render/render.h"
#include "tests/panels/panel_test_util.h"

namespace {

using panel_test::PanelCase;

const ml::Scene* bundled_scene() {
  static mlhost::LoadedScene scene;
  static int state = 0;  // 0 not tried, 1 loaded, 2 failed
  if (state == 0) {
    std::string error;
    state = mlhost::load_scene("", &scene, &error) ? 1 : 2;
    if (state == 2) ADD_FAILURE() << "bundled scene did not load: " << error;
  }
  return state == 1 ? &scene.scene : nullptr;
}

ml::Camera framing(const ml::Scene& scene, int w, int h) {
  const ml::SceneInfo& i = *scene.info;
  return ml::frame_sphere(ml::Vec3i{i.sphere_center[0], i.sphere_center[1], i.sphere_center[2]}, i.sphere_radius, w, h,
                          45 << 16);
}

// Keeps a whole frame of stored values, in any format.
class FrameSink : public ml::Sink {
 public:
  bool begin_frame(const ml::FrameInfo& f) override {
    info = f;
    stored.assign(size_t(f.width) * size_t(f.height), 0);
    return true;
  }
  bool flush(const ml::Flush& b) override {
    for (int r = 0; r < b.height; ++r)
      for (int x = 0; x < b.width; ++x)
        stored[size_t(b.y + r) * size_t(info.width) + size_t(b.x + x)] = ml::load_pixel(info.format, b.bytes, b.stride, x, r);
    flush_ready(b.buffer);
    return true;
  }
  ml::FrameInfo info;
  std::vector<uint32_t> stored;
};

ml::Status render_into(const ml::Scene& scene, const ml::Camera& cam, const ml::RenderOptions& o, ml::Sink& sink,
                       ml::Stats* stats) {
  const size_t bytes = ml::render_arena_bytes(scene, cam, o);
  std::vector<uint64_t> storage(bytes / 8 + 2);
  ml::Arena arena(storage.data(), storage.size() * 8);
  return ml::render(scene, cam, o, arena, sink, stats);
}

struct RenderCase {
  PanelCase panel;
  ml::RendererKind renderer;
};

void PrintTo(const RenderCase& c, std::ostream* os) {
  *os << c.panel.name << " at " << c.panel.rotation << (c.renderer == ml::RendererKind::Tiler ? " tiler" : " scanline");
}

std::vector<RenderCase> render_cases() {
  std::vector<RenderCase> out;
  for (const PanelCase& p : panel_test::all_cases())
    for (ml::RendererKind r : {ml::RendererKind::Tiler, ml::RendererKind::Scanline}) out.push_back({p, r});
  return out;
}

class PanelRender : public ::testing::TestWithParam<RenderCase> {};

TEST_P(PanelRender, PictureIsTheQuantizedFrame) {
  const RenderCase c = GetParam();
  const ml::Scene* scene = bundled_scene();
  ASSERT_TRUE(scene);
  std::string error;
  auto e = mlpanels::open_emulated_panel(c.panel.name, c.panel.rotation, &error);
  ASSERT_TRUE(e) << error;
  const int w = e->panel.width(), h = e->panel.height();
  const ml::PixelFormat f = e->panel.format();
  const ml::Camera cam = framing(*scene, w, h);

  ml::RenderOptions o;
  o.renderer = c.renderer;
  o.output.format = f;
  o.output.dither = false;
  // One buffer and 16-row bands; two buffers and 8-row bands; and with ordered dithering, which
  // depends on each pixel's frame position.
  for (int pass = 0; pass < 3; ++pass) {
    const int buffers = pass == 0 ? 1 : 2;
    const bool dither = pass == 2;
    o.output.buffers = buffers;
    o.output.band_rows = buffers == 1 ? 16 : 8;
    o.output.dither = dither;
    SCOPED_TRACE(dither ? "dithered" : buffers == 1 ? "one buffer" : "two buffers");
    e->emulator.reset_counts();
    ml::Stats stats;
    const ml::Status s = render_into(*scene, cam, o, e->sink, &stats);
    ASSERT_TRUE(s.ok()) << s.message << " / " << e->sink.error() << " / " << e->emulator.error();
    ASSERT_TRUE(e->emulator.ok()) << e->emulator.error();

    ml::RenderOptions ref_options = o;
    ref_options.output.format = ml::PixelFormat::Xrgb8888;
    FrameSink ref;
    ml::Stats ref_stats;
    const ml::Status rs = render_into(*scene, cam, ref_options, ref, &ref_stats);
    ASSERT_TRUE(rs.ok()) << rs.message;

    std::vector<ml::Pixel> want(ref.stored.size());
    for (size_t i = 0; i < want.size(); ++i)
      want[i] = ml::expand_stored(f, ml::quantize_pixel(f, ref.stored[i], dither, int(i % size_t(w)), int(i / size_t(w))));
    // The frame shows the scene, not just the background (Mono1 without dither lights only the
    // brightest surfaces).
    const ml::Pixel background = want[0];
    size_t scene_pixels = 0;
    for (ml::Pixel p : want) scene_pixels += p != background;
    EXPECT_GT(scene_pixels, f == ml::PixelFormat::Mono1 ? size_t(100) : want.size() / 20)
        << "the scene covers too little of the frame";
    const auto got = e->emulator.picture();
    ASSERT_EQ(got.size(), want.size());
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < got.size(); ++i)
      if (got[i] != want[i] && bad++ == 0) first = i;
    EXPECT_EQ(bad, 0u) << "first at (" << first % size_t(w) << ", " << first / size_t(w) << ")";

    const uint64_t pixel_bytes = uint64_t(w) * uint64_t(h) * uint64_t(ml::format_bits_per_pixel(f)) / 8;
    EXPECT_LE(double(e->sink.counters.bytes), 1.05 * double(pixel_bytes));
    EXPECT_EQ(e->emulator.bytes(), e->sink.counters.bytes);
    EXPECT_EQ(e->emulator.windows(), uint64_t(e->sink.counters.windows));
    EXPECT_EQ(stats.display_bytes, e->sink.counters.bytes);
    EXPECT_EQ(stats.display_windows, e->sink.counters.windows);
    EXPECT_EQ(e->emulator.data_bytes(), pixel_bytes);
  }
}

INSTANTIATE_TEST_SUITE_P(AllPanels, PanelRender, ::testing::ValuesIn(render_cases()),
                         [](const ::testing::TestParamInfo<RenderCase>& info) {
                           return panel_test::case_name(info.param.panel) +
                                  (info.param.renderer == ml::RendererKind::Tiler ? "_tiler" : "_scanline");
                         });

}  // namespace

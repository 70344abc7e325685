// Cortex-M0+ (ARMv6-M) build: the core and a minimal main that renders the configured frame into a
// sink computing a CRC-32 of the band bytes, prints it with the instruction count, and exits. Laid
// out for QEMU's `microbit` (nRF51822: 256 KB flash, 16 KB RAM), where it also runs.
#include "platform/cortex-m/common/app.h"
#include "core/pixel_format.h"

namespace {

// SysTick runs on the nRF51's 16 MHz core clock: under -icount shift=0 a tick is 62.5 instructions
// (render_frame is given 1, so it returns ticks; main scales them by 125 / 2).
constexpr uint32_t kInstructionsPerTick = 1;

class CrcSink : public ml::Sink {
 public:
  bool begin_frame(const ml::FrameInfo& f) override {
    row_bytes_ = ml::format_stride(f.format, f.width);
    return true;
  }
  bool flush(const ml::Flush& b) override {
    for (int r = 0; r < b.height; ++r) crc = ml::crc32(b.bytes + size_t(r) * b.stride, row_bytes_, crc);
    flush_ready(b.buffer);
    return true;
  }
  uint32_t crc = 0;

 private:
  uint32_t row_bytes_ = 0;
};

}  // namespace

int main() {
  fw::ticks_start();
  fw::print("firmware: m0plus\n");
  ml::Scene scene;
  if (!fw::load_scene(&scene)) return 1;
  const ml::Camera camera = fw::camera_for(scene);
  const ml::RendererKind k = (FW_RENDERERS & 1) ? ml::RendererKind::Tiler : ml::RendererKind::Scanline;
  ml::RenderOptions o = fw::options_for(k);
  ml::BlobTextureSource texels;
  fw::sample_texels_in_flash(scene, &texels, &o);
  CrcSink sink;
  ml::Stats stats;
  const uint64_t ticks = fw::render_frame(scene, camera, o, sink, &stats, kInstructionsPerTick);
  if (ticks == 0) return 1;
  fw::print("frame ");
  fw::print(fw::renderer_name(k));
  fw::print(" instructions ");
  fw::print_u64(ticks * 125 / 2);
  fw::print(" systick_ticks ");
  fw::print_u64(ticks);
  fw::print(" crc ");
  fw::print_hex32(sink.crc);
  fw::print("\n");
  fw::print_stats(k, stats, ticks * 125 / 2);
  fw::print_memory();
  return 0;
}

// lm3s6965evb firmware (Cortex-M3, 64 KB RAM, 256 KB flash, QEMU): the evaluation board's SSD0323
// OLED (128x64, 4-bit grey) on SSI0 through SsiTransport, the SSD0323 panel driver and PanelSink
// (platform/panels). Renders the configured frame (build/firmware/config/lm3s-*.h: one renderer,
// 128x64 Grey4 in 16-row bands) once into a sink that only gives the band back (the instruction
// count of the render alone) and once onto the OLED; prints the counts, stats and memory use and
// "frame shown", then waits (so the display can be captured; a semihosting exit would end QEMU).
#include "platform/cortex-m/common/app.h"
#include "platform/cortex-m/lm3s6965evb/ssi_transport.h"
#include "platform/panels/panel.h"
#include "platform/panels/panel_sink.h"

namespace {

// SysTick on the 12.5 MHz reset clock: under -icount shift=0 a tick is 80 instructions.
constexpr uint32_t kInstructionsPerTick = 80;

[[noreturn]] void halt() {
  for (;;) asm volatile("wfi");
}

}  // namespace

int main() {
  fw::ticks_start();
  fw::print("firmware: lm3s6965evb, cortex-m3, ssd0323 on ssi0\n");
  ml::Scene scene;
  if (!fw::load_scene(&scene)) return 1;
  mlpanels::Panel panel;
  if (!mlpanels::make_panel("ssd0323", 0, &panel) || panel.width() != FW_WIDTH || panel.height() != FW_HEIGHT) {
    fw::print("firmware: the configured size is not the panel's\n");
    return 1;
  }
  fw::SsiTransport transport;
  transport.init();
  mlpanels::PanelSink sink(panel, transport, 0);
  if (!sink.init()) {
    fw::print("firmware: panel init failed\n");
    return 1;
  }
  const ml::Camera camera = fw::camera_for(scene);
  const ml::RendererKind k = (FW_RENDERERS & 1) ? ml::RendererKind::Tiler : ml::RendererKind::Scanline;
  ml::RenderOptions o = fw::options_for(k);
  ml::BlobTextureSource texels;
  fw::sample_texels_in_flash(scene, &texels, &o);
  fw::print_kv("arena_needed", fw::arena_bytes_configured(scene, camera, o));

  ml::Stats stats;
  fw::NullSink null_sink;
  const uint64_t instructions = fw::render_frame(scene, camera, o, null_sink, &stats, kInstructionsPerTick);
  if (instructions == 0) return 1;
  ml::Stats shown;
  const uint64_t with_panel = fw::render_frame(scene, camera, o, sink, &shown, kInstructionsPerTick);
  if (with_panel == 0) {
    fw::print("firmware: panel: ");
    fw::print(sink.error());
    fw::print("\n");
    return 1;
  }
  fw::print("frame ");
  fw::print(fw::renderer_name(k));
  fw::print(" instructions ");
  fw::print_u64(instructions);
  fw::print(" with_panel ");
  fw::print_u64(with_panel);
  fw::print(" display_bytes ");
  fw::print_u64(shown.display_bytes);
  fw::print("\n");
  fw::print_stats(k, stats, instructions);
  fw::print_memory();
  fw::print("frame shown\n");
  halt();
}

// mps2-an385 firmware (Cortex-M3, QEMU): renders the configured frame (build/firmware/config/*.h,
// default 320x240 Rgb565Be) with each configured renderer, twice: once into a sink that only gives
// the band back (the instruction count of the render alone), once into a sink that writes the packed
// bytes of every band to the host file frame-RENDERER.raw through semihosting. Prints the counts,
// the frame's stats and the memory use, then exits (status 0 when every frame rendered).
#include "platform/cortex-m/common/app.h"
#include "core/pixel_format.h"

namespace {

// SysTick runs on the 25 MHz CPU clock: under -icount shift=0 (1 ns per instruction) a tick is 40
// instructions.
constexpr uint32_t kInstructionsPerTick = 40;

// Writes each band's packed rows (not the stride padding) to a host file.
class SemihostFileSink : public ml::Sink {
 public:
  explicit SemihostFileSink(int handle) : handle_(handle) {}
  bool begin_frame(const ml::FrameInfo& f) override {
    row_bytes_ = ml::format_stride(f.format, f.width);
    return handle_ >= 0;
  }
  bool flush(const ml::Flush& b) override {
    bool ok = true;
    if (b.stride == row_bytes_) {
      ok = fw::file_write(handle_, b.bytes, size_t(row_bytes_) * size_t(b.height));
    } else {
      for (int r = 0; r < b.height && ok; ++r) ok = fw::file_write(handle_, b.bytes + size_t(r) * b.stride, row_bytes_);
    }
    counters.bytes += uint64_t(row_bytes_) * uint64_t(b.height);
    flush_ready(b.buffer);
    return ok;
  }

 private:
  int handle_;
  uint32_t row_bytes_ = 0;
};

#ifdef FW_COUNT_CALLS
// Counters of common/call_count.S (this image links the core with -Wl,--wrap for these helpers).
extern "C" volatile uint32_t fw_calls___aeabi_ldivmod, fw_calls___aeabi_uldivmod, fw_calls___ctzdi2;
struct Calls {
  uint32_t ldivmod, uldivmod, ctzdi2;
};
Calls calls_now() { return Calls{fw_calls___aeabi_ldivmod, fw_calls___aeabi_uldivmod, fw_calls___ctzdi2}; }
void print_calls(ml::RendererKind k, const Calls& a, const Calls& b) {
  fw::print("calls ");
  fw::print(fw::renderer_name(k));
  fw::print(" __aeabi_ldivmod ");
  fw::print_u64(b.ldivmod - a.ldivmod);
  fw::print(" __aeabi_uldivmod ");
  fw::print_u64(b.uldivmod - a.uldivmod);
  fw::print(" __ctzdi2 ");
  fw::print_u64(b.ctzdi2 - a.ctzdi2);
  fw::print("\n");
}
#endif

}  // namespace

int main() {
  fw::ticks_start();
  fw::print("firmware: mps2-an385, cortex-m3\n");
  ml::Scene scene;
  const uint64_t load_start = fw::ticks_now();
  if (!fw::load_scene(&scene)) return 1;
  fw::print_kv("scene_load instructions", (fw::ticks_now() - load_start) * kInstructionsPerTick);
  const ml::Camera camera = fw::camera_for(scene);
  bool ok = true;
  const ml::RendererKind kinds[2] = {ml::RendererKind::Tiler, ml::RendererKind::Scanline};
  for (ml::RendererKind k : kinds) {
    if (!(FW_RENDERERS & (k == ml::RendererKind::Tiler ? 1 : 2))) continue;
    const ml::RenderOptions o = fw::options_for(k);
    fw::print_kv(k == ml::RendererKind::Tiler ? "arena_needed tiler" : "arena_needed scanline",
                 ml::render_arena_bytes(scene, camera, o));
    ml::Stats stats;
    fw::NullSink null_sink;
#ifdef FW_COUNT_CALLS
    const Calls before = calls_now();
#endif
    const uint64_t instructions = fw::render_frame(scene, camera, o, null_sink, &stats, kInstructionsPerTick);
#ifdef FW_COUNT_CALLS
    print_calls(k, before, calls_now());
#endif
    if (instructions == 0) {
      ok = false;
      continue;
    }
    const char* name = k == ml::RendererKind::Tiler ? "frame-tiler.raw" : "frame-scanline.raw";
    const int handle = fw::file_open_write(name);
    SemihostFileSink file_sink(handle);
    ml::Stats file_stats;
    const uint64_t with_output = fw::render_frame(scene, camera, o, file_sink, &file_stats, kInstructionsPerTick);
    if (handle >= 0) fw::file_close(handle);
    if (with_output == 0) {
      fw::print("firmware: could not write ");
      fw::print(name);
      fw::print("\n");
      ok = false;
      continue;
    }
    fw::print("frame ");
    fw::print(fw::renderer_name(k));
    fw::print(" instructions ");
    fw::print_u64(instructions);
    fw::print(" written ");
    fw::print(name);
    fw::print("\n");
    fw::print_stats(k, stats, instructions);
  }
  fw::print_memory();
  return ok ? 0 : 1;
}

// mps2-an385 firmware (Cortex-M3, QEMU): renders the configured frame (build/firmware/config/*.h,
// default 320x240 Rgb565Be) with each configured renderer, twice: once into a sink that only gives
// the band back (the instruction count of the render alone), once into a sink that writes the packed
// bytes of every band to the host file frame-RENDERER.raw through semihosting. Prints the counts,
// the frame's stats and the memory use, then exits (status 0 when every frame rendered).
#include "platform/cortex-m/common/app.h"
#include "core/pixel_format.h"
#ifdef FW_COUNT_CALLS
#include "platform/cortex-m/common/call_count.h"
#endif

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
// Lines "calls RENDERER HELPER N" and "caller RENDERER HELPER ADDRESS N" (return addresses; map them
// to functions with arm-none-eabi-addr2line -f -C -e mps2-an385-calls.elf).
void print_calls(ml::RendererKind k) {
  const fw::CallCounts& c = fw::call_counts();
  for (int h = 0; h < fw::kCountedHelpers; ++h) {
    fw::print("calls ");
    fw::print(fw::renderer_name(k));
    fw::print(" ");
    fw::print(fw::kCountedNames[h]);
    fw::print(" ");
    fw::print_u64(c.total[h]);
    fw::print("\n");
    for (const fw::CallSite& site : c.sites[h]) {
      if (site.count == 0) break;
      fw::print("caller ");
      fw::print(fw::renderer_name(k));
      fw::print(" ");
      fw::print(fw::kCountedNames[h]);
      fw::print(" ");
      fw::print_hex32(site.address);
      fw::print(" ");
      fw::print_u64(site.count);
      fw::print("\n");
    }
  }
}
#endif

#ifndef FW_COUNT_CALLS
// Instructions of one 64-bit signed division through __aeabi_ldivmod, with operands shaped like the
// projection's (a ~2^40 numerator, a ~2^20 divisor): a loop of divisions minus the same loop with an
// addition instead.
uint64_t ldivmod_instructions() {
  constexpr int kCalls = 4096;
  volatile int64_t n = (int64_t(123456789) << 10) + 77, d = (int64_t(1) << 20) + 12345;
  volatile int64_t sink = 0;
  const uint64_t t0 = fw::ticks_now();
  for (int i = 0; i < kCalls; ++i) sink = sink + n / (d + i);
  const uint64_t t1 = fw::ticks_now();
  for (int i = 0; i < kCalls; ++i) sink = sink + n + (d + i);
  const uint64_t t2 = fw::ticks_now();
  const uint64_t with = (t1 - t0) * kInstructionsPerTick, without = (t2 - t1) * kInstructionsPerTick;
  return with > without ? (with - without + kCalls / 2) / kCalls : 0;
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
    ml::RenderOptions o = fw::options_for(k);
    ml::BlobTextureSource texels;
    fw::sample_texels_in_flash(scene, &texels, &o);
    fw::print_kv(k == ml::RendererKind::Tiler ? "arena_needed tiler" : "arena_needed scanline",
                 fw::arena_bytes_configured(scene, camera, o));
    ml::Stats stats;
    fw::NullSink null_sink;
#ifdef FW_COUNT_CALLS
    fw::reset_call_counts();
#endif
    const uint64_t instructions = fw::render_frame(scene, camera, o, null_sink, &stats, kInstructionsPerTick);
#ifdef FW_COUNT_CALLS
    print_calls(k);
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
#ifndef FW_COUNT_CALLS
  fw::print_kv("ldivmod instructions_per_call", ldivmod_instructions());
#endif
  fw::print_memory();
  return ok ? 0 : 1;
}

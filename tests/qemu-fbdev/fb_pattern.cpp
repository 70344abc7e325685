// Guest side of the QEMU framebuffer test: draws the frames of pattern.h into a framebuffer through
// the fbdev sink, band by band as the renderers do (core/band.h), then prints one line
//   FBTEST READY <width> <height> <bpp> <format> <direct|converted>
// or FBTEST ERROR <message>. Built static; runs as the guest's /init payload.
//   fb_pattern [--pan] [DEVICE]   (default /dev/fb0; --pan: pan to the bottom of the virtual screen first)
//   fb_pattern --info [DEVICE]    draws nothing: waits 300 ms, prints the READY line (after another
//                                 program drew)
#include <fcntl.h>
#include <linux/fb.h>
#include <linux/kd.h>
#include <stdio.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "core/arena.h"
#include "core/band.h"
#include "platform/linux/fbdev/fbdev_sink.h"
#include "tests/qemu-fbdev/pattern.h"

namespace {

const char* format_name(ml::PixelFormat f) {
  switch (f) {
    case ml::PixelFormat::Rgb565Le: return "rgb565le";
    case ml::PixelFormat::Xrgb8888: return "xrgb8888";
    default: return "other";
  }
}

// Draws a w x h frame of `pattern` through BandOutput: bands of `band_rows`, two buffers.
bool draw(mlfb::FbdevSink& sink, int w, int h, int band_rows, ml::Pixel (*pattern)(int, int), std::string* error) {
  ml::OutputOptions out;
  out.format = sink.format();
  out.band_rows = band_rows;
  out.buffers = 2;
  std::vector<uint8_t> memory(ml::BandOutput::arena_bytes(out, w, h));
  ml::Arena arena(memory.data(), memory.size());
  ml::BandOutput bands;
  ml::Status s = bands.begin(out, w, h, arena, sink);
  std::vector<ml::Pixel> row(static_cast<size_t>(w), 0);
  for (int band = 0; s.ok() && band < bands.band_count(); ++band) {
    s = bands.start_band(band);
    for (int y = bands.band_top(band); s.ok() && y < bands.band_top(band) + bands.band_height(band); ++y) {
      for (int x = 0; x < w; ++x) row[size_t(x)] = pattern(x, y);
      bands.put_row(0, y, row.data(), w);
    }
    if (s.ok()) s = bands.finish_band();
  }
  if (s.ok()) s = bands.end();
  if (!s.ok()) *error = sink.last_error().empty() ? s.message : sink.last_error();
  return s.ok();
}

// Pans the display to the bottom of the virtual screen (FBIOPAN_DISPLAY), so the sink must honour
// yoffset for the picture to show.
bool pan_to_bottom(const std::string& device, std::string* error) {
  const int fd = open(device.c_str(), O_RDWR);
  fb_var_screeninfo var{};
  if (fd < 0 || ioctl(fd, FBIOGET_VSCREENINFO, &var) != 0) {
    *error = device + ": cannot read the screen info to pan";
    if (fd >= 0) close(fd);
    return false;
  }
  if (var.yres_virtual < 2 * var.yres) {
    // Ask for a virtual screen twice the visible height (legacy drivers such as cirrusfb allow it).
    var.yres_virtual = 2 * var.yres;
    if (ioctl(fd, FBIOPUT_VSCREENINFO, &var) != 0) ioctl(fd, FBIOGET_VSCREENINFO, &var);
  }
  if (var.yres_virtual < 2 * var.yres) {
    *error = "no room to pan: virtual height " + std::to_string(var.yres_virtual) + " for " + std::to_string(var.yres) + " rows";
    close(fd);
    return false;
  }
  var.xoffset = 0;
  var.yoffset = var.yres_virtual - var.yres;
  const bool ok = ioctl(fd, FBIOPAN_DISPLAY, &var) == 0;
  if (!ok) *error = device + ": FBIOPAN_DISPLAY failed";
  close(fd);
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  bool pan = false, info = false;
  std::string device = "/dev/fb0";
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--pan") pan = true;
    else if (std::string(argv[i]) == "--info") info = true;
    else device = argv[i];
  }
  // Keep the console from drawing over the picture.
  const int tty = open("/dev/tty0", O_RDWR);
  if (tty >= 0) {
    ioctl(tty, KDSETMODE, KD_GRAPHICS);
    close(tty);
  }
  std::string error;
  if (pan && !pan_to_bottom(device, &error)) {
    printf("FBTEST ERROR %s\n", error.c_str());
    return 1;
  }
  auto sink = mlfb::open_fbdev(device, &error);
  if (!sink) {
    printf("FBTEST ERROR %s\n", error.c_str());
    return 1;
  }
  printf("FBTEST SCREEN %s\n", sink->describe().c_str());
  if (info) {
    // Somebody else drew: only wait for the display to catch up and say what the screen is.
    usleep(300000);
    printf("FBTEST READY %d %d %d %s %s\n", sink->width(), sink->height(), sink->bits_per_pixel(),
           format_name(sink->format()), sink->direct_copy() ? "direct" : "converted");
    return 0;
  }
  if (!draw(*sink, sink->width(), sink->height(), 16, fbtest::pattern_a, &error) ||
      !draw(*sink, fbtest::kSmallWidth, fbtest::kSmallHeight, 10, fbtest::pattern_b, &error)) {
    printf("FBTEST ERROR %s\n", error.c_str());
    return 1;
  }
  // A frame larger than the screen must be refused with the documented message.
  ml::FrameInfo big;
  big.width = sink->width() + 1;
  big.height = 1;
  big.format = sink->format();
  if (sink->begin_frame(big) || sink->last_error().find("larger than the screen") == std::string::npos) {
    printf("FBTEST ERROR a frame wider than the screen was not refused\n");
    return 1;
  }
  fflush(stdout);
  // DRM fbdev emulation copies to the display some 50 ms after a write.
  usleep(300000);
  printf("FBTEST READY %d %d %d %s %s\n", sink->width(), sink->height(), sink->bits_per_pixel(),
         format_name(sink->format()), sink->direct_copy() ? "direct" : "converted");
  fflush(stdout);
  return 0;
}

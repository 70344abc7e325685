// The Linux framebuffer sink (platform/linux/fbdev): error messages of open_fbdev, and the copy and
// conversion into an in-memory "framebuffer" described by var/fix info, driven through BandOutput as
// the renderers drive it.
#include <gtest/gtest.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "core/arena.h"
#include "core/band.h"
#include "core/pixel_format.h"
#include "platform/linux/fbdev/fbdev_sink.h"

namespace {

using ml::PixelFormat;

bool one_line(const std::string& s) { return !s.empty() && s.find('\n') == std::string::npos; }

TEST(FbdevOpen, MissingDeviceSaysNoSuchDevice) {
  std::string error;
  EXPECT_EQ(mlfb::open_fbdev("/dev/nonexistent", &error), nullptr);
  EXPECT_EQ(error, "/dev/nonexistent: no such device");
}

TEST(FbdevOpen, RegularFileIsNotAFramebuffer) {
  char path[] = "/tmp/maskline-fbdev-XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(write(fd, "not a screen", 12), 12);
  close(fd);
  std::string error;
  EXPECT_EQ(mlfb::open_fbdev(path, &error), nullptr);
  unlink(path);
  EXPECT_TRUE(one_line(error)) << error;
  EXPECT_EQ(error.rfind(std::string(path) + ": not a framebuffer", 0), 0u) << error;
}

TEST(FbdevOpen, DevNullIsNotAFramebuffer) {
  std::string error;
  EXPECT_EQ(mlfb::open_fbdev("/dev/null", &error), nullptr);
  EXPECT_TRUE(one_line(error)) << error;
  EXPECT_EQ(error.rfind("/dev/null: not a framebuffer", 0), 0u) << error;
}

TEST(FbdevOpen, NullErrorPointerIsAllowed) { EXPECT_EQ(mlfb::open_fbdev("/dev/nonexistent", nullptr), nullptr); }

TEST(FbdevOpen, UnreadableDeviceSaysPermissionDenied) {
  char path[] = "/tmp/maskline-fbdev-XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  close(fd);
  chmod(path, 0);
  // Root opens any file: try as an unprivileged user in a child process then.
  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    close(pipe_fds[0]);
    if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) _exit(2);
    std::string error;
    const bool opened = mlfb::open_fbdev(path, &error) != nullptr;
    if (opened) error = "opened";
    const ssize_t n = write(pipe_fds[1], error.data(), error.size());
    _exit(n == ssize_t(error.size()) ? 0 : 3);
  }
  close(pipe_fds[1]);
  std::string error;
  char buf[256];
  ssize_t n;
  while ((n = read(pipe_fds[0], buf, sizeof buf)) > 0) error.append(buf, size_t(n));
  close(pipe_fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  unlink(path);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_EQ(error, std::string(path) + ": permission denied (is the user in the video group?)");
}

// ---- an in-memory framebuffer ----------------------------------------------------------------

struct Screen {
  fb_var_screeninfo var{};
  fb_fix_screeninfo fix{};
  std::vector<uint8_t> memory;
};

// A w x h visible screen inside a virtual one `pad` pixels larger each way, with `slack` extra bytes
// per line, panned to (xoff, yoff).
Screen make_screen(int bpp, fb_bitfield r, fb_bitfield g, fb_bitfield b, int w, int h, int xoff = 0, int yoff = 0,
                   int pad = 0, int slack = 0) {
  Screen s;
  s.var.xres = uint32_t(w);
  s.var.yres = uint32_t(h);
  s.var.xres_virtual = uint32_t(w + pad);
  s.var.yres_virtual = uint32_t(h + pad);
  s.var.xoffset = uint32_t(xoff);
  s.var.yoffset = uint32_t(yoff);
  s.var.bits_per_pixel = uint32_t(bpp);
  s.var.red = r;
  s.var.green = g;
  s.var.blue = b;
  s.fix.type = FB_TYPE_PACKED_PIXELS;
  s.fix.visual = FB_VISUAL_TRUECOLOR;
  s.fix.line_length = uint32_t((w + pad) * bpp / 8 + slack);
  s.fix.smem_len = s.fix.line_length * uint32_t(h + pad);
  s.memory.assign(s.fix.smem_len, 0xAB);
  return s;
}

fb_bitfield bf(uint32_t offset, uint32_t length) {
  fb_bitfield f{};
  f.offset = offset;
  f.length = length;
  return f;
}

std::unique_ptr<mlfb::FbdevSink> attach(Screen& s, std::string* error) {
  return mlfb::attach_fbdev_memory(s.memory.data(), s.memory.size(), s.var, s.fix, "mem", error);
}

// Reads the framebuffer word of visible pixel (x, y).
uint32_t word_at(const Screen& s, int x, int y) {
  const int bytes = int(s.var.bits_per_pixel / 8);
  const uint8_t* at = s.memory.data() + (y + int(s.var.yoffset)) * s.fix.line_length + (x + int(s.var.xoffset)) * bytes;
  uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= uint32_t(at[i]) << (8 * i);
  return v;
}

ml::Pixel pattern(int x, int y) { return ml::rgb(uint32_t(x * 37 + y) & 255, uint32_t(y * 11) & 255, uint32_t(x ^ y) & 255); }

// Draws a w x h pattern frame through BandOutput, as a renderer does.
void draw(mlfb::FbdevSink& sink, PixelFormat format, int w, int h, int band_rows, int buffers = 1) {
  ml::OutputOptions out;
  out.format = format;
  out.band_rows = band_rows;
  out.buffers = buffers;
  std::vector<uint8_t> arena_bytes(ml::BandOutput::arena_bytes(out, w, h));
  ml::Arena arena(arena_bytes.data(), arena_bytes.size());
  ml::BandOutput bands;
  ASSERT_TRUE(bands.begin(out, w, h, arena, sink).ok());
  std::vector<ml::Pixel> row(size_t(w), 0);
  for (int band = 0; band < bands.band_count(); ++band) {
    ASSERT_TRUE(bands.start_band(band).ok());
    for (int y = bands.band_top(band); y < bands.band_top(band) + bands.band_height(band); ++y) {
      for (int x = 0; x < w; ++x) row[size_t(x)] = pattern(x, y);
      bands.put_row(0, y, row.data(), w);
    }
    ASSERT_TRUE(bands.finish_band().ok()) << sink.last_error();
  }
  ASSERT_TRUE(bands.end().ok());
}

uint32_t scale(uint32_t v, uint32_t length) { return (v * ((1u << length) - 1) + 127) / 255; }

TEST(FbdevMemory, Rgb565IsCopiedAsIs) {
  Screen s = make_screen(16, bf(11, 5), bf(5, 6), bf(0, 5), 40, 30);
  std::string error;
  auto sink = attach(s, &error);
  ASSERT_TRUE(sink) << error;
  EXPECT_EQ(sink->format(), PixelFormat::Rgb565Le);
  EXPECT_TRUE(sink->direct_copy());
  EXPECT_EQ(sink->width(), 40);
  EXPECT_EQ(sink->height(), 30);
  draw(*sink, sink->format(), 40, 30, 7);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x)
      ASSERT_EQ(word_at(s, x, y), ml::quantize_pixel(PixelFormat::Rgb565Le, pattern(x, y), false, x, y)) << x << "," << y;
  EXPECT_EQ(sink->counters.bytes, 40u * 30u * 2u);
  EXPECT_EQ(sink->counters.windows, 0u);
}

TEST(FbdevMemory, Xrgb8888IsCopiedAsIsWithPanningAndLongLines) {
  Screen s = make_screen(32, bf(16, 8), bf(8, 8), bf(0, 8), 33, 21, 5, 3, 10, 12);
  std::string error;
  auto sink = attach(s, &error);
  ASSERT_TRUE(sink) << error;
  EXPECT_EQ(sink->format(), PixelFormat::Xrgb8888);
  EXPECT_TRUE(sink->direct_copy());
  draw(*sink, sink->format(), 33, 21, 4, 2);
  for (int y = 0; y < 21; ++y)
    for (int x = 0; x < 33; ++x) ASSERT_EQ(word_at(s, x, y), pattern(x, y)) << x << "," << y;
  // Outside the visible screen nothing changed.
  EXPECT_EQ(s.memory[0], 0xAB);
  EXPECT_EQ(s.memory[s.memory.size() - 1], 0xAB);
  EXPECT_EQ(sink->counters.bytes, 33u * 21u * 4u);
}

TEST(FbdevMemory, SmallFrameIsCentredAndTheRestUntouched) {
  Screen s = make_screen(32, bf(16, 8), bf(8, 8), bf(0, 8), 20, 11);
  auto sink = attach(s, nullptr);
  ASSERT_TRUE(sink);
  sink->clear(0x123456);
  draw(*sink, PixelFormat::Xrgb8888, 7, 4, 3);
  EXPECT_EQ(sink->frame_x(), 6);
  EXPECT_EQ(sink->frame_y(), 3);
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 20; ++x) {
      const bool in = x >= 6 && x < 13 && y >= 3 && y < 7;
      ASSERT_EQ(word_at(s, x, y), in ? pattern(x - 6, y - 3) : 0x123456u) << x << "," << y;
    }
}

TEST(FbdevMemory, TwentyFourBitsAreConverted) {
  Screen s = make_screen(24, bf(16, 8), bf(8, 8), bf(0, 8), 17, 9, 0, 0, 0, 1);
  auto sink = attach(s, nullptr);
  ASSERT_TRUE(sink);
  EXPECT_EQ(sink->format(), PixelFormat::Xrgb8888);
  EXPECT_FALSE(sink->direct_copy());
  draw(*sink, sink->format(), 17, 9, 4);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 17; ++x) ASSERT_EQ(word_at(s, x, y), pattern(x, y)) << x << "," << y;
  EXPECT_EQ(sink->counters.bytes, 17u * 9u * 3u);
}

TEST(FbdevMemory, BgrAndAlphaLayoutsAreConverted) {
  Screen s = make_screen(32, bf(0, 8), bf(8, 8), bf(16, 8), 9, 5);
  s.var.transp = bf(24, 8);
  auto sink = attach(s, nullptr);
  ASSERT_TRUE(sink);
  EXPECT_EQ(sink->format(), PixelFormat::Xrgb8888);
  EXPECT_FALSE(sink->direct_copy());
  draw(*sink, sink->format(), 9, 5, 2);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 9; ++x) {
      const ml::Pixel p = pattern(x, y);
      ASSERT_EQ(word_at(s, x, y), 0xFF000000u | ml::blue_of(p) << 16 | ml::green_of(p) << 8 | ml::red_of(p));
    }
}

TEST(FbdevMemory, Rgb555IsConvertedWithRounding) {
  Screen s = make_screen(16, bf(10, 5), bf(5, 5), bf(0, 5), 12, 6);
  auto sink = attach(s, nullptr);
  ASSERT_TRUE(sink);
  EXPECT_EQ(sink->format(), PixelFormat::Xrgb8888);
  draw(*sink, sink->format(), 12, 6, 6);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 12; ++x) {
      const ml::Pixel p = pattern(x, y);
      ASSERT_EQ(word_at(s, x, y), scale(ml::red_of(p), 5) << 10 | scale(ml::green_of(p), 5) << 5 | scale(ml::blue_of(p), 5));
    }
}

TEST(FbdevMemory, OtherFrameFormatsAreExpandedThenConverted) {
  // A Grey8 frame on a 32-bit screen: each grey level lands as r = g = b.
  Screen s = make_screen(32, bf(16, 8), bf(8, 8), bf(0, 8), 8, 8);
  auto sink = attach(s, nullptr);
  ASSERT_TRUE(sink);
  draw(*sink, PixelFormat::Grey8, 8, 8, 3);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const uint32_t g = ml::quantize_pixel(PixelFormat::Grey8, pattern(x, y), false, x, y);
      ASSERT_EQ(word_at(s, x, y), ml::rgb(g, g, g));
    }
}

TEST(FbdevMemory, FrameLargerThanTheScreenIsRefused) {
  Screen s = make_screen(16, bf(11, 5), bf(5, 6), bf(0, 5), 32, 24);
  auto sink = attach(s, nullptr);
  ASSERT_TRUE(sink);
  ml::FrameInfo frame;
  frame.width = 33;
  frame.height = 10;
  frame.format = sink->format();
  EXPECT_FALSE(sink->begin_frame(frame));
  EXPECT_EQ(sink->last_error(), "frame 33x10 is larger than the screen 32x24 of mem");
  frame.width = 32;
  frame.height = 25;
  EXPECT_FALSE(sink->begin_frame(frame));
  frame.height = 24;
  EXPECT_TRUE(sink->begin_frame(frame));
  EXPECT_EQ(sink->last_error(), "");
}

TEST(FbdevMemory, BandOutsideTheFrameIsRefusedAndReleased) {
  Screen s = make_screen(32, bf(16, 8), bf(8, 8), bf(0, 8), 8, 8);
  auto sink = attach(s, nullptr);
  ASSERT_TRUE(sink);
  ml::FrameInfo frame;
  frame.width = 4;
  frame.height = 4;
  ASSERT_TRUE(sink->begin_frame(frame));
  std::vector<uint8_t> band(4 * 4 * 4);
  ml::Flush f;
  f.y = 2;
  f.width = 4;
  f.height = 3;
  f.stride = 16;
  f.bytes = band.data();
  sink->lend(0);
  EXPECT_FALSE(sink->flush(f));
  EXPECT_FALSE(sink->lent(0));
  EXPECT_TRUE(one_line(sink->last_error()));
}

TEST(FbdevMemory, UnsupportedBitsPerPixel) {
  Screen s = make_screen(8, bf(0, 8), bf(0, 8), bf(0, 8), 8, 8);
  std::string error;
  EXPECT_EQ(attach(s, &error), nullptr);
  EXPECT_EQ(error, "mem: unsupported 8 bits per pixel (16, 24 or 32 only)");
}

TEST(FbdevMemory, UnsupportedLayouts) {
  std::string error;
  Screen wide = make_screen(32, bf(20, 10), bf(10, 10), bf(0, 10), 8, 8);  // 10-bit channels
  EXPECT_EQ(attach(wide, &error), nullptr);
  EXPECT_EQ(error, "mem: unsupported pixel layout r20/10 g10/10 b0/10 at 32 bpp");
  Screen outside = make_screen(16, bf(12, 5), bf(5, 6), bf(0, 5), 8, 8);  // red past bit 15
  EXPECT_EQ(attach(outside, &error), nullptr);
  EXPECT_EQ(error, "mem: unsupported pixel layout r12/5 g5/6 b0/5 at 16 bpp");
  Screen palette = make_screen(16, bf(11, 5), bf(5, 6), bf(0, 5), 8, 8);
  palette.fix.visual = FB_VISUAL_PSEUDOCOLOR;
  EXPECT_EQ(attach(palette, &error), nullptr);
  EXPECT_TRUE(one_line(error));
  EXPECT_NE(error.find("unsupported visual"), std::string::npos) << error;
  Screen planes = make_screen(16, bf(11, 5), bf(5, 6), bf(0, 5), 8, 8);
  planes.fix.type = FB_TYPE_PLANES;
  EXPECT_EQ(attach(planes, &error), nullptr);
  EXPECT_NE(error.find("unsupported pixel layout"), std::string::npos) << error;
}

TEST(FbdevMemory, VisibleScreenMustFitTheMemory) {
  Screen s = make_screen(32, bf(16, 8), bf(8, 8), bf(0, 8), 8, 8, 0, 4);  // panned past the end
  std::string error;
  EXPECT_EQ(attach(s, &error), nullptr);
  EXPECT_TRUE(one_line(error));
  EXPECT_NE(error.find("does not fit"), std::string::npos) << error;
  Screen narrow = make_screen(32, bf(16, 8), bf(8, 8), bf(0, 8), 8, 8);
  narrow.fix.line_length = 28;  // shorter than a visible row
  EXPECT_EQ(attach(narrow, &error), nullptr);
  EXPECT_NE(error.find("does not fit"), std::string::npos) << error;
}

}  // namespace

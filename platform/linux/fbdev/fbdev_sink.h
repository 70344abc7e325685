// A Sink (core/sink.h) that draws into a Linux framebuffer device (/dev/fbN). See docs/fbdev.md.
//
// open_fbdev() opens the device, reads its variable and fixed screen info and maps its memory.
// format() tells the caller which PixelFormat to render in:
//   - Rgb565Le  when the screen is 16 bpp with red 11/5, green 5/6, blue 0/5 (bands copied as is);
//   - Xrgb8888  otherwise (32 bpp red 16/8, green 8/8, blue 0/8 without alpha is copied as is; every
//     other supported layout — 24 bpp, BGR orders, RGB555, an alpha channel — is converted pixel by
//     pixel into the var-info layout while copying; alpha bits are set to opaque).
// The sink accepts frames in any PixelFormat (a format other than format() is converted through
// expand_stored()), but only format() gives a straight copy.
//
// Placement: a frame is centred on the visible screen (offset ((xres - w) / 2, (yres - h) / 2),
// rounded down); pixels outside the frame are left as they are. A frame larger than the visible
// screen is refused by begin_frame() (last_error() says why). The visible screen starts at
// xoffset/yoffset of the virtual screen; rows are line_length bytes apart.
//
// Flushing is synchronous: flush() copies the band into the mapped memory and calls
// flush_ready(band.buffer) before it returns. counters.bytes counts the bytes stored into the
// framebuffer (band width x height x bytes per framebuffer pixel); counters.windows stays 0 (a
// memory-mapped framebuffer has no address-window commands).
//
// Linux only. Assumes a little-endian CPU (framebuffer pixels in CPU byte order).
#pragma once
#include <linux/fb.h>
#include <stddef.h>
#include <stdint.h>

#include <memory>
#include <string>

#include "core/sink.h"

namespace mlfb {

class FbdevSink : public ml::Sink {
 public:
  ~FbdevSink() override;
  FbdevSink(const FbdevSink&) = delete;
  FbdevSink& operator=(const FbdevSink&) = delete;

  // The format to render in (see above).
  ml::PixelFormat format() const { return format_; }
  // The visible resolution.
  int width() const { return width_; }
  int height() const { return height_; }
  int bits_per_pixel() const { return bpp_; }
  // True when bands in format() are copied byte for byte (no per-pixel conversion).
  bool direct_copy() const { return direct_; }
  // Where the current (or next) frame's top-left pixel lands on the visible screen.
  int frame_x() const { return frame_x_; }
  int frame_y() const { return frame_y_; }
  // One line describing the screen, e.g. "/dev/fb0: 1024x768, 16 bpp r11/5 g5/6 b0/5, line 2048 bytes"
  // (with ", panned to X,Y" when the visible screen starts elsewhere and ", converted" when bands
  // are converted pixel by pixel).
  std::string describe() const;
  // Why the last begin_frame() or flush() returned false ("" when none did).
  const std::string& last_error() const { return error_; }

  // Fills the whole visible screen with one colour (converted into the screen's layout). Not
  // counted in counters (render() resets them at begin_frame anyway).
  void clear(ml::Pixel colour);

  bool begin_frame(const ml::FrameInfo& frame) override;
  bool flush(const ml::Flush& band) override;
  bool end_frame() override { return true; }

 private:
  friend std::unique_ptr<FbdevSink> open_fbdev(const std::string&, std::string*);
  friend std::unique_ptr<FbdevSink> attach_fbdev_memory(uint8_t*, size_t, const fb_var_screeninfo&,
                                                         const fb_fix_screeninfo&, const std::string&,
                                                         std::string*);
  FbdevSink() = default;
  // Checks var/fix info against a memory block of `size` bytes and sets up the layout; returns "" or
  // the reason (without the device name).
  std::string setup(uint8_t* memory, size_t size, const fb_var_screeninfo& var, const fb_fix_screeninfo& fix);
  uint32_t pack(ml::Pixel colour) const;
  void store(uint8_t* at, uint32_t value) const;
  bool fail(const std::string& message) {
    error_ = message;
    return false;
  }

  std::string name_;
  int fd_ = -1;             // owned device (open_fbdev), -1 for attached memory
  uint8_t* map_ = nullptr;  // mapped memory (munmap'ed when fd_ is ours)
  size_t map_size_ = 0;
  uint8_t* origin_ = nullptr;  // first byte of the visible screen (xoffset/yoffset applied)
  int width_ = 0, height_ = 0, bpp_ = 0, bytes_per_pixel_ = 0, xoffset_ = 0, yoffset_ = 0;
  uint32_t line_length_ = 0;
  fb_bitfield red_{}, green_{}, blue_{}, transp_{};
  ml::PixelFormat format_ = ml::PixelFormat::Xrgb8888;
  bool direct_ = false;
  // The frame being drawn.
  ml::PixelFormat frame_format_ = ml::PixelFormat::Xrgb8888;
  int frame_w_ = 0, frame_h_ = 0, frame_x_ = 0, frame_y_ = 0;
  bool in_frame_ = false;
  std::string error_;
};

// Opens a framebuffer device such as "/dev/fb0". On failure returns null and sets *error (when
// non-null) to one line naming the device: no such device, permission denied, not a framebuffer,
// unsupported bits per pixel or pixel layout, or the memory could not be mapped.
std::unique_ptr<FbdevSink> open_fbdev(const std::string& path, std::string* error);

// The same sink over a caller-owned memory block described by var/fix info (for tests and for
// framebuffers mapped some other way). `name` prefixes error messages. The memory must outlive the
// sink; `size` plays the role of smem_len.
std::unique_ptr<FbdevSink> attach_fbdev_memory(uint8_t* memory, size_t size, const fb_var_screeninfo& var,
                                               const fb_fix_screeninfo& fix, const std::string& name,
                                               std::string* error);

}  // namespace mlfb

#include "platform/linux/fbdev/fbdev_sink.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/pixel_format.h"

namespace mlfb {

namespace {

std::string bitfield(char name, const fb_bitfield& f) {
  return std::string(1, name) + std::to_string(f.offset) + "/" + std::to_string(f.length);
}

bool is(const fb_bitfield& f, uint32_t offset, uint32_t length) { return f.offset == offset && f.length == length; }

// A channel of 1..8 bits inside the pixel (longer channels would need more than 8 bits of colour).
bool channel_ok(const fb_bitfield& f, int bpp) {
  return f.length >= 1 && f.length <= 8 && f.offset + f.length <= uint32_t(bpp) && f.msb_right == 0;
}

// 0..255 to `length` bits, rounding to nearest as core/pixel_format.h does.
uint32_t scale(uint32_t v, uint32_t length) {
  const uint32_t levels = (1u << length) - 1;
  return (v * levels + 127) / 255;
}

}  // namespace

FbdevSink::~FbdevSink() {
  if (fd_ >= 0) {
    if (map_) munmap(map_, map_size_);
    close(fd_);
  }
}

std::string FbdevSink::setup(uint8_t* memory, size_t size, const fb_var_screeninfo& var,
                             const fb_fix_screeninfo& fix) {
  bpp_ = int(var.bits_per_pixel);
  if (bpp_ != 16 && bpp_ != 24 && bpp_ != 32)
    return "unsupported " + std::to_string(bpp_) + " bits per pixel (16, 24 or 32 only)";
  red_ = var.red;
  green_ = var.green;
  blue_ = var.blue;
  transp_ = var.transp;
  const std::string layout = bitfield('r', red_) + " " + bitfield('g', green_) + " " + bitfield('b', blue_);
  if (fix.type != FB_TYPE_PACKED_PIXELS || var.grayscale != 0 || var.nonstd != 0)
    return "unsupported pixel layout (not packed RGB pixels)";
  if (fix.visual != FB_VISUAL_TRUECOLOR)
    return "unsupported visual " + std::to_string(fix.visual) + " (true colour only)";
  if (!channel_ok(red_, bpp_) || !channel_ok(green_, bpp_) || !channel_ok(blue_, bpp_) ||
      (transp_.length != 0 && (transp_.length > 8 || transp_.offset + transp_.length > uint32_t(bpp_))))
    return "unsupported pixel layout " + layout + " at " + std::to_string(bpp_) + " bpp";
  width_ = int(var.xres);
  height_ = int(var.yres);
  bytes_per_pixel_ = bpp_ / 8;
  line_length_ = fix.line_length;
  if (width_ < 1 || height_ < 1) return "the screen has no visible pixels";
  const uint64_t row_end = (uint64_t(var.xoffset) + var.xres) * uint64_t(bytes_per_pixel_);
  const uint64_t rows = uint64_t(var.yoffset) + var.yres;
  if (line_length_ == 0 || row_end > line_length_ || rows * line_length_ > size)
    return "the visible screen (" + std::to_string(width_) + "x" + std::to_string(height_) + " at " +
           std::to_string(var.xoffset) + "," + std::to_string(var.yoffset) + ", line " +
           std::to_string(line_length_) + " bytes) does not fit in " + std::to_string(size) +
           " bytes of framebuffer memory";
  map_ = memory;
  map_size_ = size;
  xoffset_ = int(var.xoffset);
  yoffset_ = int(var.yoffset);
  origin_ = memory ? memory + uint64_t(var.yoffset) * line_length_ + uint64_t(var.xoffset) * uint64_t(bytes_per_pixel_)
                   : nullptr;

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  const bool little = true;
#else
  const bool little = false;
#endif
  if (bpp_ == 16 && is(red_, 11, 5) && is(green_, 5, 6) && is(blue_, 0, 5)) {
    format_ = ml::PixelFormat::Rgb565Le;
    direct_ = little && transp_.length == 0;
  } else {
    format_ = ml::PixelFormat::Xrgb8888;
    direct_ = little && bpp_ == 32 && is(red_, 16, 8) && is(green_, 8, 8) && is(blue_, 0, 8) &&
              transp_.length == 0;
  }
  return "";
}

std::string FbdevSink::describe() const {
  return name_ + ": " + std::to_string(width_) + "x" + std::to_string(height_) + ", " + std::to_string(bpp_) +
         " bpp " + bitfield('r', red_) + " " + bitfield('g', green_) + " " + bitfield('b', blue_) +
         (transp_.length ? " " + bitfield('a', transp_) : std::string()) + ", line " +
         std::to_string(line_length_) + " bytes" +
         (xoffset_ || yoffset_ ? ", panned to " + std::to_string(xoffset_) + "," + std::to_string(yoffset_) : "") +
         (direct_ ? "" : ", converted");
}

// The framebuffer word for a colour: each channel scaled to its length and shifted to its offset;
// alpha bits (if any) all ones.
uint32_t FbdevSink::pack(ml::Pixel c) const {
  uint32_t v = scale(ml::red_of(c), red_.length) << red_.offset |
               scale(ml::green_of(c), green_.length) << green_.offset |
               scale(ml::blue_of(c), blue_.length) << blue_.offset;
  if (transp_.length) v |= ((1u << transp_.length) - 1) << transp_.offset;
  return v;
}

void FbdevSink::store(uint8_t* at, uint32_t v) const {
  for (int i = 0; i < bytes_per_pixel_; ++i) at[i] = uint8_t(v >> (8 * i));
}

void FbdevSink::clear(ml::Pixel colour) {
  const uint32_t v = pack(colour);
  for (int y = 0; y < height_; ++y) {
    uint8_t* row = origin_ + uint64_t(y) * line_length_;
    for (int x = 0; x < width_; ++x) store(row + x * bytes_per_pixel_, v);
  }
}

bool FbdevSink::begin_frame(const ml::FrameInfo& frame) {
  error_.clear();
  in_frame_ = false;
  if (frame.width < 1 || frame.height < 1) return fail("empty frame");
  if (frame.width > width_ || frame.height > height_)
    return fail("frame " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                " is larger than the screen " + std::to_string(width_) + "x" + std::to_string(height_) +
                " of " + name_);
  frame_format_ = frame.format;
  frame_w_ = frame.width;
  frame_h_ = frame.height;
  frame_x_ = (width_ - frame.width) / 2;
  frame_y_ = (height_ - frame.height) / 2;
  in_frame_ = true;
  return true;
}

bool FbdevSink::flush(const ml::Flush& band) {
  if (!in_frame_) {
    flush_ready(band.buffer);
    return fail("flush outside a frame");
  }
  if (band.x < 0 || band.y < 0 || band.width < 0 || band.height < 0 || band.x + band.width > frame_w_ ||
      band.y + band.height > frame_h_) {
    flush_ready(band.buffer);
    return fail("band " + std::to_string(band.width) + "x" + std::to_string(band.height) + " at " +
                std::to_string(band.x) + "," + std::to_string(band.y) + " lies outside the frame");
  }
  const uint32_t bpp = uint32_t(bytes_per_pixel_);
  uint8_t* dst = origin_ + uint64_t(frame_y_ + band.y) * line_length_ + uint64_t(frame_x_ + band.x) * bpp;
  if (direct_ && frame_format_ == format_) {
    const size_t row_bytes = size_t(band.width) * bpp;
    for (int r = 0; r < band.height; ++r) memcpy(dst + uint64_t(r) * line_length_, band.bytes + uint64_t(r) * band.stride, row_bytes);
  } else if (frame_format_ == ml::PixelFormat::Xrgb8888) {
    for (int r = 0; r < band.height; ++r) {
      const uint8_t* src = band.bytes + uint64_t(r) * band.stride;
      uint8_t* out = dst + uint64_t(r) * line_length_;
      for (int x = 0; x < band.width; ++x, src += 4, out += bpp)
        store(out, pack(ml::rgb(src[2], src[1], src[0])));
    }
  } else {
    // Any other format: read each stored value back and expand it to a colour.
    for (int r = 0; r < band.height; ++r) {
      uint8_t* out = dst + uint64_t(r) * line_length_;
      for (int x = 0; x < band.width; ++x, out += bpp)
        store(out, pack(ml::expand_stored(frame_format_, ml::load_pixel(frame_format_, band.bytes, band.stride, x, r))));
    }
  }
  counters.bytes += uint64_t(band.width) * uint64_t(band.height) * bpp;
  flush_ready(band.buffer);
  return true;
}

std::unique_ptr<FbdevSink> attach_fbdev_memory(uint8_t* memory, size_t size, const fb_var_screeninfo& var,
                                               const fb_fix_screeninfo& fix, const std::string& name,
                                               std::string* error) {
  std::unique_ptr<FbdevSink> sink(new FbdevSink());
  sink->name_ = name;
  const std::string why = sink->setup(memory, size, var, fix);
  if (!why.empty()) {
    if (error) *error = name + ": " + why;
    return nullptr;
  }
  return sink;
}

std::unique_ptr<FbdevSink> open_fbdev(const std::string& path, std::string* error) {
  auto fail = [&](const std::string& why) -> std::unique_ptr<FbdevSink> {
    if (error) *error = path + ": " + why;
    return nullptr;
  };
  const int fd = open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    if (e == ENOENT || e == ENXIO || e == ENODEV) return fail("no such device");
    if (e == EACCES || e == EPERM) return fail("permission denied (is the user in the video group?)");
    return fail(std::string("cannot open: ") + strerror(e));
  }
  std::unique_ptr<FbdevSink> sink(new FbdevSink());
  sink->name_ = path;
  sink->fd_ = fd;  // closed by the destructor from here on
  fb_var_screeninfo var{};
  fb_fix_screeninfo fix{};
  if (ioctl(fd, FBIOGET_VSCREENINFO, &var) != 0 || ioctl(fd, FBIOGET_FSCREENINFO, &fix) != 0)
    return fail(std::string("not a framebuffer (FBIOGET_VSCREENINFO: ") + strerror(errno) + ")");
  // Check the layout before mapping, so an unsupported screen says so rather than failing to map.
  std::string why = sink->setup(nullptr, fix.smem_len, var, fix);
  if (!why.empty()) return fail(why);
  void* map = mmap(nullptr, fix.smem_len, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (map == MAP_FAILED)
    return fail("cannot map " + std::to_string(fix.smem_len) + " bytes of framebuffer memory: " + strerror(errno));
  why = sink->setup(static_cast<uint8_t*>(map), fix.smem_len, var, fix);
  if (!why.empty()) {
    munmap(map, fix.smem_len);
    sink->map_ = nullptr;
    return fail(why);
  }
  return sink;
}

}  // namespace mlfb

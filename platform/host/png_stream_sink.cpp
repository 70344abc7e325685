#include "platform/host/png_stream_sink.h"

#include <errno.h>
#include <png.h>
#include <string.h>

#include "core/pixel_format.h"

namespace mlhost {

namespace {

png_structp png_of(void* p) { return static_cast<png_structp>(p); }
png_infop info_of(void* p) { return static_cast<png_infop>(p); }

// libpng reports errors by longjmp; every call into it goes through here, with nothing to destroy
// on this frame.
template <typename F>
bool png_call(void* png, F f) {
  if (setjmp(png_jmpbuf(png_of(png)))) return false;
  f();
  return true;
}

}  // namespace

PngStreamSink::~PngStreamSink() { close(); }

void PngStreamSink::close() {
  if (png_) {
    png_structp png = png_of(png_);
    png_infop info = info_of(info_);
    png_destroy_write_struct(&png, info ? &info : nullptr);
    png_ = info_ = nullptr;
  }
  if (file_) fclose(file_);
  file_ = nullptr;
}

bool PngStreamSink::fail(const std::string& message) {
  if (error_.empty()) error_ = message;
  close();
  return false;
}

bool PngStreamSink::begin_frame(const ml::FrameInfo& frame) {
  const std::string e = contract_.begin(frame);
  if (!e.empty()) return fail("cannot write " + path_ + ": " + e);
  file_ = fopen(path_.c_str(), "wb");
  if (!file_) return fail("cannot write " + path_ + ": " + strerror(errno));
  png_ = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (png_) info_ = png_create_info_struct(png_of(png_));
  if (!png_ || !info_) return fail("cannot write " + path_ + ": libpng init failed");
  const bool ids = frame.format == ml::PixelFormat::Id32;
  row_.assign(size_t(frame.width) * (ids ? 4 : 3), 0);
  const bool ok = png_call(png_, [&] {
    png_init_io(png_of(png_), file_);
    png_set_IHDR(png_of(png_), info_of(info_), png_uint_32(frame.width), png_uint_32(frame.height), 8,
                 ids ? PNG_COLOR_TYPE_RGBA : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png_of(png_), info_of(info_));
  });
  return ok || fail("cannot write " + path_ + ": libpng error");
}

bool PngStreamSink::flush(const ml::Flush& band) {
  flush_ready(band.buffer);  // the rows are copied below, before this returns
  if (!error_.empty()) return false;
  const std::string e = contract_.check(band);
  if (!e.empty()) return fail("cannot write " + path_ + ": " + e);
  const ml::PixelFormat format = contract_.frame().format;
  for (int r = 0; r < band.height; ++r) {
    for (int x = 0; x < band.width; ++x) {
      const uint32_t v = ml::load_pixel(format, band.bytes, band.stride, x, r);
      if (format == ml::PixelFormat::Id32) {
        for (int c = 0; c < 4; ++c) row_[size_t(x) * 4 + size_t(c)] = uint8_t(v >> (8 * c));
      } else {
        const ml::Pixel p = ml::expand_stored(format, v);
        row_[size_t(x) * 3] = uint8_t(ml::red_of(p));
        row_[size_t(x) * 3 + 1] = uint8_t(ml::green_of(p));
        row_[size_t(x) * 3 + 2] = uint8_t(ml::blue_of(p));
      }
    }
    if (!png_call(png_, [&] { png_write_row(png_of(png_), row_.data()); }))
      return fail("cannot write " + path_ + ": libpng error");
  }
  counters.bytes += ml::format_band_bytes(format, band.width, band.height);  // no windows: a file
  return true;
}

bool PngStreamSink::end_frame() {
  if (!error_.empty()) return false;
  const std::string e = contract_.end();
  if (!e.empty()) return fail("cannot write " + path_ + ": " + e);
  if (!png_call(png_, [&] { png_write_end(png_of(png_), nullptr); }))
    return fail("cannot write " + path_ + ": libpng error");
  if (fflush(file_) != 0 || ferror(file_)) return fail("cannot write " + path_ + ": " + strerror(errno));
  close();
  return true;
}

}  // namespace mlhost

#include "platform/host/png_io.h"

#include <png.h>
#include <stdio.h>
#include <string.h>

#include <errno.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace mlhost {
namespace {

struct FileCloser {
  void operator()(FILE* f) const { if (f) fclose(f); }
};

// channels: 3 (RGB from 0x00RRGGBB) or 4 (little-endian bytes of the value).
std::string write_png(const std::string& path, int width, int height, const std::vector<uint32_t>& values,
                      int channels) {
  if (width <= 0 || height <= 0 || values.size() != size_t(width) * size_t(height)) {
    return "cannot write " + path + ": bad image size";
  }
  std::unique_ptr<FILE, FileCloser> file(fopen(path.c_str(), "wb"));
  if (!file) return "cannot write " + path + ": " + strerror(errno);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) return "cannot write " + path + ": libpng init failed";
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    return "cannot write " + path + ": libpng init failed";
  }
  std::vector<uint8_t> row(size_t(width) * size_t(channels));
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return "cannot write " + path + ": libpng error";
  }
  png_init_io(png, file.get());
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8,
               channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) {
    const uint32_t* src = values.data() + size_t(y) * size_t(width);
    for (int x = 0; x < width; ++x) {
      uint8_t* d = row.data() + size_t(x) * size_t(channels);
      if (channels == 3) {
        d[0] = uint8_t(src[x] >> 16);
        d[1] = uint8_t(src[x] >> 8);
        d[2] = uint8_t(src[x]);
      } else {
        d[0] = uint8_t(src[x]);
        d[1] = uint8_t(src[x] >> 8);
        d[2] = uint8_t(src[x] >> 16);
        d[3] = uint8_t(src[x] >> 24);
      }
    }
    png_write_row(png, row.data());
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (fflush(file.get()) != 0 || ferror(file.get())) return "cannot write " + path + ": " + strerror(errno);
  return "";
}

}  // namespace

std::string write_png_rgb(const std::string& path, int width, int height, const std::vector<ml::Pixel>& pixels) {
  return write_png(path, width, height, pixels, 3);
}

std::string write_png_rgba_le(const std::string& path, int width, int height,
                              const std::vector<uint32_t>& values) {
  return write_png(path, width, height, values, 4);
}

std::string read_png(const std::string& path, int* width, int* height, std::vector<uint32_t>* values,
                     bool raw_rgba) {
  png_image image;
  memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) return "cannot read " + path + ": " + image.message;
  image.format = PNG_FORMAT_RGBA;
  std::vector<uint8_t> bytes(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, bytes.data(), 0, nullptr)) {
    png_image_free(&image);
    return "cannot read " + path + ": " + image.message;
  }
  *width = int(image.width);
  *height = int(image.height);
  values->resize(size_t(image.width) * image.height);
  for (size_t i = 0; i < values->size(); ++i) {
    const uint8_t* p = bytes.data() + i * 4;
    (*values)[i] = raw_rgba ? (uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24)
                            : (uint32_t(p[0]) << 16 | uint32_t(p[1]) << 8 | uint32_t(p[2]));
  }
  return "";
}

std::vector<ml::Pixel> work_heatmap(const std::vector<uint32_t>& work_q16) {
  double top = 0;
  for (uint32_t w : work_q16) top = std::max(top, std::log2(1.0 + w / 65536.0));
  // Ramp stops: black, blue, red, yellow, white.
  static const double stops[5][3] = {{0, 0, 0}, {0, 0, 255}, {255, 0, 0}, {255, 255, 0}, {255, 255, 255}};
  std::vector<ml::Pixel> out(work_q16.size());
  for (size_t i = 0; i < work_q16.size(); ++i) {
    const double t = top > 0 ? std::log2(1.0 + work_q16[i] / 65536.0) / top : 0.0;
    const double s = t * 4.0;
    const int k = std::min(3, int(s));
    const double f = s - k;
    uint32_t c[3];
    for (int j = 0; j < 3; ++j) c[j] = uint32_t(std::lround(stops[k][j] + (stops[k + 1][j] - stops[k][j]) * f));
    out[i] = ml::rgb(c[0], c[1], c[2]);
  }
  return out;
}

}  // namespace mlhost

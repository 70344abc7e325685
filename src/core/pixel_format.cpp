#include "core/pixel_format.h"

#include <string.h>

namespace ml {

namespace {

// 4x4 Bayer thresholds, row-major.
constexpr uint8_t kBayer4[16] = {0, 8, 2, 10, 12, 4, 14, 6, 3, 11, 1, 9, 15, 7, 13, 5};

inline uint32_t threshold(int x, int y) { return kBayer4[((y & 3) << 2) | (x & 3)]; }

// v (0..255) to 0..levels.
inline uint32_t level(uint32_t v, uint32_t levels) { return (v * levels + 127) / 255; }
inline uint32_t level_dithered(uint32_t v, uint32_t levels, uint32_t t) {
  return (32 * v * levels + (2 * t + 1) * 255) / (32 * 255);
}

inline uint32_t luma(Pixel p) { return (77 * red_of(p) + 150 * green_of(p) + 29 * blue_of(p) + 128) >> 8; }

inline uint32_t quantize_one(PixelFormat format, Pixel p, bool dither, uint32_t t) {
  auto q = [&](uint32_t v, uint32_t levels) { return dither ? level_dithered(v, levels, t) : level(v, levels); };
  switch (format) {
    case PixelFormat::Rgb565Be:
    case PixelFormat::Rgb565Le:
      return q(red_of(p), 31) << 11 | q(green_of(p), 63) << 5 | q(blue_of(p), 31);
    case PixelFormat::Grey8: return q(luma(p), 255);
    case PixelFormat::Grey4: return q(luma(p), 15);
    case PixelFormat::Mono1: return q(luma(p), 1);
    case PixelFormat::Xrgb8888: return p & 0xFFFFFFu;
    case PixelFormat::Id32: return p;
  }
  return 0;
}

// Stores one value at byte-aligned position `at` (formats of 8 or more bits a pixel).
inline void store_aligned(PixelFormat format, uint8_t* at, uint32_t v) {
  switch (format) {
    case PixelFormat::Rgb565Be: at[0] = uint8_t(v >> 8); at[1] = uint8_t(v); break;
    case PixelFormat::Rgb565Le: at[0] = uint8_t(v); at[1] = uint8_t(v >> 8); break;
    case PixelFormat::Grey8: at[0] = uint8_t(v); break;
    case PixelFormat::Xrgb8888:
      at[0] = uint8_t(v); at[1] = uint8_t(v >> 8); at[2] = uint8_t(v >> 16); at[3] = 0; break;
    case PixelFormat::Id32: memcpy(at, &v, 4); break;  // native byte order
    default: break;
  }
}

constexpr int kChunk = 32;

}  // namespace

int format_bits_per_pixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::Rgb565Be:
    case PixelFormat::Rgb565Le: return 16;
    case PixelFormat::Xrgb8888:
    case PixelFormat::Id32: return 32;
    case PixelFormat::Grey8: return 8;
    case PixelFormat::Grey4: return 4;
    case PixelFormat::Mono1: return 1;
  }
  return 32;
}

int format_row_unit(PixelFormat format) { return format == PixelFormat::Mono1 ? 8 : 1; }

bool format_dithers_by_default(PixelFormat format) {
  return format == PixelFormat::Grey8 || format == PixelFormat::Grey4 || format == PixelFormat::Mono1;
}

bool format_is_lossy(PixelFormat format) {
  return format != PixelFormat::Xrgb8888 && format != PixelFormat::Id32;
}

uint32_t format_stride(PixelFormat format, int width) {
  if (format == PixelFormat::Mono1) return uint32_t(width);  // a page row: one byte a column
  return (uint32_t(width) * uint32_t(format_bits_per_pixel(format)) + 7) / 8;
}

uint32_t format_band_bytes(PixelFormat format, int width, int rows) {
  const uint32_t unit = uint32_t(format_row_unit(format));
  return format_stride(format, width) * ((uint32_t(rows) + unit - 1) / unit);
}

uint32_t quantize_pixel(PixelFormat format, Pixel p, bool dither, int x, int y) {
  return quantize_one(format, p, dither && format_is_lossy(format), threshold(x, y));
}

Pixel expand_stored(PixelFormat format, uint32_t v) {
  switch (format) {
    case PixelFormat::Rgb565Be:
    case PixelFormat::Rgb565Le: {
      const uint32_t r = v >> 11 & 31, g = v >> 5 & 63, b = v & 31;
      return rgb(r << 3 | r >> 2, g << 2 | g >> 4, b << 3 | b >> 2);
    }
    case PixelFormat::Grey8: return rgb(v & 255, v & 255, v & 255);
    case PixelFormat::Grey4: return rgb((v & 15) * 17, (v & 15) * 17, (v & 15) * 17);
    case PixelFormat::Mono1: return (v & 1) ? 0xFFFFFFu : 0;
    case PixelFormat::Xrgb8888: return v & 0xFFFFFFu;
    case PixelFormat::Id32: return v;
  }
  return 0;
}

void store_pixels(PixelFormat format, uint8_t* band, uint32_t stride, int x, int row,
                  const uint32_t* stored, int n) {
  if (format == PixelFormat::Mono1) {
    uint8_t* page = band + uint32_t(row >> 3) * stride;
    const uint8_t bit = uint8_t(1u << (row & 7));
    for (int i = 0; i < n; ++i)
      page[x + i] = uint8_t(stored[i] & 1 ? page[x + i] | bit : page[x + i] & ~bit);
    return;
  }
  uint8_t* line = band + uint32_t(row) * stride;
  if (format == PixelFormat::Grey4) {
    for (int i = 0; i < n; ++i) {
      const int px = x + i;
      uint8_t& byte = line[px >> 1];
      byte = (px & 1) ? uint8_t((byte & 0xF0) | (stored[i] & 15)) : uint8_t((byte & 0x0F) | (stored[i] & 15) << 4);
    }
    return;
  }
  const uint32_t bytes = uint32_t(format_bits_per_pixel(format) / 8);
  uint8_t* at = line + uint32_t(x) * bytes;
  for (int i = 0; i < n; ++i, at += bytes) store_aligned(format, at, stored[i]);
}

uint32_t load_pixel(PixelFormat format, const uint8_t* band, uint32_t stride, int x, int row) {
  switch (format) {
    case PixelFormat::Mono1: return band[uint32_t(row >> 3) * stride + uint32_t(x)] >> (row & 7) & 1u;
    case PixelFormat::Grey4: {
      const uint8_t byte = band[uint32_t(row) * stride + uint32_t(x >> 1)];
      return (x & 1) ? byte & 15u : byte >> 4;
    }
    default: break;
  }
  const uint32_t bytes = uint32_t(format_bits_per_pixel(format) / 8);
  const uint8_t* at = band + uint32_t(row) * stride + uint32_t(x) * bytes;
  switch (format) {
    case PixelFormat::Rgb565Be: return uint32_t(at[0]) << 8 | at[1];
    case PixelFormat::Rgb565Le: return uint32_t(at[1]) << 8 | at[0];
    case PixelFormat::Grey8: return at[0];
    case PixelFormat::Xrgb8888: return uint32_t(at[2]) << 16 | uint32_t(at[1]) << 8 | at[0];
    case PixelFormat::Id32: {
      uint32_t v;
      memcpy(&v, at, 4);
      return v;
    }
    default: return 0;
  }
}

namespace {

// Rows of whole-byte formats without dithering: one loop per format, nothing decided per pixel.
template <typename Store>
void put_bytes(uint8_t* at, int bytes, const Pixel* pixels, int n, Store&& store) {
  for (int i = 0; i < n; ++i, at += bytes) store(at, pixels[i]);
}

// level(v, 31) and level(v, 63) for every channel value, in flash: RGB565 rows without a division.
struct Rgb565Levels {
  uint8_t five[256], six[256];
  constexpr Rgb565Levels() : five(), six() {
    for (uint32_t v = 0; v < 256; ++v) {
      five[v] = uint8_t((v * 31 + 127) / 255);
      six[v] = uint8_t((v * 63 + 127) / 255);
    }
  }
};
constexpr Rgb565Levels kRgb565;

inline uint32_t rgb565_of(Pixel p) {
  return uint32_t(kRgb565.five[red_of(p)]) << 11 | uint32_t(kRgb565.six[green_of(p)]) << 5 |
         kRgb565.five[blue_of(p)];
}

// Rows are mostly runs of one colour (a surface's flat or reused shade): a colour is converted once
// a run.
struct Rgb565Cache {
  Pixel last = 0;
  uint32_t value = 0;
  uint32_t operator()(Pixel p) {
    if (p != last) {
      last = p;
      value = rgb565_of(p);
    }
    return value;
  }
};

bool put_row_fast(PixelFormat format, uint8_t* line, int x, const Pixel* pixels, int n) {
  switch (format) {
    case PixelFormat::Rgb565Be:
      put_bytes(line + 2 * x, 2, pixels, n, [cache = Rgb565Cache()](uint8_t* at, Pixel p) mutable {
        const uint32_t v = cache(p);
        at[0] = uint8_t(v >> 8);
        at[1] = uint8_t(v);
      });
      return true;
    case PixelFormat::Rgb565Le:
      put_bytes(line + 2 * x, 2, pixels, n, [cache = Rgb565Cache()](uint8_t* at, Pixel p) mutable {
        const uint32_t v = cache(p);
        at[0] = uint8_t(v);
        at[1] = uint8_t(v >> 8);
      });
      return true;
    case PixelFormat::Xrgb8888:
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
      // A Pixel is 0x00RRGGBB: in little-endian memory it already is B, G, R, 0.
      memcpy(line + 4 * x, pixels, size_t(n) * 4);
#else
      put_bytes(line + 4 * x, 4, pixels, n, [](uint8_t* at, Pixel p) {
        at[0] = uint8_t(p);
        at[1] = uint8_t(p >> 8);
        at[2] = uint8_t(p >> 16);
        at[3] = 0;
      });
#endif
      return true;
    case PixelFormat::Id32:
      memcpy(line + 4 * x, pixels, size_t(n) * 4);
      return true;
    default:
      return false;
  }
}

}  // namespace

void PixelPacker::put_row(uint8_t* band, uint32_t stride, int x, int row, int frame_y, const Pixel* pixels,
                          int n) const {
  if (!dither_ && put_row_fast(format_, band + uint32_t(row) * stride, x, pixels, n)) return;
  uint32_t stored[kChunk];
  for (int done = 0; done < n; done += kChunk) {
    const int m = n - done < kChunk ? n - done : kChunk;
    for (int i = 0; i < m; ++i)
      stored[i] = quantize_one(format_, pixels[done + i], dither_, threshold(x + done + i, frame_y));
    store_pixels(format_, band, stride, x + done, row, stored, m);
  }
}

namespace {

// A block of one stored value in a format of whole bytes a pixel: the value's bytes once, copied, on
// 64-bit hosts eight wide stores at a time, unrolled (2CylinderEngine, tiler, 1024x768: the background
// and the large parts, 2.71 M -> 0.65 M instructions with four, 0.54 M with eight; GCC keeps a loop of
// eight as a loop unless told).
template <int kBytes>
void fill_bytes(uint8_t* band, uint32_t stride, int x, int row, int w, int h, const uint8_t* pattern) {
  constexpr int kPerWide = 8 / kBytes;  // pixels an 8-byte store holds
  uint8_t wide[8];
  for (int i = 0; i < 8; i += kBytes) memcpy(wide + i, pattern, kBytes);
  for (int j = 0; j < h; ++j) {
    uint8_t* at = band + uint32_t(row + j) * stride + uint32_t(x) * kBytes;
    int i = 0;
    if (kPixelWideStores) {
      for (; i + 8 * kPerWide <= w; i += 8 * kPerWide, at += 64) {
#pragma GCC unroll 8
        for (int k = 0; k < 64; k += 8) memcpy(at + k, wide, 8);
      }
      for (; i + kPerWide <= w; i += kPerWide, at += 8) memcpy(at, wide, 8);
    }
    for (; i < w; ++i, at += kBytes) memcpy(at, pattern, kBytes);
  }
}

}  // namespace

void PixelPacker::quantize_mask_value(Pixel value) {
  store_aligned(format_, mask_pattern_, quantize_one(format_, value, false, 0));
  mask_value_ = value;
  mask_ready_ = true;
}

#if UINTPTR_MAX > 0xFFFFFFFFu  // 64-bit hosts' textured blocks; nothing of it in the boards' flash
namespace {

// The set bits of an 8x8 mask (row 0 at `line`), kBytes bytes a pixel, store(at, pixels[bit]) at each.
template <int kBytes, typename Store>
void put_mask_bytes(uint8_t* line, uint32_t stride, uint64_t mask, const Pixel* pixels, Store&& store) {
  if (mask == 0) return;
  const int skip = __builtin_ctzll(mask) >> 3;  // empty rows above the first set bit
  line += uint32_t(skip) * stride;
  pixels += 8 * skip;
  for (mask >>= 8 * skip; mask != 0; mask >>= 8, line += stride, pixels += 8)
    for (uint32_t bits = uint32_t(mask) & 0xFFu; bits != 0; bits &= bits - 1)
      store(line + __builtin_ctz(bits) * kBytes, pixels[__builtin_ctz(bits)]);
}

}  // namespace

bool PixelPacker::put_mask(uint8_t* band, uint32_t stride, int x, int row, uint64_t mask, const Pixel* pixels) const {
  if (dither_) return false;
  uint8_t* line = band + uint32_t(row) * stride;
  switch (format_) {
    case PixelFormat::Rgb565Be:
      put_mask_bytes<2>(line + 2 * x, stride, mask, pixels, [cache = Rgb565Cache()](uint8_t* at, Pixel p) mutable {
        const uint32_t v = cache(p);
        at[0] = uint8_t(v >> 8);
        at[1] = uint8_t(v);
      });
      return true;
    case PixelFormat::Rgb565Le:
      put_mask_bytes<2>(line + 2 * x, stride, mask, pixels, [cache = Rgb565Cache()](uint8_t* at, Pixel p) mutable {
        const uint32_t v = cache(p);
        at[0] = uint8_t(v);
        at[1] = uint8_t(v >> 8);
      });
      return true;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    case PixelFormat::Xrgb8888:  // as put_row: a Pixel in little-endian memory is B, G, R, 0
    case PixelFormat::Id32:
      put_mask_bytes<4>(line + 4 * x, stride, mask, pixels, [](uint8_t* at, Pixel p) { memcpy(at, &p, 4); });
      return true;
#endif
    default:
      return false;
  }
}
#else
bool PixelPacker::put_mask(uint8_t*, uint32_t, int, int, uint64_t, const Pixel*) const { return false; }
#endif

void PixelPacker::fill(uint8_t* band, uint32_t stride, int x, int row, int frame_y, int w, int h,
                       Pixel value) const {
  const int bits = format_bits_per_pixel(format_);
  if (!dither_ && bits >= 8) {
    uint8_t pattern[4];
    store_aligned(format_, pattern, quantize_one(format_, value, false, 0));
    if (bits == 8) fill_bytes<1>(band, stride, x, row, w, h, pattern);
    else if (bits == 16) fill_bytes<2>(band, stride, x, row, w, h, pattern);
    else fill_bytes<4>(band, stride, x, row, w, h, pattern);
    return;
  }
  uint32_t stored[kChunk];
  const int first = w < kChunk ? w : kChunk;
  if (!dither_) {
    const uint32_t v = quantize_one(format_, value, false, 0);
    for (int i = 0; i < first; ++i) stored[i] = v;
  }
  for (int j = 0; j < h; ++j)
    for (int done = 0; done < w; done += kChunk) {
      const int m = w - done < kChunk ? w - done : kChunk;
      if (dither_)
        for (int i = 0; i < m; ++i)
          stored[i] = quantize_one(format_, value, true, threshold(x + done + i, frame_y + j));
      store_pixels(format_, band, stride, x + done, row + j, stored, m);
    }
}

}  // namespace ml

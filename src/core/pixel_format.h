// Packing pixels into a display's format (core/sink.h: PixelFormat), once, with optional ordered
// dithering. Written down once here:
// - Channel quantization to L + 1 levels (L = 31 for RGB565 red/blue, 63 green, 15 for Grey4, 1 for
//   Mono1, 255 for Grey8): round to nearest, q = (v L + 127) / 255. With dithering, 4x4 Bayer
//   threshold t(x, y) in 0..15 at frame pixel (x, y): q = (32 v L + (2t + 1) 255) / (32 * 255), the
//   same levels on average, spread in a pattern fixed to the screen (no crawl between frames).
// - Luma (grey and mono formats): (77 R + 150 G + 29 B + 128) >> 8 (BT.601 weights, Q8).
// - Stored values: RGB565 as the 16-bit word rrrrrggggggbbbbb; grey as the level; mono as 0/1;
//   Xrgb8888 as the word 0x00RRGGBB; Id32 as the id. expand_stored() maps a stored value back to
//   0x00RRGGBB by bit replication (grey level n of Grey4 becomes n * 17 per channel).
#pragma once
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "core/build.h"
#include "core/row_stores.h"
#include "core/sink.h"

namespace ml {

int format_bits_per_pixel(PixelFormat format);
// Band heights must be multiples of this (Mono1: a page of 8 rows; others 1).
int format_row_unit(PixelFormat format);
// Whether dithering is on unless the caller says otherwise: on for grey and mono, off otherwise.
bool format_dithers_by_default(PixelFormat format);
// Whether the format can lose colour precision (RGB565, grey, mono): dithering has an effect.
bool format_is_lossy(PixelFormat format);
// Bytes from one band row (Mono1: page) to the next, for a frame `width` pixels wide.
uint32_t format_stride(PixelFormat format, int width);
// Bytes of a band `rows` high (Mono1: rows rounded up to whole pages).
uint32_t format_band_bytes(PixelFormat format, int width, int rows);

// The value the format stores for pixel p at frame position (x, y) (position matters only when
// dithering).
uint32_t quantize_pixel(PixelFormat format, Pixel p, bool dither, int x, int y);
// The colour a stored value shows as, 0x00RRGGBB (Id32: the id itself).
Pixel expand_stored(PixelFormat format, uint32_t stored);

// Writes n stored values into band row `row` (for Mono1: pixel row within the band), pixels x.. of a
// band buffer with the given stride. Grey4 and Mono1 keep the neighbouring pixels' bits.
void store_pixels(PixelFormat format, uint8_t* band, uint32_t stride, int x, int row,
                  const uint32_t* stored, int n);
// Reads back the stored value of pixel (x, row) of a band buffer.
uint32_t load_pixel(PixelFormat format, const uint8_t* band, uint32_t stride, int x, int row);

// Runs of one stored value go out in 8-byte stores on 64-bit hosts (the boards' stores are 32-bit, and
// a Cortex-M0+ has no unaligned ones).
constexpr bool kPixelWideStores = UINTPTR_MAX > 0xFFFFFFFFu;

// Packs pixels into a band buffer: quantizes (dithering at frame row `frame_y`) and stores.
class PixelPacker {
 public:
  void init(PixelFormat format, bool dither) {
    format_ = format;
    dither_ = dither && format_is_lossy(format);
    const int bits = format_bits_per_pixel(format);
    // Grey8 dithers unless told not to: it takes the runs too (one loop less in a board's flash).
    mask_bytes_ = dither_ || bits < 16 ? 0 : bits / 8;
    mask_ready_ = false;
  }
  PixelFormat format() const { return format_; }
  // n pixels of one row from a buffer.
  void put_row(uint8_t* band, uint32_t stride, int x, int row, int frame_y, const Pixel* pixels, int n) const;
  // A w x h block of one colour.
  void fill(uint8_t* band, uint32_t stride, int x, int row, int frame_y, int w, int h, Pixel value) const;
  // Whether fill_mask stores `value` without quantizing it first (the last value it was given).
  bool mask_value_ready(Pixel value) const { return mask_ready_ && value == mask_value_; }
  // The set bits of an 8x8 mask (bit = r * 8 + c: pixel (x + c, row + r)) in one colour, the value
  // quantized once for the whole block: the same stored values as fill() gives those pixels. Returns how
  // many pixels it wrote (counted as they are stored: cheaper than a population count without a popcnt
  // instruction), or -1 (nothing written) when the stored value depends on the position (dithering) or
  // the format has less than 16 bits a pixel (grey dithers by default; one loop less in a board's flash):
  // then the caller fills the mask's runs.
  // Inline on 64-bit hosts: a tiled block's call and its saved registers cost as much as its stores
  // (2CylinderEngine at 1024x768: 18,608 blocks).
  ML_HOST_INLINE int fill_mask(uint8_t* band, uint32_t stride, int x, int row, uint64_t mask, Pixel value) {
    if (mask_bytes_ == 0) return -1;
    if (!mask_value_ready(value)) quantize_mask_value(value);
    // A local copy: the band's bytes cannot alias it, so it stays in a register through the stores.
    uint8_t pattern[4];
    memcpy(pattern, mask_pattern_, sizeof pattern);
    uint8_t* line = band + uint32_t(row) * stride + uint32_t(x) * uint32_t(mask_bytes_);
    if (mask_bytes_ == 2) return fill_mask_bytes<2>(line, stride, mask, pattern);
    return fill_mask_bytes<4>(line, stride, mask, pattern);
  }
  // The set bits of an 8x8 mask (as fill_mask) in their own colours, pixels[bit] (bit = r * 8 + c):
  // the stored values put_row gives them. False (nothing written) for dithering and formats of less
  // than 16 bits a pixel (the caller puts the mask's runs). For 64-bit hosts' textured blocks.
  bool put_mask(uint8_t* band, uint32_t stride, int x, int row, uint64_t mask, const Pixel* pixels) const;
  // Where pixel (x, row) lies in the band when the format stores a Pixel as it is (XRGB8888 on a
  // little-endian machine, aligned), with the Pixels between rows in *pixel_stride: its colours may be
  // written there directly (put_row's values). Null otherwise.
  Pixel* pixels_at(uint8_t* band, uint32_t stride, int x, int row, uint32_t* pixel_stride) const {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    uint8_t* at = band + uint32_t(row) * stride + 4 * uint32_t(x);
    if (format_ != PixelFormat::Xrgb8888 || dither_ || ((reinterpret_cast<uintptr_t>(at) | stride) & 3) != 0)
      return nullptr;
    *pixel_stride = stride / 4;
    return reinterpret_cast<Pixel*>(at);
#else
    (void)band, (void)stride, (void)x, (void)row, (void)pixel_stride;
    return nullptr;
#endif
  }

 private:
  // mask_pattern_ and mask_value_ for value.
  void quantize_mask_value(Pixel value);
  // The set bits of an 8x8 mask (row 0 at `line`), one stored value of kBytes bytes a pixel. On 64-bit
  // hosts each row's own stores, through a jump on its byte (store_mask_rows); on the boards a full row
  // is eight stores and any other row one store a set bit (runs found with two bit scans a row cost
  // more than these stores: bundled scene 0.71 M -> 0.84 M). Returns the pixels stored. Inlined in
  // fill_mask (on the boards, in its one copy optimized for size).
  template <int kBytes>
  [[gnu::always_inline]] static int fill_mask_bytes(uint8_t* line, uint32_t stride, uint64_t mask, const uint8_t* pattern) {
    if (mask == 0) return 0;
    uint8_t wide[8];  // a full row in 8-byte stores of the value repeated (kPixelWideStores)
    for (int i = 0; i < 8; i += kBytes) memcpy(wide + i, pattern, kBytes);
    // Empty rows above the first set bit are skipped at once (a small triangle's blocks hold a few rows).
    const int skip = __builtin_ctzll(mask) >> 3;
    line += uint32_t(skip) * stride;
    mask >>= 8 * skip;
    if constexpr (kPixelWideStores) return store_mask_rows<kBytes>(line, stride, mask, wide);
    int stored = 0;
    for (; mask != 0; mask >>= 8, line += stride) {
      uint32_t bits = uint32_t(mask) & 0xFFu;
      if (bits == 0xFFu) {
        if (kPixelWideStores) {
          for (int i = 0; i < 8 * kBytes; i += 8) memcpy(line + i, wide, 8);
        } else {
          for (int i = 0; i < 8; ++i) memcpy(line + i * kBytes, pattern, kBytes);
        }
        stored += 8;
        continue;
      }
      for (; bits != 0; bits &= bits - 1, ++stored) memcpy(line + size_t(__builtin_ctz(bits)) * kBytes, pattern, kBytes);
    }
    return stored;
  }

  PixelFormat format_ = PixelFormat::Xrgb8888;
  bool dither_ = false;
  int mask_bytes_ = 4;  // bytes a pixel fill_mask stores, 0 when it cannot (dithering, under 16 bits)
  // The stored bytes of the value fill_mask quantized last (a piece's blocks share one colour).
  bool mask_ready_ = false;
  Pixel mask_value_ = 0;
  uint8_t mask_pattern_[4] = {};
};

}  // namespace ml

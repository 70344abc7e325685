// Pixel formats (core/pixel_format.h): every format stores and loads back what it quantized,
// quantization is round-to-nearest, dithering keeps the average and only moves a value by one level,
// and sub-byte formats leave their neighbours alone.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/pixel_format.h"

namespace {

const ml::PixelFormat kAll[] = {ml::PixelFormat::Rgb565Be, ml::PixelFormat::Rgb565Le, ml::PixelFormat::Xrgb8888,
                                ml::PixelFormat::Grey8,    ml::PixelFormat::Grey4,    ml::PixelFormat::Mono1,
                                ml::PixelFormat::Id32};

TEST(PixelFormat, StoreLoadRoundTripsAndKeepsNeighbours) {
  std::mt19937 rng(5);
  for (ml::PixelFormat f : kAll) {
    const int width = 13, rows = 16;
    const uint32_t stride = ml::format_stride(f, width);
    std::vector<uint8_t> band(ml::format_band_bytes(f, width, rows) + 4, 0x5A);
    std::vector<uint32_t> expect(size_t(width) * rows);
    // Write pixels one at a time in a random order: each store must leave the others alone.
    std::vector<int> order(expect.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = int(i);
    std::shuffle(order.begin(), order.end(), rng);
    for (int i : order) {
      const ml::Pixel p = rng() & 0xFFFFFF;
      const uint32_t v = ml::quantize_pixel(f, p, false, i % width, i / width);
      ml::store_pixels(f, band.data(), stride, i % width, i / width, &v, 1);
      expect[size_t(i)] = v;
    }
    for (int i = 0; i < int(expect.size()); ++i)
      ASSERT_EQ(ml::load_pixel(f, band.data(), stride, i % width, i / width), expect[size_t(i)]) << int(f) << " " << i;
    EXPECT_EQ(band[band.size() - 1], 0x5A) << "wrote past the band";
  }
}

// fill_mask writes exactly the mask's pixels, each with the value fill() gives it, counts them, and
// leaves every other byte of the band as it was; it declines (writing nothing, -1) exactly for dithered
// formats and those of less than 16 bits a pixel, whose pixels the caller fills run by run.
TEST(PixelFormat, FillMaskEqualsFillOfEachSetPixel) {
  std::mt19937 rng(11);
  for (ml::PixelFormat f : kAll)
    for (bool dither : {false, true}) {
      // One packer for every trial: it keeps the last colour's stored bytes, so colours change and
      // repeat from block to block as a frame's pieces do.
      ml::PixelPacker packer;
      packer.init(f, dither);
      ml::Pixel last = 0;
      for (int trial = 0; trial < 40; ++trial) {
        const int width = 29, rows = 24;
        const uint32_t stride = ml::format_stride(f, width);
        std::vector<uint8_t> by_mask(ml::format_band_bytes(f, width, rows) + 4);
        for (uint8_t& b : by_mask) b = uint8_t(rng());
        std::vector<uint8_t> by_fill = by_mask;
        // Full rows, empty rows and ragged ones.
        uint64_t mask = (uint64_t(rng()) << 32) | rng();
        mask &= (uint64_t(rng()) << 32) | rng();
        for (int r = 0; r < 8; ++r) {
          const uint32_t pick = rng() % 4;
          if (pick == 0) mask |= uint64_t(0xFF) << (8 * r);
          if (pick == 1) mask &= ~(uint64_t(0xFF) << (8 * r));
        }
        const int x = int(rng() % uint32_t(width - 7));
        const int row = int(rng() % uint32_t(rows - 7));
        const int frame_y = row + 40;
        const ml::Pixel value = trial % 3 == 2 ? last : rng() & 0xFFFFFF;
        last = value;
        const bool whole_bytes = ml::format_bits_per_pixel(f) >= 16 && !(dither && ml::format_is_lossy(f));
        ASSERT_EQ(packer.fill_mask(by_mask.data(), stride, x, row, mask, value),
                  whole_bytes ? __builtin_popcountll(mask) : -1);
        if (!whole_bytes) {
          ASSERT_EQ(by_mask, by_fill) << "format " << int(f) << " wrote although it declined";
          continue;
        }
        for (int bit = 0; bit < 64; ++bit)
          if (mask >> bit & 1)
            packer.fill(by_fill.data(), stride, x + (bit & 7), row + (bit >> 3), frame_y + (bit >> 3), 1, 1, value);
        ASSERT_EQ(by_mask, by_fill) << "format " << int(f) << " dither " << dither << " mask " << std::hex << mask;
      }
    }
}

// Each of the 256 row bytes (one store sequence each on 64-bit hosts) in each row of a block and beside
// a full row: exactly its pixels stored, in every format fill_mask takes, at an odd x (unaligned).
TEST(PixelFormat, FillMaskStoresEveryRowByteExactly) {
  for (ml::PixelFormat f : kAll) {
    if (ml::format_bits_per_pixel(f) < 16) continue;
    ml::PixelPacker packer;
    packer.init(f, false);
    const int width = 13, rows = 9, x = 3, row = 1;
    const uint32_t stride = ml::format_stride(f, width);
    const ml::Pixel value = 0x3C96E1;
    for (uint32_t bits = 0; bits < 256; ++bits)
      for (int r = 0; r < 8; ++r) {
        const uint64_t mask = uint64_t(bits) << (8 * r) | (r > 0 ? 0xFFu : 0u);
        std::vector<uint8_t> by_mask(ml::format_band_bytes(f, width, rows), 0xA5);
        std::vector<uint8_t> by_fill = by_mask;
        ASSERT_EQ(packer.fill_mask(by_mask.data(), stride, x, row, mask, value), __builtin_popcountll(mask));
        for (int bit = 0; bit < 64; ++bit)
          if (mask >> bit & 1) packer.fill(by_fill.data(), stride, x + (bit & 7), row + (bit >> 3), 0, 1, 1, value);
        ASSERT_EQ(by_mask, by_fill) << "format " << int(f) << " row " << r << " bits " << bits;
      }
  }
}

TEST(PixelFormat, QuantizesToNearestAndExpandsBack) {
  EXPECT_EQ(ml::quantize_pixel(ml::PixelFormat::Rgb565Be, 0xFFFFFF, false, 0, 0), 0xFFFFu);
  EXPECT_EQ(ml::quantize_pixel(ml::PixelFormat::Rgb565Le, 0xFF0000, false, 0, 0), 0xF800u);
  EXPECT_EQ(ml::quantize_pixel(ml::PixelFormat::Grey4, 0xFFFFFF, false, 0, 0), 15u);
  EXPECT_EQ(ml::quantize_pixel(ml::PixelFormat::Mono1, 0x7F7F7F, false, 0, 0), 0u);
  EXPECT_EQ(ml::quantize_pixel(ml::PixelFormat::Mono1, 0x818181, false, 0, 0), 1u);
  EXPECT_EQ(ml::expand_stored(ml::PixelFormat::Grey4, 7), 0x777777u);
  EXPECT_EQ(ml::expand_stored(ml::PixelFormat::Rgb565Be, 0xFFFF), 0xFFFFFFu);
  // Every 8-bit value lands on the nearest of the format's levels.
  for (uint32_t v = 0; v < 256; ++v) {
    const uint32_t r5 = ml::quantize_pixel(ml::PixelFormat::Rgb565Be, v << 16, false, 0, 0) >> 11;
    EXPECT_LE(std::abs(int(r5 * 255) - int(v * 31)), 255 / 2 + 1) << v;
    const uint32_t g4 = ml::quantize_pixel(ml::PixelFormat::Grey4, v * 0x010101, false, 0, 0);
    EXPECT_LE(std::abs(int(g4 * 255) - int(v * 15)), 255 / 2 + 1) << v;
  }
}

TEST(PixelFormat, DitherKeepsTheAverageAndMovesAtMostOneLevel) {
  for (ml::PixelFormat f : {ml::PixelFormat::Grey4, ml::PixelFormat::Mono1, ml::PixelFormat::Rgb565Be}) {
    const uint32_t levels = f == ml::PixelFormat::Grey4 ? 15 : f == ml::PixelFormat::Mono1 ? 1 : 31;
    for (uint32_t v = 0; v < 256; v += 5) {
      const ml::Pixel p = f == ml::PixelFormat::Rgb565Be ? v << 16 : v * 0x010101;
      const uint32_t plain = ml::quantize_pixel(f, p, false, 0, 0) >> (f == ml::PixelFormat::Rgb565Be ? 11 : 0);
      double sum = 0;
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
          const uint32_t d = ml::quantize_pixel(f, p, true, x, y) >> (f == ml::PixelFormat::Rgb565Be ? 11 : 0);
          EXPECT_LE(std::abs(int(d) - int(plain)), 1) << v;
          sum += d;
        }
      // The 4x4 tile's mean is v in level units, to within one sixteenth of a level.
      EXPECT_NEAR(sum / 16.0, double(v) * levels / 255.0, 1.0 / 16 + 1e-9) << int(f) << " v " << v;
    }
  }
  // Lossless formats ignore the dither flag.
  EXPECT_EQ(ml::quantize_pixel(ml::PixelFormat::Xrgb8888, 0x123456, true, 1, 2), 0x123456u);
}

TEST(PixelFormat, BandSizesFollowTheFormats) {
  EXPECT_EQ(ml::format_band_bytes(ml::PixelFormat::Rgb565Be, 320, 16), 10240u);
  EXPECT_EQ(ml::format_band_bytes(ml::PixelFormat::Grey4, 128, 64), 4096u);
  EXPECT_EQ(ml::format_band_bytes(ml::PixelFormat::Grey4, 5, 1), 3u);
  EXPECT_EQ(ml::format_band_bytes(ml::PixelFormat::Mono1, 128, 64), 1024u);
  EXPECT_EQ(ml::format_band_bytes(ml::PixelFormat::Mono1, 128, 9), 256u);  // two pages
  EXPECT_EQ(ml::format_row_unit(ml::PixelFormat::Mono1), 8);
  EXPECT_TRUE(ml::format_dithers_by_default(ml::PixelFormat::Grey4));
  EXPECT_FALSE(ml::format_dithers_by_default(ml::PixelFormat::Rgb565Be));
}

}  // namespace

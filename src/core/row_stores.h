// The set pixels of one 8-pixel row of a block in one stored value, through a jump on the row's byte
// to straight-line stores at constant offsets (64-bit hosts: PixelPacker::fill_mask). A row's runs go
// out in the widest stores they fill (8, 4 or 2 bytes), so a full row of 4-byte pixels is four stores
// and a ragged one a store or two a run, instead of a bit scan and a store a pixel. Tiled blocks are
// mostly full rows or one run a row (2CylinderEngine at 1024x768: 46,000 ragged rows a frame).
#pragma once
#include <stdint.h>
#include <string.h>

namespace ml {

// The length of the run of set bits of a row byte from bit `at` on.
constexpr int row_run_at(unsigned bits, int at) {
  int n = 0;
  while (at + n < 8 && ((bits >> (at + n)) & 1u)) ++n;
  return n;
}

// Stores the value (wide: its kBytes bytes repeated to 8) at the pixels of row byte kBits from kAt on.
template <int kBytes, unsigned kBits, int kAt = 0>
[[gnu::always_inline]] inline void store_row_bits(uint8_t* line, const uint8_t* wide) {
  if constexpr (kAt < 8) {
    if constexpr (((kBits >> kAt) & 1u) == 0) {
      store_row_bits<kBytes, kBits, kAt + 1>(line, wide);
    } else {
      constexpr int kRunBytes = row_run_at(kBits, kAt) * kBytes;
      constexpr int kStore = kRunBytes >= 8 ? 8 : kRunBytes >= 4 ? 4 : kRunBytes >= 2 ? 2 : 1;
      memcpy(line + kAt * kBytes, wide, kStore);
      store_row_bits<kBytes, kBits, kAt + kStore / kBytes>(line, wide);
    }
  }
}

// The set bits of an 8x8 mask (bit r * 8 + c: pixel c of row r, rows `stride` bytes apart from `line`)
// in the value; returns the pixels stored. kBytes is 2 or 4.
template <int kBytes>
[[gnu::always_inline]] inline int store_mask_rows(uint8_t* line, uint32_t stride, uint64_t mask, const uint8_t* wide) {
  static_assert(kBytes == 2 || kBytes == 4, "a pixel in a power-of-two share of an 8-byte store");
  int stored = 0;
  for (; mask != 0; mask >>= 8, line += stride) {
    switch (unsigned(mask) & 0xFFu) {
#define ML_ROW_CASE(b)                                 \
  case (b):                                            \
    store_row_bits<kBytes, (b)>(line, wide);           \
    stored += __builtin_popcount(b);                   \
    break;
#define ML_ROW_CASES_4(b) ML_ROW_CASE(b) ML_ROW_CASE((b) + 1) ML_ROW_CASE((b) + 2) ML_ROW_CASE((b) + 3)
#define ML_ROW_CASES_16(b) ML_ROW_CASES_4(b) ML_ROW_CASES_4((b) + 4) ML_ROW_CASES_4((b) + 8) ML_ROW_CASES_4((b) + 12)
#define ML_ROW_CASES_64(b) \
  ML_ROW_CASES_16(b) ML_ROW_CASES_16((b) + 16) ML_ROW_CASES_16((b) + 32) ML_ROW_CASES_16((b) + 48)
      ML_ROW_CASES_64(0)
      ML_ROW_CASES_64(64)
      ML_ROW_CASES_64(128)
      ML_ROW_CASES_64(192)
#undef ML_ROW_CASES_64
#undef ML_ROW_CASES_16
#undef ML_ROW_CASES_4
#undef ML_ROW_CASE
    }
  }
  return stored;
}

}  // namespace ml

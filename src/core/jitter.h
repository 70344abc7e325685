// Jittered sample patterns (RenderOptions::samples = Jittered; docs/tiler.md): with f samples a pixel
// per axis (pitch p = 256 / f subpixels), sample (sx, sy) of pixel (px, py) lies at subpixel
//   (256 px + p sx + jx, 256 py + p sy + jy),  1 <= jx, jy <= p - 1,
// strictly inside its sub-cell, instead of the regular grid's p / 2. Every pixel uses one of
// kJitterPatterns patterns, chosen by a hash of its position and the seed, so no pattern repeats
// visibly; a pattern's offsets are a hash of the pattern and the sample. Integers only, the same on
// every machine: the tiler, the scanline renderer (Camera::sample_shift) and the tests share it.
#pragma once
#include <stdint.h>

namespace ml {

constexpr uint32_t kJitterPatterns = 16;

// murmur3's 32-bit finaliser: every input bit reaches every output bit.
constexpr uint32_t jitter_mix(uint32_t h) {
  h ^= h >> 16;
  h *= 0x85EBCA6Bu;
  h ^= h >> 13;
  h *= 0xC2B2AE35u;
  return h ^ (h >> 16);
}

// The pattern (0 .. kJitterPatterns - 1) of pixel (px, py).
constexpr uint32_t jitter_pattern(int px, int py, uint32_t seed) {
  return jitter_mix(uint32_t(px) * 0x9E3779B1u ^ jitter_mix(uint32_t(py) ^ seed)) % kJitterPatterns;
}

// Offset (jx, jy) in 1 .. pitch - 1 of sample (sx, sy) (each 0..7) in pattern `pattern`.
inline void jitter_offset(uint32_t pattern, int sx, int sy, int32_t pitch, int32_t* jx, int32_t* jy) {
  const uint32_t h = jitter_mix(pattern * 64u + uint32_t(sy) * 8u + uint32_t(sx) + 0x51ED27u);
  const uint32_t span = uint32_t(pitch) - 1;  // 1 .. pitch - 1
  *jx = 1 + int32_t(((h & 0xFFFFu) * span) >> 16);
  *jy = 1 + int32_t(((h >> 16) * span) >> 16);
}

// Bytes of a table of every pattern's offsets for f samples a pixel per axis (fill_jitter_table).
constexpr uint32_t jitter_table_bytes(int f) { return kJitterPatterns * uint32_t(f * f) * 2u; }

// table[(pattern * f * f + sy * f + sx) * 2 + {0, 1}] = jx, jy (each below 256 / f <= 128).
inline void fill_jitter_table(int f, uint8_t* table) {
  for (uint32_t k = 0; k < kJitterPatterns; ++k)
    for (int s = 0; s < f * f; ++s) {
      int32_t jx, jy;
      jitter_offset(k, s % f, s / f, 256 / f, &jx, &jy);
      table[(k * uint32_t(f * f) + uint32_t(s)) * 2] = uint8_t(jx);
      table[(k * uint32_t(f * f) + uint32_t(s)) * 2 + 1] = uint8_t(jy);
    }
}

}  // namespace ml

// The synthetic frames of the QEMU framebuffer test, shared by the guest program (fb_pattern.cpp)
// and the host-side check (fb_check.cpp): a full-screen frame A, then a smaller frame B of odd size
// drawn centred over it. Both patterns reach every channel value and change at every pixel, so a
// wrong stride, offset, channel order or rounding shows.
#pragma once
#include "core/sink.h"

namespace fbtest {

constexpr int kSmallWidth = 301, kSmallHeight = 203;

inline ml::Pixel pattern_a(int x, int y) {
  const uint32_t r = uint32_t(x) & 255, g = uint32_t(y) & 255, b = uint32_t(x * 3 + y * 5) & 255;
  // Colour bars along the top, gradients below.
  if (y < 32) {
    const int bar = (x / 32) & 7;
    return ml::rgb(bar & 4 ? 255 : 0, bar & 2 ? 255 : 0, bar & 1 ? 255 : 0);
  }
  return ml::rgb(r, g, b);
}

inline ml::Pixel pattern_b(int x, int y) {
  if (x == 0 || y == 0 || x == kSmallWidth - 1 || y == kSmallHeight - 1) return 0xFFFFFF;  // a white border
  return ml::rgb(uint32_t(x * 7 + y) & 255, 255 - (uint32_t(y * 3) & 255), uint32_t(x ^ y) & 255);
}

// The expected colour of screen pixel (x, y) on a w x h screen after both frames.
inline ml::Pixel expected(int x, int y, int w, int h) {
  const int bx = (w - kSmallWidth) / 2, by = (h - kSmallHeight) / 2;
  if (x >= bx && x < bx + kSmallWidth && y >= by && y < by + kSmallHeight) return pattern_b(x - bx, y - by);
  return pattern_a(x, y);
}

}  // namespace fbtest

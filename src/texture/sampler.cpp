#include "texture/sampler.h"

namespace ml {
namespace {

// A texel index along one axis of `size` texels (a power of two) under a wrap mode.
inline int32_t wrap(int64_t i, uint32_t size, uint8_t mode) {
  const int64_t n = int64_t(size);
  if (mode == uint8_t(TextureWrap::ClampToEdge)) return int32_t(i < 0 ? 0 : (i >= n ? n - 1 : i));
  if (mode == uint8_t(TextureWrap::MirroredRepeat)) {
    const int64_t m = i & (2 * n - 1);  // two's complement: the period is 2n for negative i too
    return int32_t(m < n ? m : 2 * n - 1 - m);
  }
  return int32_t(i & (n - 1));
}

inline Pixel from_565(uint32_t c) {
  const uint32_t r = (c >> 11) & 31, g = (c >> 5) & 63, b = c & 31;
  return rgb((r << 3) | (r >> 2), (g << 2) | (g >> 4), (b << 3) | (b >> 2));
}

// Inlined into both filters: a call per texel costs as much as the fetch.
__attribute__((always_inline)) inline Pixel texel(const TextureTexels& t, const uint8_t* bytes, int32_t x, int32_t y) {
  const uint32_t i = uint32_t(y) * t.width + uint32_t(x);
  switch (TexelFormat(t.format)) {
    case TexelFormat::Rgb565: return from_565(bytes[2 * i] | (uint32_t(bytes[2 * i + 1]) << 8));
    case TexelFormat::Palette8: {
      uint32_t index = bytes[2u * t.palette_size + i];
      if (index >= t.palette_size) index = t.palette_size - 1u;
      return from_565(bytes[2 * index] | (uint32_t(bytes[2 * index + 1]) << 8));
    }
    case TexelFormat::Grey4: {
      const uint32_t row = (uint32_t(t.width) + 1) / 2;
      const uint32_t byte = bytes[uint32_t(y) * row + uint32_t(x) / 2];
      const uint32_t g = ((x & 1) ? byte >> 4 : byte) & 15;
      return rgb(g * 17, g * 17, g * 17);
    }
    default: return 0;
  }
}

// (a (256 - f) + b f + 128) >> 8 per channel, f in 0..256. Red and blue share one multiply in two
// 16-bit lanes (each lane's sum stays below 2^16), green takes another: the same values as channel
// by channel.
inline Pixel lerp(Pixel a, Pixel b, uint32_t f) {
  const uint32_t g = 256 - f;
  const uint32_t rb = ((a & 0xFF00FF) * g + (b & 0xFF00FF) * f + 0x800080) >> 8;
  const uint32_t gg = ((a & 0xFF00) * g + (b & 0xFF00) * f + 0x8000) >> 8;
  return (rb & 0xFF00FF) | (gg & 0xFF00);
}

}  // namespace

Pixel sample_texture(const TextureTexels& t, const uint8_t* bytes, const int32_t uv[2]) {
  // Texel space: u * width in Q16 (|u| < 2^31, width <= 2^10: below 2^41).
  const int64_t su = int64_t(uv[0]) * t.width, sv = int64_t(uv[1]) * t.height;
  if (t.filter != uint8_t(TextureFilter::Bilinear)) {
    return texel(t, bytes, wrap(su >> 16, t.width, t.wrap_s), wrap(sv >> 16, t.height, t.wrap_t));
  }
  // Texel centres sit at half-integers: shift by half a texel, then blend the 2x2 neighbours.
  const int64_t bu = su - 32768, bv = sv - 32768;
  const int64_t x0 = bu >> 16, y0 = bv >> 16;
  const uint32_t fx = uint32_t((bu >> 8) & 0xFF), fy = uint32_t((bv >> 8) & 0xFF);
  const int32_t xa = wrap(x0, t.width, t.wrap_s), xb = wrap(x0 + 1, t.width, t.wrap_s);
  const int32_t ya = wrap(y0, t.height, t.wrap_t), yb = wrap(y0 + 1, t.height, t.wrap_t);
  const Pixel top = lerp(texel(t, bytes, xa, ya), texel(t, bytes, xb, ya), fx);
  const Pixel bottom = lerp(texel(t, bytes, xa, yb), texel(t, bytes, xb, yb), fx);
  return lerp(top, bottom, fy);
}

}  // namespace ml

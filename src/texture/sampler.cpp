#include "texture/sampler.h"

namespace ml {
namespace {

// The nearest loops unrolled by 8 on the host (the loop's count, compare and branch once every 8
// samples: about 2 instructions a sample less); not in the firmware (ML_TEXTURE_RUNS_GENERAL_ONLY), for
// its code budget.
#ifndef ML_TEXTURE_RUNS_GENERAL_ONLY
#define ML_UNROLL_TEXEL_LOOP _Pragma("GCC unroll 8")
#else
#define ML_UNROLL_TEXEL_LOOP
#endif

// Helpers of the run loops forced inline on the host (inlined or not, the loops around them compile
// differently); the firmware leaves them to -Os, for its code budget.
#ifndef ML_TEXTURE_RUNS_GENERAL_ONLY
#define ML_RUN_HELPER __attribute__((always_inline)) inline
#define ML_RUN_LAMBDA __attribute__((always_inline))
#else
#define ML_RUN_HELPER inline
#define ML_RUN_LAMBDA
#endif

// A texel index along one axis of `size` texels (a power of two) under wrap mode M.
template <TextureWrap M>
__attribute__((always_inline)) inline int32_t wrap_as(int64_t i, int32_t size) {
  if (M == TextureWrap::ClampToEdge) return int32_t(i < 0 ? 0 : (i >= size ? size - 1 : i));
  if (M == TextureWrap::MirroredRepeat) {
    const int32_t m = int32_t(i) & (2 * size - 1);  // two's complement: the period is 2n for negative i too
    return m < size ? m : 2 * size - 1 - m;
  }
  return int32_t(i) & (size - 1);
}

// wrap_as() with the mode known when drawing.
inline int32_t wrap(int64_t i, uint32_t size, uint8_t mode) {
  if (mode == uint8_t(TextureWrap::ClampToEdge)) return wrap_as<TextureWrap::ClampToEdge>(i, int32_t(size));
  if (mode == uint8_t(TextureWrap::MirroredRepeat)) return wrap_as<TextureWrap::MirroredRepeat>(i, int32_t(size));
  return wrap_as<TextureWrap::Repeat>(i, int32_t(size));
}

inline uint32_t expand5(uint32_t v) { return (v << 3) | (v >> 2); }
inline uint32_t expand6(uint32_t v) { return (v << 2) | (v >> 4); }

inline Pixel from_565(uint32_t c) {
  return rgb(expand5((c >> 11) & 31), expand6((c >> 5) & 63), expand5(c & 31));
}

inline uint32_t load16(const uint8_t* p) { return p[0] | (uint32_t(p[1]) << 8); }

// Texel (x, y) decoded from the bytes. Inlined into both filters: a call per texel costs as much as
// the fetch.
__attribute__((always_inline)) inline Pixel texel(const TextureTexels& t, const uint8_t* bytes, int32_t x, int32_t y) {
  const uint32_t i = uint32_t(y) * t.width + uint32_t(x);
  switch (TexelFormat(t.format)) {
    case TexelFormat::Rgb565: return from_565(load16(bytes + 2 * i));
    case TexelFormat::Palette8: {
      uint32_t index = bytes[2u * t.palette_size + i];
      if (index >= t.palette_size) index = t.palette_size - 1u;
      return from_565(load16(bytes + 2 * index));
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

// Texels (x, y) of format F through a make_texel_lut table. A value of its own, so that the loops
// keep the fields in registers (stores of the colours cannot change them).
// Entry: Pixel, or on 64-bit hosts a table's colours in lanes (TexturePager::lanes_of).
template <TexelFormat F, typename Entry = Pixel>
struct LutTexels {
  const uint8_t* texels;  // the indices (Palette8), levels (Grey4) or colours (Rgb565)
  const Entry* lut;
  uint32_t row;           // the bytes (Grey4) or texels a row: a product per texel, no shift by a
                          // count (which x86 holds in one register, wanted by the coordinates)
  LutTexels(const TextureTexels& t, const uint8_t* bytes, const Entry* table)
      : texels(bytes + (F == TexelFormat::Palette8 ? 2u * t.palette_size : 0u)),
        lut(table),
        row(F == TexelFormat::Grey4 ? (uint32_t(t.width) + 1) / 2 : t.width) {}
  __attribute__((always_inline)) Entry operator()(int32_t x, int32_t y) const {
    const uint32_t row = uint32_t(y) * this->row;  // indices widened as addresses: no zero-extension a texel
    if (F == TexelFormat::Palette8) return lut[texels[uintptr_t(row) + uint32_t(x)]];
    if (F == TexelFormat::Grey4) {
      const uint32_t byte = texels[uintptr_t(row) + uint32_t(x) / 2];
      return lut[((x & 1) ? byte >> 4 : byte) & 15];
    }
    const uint32_t c = load16(texels + 2 * (uintptr_t(row) + uint32_t(x)));
    return lut[c >> 11] | lut[32 + ((c >> 5) & 63)] | lut[96 + (c & 31)];
  }
};

// (a (256 - f) + b f + 128) >> 8 per channel, f in 0..256. Red and blue share one multiply in two
// 16-bit lanes (each lane's sum stays below 2^16), green takes another: the same values as channel
// by channel.
inline Pixel lerp(Pixel a, Pixel b, uint32_t f) {
  const uint32_t g = 256 - f;
  const uint32_t rb = ((a & 0xFF00FF) * g + (b & 0xFF00FF) * f + 0x800080) >> 8;
  const uint32_t gg = ((a & 0xFF00) * g + (b & 0xFF00) * f + 0x8000) >> 8;
  return (rb & 0xFF00FF) | (gg & 0xFF00);
}

// lerp() on colours spread to 16-bit lanes of a machine word. 64-bit words (blue at bit 0, red at
// 16, green at 32): one multiply per colour for all three channels; each lane's sum stays below 2^16,
// so the lanes give lerp()'s values. 32-bit words (Cortex-M, where a 64-bit product is several
// instructions or a library call): lerp() itself on the colours.
#if UINTPTR_MAX > 0xFFFFFFFFu
using Spread = uint64_t;
constexpr uint64_t kSpreadMask = 0x000000FF00FF00FFull;
inline Spread spread(Pixel c) { return (c | (uint64_t(c) << 24)) & kSpreadMask; }
inline Spread spread(Spread s) { return s; }  // a colour already in lanes (TexturePager::lanes_of)
inline Pixel unspread(Spread s) { return Pixel(s | (s >> 24)) & 0xFFFFFF; }
inline Spread lerp_spread(Spread a, Spread b, uint32_t f) {
  return ((a * (256 - f) + b * f + 0x0000008000800080ull) >> 8) & kSpreadMask;
}
// A colour's channels as multipliers of the lanes (blue, red, green).
struct Tint {
  uint64_t b, r, g;
};
inline Tint tint_of(Pixel c) { return Tint{c & 0xFF, (c >> 16) & 0xFF, (c >> 8) & 0xFF}; }
// modulate_texel on a colour in lanes: the three products in their lanes (each <= 255 * 255 <
// 2^16), each rounded as round(p / 255) = (x + (x >> 8)) >> 8 with x = p + 128 (<= 65,153, and the
// sum <= 65,407: no carry between lanes). The same values as modulate_texel's ((p + 128) 257) >> 16
// for every texel and colour channel (tests/texture/texture_test.cpp tries them all).
inline Spread modulate_spread(Spread s, const Tint& c) {
  const uint64_t x = (s & 0xFF) * c.b + (s & 0xFF0000) * c.r + (s & 0xFF00000000ull) * c.g + 0x0000008000800080ull;
  return ((x + ((x >> 8) & kSpreadMask)) >> 8) & kSpreadMask;
}
// A grey colour's (its three channels alike: white light on a white base colour, the common textured
// case) one multiplier for all three lanes, or 0 (1..255 for grey; black takes modulate_spread).
inline uint64_t grey_of(const Tint& c) { return c.b == c.r && c.b == c.g ? c.b : 0; }
// modulate_spread for a grey colour: one product for the three lanes (each lane's value <= 255, so
// each product stays in its lane), rounded alike: the same values.
inline Spread modulate_spread_grey(Spread s, uint64_t grey) {
  const uint64_t x = s * grey + 0x0000008000800080ull;
  return ((x + ((x >> 8) & kSpreadMask)) >> 8) & kSpreadMask;
}
#else
using Spread = Pixel;
inline Spread spread(Pixel c) { return c; }
inline Pixel unspread(Spread s) { return s; }
inline Spread lerp_spread(Spread a, Spread b, uint32_t f) { return lerp(a, b, f); }
using Tint = Pixel;
inline Tint tint_of(Pixel c) { return c; }
inline Spread modulate_spread(Spread s, Tint c) { return modulate_texel(s, c); }
inline uint32_t grey_of(Tint) { return 0; }
inline Spread modulate_spread_grey(Spread s, uint32_t grey) { return modulate_texel(s, grey * 0x010101u); }
#endif

// The 2x2 texels bilinear filtering blends at uv, and the blend's weights (1/256).
struct Taps {
  int32_t xa, xb, ya, yb;
  uint32_t fx, fy;
};

// The taps of a texture repeating on both axes, of sizes width x height (masks mu, mv: one less).
// Modulo 2^32: the bits kept (the fraction's 8 below bit 16, the texel's at most kMaxTextureDimBits
// above it) lie below bit 32: the same values as in 64 bits (bilinear_taps).
__attribute__((always_inline)) inline Taps repeat_taps(uint32_t width, uint32_t height, uint32_t mu, uint32_t mv,
                                                       int32_t u, int32_t v) {
  Taps k;
  const uint32_t bu = uint32_t(u) * width - 32768u, bv = uint32_t(v) * height - 32768u;
  k.fx = (bu >> 8) & 0xFF;
  k.fy = (bv >> 8) & 0xFF;
  k.xa = int32_t((bu >> 16) & mu);
  k.xb = int32_t((uint32_t(k.xa) + 1) & mu);
  k.ya = int32_t((bv >> 16) & mv);
  k.yb = int32_t((uint32_t(k.ya) + 1) & mv);
  return k;
}

// Repeat: both axes repeat (wrapping is a mask).
template <bool Repeat>
__attribute__((always_inline)) inline Taps bilinear_taps(const TextureTexels& t, int32_t u, int32_t v) {
  if (Repeat) return repeat_taps(t.width, t.height, t.width - 1u, t.height - 1u, u, v);
  // Texel space: u * width in Q16 (|u| < 2^31, width <= 2^10: below 2^41). Texel centres sit at
  // half-integers: shift by half a texel, then blend the 2x2 neighbours.
  Taps k;
  const int64_t bu = int64_t(u) * t.width - 32768, bv = int64_t(v) * t.height - 32768;
  const int64_t x0 = bu >> 16, y0 = bv >> 16;
  k.fx = uint32_t((bu >> 8) & 0xFF);
  k.fy = uint32_t((bv >> 8) & 0xFF);
  k.xa = wrap(x0, t.width, t.wrap_s);
  k.xb = wrap(x0 + 1, t.width, t.wrap_s);
  k.ya = wrap(y0, t.height, t.wrap_t);
  k.yb = wrap(y0 + 1, t.height, t.wrap_t);
  return k;
}

// A repeating texture's sizes and masks, worked out once for a loop's many samples (lanes_spans: the
// masks are not made again for each span), and bilinear_taps<true>'s taps of them.
struct RepeatSizes {
  uint32_t width, height, mu, mv;
};
template <bool Repeat>
__attribute__((always_inline)) inline Taps bilinear_taps(const RepeatSizes& t, int32_t u, int32_t v) {
  static_assert(Repeat, "sizes of a repeating texture");
  return repeat_taps(t.width, t.height, t.mu, t.mv, u, v);
}

// Bilinear filtering at uv of the texels fetch(x, y) gives.
template <bool Repeat, typename Fetch>
__attribute__((always_inline)) inline Pixel bilinear(const TextureTexels& t, int32_t u, int32_t v, Fetch fetch) {
  const Taps k = bilinear_taps<Repeat>(t, u, v);
  const Pixel top = lerp(fetch(k.xa, k.ya), fetch(k.xb, k.ya), k.fx);
  const Pixel bottom = lerp(fetch(k.xa, k.yb), fetch(k.xb, k.yb), k.fx);
  return lerp(top, bottom, k.fy);
}

// A small triangle's bilinear filtering (the texels filtered, then multiplied: docs/textures.md):
// modulate_texel(bilinear(t, u, v, fetch), colour) for tint = tint_of(colour), the blend and the
// product in lanes (the same values). Grey: the colour is grey, grey_of(tint) its multiplier. T:
// TextureTexels, or RepeatSizes when Repeat.
template <bool Repeat, bool Grey, typename Fetch, typename T>
__attribute__((always_inline)) inline Pixel bilinear_tinted(const T& t, int32_t u, int32_t v, Fetch fetch,
                                                            const Tint& tint) {
  const Taps k = bilinear_taps<Repeat>(t, u, v);
  const Spread top = lerp_spread(spread(fetch(k.xa, k.ya)), spread(fetch(k.xb, k.ya)), k.fx);
  const Spread bottom = lerp_spread(spread(fetch(k.xa, k.yb)), spread(fetch(k.xb, k.yb)), k.fx);
  const Spread filtered = lerp_spread(top, bottom, k.fy);
  return unspread(Grey ? modulate_spread_grey(filtered, grey_of(tint)) : modulate_spread(filtered, tint));
}

// Stepped coordinates a (start) and s (step) of two axes, to be shifted right by shift[0] and
// shift[1]: the axis of the smaller shift is scaled up so that both take the larger one, returned
// (floor(a 2^d / 2^(r + d)) = floor(a / 2^r)): one shift count in the loops (x86 shifts by a count
// held in one register). |a|, |s| < 2^37 and d <= 10: within int64.
ML_RUN_HELPER int common_shift(int64_t a[2], int64_t s[2], const int shift[2]) {
  const int k = shift[0] < shift[1] ? 0 : 1, d = shift[1 - k] - shift[k];
  a[k] *= int64_t(1) << d;
  s[k] *= int64_t(1) << d;
  return shift[1 - k];
}

// Whether the texel indices a >> shift of samples 0 .. n - 1 (a stepped by s) all lie in
// [0, last]: along a piece they are monotonic, so its ends decide. Wrapping leaves such indices as
// they are, whatever the mode.
ML_RUN_HELPER bool within(int64_t a, int64_t s, int32_t n, int shift, int32_t last) {
  const int64_t first = a >> shift, end = (a + s * (n - 1)) >> shift;
  return first >= 0 && end >= 0 && first <= last && end <= last;
}

// How the bilinear and nearest loops wrap texel indices: a mask (both axes repeat), each axis by its
// mode, or not at all (every index of the run inside the texture: `within`).
enum class Wrapping { Mask, Modes, Inside };

// bilinear_run's loop: a = (a_u, a_v) in units of 1/256 texel << right, stepped by s.
template <Wrapping W, typename Fetch>
__attribute__((always_inline)) inline void bilinear_loop(const TextureTexels& t, int right, int64_t au, int64_t av,
                                                         int64_t su, int64_t sv, Fetch fetch, int32_t n, Pixel* out) {
  const int32_t mu = int32_t(t.width) - 1, mv = int32_t(t.height) - 1;
  for (int32_t i = 0; i < n; ++i, au += su, av += sv) {
    const int64_t cu = au >> right, cv = av >> right;
    const uint32_t fx = uint32_t(cu) & 0xFF, fy = uint32_t(cv) & 0xFF;
    int32_t xa, xb, ya, yb;
    if (W == Wrapping::Mask) {
      xa = int32_t(cu >> 8) & mu;
      xb = (xa + 1) & mu;
      ya = int32_t(cv >> 8) & mv;
      yb = (ya + 1) & mv;
    } else if (W == Wrapping::Inside) {
      xa = int32_t(cu >> 8);
      xb = xa + 1;
      ya = int32_t(cv >> 8);
      yb = ya + 1;
    } else {
      xa = wrap(cu >> 8, t.width, t.wrap_s);
      xb = wrap((cu >> 8) + 1, t.width, t.wrap_s);
      ya = wrap(cv >> 8, t.height, t.wrap_t);
      yb = wrap((cv >> 8) + 1, t.height, t.wrap_t);
    }
    const Spread top = lerp_spread(spread(fetch(xa, ya)), spread(fetch(xb, ya)), fx);
    const Spread bottom = lerp_spread(spread(fetch(xa, yb)), spread(fetch(xb, yb)), fx);
    out[i] = unspread(lerp_spread(top, bottom, fy));
  }
}

// n samples of bilinear filtering along an affine piece, a = (a_u, a_v) stepped by s: the same
// colours as bilinear() at (int32_t(a_u >> bits), int32_t(a_v >> bits)) (the coordinates of a piece
// stay within int32, its ends being such). For textures of at most 256 texels a side (the
// compiler's default limit), without bilinear()'s products per sample: in units of 1/256 texel less
// half a texel, floor(floor(a / 2^bits) 2^size_bits / 256) - 128 is (a - 128 2^r) >> r with
// r = bits + 8 - size_bits >= 0: the texel a >> 8, the fraction the low 8 bits. Runs whose two
// texels a side stay inside the texture take no wrapping.
template <bool Repeat, typename Fetch>
__attribute__((always_inline)) inline void bilinear_run(const TextureTexels& t, const int32_t size_bits[2], int bits,
                                                        int64_t au, int64_t av, int64_t su, int64_t sv, Fetch fetch,
                                                        int32_t n, Pixel* out) {
#ifndef ML_TEXTURE_RUNS_GENERAL_ONLY
  const bool general = size_bits[0] > 8 || size_bits[1] > 8;
#else
  const bool general = true;  // the firmware's code budget: only bilinear()
#endif
  if (general) {
    if constexpr (sizeof(decltype(fetch(0, 0))) > sizeof(Pixel)) {  // colours in lanes (lanes_run): as colours
      const auto colour_at = [&](int32_t x, int32_t y) { return unspread(fetch(x, y)); };
      for (int32_t i = 0; i < n; ++i, au += su, av += sv)
        out[i] = bilinear<Repeat>(t, int32_t(au >> bits), int32_t(av >> bits), colour_at);
    } else {
      for (int32_t i = 0; i < n; ++i, au += su, av += sv)
        out[i] = bilinear<Repeat>(t, int32_t(au >> bits), int32_t(av >> bits), fetch);
    }
    return;
  }
  const int shifts[2] = {bits + 8 - size_bits[0], bits + 8 - size_bits[1]};
  int64_t a[2] = {au - (int64_t(128) << shifts[0]), av - (int64_t(128) << shifts[1])}, s[2] = {su, sv};
  const int right = common_shift(a, s, shifts);
  if (Repeat) return bilinear_loop<Wrapping::Mask>(t, right, a[0], a[1], s[0], s[1], fetch, n, out);
#ifndef ML_TEXTURE_RUNS_GENERAL_ONLY
  if (within(a[0], s[0], n, right + 8, int32_t(t.width) - 2) && within(a[1], s[1], n, right + 8, int32_t(t.height) - 2))
    return bilinear_loop<Wrapping::Inside>(t, right, a[0], a[1], s[0], s[1], fetch, n, out);
#endif
  bilinear_loop<Wrapping::Modes>(t, right, a[0], a[1], s[0], s[1], fetch, n, out);
}

// Texel (x, y) of the texture's white table (its texels decoded once), the format looked at per texel
// (the boards' per-sample loop below: one function for all three formats, their code budget).
__attribute__((always_inline)) inline Pixel white_texel(const TextureTexels& t, const uint8_t* bytes, const Pixel* white,
                                                        int32_t x, int32_t y) {
  switch (TexelFormat(t.format)) {
    case TexelFormat::Palette8: return LutTexels<TexelFormat::Palette8>(t, bytes, white)(x, y);
    case TexelFormat::Grey4: return LutTexels<TexelFormat::Grey4>(t, bytes, white)(x, y);
    default: return LutTexels<TexelFormat::Rgb565>(t, bytes, white)(x, y);
  }
}
// A small triangle's bilinear sample through the white table: the filter of the table's texels,
// x colour, as textured_colour's small order gives it.
Pixel small_bilinear_white(const TextureTexels& t, const uint8_t* bytes, const Pixel* white, const int32_t uv[2],
                           Pixel colour) {
  const auto fetch = [&](int32_t x, int32_t y) { return white_texel(t, bytes, white, x, y); };
  return modulate_texel(bilinear<false>(t, uv[0], uv[1], fetch), colour);
}

// The textured colour at uv decoding texels one by one: nearest, the texel x colour (the texel from
// the texture's white table when given one); bilinear, the filter of the texels x colour (each
// neighbour modulated, as a modulated texel table gives them), or for a small triangle the filter of
// the texels, x colour.
Pixel textured_colour(const TextureTexels& t, const uint8_t* bytes, const int32_t uv[2], Pixel colour, bool small,
                      const Pixel* white = nullptr) {
  if (t.filter != uint8_t(TextureFilter::Bilinear)) {
    const int64_t su = int64_t(uv[0]) * t.width, sv = int64_t(uv[1]) * t.height;
    const int32_t x = wrap(su >> 16, t.width, t.wrap_s), y = wrap(sv >> 16, t.height, t.wrap_t);
    return modulate_texel(white ? white_texel(t, bytes, white, x, y) : texel(t, bytes, x, y), colour);
  }
  // One filter for both orders (modulate_texel leaves a colour as it is for white): the code budget.
  const Pixel first = small ? 0xFFFFFF : colour, then = small ? colour : 0xFFFFFF;
  return modulate_texel(
      bilinear<false>(t, uv[0], uv[1], [&](int32_t x, int32_t y) { return modulate_texel(texel(t, bytes, x, y), first); }),
      then);
}

// n samples of one affine piece, from sample j of it, through the table (texels modulated by the
// colour, then by `after`; after is white for bilinear filtering). Nearest filtering takes the texel
// index straight from the stepped coordinate: floor(floor(a / 2^bits) W / 2^16) is
// a >> (bits + 16 - log2 W) for a power-of-two W.
template <TexelFormat F, bool Bilinear, bool Repeat>
void piece_run(const TexturePiece& pc, const TexturePlanes& p, const TextureTexels& texture, const uint8_t* bytes,
               const Pixel* lut, Pixel after, int64_t j, int32_t n, Pixel* out) {
  const TextureTexels t = texture;  // a local copy: its fields stay in registers
  const LutTexels<F> fetch(t, bytes, lut);
  const int bits = pc.bits;
  int64_t au = int64_t(pc.uv[0]) * (int64_t(1) << bits) + pc.step[0] * j;
  int64_t av = int64_t(pc.uv[1]) * (int64_t(1) << bits) + pc.step[1] * j;
  const int64_t su = pc.step[0], sv = pc.step[1];
  if (Bilinear) {
    bilinear_run<Repeat>(t, p.size_bits, bits, au, av, su, sv, fetch, n, out);
    return;
  }
  const int shifts[2] = {bits + 16 - p.size_bits[0], bits + 16 - p.size_bits[1]};
  int64_t a[2] = {au, av}, s[2] = {su, sv};
  const int shift = common_shift(a, s, shifts);
  au = a[0], av = a[1];
  if (Repeat) {
    const int32_t mask_u = int32_t(t.width) - 1, mask_v = int32_t(t.height) - 1;
    if (after == 0xFFFFFF) {
      ML_UNROLL_TEXEL_LOOP
      for (int32_t i = 0; i < n; ++i, au += s[0], av += s[1])
        out[i] = fetch(int32_t(au >> shift) & mask_u, int32_t(av >> shift) & mask_v);
      return;
    }
    for (int32_t i = 0; i < n; ++i, au += s[0], av += s[1])
      out[i] = modulate_texel(fetch(int32_t(au >> shift) & mask_u, int32_t(av >> shift) & mask_v), after);
    return;
  }
  for (int32_t i = 0; i < n; ++i, au += s[0], av += s[1]) {
    const int32_t x = wrap(au >> shift, t.width, t.wrap_s), y = wrap(av >> shift, t.height, t.wrap_t);
    out[i] = modulate_texel(fetch(x, y), after);
  }
}

// Nearest texels of n samples whose indices (a + s j) >> shift on both axes lie inside the texture.
template <typename Fetch>
__attribute__((always_inline)) inline void nearest_inside(const Fetch& fetch, int64_t au, int64_t av, int64_t su,
                                                          int64_t sv, int shift, int32_t n, Pixel* out) {
  ML_UNROLL_TEXEL_LOOP
  for (int32_t i = 0; i < n; ++i, au += su, av += sv) out[i] = fetch(int32_t(au >> shift), int32_t(av >> shift));
}

// One axis of a run whose texel indices (a + s j) >> shift leave the texture (2^size_bits texels, wrap
// mode M): how many samples from j = 0 on (at most n) keep their index in sample 0's cell of the wrap
// (a period of Repeat, a half period of MirroredRepeat, the texture or one side of it for
// ClampToEdge), with *a and *s replaced by a start and step whose indices are the wrapped ones there:
// the start moved by whole periods; in a mirrored half, reversed (C - (x >> shift) is
// (~x + (C + 1) 2^shift) >> shift, and ~x = -x - 1); on a clamped side, constant. Along a run the
// indices are monotonic, so a cell is one stretch of samples.
template <TextureWrap M>
__attribute__((always_inline)) inline int32_t wrap_cell(int64_t* a, int64_t* s, int shift, int size_bits, int32_t n) {
  const int64_t one = int64_t(1) << shift, size = int64_t(1) << size_bits, i = *a >> shift;
  int64_t lo = (i >> size_bits) * size, hi = lo + size;  // the cell's indices [lo, hi)
  bool below = true, above = true;                      // whether it ends there
  if (M == TextureWrap::ClampToEdge) {
    lo = i < 0 ? 0 : (i < size ? 0 : size);
    hi = i < 0 ? 0 : size;
    below = i >= 0;
    above = i < size;
  }
  uint64_t count = uint64_t(n);
  if (*s > 0 && above) count = udiv64(uint64_t(hi * one - *a) + uint64_t(*s) - 1, uint64_t(*s));  // ceil
  if (*s < 0 && below) count = udiv64(uint64_t(*a - lo * one), uint64_t(-*s)) + 1;
  if (M == TextureWrap::ClampToEdge) {
    if (i < 0 || i >= size) {
      *a = i < 0 ? 0 : (size - 1) * one;
      *s = 0;
    }
  } else if (M == TextureWrap::MirroredRepeat && ((i >> size_bits) & 1)) {
    *a = hi * one - 1 - *a;
    *s = -*s;
  } else {
    *a -= lo * one;
  }
  return count < uint64_t(n) ? int32_t(count) : n;
}

// The wrap cells a run's indices (a + s j) >> shift cross along one axis (periods of the texture's
// 2^size_bits texels: for a clamped axis at least those crossed).
inline int64_t cells_crossed(int64_t a, int64_t s, int32_t n, int shift, int size_bits) {
  const int64_t first = (a >> shift) >> size_bits, last = ((a + s * (n - 1)) >> shift) >> size_bits;
  return first < last ? last - first : first - last;
}

// Nearest filtering, both axes' wrap modes fixed (mirrored and clamped textures: no mode tests per
// sample); the table gives texels modulated by the colour. A run whose indices leave the texture is
// cut at the wrap's cells (wrap_cell) when it crosses few of them, each cell drawn as if inside.
template <TexelFormat F, TextureWrap S, TextureWrap T>
void nearest_run(const TexturePiece& pc, const TexturePlanes& p, const TextureTexels& texture, const uint8_t* bytes,
                 const Pixel* lut, int64_t j, int32_t n, Pixel* out) {
  const LutTexels<F> fetch(texture, bytes, lut);
  const int32_t width = texture.width, height = texture.height;
  const int bits = pc.bits;
  int64_t au = int64_t(pc.uv[0]) * (int64_t(1) << bits) + pc.step[0] * j;
  int64_t av = int64_t(pc.uv[1]) * (int64_t(1) << bits) + pc.step[1] * j;
  const int shifts[2] = {bits + 16 - p.size_bits[0], bits + 16 - p.size_bits[1]};
  int64_t a[2] = {au, av}, s[2] = {pc.step[0], pc.step[1]};
  const int shift = common_shift(a, s, shifts);
  au = a[0], av = a[1];
  const int64_t su = s[0], sv = s[1];
  const bool inside_u = within(au, su, n, shift, width - 1), inside_v = within(av, sv, n, shift, height - 1);
  if (inside_u && inside_v) return nearest_inside(fetch, au, av, su, sv, shift, n, out);
  // A cell of an axis costs about what wrapping 4 samples does: cut runs of at least 8 samples a cell.
  if (n >= 8 && (1 + (inside_u ? 0 : cells_crossed(au, su, n, shift, p.size_bits[0])) +
                 (inside_v ? 0 : cells_crossed(av, sv, n, shift, p.size_bits[1]))) * 8 <= n) {
    while (n > 0) {
      int64_t cu = au, tu = su, cv = av, tv = sv;
      const int32_t m = min_of(inside_u ? n : wrap_cell<S>(&cu, &tu, shift, p.size_bits[0], n),
                               inside_v ? n : wrap_cell<T>(&cv, &tv, shift, p.size_bits[1], n));
      nearest_inside(fetch, cu, cv, tu, tv, shift, m, out);
      out += m;
      n -= m;
      au += su * m;
      av += sv * m;
    }
    return;
  }
  for (int32_t i = 0; i < n; ++i, au += su, av += sv)
    out[i] = fetch(wrap_as<S>(au >> shift, width), wrap_as<T>(av >> shift, height));
}

// A run of one affine piece (piece_run's arguments), chosen once per call of texture_rows for the
// texture's format, filter and wraps: no tests of them per piece or per row.
using PieceRun = void (*)(const TexturePiece& pc, const TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes,
                          const Pixel* lut, Pixel after, int64_t j, int32_t n, Pixel* out);

#ifndef ML_TEXTURE_RUNS_GENERAL_ONLY
// A bilinear run through the white table, each texel multiplied by `after` before the filter (as a
// table of that colour gives them: a run too short to have one made). A function of its own, so that
// piece_run's loops keep their code.
template <TexelFormat F, bool Repeat>
void bilinear_white_run(const TexturePiece& pc, const TexturePlanes& p, const TextureTexels& texture,
                        const uint8_t* bytes, const Pixel* lut, Pixel after, int64_t j, int32_t n, Pixel* out) {
  const TextureTexels t = texture;
  const LutTexels<F> fetch(t, bytes, lut);
  const auto modulated = [&](int32_t x, int32_t y) { return modulate_texel(fetch(x, y), after); };
  const int bits = pc.bits;
  const int64_t au = int64_t(pc.uv[0]) * (int64_t(1) << bits) + pc.step[0] * j;
  const int64_t av = int64_t(pc.uv[1]) * (int64_t(1) << bits) + pc.step[1] * j;
  bilinear_run<Repeat>(t, p.size_bits, bits, au, av, pc.step[0], pc.step[1], modulated, n, out);
}

// nearest_run as a PieceRun (the table's colours are the output: after is white).
template <TexelFormat F, TextureWrap S, TextureWrap T>
void nearest_piece(const TexturePiece& pc, const TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes,
                   const Pixel* lut, Pixel, int64_t j, int32_t n, Pixel* out) {
  nearest_run<F, S, T>(pc, p, t, bytes, lut, j, n, out);
}

template <TexelFormat F, TextureWrap S>
PieceRun nearest_piece_s(uint8_t wrap_t) {
  switch (TextureWrap(wrap_t)) {
    case TextureWrap::Repeat:
      if constexpr (S == TextureWrap::Repeat) return nullptr;  // both axes repeat: piece_run's mask loop
      else return &nearest_piece<F, S, TextureWrap::Repeat>;
    case TextureWrap::MirroredRepeat: return &nearest_piece<F, S, TextureWrap::MirroredRepeat>;
    case TextureWrap::ClampToEdge: return &nearest_piece<F, S, TextureWrap::ClampToEdge>;
    default: return nullptr;
  }
}

template <TexelFormat F>
PieceRun piece_run_for(const TextureTexels& t, Pixel after) {
  const bool repeat = t.wrap_s == uint8_t(TextureWrap::Repeat) && t.wrap_t == uint8_t(TextureWrap::Repeat);
  if (t.filter == uint8_t(TextureFilter::Bilinear) && after != 0xFFFFFF)
    return repeat ? &bilinear_white_run<F, true> : &bilinear_white_run<F, false>;
  if (t.filter == uint8_t(TextureFilter::Bilinear))
    return repeat ? &piece_run<F, true, true> : &piece_run<F, true, false>;
  if (repeat) return &piece_run<F, false, true>;
  PieceRun run = nullptr;
  if (after == 0xFFFFFF) {
    switch (TextureWrap(t.wrap_s)) {
      case TextureWrap::Repeat: run = nearest_piece_s<F, TextureWrap::Repeat>(t.wrap_t); break;
      case TextureWrap::MirroredRepeat: run = nearest_piece_s<F, TextureWrap::MirroredRepeat>(t.wrap_t); break;
      case TextureWrap::ClampToEdge: run = nearest_piece_s<F, TextureWrap::ClampToEdge>(t.wrap_t); break;
      default: break;
    }
  }
  return run ? run : &piece_run<F, false, false>;
}
#else
// The firmware's runs (ML_TEXTURE_RUNS_GENERAL_ONLY, set by the firmware build, Makefile fw_opt: its
// code budget): one function a format, the filter and the wraps tested per piece, and no runs
// specialized by wrap mode (eight instances, about 10 KB of Cortex-M code; the general run gives the
// same texels).
template <TexelFormat F>
void format_run(const TexturePiece& pc, const TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes,
                const Pixel* lut, Pixel after, int64_t j, int32_t n, Pixel* out) {
  const bool repeat = t.wrap_s == uint8_t(TextureWrap::Repeat) && t.wrap_t == uint8_t(TextureWrap::Repeat);
  if (t.filter == uint8_t(TextureFilter::Bilinear)) {
    if (repeat) piece_run<F, true, true>(pc, p, t, bytes, lut, after, j, n, out);
    else piece_run<F, true, false>(pc, p, t, bytes, lut, after, j, n, out);
  } else if (repeat) {
    piece_run<F, false, true>(pc, p, t, bytes, lut, after, j, n, out);
  } else {
    piece_run<F, false, false>(pc, p, t, bytes, lut, after, j, n, out);
  }
}

template <TexelFormat F>
PieceRun piece_run_for(const TextureTexels&, Pixel) {
  return &format_run<F>;
}
#endif

#if UINTPTR_MAX > 0xFFFFFFFFu && !defined(ML_TEXTURE_RUNS_GENERAL_ONLY)
// piece_run's bilinear samples through a table of the colour whose colours are already in lanes
// (TexturePager::lanes_of): the same blends, without spreading each texel.
using LanesRun = void (*)(const TexturePiece& pc, const TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes,
                          const uint64_t* lanes, int64_t j, int32_t n, Pixel* out);
template <TexelFormat F, bool Repeat>
void lanes_run(const TexturePiece& pc, const TexturePlanes& p, const TextureTexels& texture, const uint8_t* bytes,
               const uint64_t* lanes, int64_t j, int32_t n, Pixel* out) {
  const TextureTexels t = texture;  // a local copy: its fields stay in registers
  const LutTexels<F, Spread> fetch(t, bytes, lanes);
  const int bits = pc.bits;
  const int64_t au = int64_t(pc.uv[0]) * (int64_t(1) << bits) + pc.step[0] * j;
  const int64_t av = int64_t(pc.uv[1]) * (int64_t(1) << bits) + pc.step[1] * j;
  bilinear_run<Repeat>(t, p.size_bits, bits, au, av, pc.step[0], pc.step[1], fetch, n, out);
}
template <TexelFormat F>
LanesRun lanes_run_for(const TextureTexels& t) {
  const bool repeat = t.wrap_s == uint8_t(TextureWrap::Repeat) && t.wrap_t == uint8_t(TextureWrap::Repeat);
  return repeat ? &lanes_run<F, true> : &lanes_run<F, false>;
}
LanesRun lanes_run_of(const TextureTexels& t) {
  switch (TexelFormat(t.format)) {
    case TexelFormat::Palette8: return lanes_run_for<TexelFormat::Palette8>(t);
    case TexelFormat::Grey4: return lanes_run_for<TexelFormat::Grey4>(t);
    case TexelFormat::Rgb565: return lanes_run_for<TexelFormat::Rgb565>(t);
    default: return nullptr;
  }
}
#endif

// The run for texture t's format (null: no texels, format None).
PieceRun piece_run_of(const TextureTexels& t, Pixel after) {
  switch (TexelFormat(t.format)) {
    case TexelFormat::Palette8: return piece_run_for<TexelFormat::Palette8>(t, after);
    case TexelFormat::Grey4: return piece_run_for<TexelFormat::Grey4>(t, after);
    case TexelFormat::Rgb565: return piece_run_for<TexelFormat::Rgb565>(t, after);
    default: return nullptr;
  }
}

}  // namespace

Pixel sample_texture(const TextureTexels& t, const uint8_t* bytes, const int32_t uv[2]) {
  return textured_colour(t, bytes, uv, 0xFFFFFF, false);
}

Pixel sample_texture(const TextureTexels& t, const uint8_t* bytes, const int32_t uv[2], Pixel colour, bool small) {
  return textured_colour(t, bytes, uv, colour, small);
}

namespace {

// The colour at uv through a table of this texture for a colour, `after` left to apply (white: none):
// nearest, the texel x after; bilinear, the filter of the texels each x after, or for a small
// triangle (the white table) the filter of the texels x after (as textured_colour).
template <TexelFormat F>
Pixel sample_lut(const TextureTexels& t, const uint8_t* bytes, const Pixel* lut, Pixel after, const int32_t uv[2],
                 bool small) {
  const LutTexels<F> fetch(t, bytes, lut);
  if (t.filter == uint8_t(TextureFilter::Bilinear)) {  // as textured_colour
    const Pixel first = small ? 0xFFFFFF : after, then = small ? after : 0xFFFFFF;
    return modulate_texel(
        bilinear<false>(t, uv[0], uv[1], [&](int32_t x, int32_t y) { return modulate_texel(fetch(x, y), first); }), then);
  }
  const int64_t su = int64_t(uv[0]) * t.width, sv = int64_t(uv[1]) * t.height;
  return modulate_texel(fetch(wrap(su >> 16, t.width, t.wrap_s), wrap(sv >> 16, t.height, t.wrap_t)), after);
}

// The runs: a Runs value whose next(&run) gives each run in turn, none empty, false after the last
// (texture_rows' rows, texture_runs' list, sample_block's mask), and place(run, &out) where its
// colours go: a list's one after another from out, a mask's to their places in a block of rows
// `stride` apart. each_of_runs calls f(uv, at) for each sample in turn with its coordinates (steps:
// ExactSteps or BoxSteps, started at each run and stepped along it) and where its colour goes. (A
// mask's runs are short, the textured duck's blocks 20,580 samples in 9,169 runs, but a loop over the
// set bits testing each against the last cost more: the duck's tiler frame 13,577,728 instructions
// with it, 13,486,399 so.)
template <typename Runs, typename Steps, typename Sample>
ML_RUN_HELPER void each_of_runs(Runs& runs, const TexturePlanes& p, Steps& steps, Pixel* out, Sample sample) {
  int32_t uv[2];
  for (SampleRun run; runs.next(&run);) {
    steps.start(p, run.x, run.y);
    Pixel* at = runs.place(run, &out);
    Pixel* const stop = at + run.n;
    do {
      steps.next(uv);
      sample(uv, at);
    } while (++at != stop);
  }
}
// place of runs whose colours go one after another from out (RowRuns, ListRuns).
struct InOrderRuns {
  Pixel* place(const SampleRun& run, Pixel** out) const { return (*out += run.n) - run.n; }
};
struct RowRuns : InOrderRuns {  // rows y .. end - 1 of samples x .. x + n - 1
  int32_t x, y, n, end;
  bool next(SampleRun* run) {
    if (y == end || n <= 0) return false;  // (no rows of no samples)
    *run = SampleRun{x, y++, n};
    return true;
  }
};
struct ListRuns : InOrderRuns {
  const SampleRun *at, *end;
  bool next(SampleRun* run) {
    while (at != end && at->n <= 0) ++at;  // (empty runs skipped)
    if (at == end) return false;
    *run = *at++;
    return true;
  }
};
// The set bits of an 8x8 mask (bit 8 r + c: sample (x + c, y + r)), a run of a row's adjacent bits at
// a time, in bit order; sample (x + c, y + r)'s colour goes to out[r stride + c].
struct MaskRuns {
  uint64_t mask;
  int32_t x, y;
  uint32_t stride;
  bool next(SampleRun* run) {
    if (mask == 0) return false;
    *run = take_mask_run(&mask, x, y);
    return true;
  }
  Pixel* place(const SampleRun& run, Pixel** out) const {
    return *out + uint32_t(run.y - y) * stride + uint32_t(run.x - x);
  }
};

#ifndef ML_TEXTURE_RUNS_GENERAL_ONLY
// body(steps) with the small triangle's steps: its box's sums (boxed) or each sample's own.
template <typename Body>
ML_RUN_HELPER void with_steps(const TexturePlanes& p, Body body) {
  if (p.boxed) {
#if UINTPTR_MAX > 0xFFFFFFFFu
    if (p.sums.plain) {
      BoxSteps<true> steps(p);
      body(steps);
      return;
    }
#endif
    BoxSteps<> steps(p);
    body(steps);
  } else {
    ExactSteps steps(p);
    body(steps);
  }
}

// A flag as a type: a generic lambda's template argument.
template <bool B>
struct Flag {
  static constexpr bool value = B;
};

// Bilinear samples along the runs (with_steps' coordinates), each the filter of the texels `fetch`
// gives, then multiplied by `tint`: a loop for each of repeat or not, a grey colour or not.
template <typename Fetch, typename Runs>
ML_RUN_HELPER void bilinear_runs(TexturePlanes& p, const TextureTexels& t, const Fetch& fetch, const Tint& tint, bool repeat,
                                 Runs runs, Pixel* out) {
  const bool grey = grey_of(tint) != 0;
  with_steps(p, [&](auto& steps) ML_RUN_LAMBDA {
    const auto each = [&](auto repeats, auto greys) ML_RUN_LAMBDA {
      each_of_runs(runs, p, steps, out, [&](const int32_t* uv, Pixel* at) ML_RUN_LAMBDA {
        *at = bilinear_tinted<decltype(repeats)::value, decltype(greys)::value>(t, uv[0], uv[1], fetch, tint);
      });
    };
    if (repeat) grey ? each(Flag<true>{}, Flag<true>{}) : each(Flag<true>{}, Flag<false>{});
    else grey ? each(Flag<false>{}, Flag<true>{}) : each(Flag<false>{}, Flag<false>{});
  });
}

// A small triangle's samples (TexturePlanes::exact): coordinates sample by sample along each run
// (with_steps), each sample's colour through the table (nearest filtering: its texel taken here,
// format F known; bilinear, the white table's texels filtered, then multiplied) or decoded, without
// one. (The firmware, ML_TEXTURE_RUNS_GENERAL_ONLY, for its code budget: texture_rows' samples one
// by one, each through texture_uv.)
template <TexelFormat F, typename Runs>
ML_RUN_HELPER void exact_runs(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const Pixel* lut, Pixel lut_colour,
                Pixel colour, Runs runs, Pixel* out) {
  const bool nearest = lut && t.filter != uint8_t(TextureFilter::Bilinear);
  const Pixel after = lut_colour == colour ? 0xFFFFFF : colour;
  const LutTexels<F> fetch(t, bytes, lut);
  const int sb[2] = {16 - p.size_bits[0], 16 - p.size_bits[1]};  // floor(u W / 2^16) for W = 2^size_bits
  const bool repeat = t.wrap_s == uint8_t(TextureWrap::Repeat) && t.wrap_t == uint8_t(TextureWrap::Repeat);
  if (lut && !nearest && lut_colour == 0xFFFFFF) {  // bilinear: the filter of the texels, then the product, as sample_texture
    bilinear_runs(p, t, fetch, tint_of(colour), repeat, runs, out);
    return;
  }
  with_steps(p, [&](auto& steps) ML_RUN_LAMBDA {
    if (nearest && repeat) {  // wrapping is a mask (wrap_as<Repeat>)
      const int32_t mu = int32_t(t.width) - 1, mv = int32_t(t.height) - 1;
      each_of_runs(runs, p, steps, out, [&](const int32_t* uv, Pixel* at) ML_RUN_LAMBDA {
        const Pixel texel = fetch((uv[0] >> sb[0]) & mu, (uv[1] >> sb[1]) & mv);
        *at = after == 0xFFFFFF ? texel : modulate_texel(texel, after);
      });
    } else if (nearest) {
      each_of_runs(runs, p, steps, out, [&](const int32_t* uv, Pixel* at) ML_RUN_LAMBDA {
        const Pixel texel = fetch(wrap(uv[0] >> sb[0], t.width, t.wrap_s), wrap(uv[1] >> sb[1], t.height, t.wrap_t));
        *at = after == 0xFFFFFF ? texel : modulate_texel(texel, after);
      });
    } else {
      each_of_runs(runs, p, steps, out, [&](const int32_t* uv, Pixel* at) ML_RUN_LAMBDA {
        *at = lut ? sample_texture(t, bytes, lut, lut_colour, uv, colour, true)
                  : textured_colour(t, bytes, uv, colour, true);
      });
    }
  });
}

// exact_runs for texture_rows' block of rows and texture_runs' runs, format F.
template <TexelFormat F>
[[gnu::noinline]] void exact_rows(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const Pixel* lut, Pixel lut_colour,
                Pixel colour, int32_t x, int32_t y, int32_t n, int32_t rows, Pixel* out) {
  exact_runs<F>(p, t, bytes, lut, lut_colour, colour, RowRuns{{}, x, y, n, y + rows}, out);
}
template <TexelFormat F>  // one row: no loop over rows around its samples
[[gnu::noinline]] void exact_row(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const Pixel* lut, Pixel lut_colour,
                Pixel colour, int32_t x, int32_t y, int32_t n, Pixel* out) {
  exact_runs<F>(p, t, bytes, lut, lut_colour, colour, RowRuns{{}, x, y, n, y + 1}, out);
}
template <TexelFormat F, typename Runs>  // texture_runs' list (ListRuns), sample_block's mask (MaskRuns)
[[gnu::noinline]] void exact_list(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const Pixel* lut, Pixel lut_colour,
                Pixel colour, Runs runs, Pixel* out) {
  exact_runs<F>(p, t, bytes, lut, lut_colour, colour, runs, out);
}

#if UINTPTR_MAX > 0xFFFFFFFFu
// exact_runs' bilinear samples through the white table with its colours already in lanes
// (TexturePager::lanes_of): the filter of the texels, then the product, without spreading each
// texel. Functions of their own, so that exact_runs' loops keep their code.
template <TexelFormat F, typename Runs>
ML_RUN_HELPER void exact_lanes_runs(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const uint64_t* lanes,
                                    Pixel colour, Runs runs, Pixel* out) {
  const LutTexels<F, Spread> fetch(t, bytes, lanes);
  const bool repeat = t.wrap_s == uint8_t(TextureWrap::Repeat) && t.wrap_t == uint8_t(TextureWrap::Repeat);
  bilinear_runs(p, t, fetch, tint_of(colour), repeat, runs, out);
}
template <TexelFormat F>
[[gnu::noinline]] void exact_lanes_rows(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const uint64_t* lanes,
                                        Pixel colour, int32_t x, int32_t y, int32_t n, int32_t rows, Pixel* out) {
  exact_lanes_runs<F>(p, t, bytes, lanes, colour, RowRuns{{}, x, y, n, y + rows}, out);
}
template <TexelFormat F>
[[gnu::noinline]] void exact_lanes_row(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const uint64_t* lanes,
                                       Pixel colour, int32_t x, int32_t y, int32_t n, Pixel* out) {
  exact_lanes_runs<F>(p, t, bytes, lanes, colour, RowRuns{{}, x, y, n, y + 1}, out);
}
template <TexelFormat F, typename Runs>
[[gnu::noinline]] void exact_lanes_list(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const uint64_t* lanes,
                                        Pixel colour, Runs runs, Pixel* out) {
  exact_lanes_runs<F>(p, t, bytes, lanes, colour, runs, out);
}
#endif

// texture_rows for a small triangle, format F: one row (the scanline renderer's spans of a few
// samples, which a loop over rows around them would cost more than) or a block of rows, through the
// white table's lanes when given (bilinear).
template <TexelFormat F>
inline void exact_format_rows(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const Pixel* lut,
                              Pixel lut_colour, Pixel colour, int32_t x, int32_t y, int32_t n, int32_t rows,
                              const uint64_t* lanes, Pixel* out) {
#if UINTPTR_MAX > 0xFFFFFFFFu
  if (lanes && blends_table_as_is(t, true, lut_colour, colour)) {
    if (rows == 1) return exact_lanes_row<F>(p, t, bytes, lanes, colour, x, y, n, out);
    return exact_lanes_rows<F>(p, t, bytes, lanes, colour, x, y, n, rows, out);
  }
#else
  (void)lanes;
#endif
  if (rows == 1) return exact_row<F>(p, t, bytes, lut, lut_colour, colour, x, y, n, out);
  exact_rows<F>(p, t, bytes, lut, lut_colour, colour, x, y, n, rows, out);
}
#endif

}  // namespace

Pixel sample_texture(const TextureTexels& t, const uint8_t* bytes, const Pixel* lut, Pixel lut_colour,
                     const int32_t uv[2], Pixel colour, bool small) {
  // A small triangle's bilinear filter blends unmodulated texels: a table of a colour cannot serve it.
  if (small && t.filter == uint8_t(TextureFilter::Bilinear) && lut_colour != 0xFFFFFF)
    return textured_colour(t, bytes, uv, colour, true);
  const Pixel after = lut_colour == colour ? 0xFFFFFF : colour;
  switch (TexelFormat(t.format)) {
    case TexelFormat::Palette8: return sample_lut<TexelFormat::Palette8>(t, bytes, lut, after, uv, small);
    case TexelFormat::Grey4: return sample_lut<TexelFormat::Grey4>(t, bytes, lut, after, uv, small);
    case TexelFormat::Rgb565: return sample_lut<TexelFormat::Rgb565>(t, bytes, lut, after, uv, small);
    default: return colour;
  }
}

void make_texel_lut(const TextureTexels& t, const uint8_t* bytes, Pixel colour, Pixel* lut) {
  switch (TexelFormat(t.format)) {
    case TexelFormat::Palette8:
      for (uint32_t i = 0; i < kTexelLutEntries; ++i) {
        const uint32_t index = i < t.palette_size ? i : t.palette_size - 1u;
        lut[i] = modulate_texel(from_565(load16(bytes + 2 * index)), colour);
      }
      return;
    case TexelFormat::Grey4:
      for (uint32_t g = 0; g < 16; ++g) lut[g] = modulate_texel(rgb(g * 17, g * 17, g * 17), colour);
      return;
    case TexelFormat::Rgb565:
      for (uint32_t v = 0; v < 32; ++v) {
        lut[v] = modulate_texel(rgb(expand5(v), 0, 0), colour);
        lut[96 + v] = modulate_texel(rgb(0, 0, expand5(v)), colour);
      }
      for (uint32_t v = 0; v < 64; ++v) lut[32 + v] = modulate_texel(rgb(0, expand6(v), 0), colour);
      return;
    default: return;
  }
}

void spread_texel_lut(const TextureTexels& t, const Pixel* lut, uint64_t* lanes) {
#if UINTPTR_MAX > 0xFFFFFFFFu
  const uint32_t n = t.format == uint8_t(TexelFormat::Grey4) ? 16 : t.format == uint8_t(TexelFormat::Rgb565) ? 128 : kTexelLutEntries;
  for (uint32_t i = 0; i < n; ++i) lanes[i] = spread(lut[i]);
#else
  (void)t, (void)lut, (void)lanes;
#endif
}

namespace {
// Samples x .. x + n - 1 of `rows` rows (one after another in out), a run of each planes' piece
// (texture_piece) at a time: run(piece, j, m, out) draws m samples from the piece's j-th into out.
template <typename Run>
ML_RUN_HELPER void piece_runs(TexturePlanes& p, int32_t x, int32_t y, int32_t n, int32_t rows, Pixel* out, Run run) {
  for (int32_t r = 0; r < rows; ++r)
    for (int32_t left = n, xx = x; left > 0;) {
      const TexturePiece& pc = texture_piece(p, xx, y + r);
      const int64_t j = xx - pc.x;
      const int32_t m = min_of(left, int32_t((int64_t(1) << pc.bits) - j));
      run(pc, j, m, out);
      xx += m;
      left -= m;
      out += m;
    }
}
}  // namespace

void texture_rows(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const Pixel* lut, Pixel lut_colour,
                  Pixel colour, int32_t x, int32_t y, int32_t n, int32_t rows, Pixel* out, const uint64_t* lanes) {
#ifndef ML_TEXTURE_RUNS_GENERAL_ONLY
  if (p.exact) {
    switch (TexelFormat(t.format)) {
      case TexelFormat::Palette8:
        return exact_format_rows<TexelFormat::Palette8>(p, t, bytes, lut, lut_colour, colour, x, y, n, rows, lanes, out);
      case TexelFormat::Grey4:
        return exact_format_rows<TexelFormat::Grey4>(p, t, bytes, lut, lut_colour, colour, x, y, n, rows, lanes, out);
      case TexelFormat::Rgb565:
        return exact_format_rows<TexelFormat::Rgb565>(p, t, bytes, lut, lut_colour, colour, x, y, n, rows, lanes, out);
      default: break;
    }
  }
#endif
  (void)lanes;
  const Pixel after = lut_colour == colour ? 0xFFFFFF : colour;  // the product left per sample
#ifndef ML_TEXTURE_RUNS_GENERAL_ONLY
  // Bilinear runs multiply the white table's texels by `after` before the filter (small triangles,
  // which filter first, took exact_rows above).
  const bool per_sample = !lut;
#else
  // Bilinear runs blend the table's texels as they are: those of the colour, or white ones drawn in
  // white (a small triangle's filter then product is the same). The other samples are decoded (the
  // same colours, without the table's code), and a small triangle's nearest samples go one by one
  // through its white table (as runs, each of its samples would be a piece of its own).
  const bool bilinear = t.filter == uint8_t(TextureFilter::Bilinear);
  const bool per_sample =
      !lut || (bilinear ? lut_colour != colour || (p.exact && colour != 0xFFFFFF) : p.exact && p.boxed);
#endif
  if (per_sample) {
    for (int32_t r = 0; r < rows; ++r) {
      if (p.boxed) {  // a small triangle: its box's sums stepped along the row (box_uv's coordinates)
        const Pixel* const white = lut && lut_colour == 0xFFFFFF ? lut : nullptr;
        const bool bilinear_white = white && t.filter == uint8_t(TextureFilter::Bilinear);
        BoxSteps steps(p);
        steps.start(p, x, y + r);
        for (int32_t i = 0; i < n; ++i) {
          int32_t uv[2];
          steps.next(uv);
          *out++ = bilinear_white ? small_bilinear_white(t, bytes, lut, uv, colour)
                                  : textured_colour(t, bytes, uv, colour, true, white);
        }
        continue;
      }
      for (int32_t i = 0; i < n; ++i) {
        int32_t uv[2];
        texture_uv(p, x + i, y + r, uv);
        *out++ = textured_colour(t, bytes, uv, colour, p.exact);
      }
    }
    return;
  }
#if UINTPTR_MAX > 0xFFFFFFFFu && !defined(ML_TEXTURE_RUNS_GENERAL_ONLY)
  if (lanes && blends_table_as_is(t, false, lut_colour, colour)) {
    const LanesRun lanes_run = lanes_run_of(t);
    if (lanes_run) {
      piece_runs(p, x, y, n, rows, out, [&](const TexturePiece& pc, int64_t j, int32_t m, Pixel* o) {
        lanes_run(pc, p, t, bytes, lanes, j, m, o);
      });
      return;
    }
  }
#endif
  const PieceRun run = piece_run_of(t, after);
  if (!run) {
    for (int32_t i = 0; i < n * rows; ++i) out[i] = colour;
    return;
  }
  piece_runs(p, x, y, n, rows, out, [&](const TexturePiece& pc, int64_t j, int32_t m, Pixel* o) {
    run(pc, p, t, bytes, lut, after, j, m, o);
  });
}

namespace {
// texture_runs and sample_block: a small triangle's runs through one loop of its format and table,
// else each run through texture_rows.
template <typename Runs>
void runs_of(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const Pixel* lut, Pixel lut_colour,
             Pixel colour, Runs runs, Pixel* out, const uint64_t* lanes) {
#ifndef ML_TEXTURE_RUNS_GENERAL_ONLY
  if (p.exact) {
#if UINTPTR_MAX > 0xFFFFFFFFu
    if (lanes && blends_table_as_is(t, true, lut_colour, colour)) {
      switch (TexelFormat(t.format)) {
        case TexelFormat::Palette8: return exact_lanes_list<TexelFormat::Palette8>(p, t, bytes, lanes, colour, runs, out);
        case TexelFormat::Grey4: return exact_lanes_list<TexelFormat::Grey4>(p, t, bytes, lanes, colour, runs, out);
        case TexelFormat::Rgb565: return exact_lanes_list<TexelFormat::Rgb565>(p, t, bytes, lanes, colour, runs, out);
        default: break;
      }
    }
#endif
    switch (TexelFormat(t.format)) {
      case TexelFormat::Palette8: return exact_list<TexelFormat::Palette8>(p, t, bytes, lut, lut_colour, colour, runs, out);
      case TexelFormat::Grey4: return exact_list<TexelFormat::Grey4>(p, t, bytes, lut, lut_colour, colour, runs, out);
      case TexelFormat::Rgb565: return exact_list<TexelFormat::Rgb565>(p, t, bytes, lut, lut_colour, colour, runs, out);
      default: break;
    }
  }
#endif
  (void)lanes;
  for (SampleRun run; runs.next(&run);)
    texture_rows(p, t, bytes, lut, lut_colour, colour, run.x, run.y, run.n, 1, runs.place(run, &out));
}
}  // namespace

void texture_runs(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const Pixel* lut, Pixel lut_colour,
                  Pixel colour, const SampleRun* runs, int32_t count, Pixel* out, const uint64_t* lanes) {
  runs_of(p, t, bytes, lut, lut_colour, colour, ListRuns{{}, runs, runs + count}, out, lanes);
}

namespace {
// TextureSampling's loops: a small triangle's samples through the table's lanes (exact_lanes_runs) or
// the table (exact_runs) of format F, or any piece's as texture_runs and texture_rows draw them.
#if UINTPTR_MAX > 0xFFFFFFFFu && !defined(ML_TEXTURE_RUNS_GENERAL_ONLY)
template <TexelFormat F>
void lanes_block(const TextureSampling& s, uint64_t mask, int32_t x, int32_t y, Pixel* out, uint32_t stride) {
  exact_lanes_runs<F>(*s.planes, *s.texture, s.bytes, s.lanes, s.colour, MaskRuns{mask, x, y, stride}, out);
}
template <TexelFormat F>
void table_block(const TextureSampling& s, uint64_t mask, int32_t x, int32_t y, Pixel* out, uint32_t stride) {
  exact_runs<F>(*s.planes, *s.texture, s.bytes, s.lut, s.lut_colour, s.colour, MaskRuns{mask, x, y, stride}, out);
}
template <TexelFormat F>
void lanes_row(const TextureSampling& s, int32_t x, int32_t y, int32_t n, Pixel* out) {
  exact_lanes_runs<F>(*s.planes, *s.texture, s.bytes, s.lanes, s.colour, RowRuns{{}, x, y, n, y + 1}, out);
}
template <TexelFormat F>
void table_row(const TextureSampling& s, int32_t x, int32_t y, int32_t n, Pixel* out) {
  exact_runs<F>(*s.planes, *s.texture, s.bytes, s.lut, s.lut_colour, s.colour, RowRuns{{}, x, y, n, y + 1}, out);
}
// One span of lanes_spans through bilinear_runs: a small triangle left divided, or a colour not grey.
template <TexelFormat F>
[[gnu::noinline]] void lanes_span(const TextureTexels& t, const LutTexels<F, Spread>& fetch, bool repeat,
                                  const SmallSpan& sp, int32_t y, Pixel* row) {
  bilinear_runs(*sp.planes, t, fetch, tint_of(sp.colour), repeat, RowRuns{{}, sp.x, y, sp.n, y + 1}, row + sp.x);
}
// lanes_spans for one wrap (Repeat: both axes repeat). A boxed span of a grey colour (white light on a
// white base colour, the common case) takes its loop here, BoxSteps' coordinates and bilinear_tinted's
// colours sample by sample (bilinear_runs' values, without its wrap and colour tests a span); the
// others lanes_span, out of this loop's registers.
template <TexelFormat F, bool Repeat>
__attribute__((always_inline)) inline void lanes_spans_as(const TextureTexels& t, const LutTexels<F, Spread>& fetch,
                                                          const SmallSpan* sp, const SmallSpan* end, int32_t y,
                                                          Pixel* row) {
  const RepeatSizes sizes{t.width, t.height, t.width - 1u, t.height - 1u};
  for (; sp != end; ++sp) {
    const TexturePlanes& p = *sp->planes;
    const Pixel c = sp->colour;
    const uint32_t grey = c & 0xFF;
    // A grey colour, as bilinear_runs' grey_of, but black too: modulate_spread_grey's 0 gives
    // modulate_spread's black. (Spans have n >= 1.)
    if (!p.boxed || c != grey * 0x010101u) {
      lanes_span<F>(t, fetch, Repeat, *sp, y, row);
      continue;
    }
    const Tint tint{grey, grey, grey};  // tint_of(c), its grey_of known to be `grey`
    Pixel* out = row + sp->x;
    Pixel* const stop = out + sp->n;
    const auto samples = [&](auto steps) ML_RUN_LAMBDA {
      steps.start(p, sp->x, y);
      do {
        int32_t uv[2];
        steps.next(uv);
        *out = Repeat ? bilinear_tinted<true, true>(sizes, uv[0], uv[1], fetch, tint)
                      : bilinear_tinted<false, true>(t, uv[0], uv[1], fetch, tint);
      } while (++out != stop);
    };
    if (p.sums.plain) samples(BoxSteps<true>(p));
    else samples(BoxSteps<false>(p));
  }
}
// A row's small-triangle spans through one loop: what they share (the texture, its table or lanes)
// looked at once.
template <TexelFormat F>
void lanes_spans(const TextureSampling& s, const SmallSpan* spans, uint32_t count, int32_t y, Pixel* row) {
  const TextureTexels t = *s.texture;  // a copy: the colours' stores cannot change it
  const LutTexels<F, Spread> fetch(t, s.bytes, s.lanes);
  const bool repeat = t.wrap_s == uint8_t(TextureWrap::Repeat) && t.wrap_t == uint8_t(TextureWrap::Repeat);
  if (repeat) lanes_spans_as<F, true>(t, fetch, spans, spans + count, y, row);
  else lanes_spans_as<F, false>(t, fetch, spans, spans + count, y, row);
}
template <TexelFormat F>
void table_spans(const TextureSampling& s, const SmallSpan* spans, uint32_t count, int32_t y, Pixel* row) {
  for (const SmallSpan *sp = spans, *end = spans + count; sp != end; ++sp)
    exact_runs<F>(*sp->planes, *s.texture, s.bytes, s.lut, s.lut_colour, sp->colour, RowRuns{{}, sp->x, y, sp->n, y + 1},
                  row + sp->x);
}
template <TexelFormat F>
void exact_sampling(TextureSampling* s, bool in_lanes) {
  s->block = in_lanes ? lanes_block<F> : table_block<F>;
  s->row = in_lanes ? lanes_row<F> : table_row<F>;
  s->spans = in_lanes ? lanes_spans<F> : table_spans<F>;
}
#endif
void any_block(const TextureSampling& s, uint64_t mask, int32_t x, int32_t y, Pixel* out, uint32_t stride) {
  runs_of(*s.planes, *s.texture, s.bytes, s.lut, s.lut_colour, s.colour, MaskRuns{mask, x, y, stride}, out, s.lanes);
}
void any_row(const TextureSampling& s, int32_t x, int32_t y, int32_t n, Pixel* out) {
  texture_rows(*s.planes, *s.texture, s.bytes, s.lut, s.lut_colour, s.colour, x, y, n, 1, out, s.lanes);
}
void any_spans(const TextureSampling& s, const SmallSpan* spans, uint32_t count, int32_t y, Pixel* row) {
  for (const SmallSpan *sp = spans, *end = spans + count; sp != end; ++sp)
    texture_rows(*sp->planes, *s.texture, s.bytes, s.lut, s.lut_colour, sp->colour, sp->x, y, sp->n, 1, row + sp->x,
                 s.lanes);
}
}  // namespace

TextureSampling texture_sampling(TexturePlanes& p, const TextureTexels& t, const uint8_t* bytes, const Pixel* lut,
                                 Pixel lut_colour, Pixel colour, const uint64_t* lanes) {
  TextureSampling s{&p, &t, bytes, lut, lut_colour, colour, lanes, any_block, any_row, any_spans};
#if UINTPTR_MAX > 0xFFFFFFFFu && !defined(ML_TEXTURE_RUNS_GENERAL_ONLY)
  if (!p.exact) return s;  // as runs_of and texture_rows
  const bool in_lanes = lanes && blends_table_as_is(t, true, lut_colour, colour);
  switch (TexelFormat(t.format)) {
    case TexelFormat::Palette8: exact_sampling<TexelFormat::Palette8>(&s, in_lanes); break;
    case TexelFormat::Grey4: exact_sampling<TexelFormat::Grey4>(&s, in_lanes); break;
    case TexelFormat::Rgb565: exact_sampling<TexelFormat::Rgb565>(&s, in_lanes); break;
    default: break;
  }
#endif
  return s;
}

}  // namespace ml

// Texel lookup: wrap modes, nearest and bilinear filtering over the device formats of
// scene/blob_format.h, and the texel x colour product both renderers use.
#pragma once
#include <stdint.h>

#include "core/sink.h"
#include "scene/blob_format.h"
#include "texture/mapping.h"

namespace ml {

// The colour of a texture at texture coordinates uv (Q16.16; 0..1 spans the texture once), with the
// texture's sampler. `bytes` are the texture's TextureTexels::bytes bytes (from the pager); any byte
// values are safe (a palette index past the palette reads its last colour).
Pixel sample_texture(const TextureTexels& texture, const uint8_t* bytes, const int32_t uv[2]);

// The texture at uv drawn in `colour` (lighting, the base colour factor): nearest filtering gives
// modulate_texel(texel, colour); bilinear filtering blends the four texels each modulated by colour
// (so a table of modulated texels, below, gives the same colours), except for a small triangle
// (`small`: TexturePlanes::exact), which blends the texels and modulates the blend once:
// modulate_texel(filtered, colour) (its samples take the white table; docs/textures.md).
Pixel sample_texture(const TextureTexels& texture, const uint8_t* bytes, const int32_t uv[2], Pixel colour,
                     bool small);

// texel * colour / 255 per channel, rounded: lighting (or the base colour factor) modulates a texel.
inline Pixel modulate_texel(Pixel texel, Pixel colour) {
  if (colour == 0xFFFFFF) return texel;  // the same result, cheaper: unlit white materials
  // Channel by channel, written out (a loop over the shifts stays a loop in some builds).
  const uint32_t r = ((texel >> 16) & 0xFF) * ((colour >> 16) & 0xFF);  // <= 255 * 255
  const uint32_t g = ((texel >> 8) & 0xFF) * ((colour >> 8) & 0xFF);
  const uint32_t b = (texel & 0xFF) * (colour & 0xFF);
  return ((((r + 128) * 257) >> 16) << 16) | ((((g + 128) * 257) >> 16) << 8) | (((b + 128) * 257) >> 16);  // round(p / 255)
}

// sample_texture(texture, bytes, uv, colour, small) through a make_texel_lut table of this texture for
// lut_colour (colour, or white: the colour applied per texel, or per sample for a small triangle's
// bilinear filter): the same colour.
Pixel sample_texture(const TextureTexels& texture, const uint8_t* bytes, const Pixel* lut, Pixel lut_colour,
                     const int32_t uv[2], Pixel colour, bool small);

// A texel look-up table: a texture's colours decoded once (and modulated by one colour), so a
// texel costs a load instead of a decode and a product. Palette8: the palette (indices past it read
// its last colour); Grey4: the 16 levels; Rgb565: red (32 entries), green (64) and blue (32) parts in
// their places, OR-ed together. Modulation is per channel, so a modulated table gives exactly
// modulate_texel(texel, colour).
constexpr uint32_t kTexelLutEntries = 256;
void make_texel_lut(const TextureTexels& texture, const uint8_t* bytes, Pixel colour, Pixel* lut);
// A table of make_texel_lut's (of texture's format) with each colour spread to 16-bit lanes of a
// 64-bit word (blue, red, green): what the bilinear filters blend on a 64-bit host (TexturePager::
// lanes_of). Nothing on 32-bit boards.
void spread_texel_lut(const TextureTexels& texture, const Pixel* lut, uint64_t* lanes);
// Whether texture_rows / texture_runs blend a table's colours as they are, so that they take its lanes:
// a bilinear texture's white table for a small triangle (exact planes: the filter, then the product),
// or a table of the colour drawn.
inline bool blends_table_as_is(const TextureTexels& texture, bool exact, Pixel lut_colour, Pixel colour) {
  return texture.filter == uint8_t(TextureFilter::Bilinear) && lut_colour == (exact ? 0xFFFFFFu : colour);
}

// The textured colours of lattice samples x .. x + n - 1 of row y (texture coordinates from the
// planes, the texture's filter and wraps) drawn in `colour`, into out: the same colours as
// sample_texture(texture, bytes, texture_uv(...), colour, planes.exact) sample by sample. lut: a
// make_texel_lut table of this texture for colour `lut_colour`, or null (texels decoded one by one);
// lut_colour is either `colour` (no product per sample) or white (the product per texel, or per
// sample: a small triangle's bilinear filter). A small triangle's planes (TexturePlanes::exact) take
// each sample's own coordinates (the box's sums, or the exact division). lanes: lut's colours in lanes (TexturePager::lanes_of), or
// null; a bilinear filter that blends lut's colours as they are takes them from there (the same
// colours; 64-bit hosts).
// texture_rows: `rows` such rows (y, y + 1, ...) of n samples each, one after another in out (the
// format, filter and wraps looked at once for them all: the tiler's blocks).
void texture_rows(TexturePlanes& planes, const TextureTexels& texture, const uint8_t* bytes, const Pixel* lut,
                  Pixel lut_colour, Pixel colour, int32_t x, int32_t y, int32_t n, int32_t rows, Pixel* out,
                  const uint64_t* lanes = nullptr);
inline void texture_row(TexturePlanes& planes, const TextureTexels& texture, const uint8_t* bytes, const Pixel* lut,
                        Pixel lut_colour, Pixel colour, int32_t x, int32_t y, int32_t n, Pixel* out,
                        const uint64_t* lanes = nullptr) {
  texture_rows(planes, texture, bytes, lut, lut_colour, colour, x, y, n, 1, out, lanes);
}

// Samples x .. x + n - 1 of lattice row y.
struct SampleRun {
  int32_t x, y, n;
};
// The first run of an 8x8 mask's set bits (bit 8 r + c: sample (x + c, y + r)), adjacent bits of one
// row, taken off *mask (not 0).
inline SampleRun take_mask_run(uint64_t* mask, int32_t x, int32_t y) {
  const int at = __builtin_ctzll(*mask), start = at & 7;
  const uint32_t rest = uint32_t(*mask >> at) & (0xFFu >> start);  // the row from the run's start
  const int n = __builtin_ctz(~rest);                               // ends at the row's end at the latest
  *mask &= ~(((uint64_t(1) << n) - 1) << at);
  return SampleRun{x + start, y + (at >> 3), n};
}
// texture_row for each of `count` runs, their colours one after another in out: the tiler's block of
// a small triangle, a few short runs (the format and the table looked at once for them all).
void texture_runs(TexturePlanes& planes, const TextureTexels& texture, const uint8_t* bytes, const Pixel* lut,
                  Pixel lut_colour, Pixel colour, const SampleRun* runs, int32_t count, Pixel* out,
                  const uint64_t* lanes = nullptr);
// A piece's samples drawn many calls at a time with what the calls share looked at once (64-bit
// hosts): texture_sampling takes the planes, texture, table and colours and picks the loop for the
// format, filter and table; then each call draws a small triangle's (TexturePlanes::exact) samples
// straight through that loop, others through texture_rows. Between calls the planes may be changed
// for another small triangle's and the colour for its colour, the rest staying (a small triangle's
// table is its texture's white one whatever its colour: blends_table_as_is).
// sample_block: texture_runs for the set bits of an 8x8 mask (bit 8 r + c: sample (x + c, y + r)),
// the colour of sample (x + c, y + r) into out[r stride + c] (a block buffer, or the band itself): the
// tiler's blocks, without a list of their runs. sample_row: texture_row's samples x .. x + n - 1 of
// row y (the scanline renderer's spans). sample_spans: several small triangles' spans of row y, each
// with its own planes and colour, in one call (the scanline renderer's row of small triangles).
struct SmallSpan {
  TexturePlanes* planes;  // a small triangle's (TexturePlanes::exact)
  Pixel colour;
  int32_t x, n;           // samples x .. x + n - 1 (n >= 1), their colours into row[x .. x + n - 1]
};
struct TextureSampling {
  TexturePlanes* planes;
  const TextureTexels* texture;
  const uint8_t* bytes;
  const Pixel* lut;
  Pixel lut_colour, colour;
  const uint64_t* lanes;
  void (*block)(const TextureSampling& s, uint64_t mask, int32_t x, int32_t y, Pixel* out, uint32_t stride);
  void (*row)(const TextureSampling& s, int32_t x, int32_t y, int32_t n, Pixel* out);
  void (*spans)(const TextureSampling& s, const SmallSpan* spans, uint32_t count, int32_t y, Pixel* row);
};
TextureSampling texture_sampling(TexturePlanes& planes, const TextureTexels& texture, const uint8_t* bytes,
                                 const Pixel* lut, Pixel lut_colour, Pixel colour, const uint64_t* lanes = nullptr);
inline void sample_block(const TextureSampling& s, uint64_t mask, int32_t x, int32_t y, Pixel* out, uint32_t stride) {
  s.block(s, mask, x, y, out, stride);
}
inline void sample_row(const TextureSampling& s, int32_t x, int32_t y, int32_t n, Pixel* out) {
  s.row(s, x, y, n, out);
}
inline void sample_spans(const TextureSampling& s, const SmallSpan* spans, uint32_t count, int32_t y, Pixel* row) {
  s.spans(s, spans, count, y, row);
}

}  // namespace ml

// Texel lookup: wrap modes, nearest and bilinear filtering over the device formats of
// scene/blob_format.h, and the texel x colour product both renderers use.
#pragma once
#include <stdint.h>

#include "core/sink.h"
#include "scene/blob_format.h"

namespace ml {

// The colour of a texture at texture coordinates uv (Q16.16; 0..1 spans the texture once), with the
// texture's sampler. `bytes` are the texture's TextureTexels::bytes bytes (from the pager); any byte
// values are safe (a palette index past the palette reads its last colour).
Pixel sample_texture(const TextureTexels& texture, const uint8_t* bytes, const int32_t uv[2]);

// texel * colour / 255 per channel, rounded: lighting (or the base colour factor) modulates a texel.
inline Pixel modulate_texel(Pixel texel, Pixel colour) {
  if (colour == 0xFFFFFF) return texel;  // the same result, cheaper: unlit white materials
  uint32_t out = 0;
  for (int shift = 0; shift <= 16; shift += 8) {
    const uint32_t p = ((texel >> shift) & 0xFF) * ((colour >> shift) & 0xFF);  // <= 255 * 255
    out |= (((p + 128) * 257) >> 16) << shift;                                   // round(p / 255)
  }
  return out;
}

}  // namespace ml

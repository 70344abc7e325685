// The oracle's reference texturer, in doubles and independent of src/: for every pixel whose front
// triangle the reference rasterizer found (oracle.h), the ray through the pixel centre hits that
// triangle's world-space plane; its barycentric weights there interpolate the texture coordinates
// (perspective-correct by construction) and the texel is looked up with the glTF sampler rules.
#pragma once
#include <stdint.h>

#include <vector>

#include "tests/oracle/oracle.h"

namespace oracle {

enum class Wrap { Repeat, Mirrored, Clamp };

struct Texture {
  int width = 0, height = 0;
  std::vector<uint32_t> rgb;  // 0xRRGGBB, rows top first
  Wrap wrap_s = Wrap::Repeat, wrap_t = Wrap::Repeat;
  bool bilinear = false;
};

struct Surface {
  double uv[3][2] = {};  // per triangle vertex
  int texture = -1;      // index into the textures, -1: untextured
  uint32_t base = 0;     // 0xRRGGBB base colour
};

struct TexturedPixel {
  bool known = false;    // textured front surface, away from triangle and (nearest) texel edges
  double rgb[3] = {0, 0, 0};  // texel x base / 255 per channel, before rounding
};

// Expected unlit colours. texel_margin: nearest-filtered samples whose texel coordinate lies within
// this fraction of a texel of a texel edge are left unknown; edge_margin: pixels as in Result::decisive.
std::vector<TexturedPixel> texture_image(const std::vector<Triangle>& triangles, const std::vector<Surface>& surfaces,
                                         const std::vector<Texture>& textures, const Camera& camera,
                                         const Result& visible, double texel_margin, double edge_margin);

}  // namespace oracle

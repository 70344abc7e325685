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
  // Mip levels 1, 2, ... (each a texture of its own). A triangle samples level
  // floor(log2(texel area / pixel area) / 2 + 1/2), clamped to them (texture/mapping.h).
  std::vector<Texture> levels;
};

struct Surface {
  double uv[3][2] = {};  // per triangle vertex
  int texture = -1;      // index into the textures, -1: untextured
  uint32_t base = 0;     // 0xRRGGBB base colour
};

struct TexturedPixel {
  bool known = false;    // textured front surface, away from triangle and (nearest) texel edges
  double rgb[3] = {0, 0, 0};  // texel x base / 255 per channel, before rounding
  double slack[3] = {0, 0, 0};  // bilinear: how far the colour may move within the coordinate error
};

// How far a renderer's texture coordinates may stray from the exact ones, in texels: the larger of
// `texel` (nearest or bilinear filtering) and `shift` times the mean texel step per pixel along the
// row over the pixel's segment (`segment` pixels from a multiple of it; both axes, the larger).
// All zero: exact coordinates.
struct CoordinateError {
  double texel_nearest = 0, texel_bilinear = 0, shift = 0;
  int segment = 1;
};

// Expected unlit colours. Triangles whose mip level is within level_margin of the next (in that
// level's log2 units) or that reach behind the near plane are left unknown when their texture has
// levels. texel_margin: nearest-filtered samples whose texel coordinate lies within
// this fraction of a texel (plus the coordinate error) of a texel edge are left unknown; bilinear
// samples get a slack of twice the coordinate error times the largest step between neighbouring
// texels, or the range of the texels within reach if smaller; edge_margin: pixels as in Result::decisive.
std::vector<TexturedPixel> texture_image(const std::vector<Triangle>& triangles, const std::vector<Surface>& surfaces,
                                         const std::vector<Texture>& textures, const Camera& camera,
                                         const Result& visible, double texel_margin, double edge_margin,
                                         const CoordinateError& error = CoordinateError());

}  // namespace oracle

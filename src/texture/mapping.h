// Perspective-correct texture mapping in integers, shared by both renderers so that they pick the
// same texel at every sample (docs/textures.md).
//
// For a sample whose view ray has direction d and a triangle with view-space vertices P0, P1, P2,
// the perspective-correct barycentric weight of vertex i is e_i / (e_0 + e_1 + e_2) with
// e_i = d . (P_j x P_k) (i, j, k cyclic). d = (sx - cx, sy - cy, focal) is linear in the sample's
// screen position, so each e_i is a plane over the renderer's sample lattice, evaluated exactly in
// int64 — the integer form of stepping u/w, v/w and 1/w. The planes come from the whole original
// triangle (never a clipped or BSP-split piece), so every piece of it, in either renderer, maps
// identically; triangles crossing the near plane need no special case.
#pragma once
#include <stdint.h>

#include "core/fixed.h"
#include "scene/scene.h"
#include "view/view.h"

namespace ml {

struct TexturePlanes {
  int64_t a[3], b[3], k[3];   // e_i(X, Y) = a_i X + b_i Y + k_i, |e_i| < 2^61 on the lattice
  int32_t uv[3][2];           // the triangle's TEXCOORD_0, Q16.16
  // e_i at the last sample evaluated, (ex, ey): the sample to its right steps by a_i. Integer steps
  // are exact, so stepping gives the values evaluating gives, whatever order samples come in.
  int64_t e[3];
  int32_t ex, ey;
};

// Sample (X, Y) of the lattice lies at subpixel ((256 X + ox) / den, (256 Y + oy) / den): den = 1,
// ox = oy = 128 are pixel centres (the tiler and the 1x1 scanline renderer).
void make_texture_planes(const View& view, const Vec3i world[3], const int32_t uv[3][2], int32_t den,
                         int32_t ox, int32_t oy, TexturePlanes* out);

// Texture coordinates (Q16.16) at lattice sample (X, Y) >= 0: sum uv_i e_i / sum e_i, floored.
void texture_uv(TexturePlanes& p, int32_t x, int32_t y, int32_t uv[2]);

// The texture (index into the scene's textures) triangle `id` is drawn with, or kNone when its
// material has no texels. Only valid on a Scene from read_scene.
uint32_t triangle_texture(const Scene& scene, uint32_t id);

// make_texture_planes for triangle `id` of the scene (its world positions and TEXCOORD_0).
void triangle_texture_planes(const Scene& scene, const View& view, uint32_t id, int32_t den, int32_t ox,
                             int32_t oy, TexturePlanes* out);

}  // namespace ml

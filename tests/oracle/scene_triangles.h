// Test-side bridge from a validated scene (src/scene) to the oracle's double-precision input. This is
// the only oracle-related file that uses src/; the oracle itself does not.
#pragma once
#include <vector>

#include "core/sink.h"
#include "scene/scene.h"
#include "tests/oracle/oracle.h"
#include "tests/oracle/texturer.h"
#include "view/view.h"

namespace oracle {

// World triangles of every scene triangle, index = triangle id, with the material's doubleSided flag.
std::vector<Triangle> scene_triangles(const ml::Scene& scene);

// Per triangle: TEXCOORD_0 in doubles, the texture (when its material has texels) and base colour.
std::vector<Surface> scene_surfaces(const ml::Scene& scene);

// Every texture's texels decoded from the blob's device format by test code (not src/texture).
std::vector<Texture> scene_textures(const ml::Scene& scene);

// The same camera in doubles (world units, degrees).
Camera to_oracle_camera(const ml::Camera& camera);

// Triangle `id`'s unlit colour (its material's base colour), `background` for id < 0 (no hit).
ml::Pixel base_colour(const ml::Scene& scene, int64_t id, ml::Pixel background);

// The oracle's unlit picture box-filtered from rays x rays rays a pixel: per pixel, the mean of each
// channel (0..255, as doubles) of the rays' base colours, three values a pixel.
std::vector<double> box_filtered_unlit(const ml::Scene& scene, const ml::Camera& camera, int rays,
                                       ml::Pixel background);

// The same rays filtered by the tiler's cosine-hump kernel (tools/maskgen/filter_gen.h: one pixel in
// radius, w(r) = (1 + cos(pi r)) / 2, over the 3 x 3 pixels around each pixel), each ray weighted by
// the kernel at its own position, normalised by the weight of the on-screen rays.
std::vector<double> cosine_filtered_unlit(const ml::Scene& scene, const ml::Camera& camera, int rays,
                                          ml::Pixel background);

}  // namespace oracle

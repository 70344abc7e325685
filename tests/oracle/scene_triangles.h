// Test-side bridge from a validated scene (src/scene) to the oracle's double-precision input. This is
// the only oracle-related file that uses src/; the oracle itself does not.
#pragma once
#include <vector>

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

}  // namespace oracle

// Host-side scene loading and glTF-unit conversions shared by the CLI, the tests and the benchmark.
// A scene comes from a .glb/.gltf file (compiled in memory), a .mls blob, or the bundled default.
#pragma once
#include <stdint.h>

#include <string>
#include <vector>

#include "core/fixed.h"
#include "scene/scene.h"
#include "tools/scenec/scenec.h"

namespace mlhost {

struct LoadedScene {
  ml::Blob blob;                      // 8-byte aligned; scene points into it
  ml::Scene scene;
  std::string name;                   // file path or "default"
  std::vector<std::string> warnings;  // from the scene compiler
  ml::CameraHint camera;              // world units; valid for procedural scenes
};

// Loads `path` (empty = the bundled default scene; "builtin:banded" = the four-texture banded scene).
// On failure returns false and sets a one-line message. `progress` prints a note on stderr when
// compiling takes long and stderr is a terminal. `options` apply to glTF and procedural scenes.
bool load_scene(const std::string& path, LoadedScene* out, std::string* error, bool progress = false,
                const ml::CompileOptions& options = ml::CompileOptions());

// Validates a compiled blob into `out` (blob and scene); false with a one-line message.
bool adopt_compiled(ml::CompileResult result, const std::string& name, LoadedScene* out, std::string* error);

// glTF units <-> world units (blob_format.h: world = (gltf - gltf_center) * gltf_to_world).
struct GltfMapping {
  double center[3] = {0, 0, 0};
  double to_world = 1;
};
GltfMapping gltf_mapping(const ml::Scene& scene);

// A glTF point in world units, rounded; false when it falls outside |c| < kWorldLimit.
bool gltf_point_to_world(const GltfMapping& m, const double gltf[3], ml::Vec3i* out);
// World coordinate back to glTF units.
double world_to_gltf(const GltfMapping& m, int axis, double world);

}  // namespace mlhost

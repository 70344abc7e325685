// 2CylinderEngine (Debian's assimp-testmodels), compiled once per test binary and shared by every
// test that renders it: compiling it takes seconds under the sanitizers.
#pragma once
#include <unistd.h>

#include <string>

#include <gtest/gtest.h>

#include "platform/host/scene_load.h"
#include "tests/common/gltf_files.h"

namespace testfiles {

inline std::string engine_path() {
  return std::string(kAssimpGltf2Models) + "/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
}

// The loaded engine, or nullptr when assimp-testmodels is not installed (a load failure is a test
// failure). An inline function's static is one object across the whole binary.
inline const mlhost::LoadedScene* engine_scene() {
  static mlhost::LoadedScene scene;
  static int state = 0;  // 0 not tried, 1 loaded, 2 not installed, 3 failed to load
  if (state == 0) {
    std::string error;
    if (access(engine_path().c_str(), R_OK) != 0) {
      state = 2;
    } else {
      state = mlhost::load_scene(engine_path(), &scene, &error) ? 1 : 3;
      if (state == 3) ADD_FAILURE() << "2CylinderEngine.glb did not load: " << error;
    }
  }
  return state == 1 ? &scene : nullptr;
}

}  // namespace testfiles

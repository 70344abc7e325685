// Helpers of the texture tests: loading the textured scenes, a camera for them and one frame into the
// checking in-memory sink.
#pragma once
#include <cmath>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "core/arena.h"
#include "platform/host/image_sink.h"
#include "platform/host/scene_load.h"
#include "render/render.h"
#include "tests/common/assimp_models.h"
#include "tests/common/gltf_files.h"
#include "texture/pager.h"

namespace textest {

inline std::string model(const std::string& rel) { return std::string(testfiles::kAssimpGltf2Models) + "/" + rel; }

// The COLLADA duck of assimp-testmodels (4,212 triangles and one 256x256 texture: a real model of many
// small textured triangles, the duck of docs/benchmarks.md), its texture beside it (the glb names
// ./duckCM.tga).
inline std::string duck_model() { return testfiles::converted_model("Collada/duck.dae", {"duckCM.tga"}); }

// The textured inputs: the banded scene, the assimp models with textures and the duck; BoxTextured's
// sampler asks for mip levels, and the duck and the banded scene are also compiled with them ("mips:"
// before a path: load() compiles it with --mips on), the duck with every texture nearest too
// ("nearest:": --texture-filter nearest).
inline std::vector<std::string> textured_scenes() {
  return {"builtin:banded", model("BoxTextured-glTF/BoxTextured.gltf"), model("BoxTextured-glTF-Binary/BoxTextured.glb"),
          model("BoxTextured-glTF-Embedded/BoxTextured.gltf"), model("BoxTexcoords-glTF/boxTexcoords.gltf"),
          model("textureTransform/TextureTransformTest.gltf"), duck_model(), "mips:builtin:banded",
          "mips:" + duck_model(), "nearest:" + duck_model()};
}

// Loads once per test binary (compiling the models takes a moment under the sanitizers).
inline const mlhost::LoadedScene& load(const std::string& path) {
  static std::map<std::string, mlhost::LoadedScene> cache;  // nodes never move: scene pointers stay valid
  const auto found = cache.find(path);
  if (found != cache.end()) return found->second;
  mlhost::LoadedScene& loaded = cache[path];
  std::string error;
  ml::CompileOptions options;
  std::string file = path;
  if (file.rfind("mips:", 0) == 0) {
    file = file.substr(5);
    options.texture_mips = ml::TextureMipChoice::On;
  } else if (file.rfind("nearest:", 0) == 0) {
    file = file.substr(8);
    options.texture_filter = ml::TextureFilterChoice::Nearest;
  }
  if (!mlhost::load_scene(file, &loaded, &error, false, options)) loaded.name = "FAILED: " + error;
  return loaded;
}

inline ml::Vec3i round3(const double v[3]) {
  return ml::Vec3i{int32_t(std::lround(v[0])), int32_t(std::lround(v[1])), int32_t(std::lround(v[2]))};
}

// The scene's camera hint when it has one, else a three-quarter view framing its bounding sphere;
// `turn` orbits the eye about the vertical through the target by that many degrees.
inline ml::Camera camera_for(const mlhost::LoadedScene& loaded, int width, int height, double turn = 0) {
  const ml::SceneInfo& i = *loaded.scene.info;
  ml::Camera c = ml::frame_sphere(ml::Vec3i{i.sphere_center[0], i.sphere_center[1], i.sphere_center[2]},
                                  i.sphere_radius, width, height, 45 << 16);
  if (loaded.camera.valid) {
    c.eye = round3(loaded.camera.eye);
    c.target = round3(loaded.camera.target);
    c.up = ml::Vec3i{0, 1024, 0};
    c.near = 64;
  }
  if (turn != 0) {
    const double a = turn * M_PI / 180.0;
    const double dx = c.eye.x - c.target.x, dz = c.eye.z - c.target.z;
    c.eye.x = c.target.x + int32_t(std::lround(dx * std::cos(a) - dz * std::sin(a)));
    c.eye.z = c.target.z + int32_t(std::lround(dx * std::sin(a) + dz * std::cos(a)));
  }
  return c;
}

struct Frame {
  ml::Status status;
  ml::Stats stats;
  std::vector<ml::Pixel> pixels;
  bool contract = false;
  std::string contract_error;
};

// One frame with an arena of exactly render_arena_bytes (or `arena_bytes` when given).
inline Frame render(const ml::Scene& scene, const ml::Camera& camera, const ml::RenderOptions& o,
                    size_t arena_bytes = 0) {
  Frame f;
  const size_t bytes = arena_bytes ? arena_bytes : ml::render_arena_bytes(scene, camera, o);
  std::vector<uint64_t> storage(bytes / 8 + 1);
  ml::Arena arena(storage.data(), bytes);
  mlhost::ImageSink sink;
  f.status = ml::render(scene, camera, o, arena, sink, &f.stats);
  f.contract = sink.contract_ok();
  f.contract_error = sink.contract_error();
  f.pixels = sink.pixels();
  return f;
}

inline ml::RenderOptions options(ml::RendererKind r, ml::ShadingMode s = ml::ShadingMode::Unlit, int aa = 1) {
  ml::RenderOptions o;
  o.renderer = r;
  o.shading = s;
  o.aa = aa;
  return o;
}

// A pager over its own arena, begun with the whole pool and its plan finished (began: whether begin
// succeeded): get() loads any texture, and nothing is evicted.
struct WholePoolPager {
  explicit WholePoolPager(const ml::Scene& scene)
      : memory(ml::TexturePager::arena_bytes(scene, ml::kTexturePoolAll)), arena(memory.data(), memory.size()) {
    began = pager.begin(scene, nullptr, ml::kTexturePoolAll, arena, &stats).ok();
    if (began) pager.finish_plan();
  }
  std::vector<uint8_t> memory;
  ml::Arena arena;
  ml::TexturePager pager;
  ml::Stats stats;
  bool began = false;
};

// A TextureSource over the blob that fails its Nth read (1-based), counting every read.
class FailingSource : public ml::TextureSource {
 public:
  FailingSource(const ml::Scene& scene, int fail_at) : blob_(scene), fail_at_(fail_at) {}
  bool read(uint32_t texture, uint8_t* dst, uint32_t bytes) override {
    ++reads;
    if (reads == fail_at_) return false;
    return blob_.read(texture, dst, bytes);
  }
  int reads = 0;

 private:
  ml::BlobTextureSource blob_;
  int fail_at_;
};

}  // namespace textest

#include "platform/host/scene_load.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace mlhost {
namespace {

std::string lower_extension(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string e = path.substr(dot);
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(tolower(c)); });
  return e;
}

// Prints "compiling ..." on a terminal when a compile is still running after two seconds.
class SlowNote {
 public:
  SlowNote(bool enabled, const std::string& what) {
    if (!enabled || !isatty(2)) return;
    thread_ = std::thread([this, what] {
      std::unique_lock<std::mutex> lock(mutex_);
      if (!done_cv_.wait_for(lock, std::chrono::seconds(2), [this] { return done_; }))
        fprintf(stderr, "maskline: %s ...\n", what.c_str());
    });
  }
  ~SlowNote() {
    if (!thread_.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    done_cv_.notify_all();
    thread_.join();
  }

 private:
  std::mutex mutex_;
  std::condition_variable done_cv_;
  bool done_ = false;
  std::thread thread_;
};

bool validate(LoadedScene* out, std::string* error) {
  const ml::Status s = ml::read_scene(out->blob.data(), out->blob.size, &out->scene);
  if (!s.ok()) {
    *error = out->name + ": invalid scene blob: " + s.message;
    return false;
  }
  return true;
}

}  // namespace

bool adopt_compiled(ml::CompileResult result, const std::string& name, LoadedScene* out, std::string* error) {
  out->name = name;
  if (!result.ok) {
    // One line, which says why (a model with no triangles names what it has instead).
    *error = result.error.empty() ? name + ": compile failed" : result.error;
    return false;
  }
  out->blob = std::move(result.blob);  // a big scene's blob is tens of megabytes: never copy it
  out->warnings = std::move(result.warnings);
  out->camera = result.camera;
  return validate(out, error);
}

bool load_scene(const std::string& path, LoadedScene* out, std::string* error, bool progress,
                const ml::CompileOptions& options) {
  if (path.empty()) {
    SlowNote note(progress, "building the default scene");
    return adopt_compiled(ml::build_default_scene(options), "default", out, error);
  }
  if (path == "builtin:banded") return adopt_compiled(ml::build_banded_scene(options), path, out, error);
  out->name = path;
  std::string ext = lower_extension(path);
  if (ext != ".glb" && ext != ".gltf" && ext != ".mls") {
    // Unknown extension: decide by the first bytes.
    // Non-blocking open: a FIFO must not wait for a writer; only regular files are read.
    const int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
      *error = "cannot open " + path + ": " + strerror(errno);
      return false;
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
      close(fd);
      *error = path + ": not a regular file";
      return false;
    }
    unsigned char head[4] = {0, 0, 0, 0};
    const ssize_t n = read(fd, head, 4);
    close(fd);
    const size_t got = n > 0 ? size_t(n) : 0;
    if (got == 4 && memcmp(head, "glTF", 4) == 0) ext = ".glb";
    else if (got == 4 && memcmp(head, "MLSC", 4) == 0) ext = ".mls";
    else if (got >= 1 && head[0] == '{') ext = ".gltf";
    else {
      *error = path + ": unknown scene type (expected .glb, .gltf or .mls)";
      return false;
    }
  }
  if (ext == ".mls") {
    if (!ml::load_blob_file(path, &out->blob, error)) return false;
    return validate(out, error);
  }
  SlowNote note(progress, "compiling " + path);
  return adopt_compiled(ml::compile_gltf_file(path, options), path, out, error);
}

GltfMapping gltf_mapping(const ml::Scene& scene) {
  GltfMapping m;
  auto as_float = [](uint32_t bits) {
    float f;
    memcpy(&f, &bits, sizeof f);
    return double(f);
  };
  for (int i = 0; i < 3; ++i) m.center[i] = as_float(scene.info->gltf_center_bits[i]);
  m.to_world = as_float(scene.info->gltf_to_world_bits);
  if (!std::isfinite(m.to_world) || !(m.to_world > 0)) m.to_world = 1;
  for (double& c : m.center)
    if (!std::isfinite(c)) c = 0;
  return m;
}

bool gltf_point_to_world(const GltfMapping& m, const double gltf[3], ml::Vec3i* out) {
  double w[3];
  for (int i = 0; i < 3; ++i) {
    w[i] = std::round((gltf[i] - m.center[i]) * m.to_world);
    if (!(std::fabs(w[i]) < double(ml::kWorldLimit))) return false;
  }
  *out = ml::Vec3i{int32_t(w[0]), int32_t(w[1]), int32_t(w[2])};
  return true;
}

double world_to_gltf(const GltfMapping& m, int axis, double world) { return world / m.to_world + m.center[axis]; }

}  // namespace mlhost

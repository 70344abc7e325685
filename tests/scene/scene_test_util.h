// Helpers shared by the scene reader tests (tests/scene/) and the compiler tests (tests/scenec/): cached compiled scenes, temp files, blob surgery.
#pragma once
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <system_error>
#include <vector>
#include <unistd.h>

#include "scene/scene.h"
#include "tests/common/gltf_files.h"
#include "tools/scenec/scenec.h"

namespace scenetest {

constexpr const char* kModels = testfiles::kAssimpGltf2Models;
inline std::string engine_path() {
  return std::string(kModels) + "/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
}

inline bool file_exists(const std::string& path) { return access(path.c_str(), R_OK) == 0; }

// A fresh temporary directory, removed with its contents when the test binary exits.
inline std::string temp_dir() {
  static std::vector<std::string> made;
  static const bool registered = [] {
    std::atexit([] {
      for (const std::string& d : made) {
        std::error_code ignored;
        std::filesystem::remove_all(d, ignored);
      }
    });
    return true;
  }();
  (void)registered;
  char tmpl[] = "/tmp/maskline-scene-XXXXXX";
  const char* dir = mkdtemp(tmpl);
  if (!dir) return std::string("/tmp");
  made.push_back(dir);
  return std::string(dir);
}

// Base64 text of bytes (glTF data: URIs in generated test files).
inline std::string base64(const std::vector<uint8_t>& data) {
  static const char* kTable = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < data.size(); i += 3) {
    uint32_t v = uint32_t(data[i]) << 16;
    if (i + 1 < data.size()) v |= uint32_t(data[i + 1]) << 8;
    if (i + 2 < data.size()) v |= data[i + 2];
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += i + 1 < data.size() ? kTable[(v >> 6) & 63] : '=';
    out += i + 2 < data.size() ? kTable[v & 63] : '=';
  }
  return out;
}

inline void write_file(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return;
  std::fwrite(text.data(), 1, text.size(), f);
  std::fclose(f);
}

// Procedural scenes compiled once per test binary (they are shared by several suites).
inline const ml::CompileResult& cached(const std::string& name) {
  static std::map<std::string, ml::CompileResult> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  ml::CompileResult r;
  if (name == "default") r = ml::build_default_scene();
  else if (name == "office2") r = ml::build_office_scene(2);
  else if (name == "office8") r = ml::build_office_scene(8);
  else if (name == "tessellated") r = ml::build_tessellated_scene(100000);
  else if (name == "engine") r = ml::compile_gltf_file(engine_path());
  return cache.emplace(name, std::move(r)).first->second;
}

// Two boxes through each other (so the BSP splits) with a textured (4 x 4 texels) and a double-sided masked material:
// a small scene whose blob has every section.
inline ml::SceneMesh crossing_boxes_mesh() {
  using namespace ml;
  SceneMesh mesh;
  MeshMaterial a, b;
  a.texture = 0;
  b.double_sided = true;
  b.alpha_mode = AlphaMode::Mask;
  mesh.materials = {a, b};
  mesh.texture_images = {0};
  MeshImage image;  // 4 x 4, three colours: stored as an 8-bit palette texture
  image.width = image.height = 4;
  for (int i = 0; i < 16; ++i) image.rgba.insert(image.rgba.end(), {uint8_t(i % 3 * 100), 80, uint8_t(i / 5 * 60), 255});
  mesh.images = {image};
  MeshNode root;
  root.name = "root";
  mesh.nodes.push_back(root);
  auto box = [](MeshPrimitive* p, double x0, double y0, double z0, double x1, double y1, double z1) {
    const double c[8][3] = {{x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0},
                            {x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}};
    const uint32_t f[6][4] = {{4, 5, 6, 7}, {1, 0, 3, 2}, {5, 1, 2, 6}, {0, 4, 7, 3}, {7, 6, 2, 3}, {0, 1, 5, 4}};
    for (auto& q : f) {
      const uint32_t base = uint32_t(p->vertices.size());
      for (uint32_t k : q) {
        MeshVertex v;
        for (int a = 0; a < 3; ++a) v.position[a] = c[k][a];
        p->vertices.push_back(v);
      }
      p->triangles.push_back({base, base + 1, base + 2});
      p->triangles.push_back({base, base + 2, base + 3});
    }
  };
  for (int i = 0; i < 2; ++i) {
    MeshNode n;
    n.parent = 0;
    MeshPrimitive p;
    p.material = uint32_t(i);
    if (i == 0) box(&p, 0, 0, 0, 4, 1, 1);
    else box(&p, 1.5, -1, -1, 2.5, 2, 2);
    n.primitives.push_back(p);
    mesh.nodes.push_back(n);
  }
  return mesh;
}

// Section entry of a type inside a blob, or nullptr.
inline ml::SectionEntry* find_section(ml::Blob* blob, ml::SectionType type) {
  ml::BlobHeader* h = reinterpret_cast<ml::BlobHeader*>(blob->bytes());
  ml::SectionEntry* table = reinterpret_cast<ml::SectionEntry*>(blob->bytes() + sizeof(ml::BlobHeader));
  for (uint32_t i = 0; i < h->section_count; ++i) {
    if (table[i].type == uint32_t(type)) return &table[i];
  }
  return nullptr;
}

template <typename T>
T* section(ml::Blob* blob, ml::SectionType type) {
  ml::SectionEntry* e = find_section(blob, type);
  return e ? reinterpret_cast<T*>(blob->bytes() + e->offset) : nullptr;
}

inline ml::BlobHeader* header(ml::Blob* blob) { return reinterpret_cast<ml::BlobHeader*>(blob->bytes()); }

inline void fix_crc(ml::Blob* blob) {
  header(blob)->crc32 = ml::crc32(blob->bytes() + 16, blob->size - 16);
}

inline ml::Status read(const ml::Blob& blob, ml::Scene* scene = nullptr) {
  ml::Scene local;
  return ml::read_scene(blob.data(), blob.size, scene ? scene : &local);
}

// Front-to-back piece order of a BSP for an eye (the rule of blob_format.h), iteratively.
inline std::vector<uint32_t> bsp_order(const ml::Scene& s, const ml::Vec3i& eye) {
  std::vector<uint32_t> order;
  if (s.bsp_node_count == 0) return order;
  struct Frame {
    uint32_t node;
    int phase;
  };
  std::vector<Frame> stack{{0, 0}};
  while (!stack.empty()) {
    Frame& f = stack.back();
    const ml::BspNode& n = s.bsp_nodes[f.node];
    const int64_t side = int64_t(n.normal[0]) * eye.x + int64_t(n.normal[1]) * eye.y +
                         int64_t(n.normal[2]) * eye.z - n.d;
    const uint32_t first = side >= 0 ? n.front : n.back;
    const uint32_t second = side >= 0 ? n.back : n.front;
    if (f.phase == 0) {
      f.phase = 1;
      if (first != ml::kNone) stack.push_back({first, 0});
    } else if (f.phase == 1) {
      f.phase = 2;
      for (uint32_t p = 0; p < n.piece_count; ++p) order.push_back(n.first_piece + p);
      if (second != ml::kNone) stack.push_back({second, 0});
    } else {
      stack.pop_back();
    }
  }
  return order;
}

}  // namespace scenetest

// compile_mesh: the one back end from SceneMesh to a scene blob (glTF and procedural scenes alike).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>

#include "scene/scene.h"
#include "tools/scenec/internal.h"

namespace ml {

using scenec_detail::dequantize;
using scenec_detail::quantize_axis;
using scenec_detail::quantize_normal;

namespace {

uint32_t float_bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

uint8_t unit_to_u8(double v) {
  if (!(v >= 0)) return 0;   // also NaN
  if (v >= 1) return 255;
  return uint8_t(std::lround(v * 255.0));
}

bool finite3(const double* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

// Appends sections and the header into a blob.
class BlobWriter {
 public:
  template <typename T>
  void add(SectionType type, const std::vector<T>& items) {
    Section s;
    s.type = type;
    s.count = uint32_t(items.size());
    s.bytes.resize(items.size() * sizeof(T));
    if (!items.empty()) std::memcpy(s.bytes.data(), items.data(), s.bytes.size());
    sections_.push_back(std::move(s));
  }

  bool finish(Blob* out, std::string* error) const {
    uint64_t offset = sizeof(BlobHeader) + sections_.size() * sizeof(SectionEntry);
    std::vector<SectionEntry> table;
    for (const Section& s : sections_) {
      offset = (offset + 7) & ~uint64_t(7);
      table.push_back(SectionEntry{uint32_t(s.type), uint32_t(offset), uint32_t(s.bytes.size()), s.count});
      offset += s.bytes.size();
    }
    if (offset > std::numeric_limits<uint32_t>::max()) {
      *error = "scene too large for the blob format (over 4 GiB)";
      return false;
    }
    out->resize(size_t(offset));
    uint8_t* base = out->bytes();
    BlobHeader h{};
    h.magic = kBlobMagic;
    h.version = kBlobVersion;
    h.header_bytes = sizeof(BlobHeader);
    h.total_size = uint32_t(offset);
    h.section_count = uint32_t(sections_.size());
    std::memcpy(base + sizeof(BlobHeader), table.data(), table.size() * sizeof(SectionEntry));
    for (size_t i = 0; i < sections_.size(); ++i) {
      if (!sections_[i].bytes.empty()) {
        std::memcpy(base + table[i].offset, sections_[i].bytes.data(), sections_[i].bytes.size());
      }
    }
    std::memcpy(base, &h, sizeof(h));
    h.crc32 = crc32(base + 16, out->size - 16);
    std::memcpy(base, &h, sizeof(h));
    return true;
  }

 private:
  struct Section {
    SectionType type;
    uint32_t count = 0;
    std::vector<uint8_t> bytes;
  };
  std::vector<Section> sections_;
};

bool validate_mesh(const SceneMesh& mesh, std::string* error, size_t* triangle_total) {
  size_t triangles = 0, vertices = 0;
  for (size_t m = 0; m < mesh.materials.size(); ++m) {
    const uint32_t t = mesh.materials[m].texture;
    if (t != kNone && t >= mesh.texture_images.size()) {
      *error = "material " + std::to_string(m) + ": texture index out of range";
      return false;
    }
  }
  for (size_t i = 0; i < mesh.nodes.size(); ++i) {
    const MeshNode& node = mesh.nodes[i];
    if (node.parent != kNone && node.parent >= i) {
      *error = "node " + std::to_string(i) + ": parent must come before the node";
      return false;
    }
    for (size_t p = 0; p < node.primitives.size(); ++p) {
      const MeshPrimitive& prim = node.primitives[p];
      const std::string where = "node " + std::to_string(i) + " primitive " + std::to_string(p);
      if (prim.material >= mesh.materials.size()) {
        *error = where + ": material index out of range";
        return false;
      }
      for (const MeshVertex& v : prim.vertices) {
        if (!finite3(v.position, 3) || !finite3(v.normal, 3) || !finite3(v.uv, 2)) {
          *error = where + ": non-finite vertex attribute";
          return false;
        }
      }
      for (const auto& t : prim.triangles) {
        for (uint32_t k : t) {
          if (k >= prim.vertices.size()) {
            *error = where + ": triangle vertex index out of range";
            return false;
          }
        }
      }
      if (prim.vertices.size() > 0xFFFFFFFFu || prim.triangles.size() > 0xFFFFFFFFu) {
        *error = where + ": too many vertices";
        return false;
      }
      if (!prim.triangles.empty()) vertices += prim.vertices.size();
      triangles += prim.triangles.size();
    }
  }
  if (triangles == 0) {
    *error = "scene has no triangles";
    return false;
  }
  if (triangles > 0x7FFFFFFFu / 4 || vertices > 0x7FFFFFFFu / 4) {
    *error = "scene too large (" + std::to_string(triangles) + " triangles)";
    return false;
  }
  *triangle_total = triangles;
  return true;
}

}  // namespace

CompileResult compile_mesh(const SceneMesh& mesh, const CompileOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CompileResult result;
  try {
    size_t triangle_total = 0;
    if (!validate_mesh(mesh, &result.error, &triangle_total)) return result;

    // ---- normalization: bbox centre to the origin, largest half-extent to 2^16 world units ----------
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (const MeshNode& node : mesh.nodes) {
      for (const MeshPrimitive& prim : node.primitives) {
        if (prim.triangles.empty()) continue;
        for (const MeshVertex& v : prim.vertices) {
          for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], v.position[a]);
            hi[a] = std::max(hi[a], v.position[a]);
          }
        }
      }
    }
    float center_f[3];
    double half = 0;
    for (int a = 0; a < 3; ++a) {
      center_f[a] = float(0.5 * lo[a] + 0.5 * hi[a]);
      half = std::max(half, std::max(hi[a] - double(center_f[a]), double(center_f[a]) - lo[a]));
    }
    const double target = double(1 << kWorldSceneBits);
    float to_world_f = 1.0f;
    if (half > 0) {
      to_world_f = float(target / half);
      while (std::isfinite(to_world_f) && to_world_f > 0 && double(to_world_f) * half > target) {
        to_world_f = std::nextafter(to_world_f, 0.0f);
      }
    }
    if (!std::isfinite(center_f[0]) || !std::isfinite(center_f[1]) || !std::isfinite(center_f[2]) ||
        !std::isfinite(to_world_f) || !(to_world_f > 0)) {
      result.error = "scene extent cannot be normalized (too large or too small)";
      return result;
    }
    const double to_world = to_world_f;
    auto world_of = [&](const double* p, int a) { return (p[a] - double(center_f[a])) * to_world; };

    // ---- batches: quantize each primitive over its own box ------------------------------------------
    std::vector<Material> materials;
    for (const MeshMaterial& m : mesh.materials) {
      Material out{};
      for (int c = 0; c < 4; ++c) out.base_color[c] = unit_to_u8(m.base_color[c]);
      out.texture = m.texture;
      out.double_sided = m.double_sided ? 1 : 0;
      out.alpha_mode = uint8_t(m.alpha_mode);
      out.alpha_cutoff = unit_to_u8(m.alpha_cutoff);
      materials.push_back(out);
    }
    std::vector<TextureRef> textures;
    for (uint32_t image : mesh.texture_images) textures.push_back(TextureRef{image, 0});
    // Texels: each texture encoded from its image (none when the image is missing), 4-aligned.
    std::vector<TextureTexels> texture_texels;
    std::vector<uint8_t> texels;
    bool any_texels = false;
    for (size_t t = 0; t < mesh.texture_images.size(); ++t) {
      const uint32_t image = mesh.texture_images[t];
      const MeshImage none;
      const MeshImage& img = image < mesh.images.size() ? mesh.images[image] : none;
      const MeshSampler sampler = t < mesh.texture_samplers.size() ? mesh.texture_samplers[t] : MeshSampler();
      EncodedTexture enc = encode_texture(img, sampler, options);
      if (enc.info.format != uint8_t(TexelFormat::None)) {
        enc.info.offset = uint32_t(texels.size());
        texels.insert(texels.end(), enc.bytes.begin(), enc.bytes.end());
        while (texels.size() % 4) texels.push_back(0);
        any_texels = true;
      }
      texture_texels.push_back(enc.info);
    }

    std::vector<Batch> batches;
    std::vector<Vertex> vertices;
    std::vector<Triangle> triangles;
    std::vector<Node> nodes;
    triangles.reserve(triangle_total);
    for (size_t ni = 0; ni < mesh.nodes.size(); ++ni) {
      const MeshNode& node = mesh.nodes[ni];
      Node out_node{};
      out_node.parent = node.parent;
      out_node.first_batch = uint32_t(batches.size());
      for (const MeshPrimitive& prim : node.primitives) {
        if (prim.triangles.empty()) continue;
        double blo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, bhi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
        for (const MeshVertex& v : prim.vertices) {
          for (int a = 0; a < 3; ++a) {
            const double w = world_of(v.position, a);
            blo[a] = std::min(blo[a], w);
            bhi[a] = std::max(bhi[a], w);
          }
        }
        Batch b{};
        b.material = prim.material;
        b.node = uint32_t(ni);
        b.first_vertex = uint32_t(vertices.size());
        b.vertex_count = uint32_t(prim.vertices.size());
        b.first_triangle = uint32_t(triangles.size());
        b.triangle_count = uint32_t(prim.triangles.size());
        for (int a = 0; a < 3; ++a) {
          const double mid = std::nearbyint(0.5 * (blo[a] + bhi[a]));
          const double ext = std::max(bhi[a] - mid, mid - blo[a]);
          b.offset[a] = int32_t(mid);
          b.scale[a] = int32_t(std::max(1.0, std::ceil(ext * 65536.0 / 32767.0)));
        }
        for (const MeshVertex& v : prim.vertices) {
          Vertex q{};
          for (int a = 0; a < 3; ++a) q.position[a] = quantize_axis(b, a, world_of(v.position, a));
          quantize_normal(v.normal, q.normal);
          for (int a = 0; a < 2; ++a) {
            const double uv = std::min(std::max(v.uv[a] * 65536.0, -2147483648.0), 2147483647.0);
            q.uv[a] = int32_t(std::llround(uv));
          }
          vertices.push_back(q);
        }
        for (const auto& t : prim.triangles) {
          triangles.push_back(Triangle{{b.first_vertex + t[0], b.first_vertex + t[1], b.first_vertex + t[2]},
                                       uint32_t(batches.size())});
        }
        batches.push_back(b);
      }
      out_node.batch_count = uint32_t(batches.size()) - out_node.first_batch;
      nodes.push_back(out_node);
    }

    // ---- BSP -----------------------------------------------------------------------------------------
    scenec_detail::BspResult bsp;
    if (options.build_bsp) {
      const auto bsp_start = std::chrono::steady_clock::now();
      if (!scenec_detail::build_bsp(batches, triangles, &vertices, options, &bsp, &result.error)) return result;
      scenec_detail::fill_subtree_bounds(batches, triangles, vertices, &bsp);
      result.report.bsp_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - bsp_start).count();
    }

    // ---- info: bounds and sphere of what the renderer will see ----------------------------------------
    SceneInfo info{};
    int32_t bmin[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, bmax[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    auto extend = [&](const Vec3i& w) {
      const int32_t c[3] = {w.x, w.y, w.z};
      for (int a = 0; a < 3; ++a) {
        bmin[a] = std::min(bmin[a], c[a]);
        bmax[a] = std::max(bmax[a], c[a]);
      }
    };
    for (const Batch& b : batches) {
      for (uint32_t i = 0; i < b.vertex_count; ++i) extend(dequantize(b, vertices[b.first_vertex + i].position));
    }
    if (!bsp.nodes.empty()) {  // split points: the root's subtree bounds already hold every piece vertex
      const BspNode& root = bsp.nodes[0];
      extend(Vec3i{root.bounds_min[0], root.bounds_min[1], root.bounds_min[2]});
      extend(Vec3i{root.bounds_max[0], root.bounds_max[1], root.bounds_max[2]});
    }
    double radius2 = 0;
    for (int a = 0; a < 3; ++a) {
      info.bounds_min[a] = bmin[a];
      info.bounds_max[a] = bmax[a];
      info.sphere_center[a] = int32_t(div_floor(int64_t(bmin[a]) + bmax[a], 2));
    }
    auto sphere = [&](const Vec3i& w) {
      const double dx = double(w.x) - info.sphere_center[0], dy = double(w.y) - info.sphere_center[1],
                   dz = double(w.z) - info.sphere_center[2];
      radius2 = std::max(radius2, dx * dx + dy * dy + dz * dz);
    };
    for (const Batch& b : batches) {
      for (uint32_t i = 0; i < b.vertex_count; ++i) sphere(dequantize(b, vertices[b.first_vertex + i].position));
    }
    info.sphere_radius = int32_t(std::ceil(std::sqrt(radius2))) + 1;
    for (int a = 0; a < 3; ++a) info.gltf_center_bits[a] = float_bits(center_f[a]);
    info.gltf_to_world_bits = float_bits(to_world_f);
    info.bsp_depth = bsp.depth;

    // ---- write ---------------------------------------------------------------------------------------
    BlobWriter writer;
    writer.add(SectionType::Info, std::vector<SceneInfo>{info});
    writer.add(SectionType::Materials, materials);
    writer.add(SectionType::Batches, batches);
    writer.add(SectionType::Vertices, vertices);
    writer.add(SectionType::Triangles, triangles);
    writer.add(SectionType::Nodes, nodes);
    if (!bsp.nodes.empty()) {
      writer.add(SectionType::BspNodes, bsp.nodes);
      writer.add(SectionType::BspPieces, bsp.pieces);
    }
    if (!textures.empty()) writer.add(SectionType::Textures, textures);
    if (any_texels) {
      while (texels.size() % 8) texels.push_back(0);  // the blob keeps ending on a multiple of 8
      writer.add(SectionType::TextureTexels, texture_texels);
      writer.add(SectionType::Texels, texels);
    }
    if (!writer.finish(&result.blob, &result.error)) return result;

    // The reader is the judge: a blob it refuses is a compiler bug, reported rather than returned.
    Scene scene;
    const Status st = read_scene(result.blob.data(), result.blob.size, &scene);
    if (!st.ok()) {
      result.error = std::string("internal error: compiled blob rejected: ") + st.message;
      result.blob = Blob();
      return result;
    }

    CompileReport& r = result.report;
    r.triangles = uint32_t(triangles.size());
    r.vertices = uint32_t(vertices.size());
    r.nodes = uint32_t(nodes.size());
    r.materials = uint32_t(materials.size());
    r.batches = uint32_t(batches.size());
    r.textures = uint32_t(textures.size());
    for (const TextureTexels& t : texture_texels) r.texture_bytes += t.bytes;
    r.bsp_nodes = uint32_t(bsp.nodes.size());
    r.bsp_pieces = uint32_t(bsp.pieces.size());
    r.bsp_depth = bsp.depth;
    r.bsp_split_vertices = bsp.split_vertices;
    r.split_ratio = bsp.nodes.empty() ? 0.0 : double(bsp.pieces.size()) / double(triangles.size());
    r.blob_bytes = result.blob.size;

    if (mesh.camera.valid) {
      result.camera.valid = true;
      for (int a = 0; a < 3; ++a) {
        result.camera.eye[a] = world_of(mesh.camera.eye, a);
        result.camera.target[a] = world_of(mesh.camera.target, a);
        result.camera.up[a] = mesh.camera.up[a];
      }
    }
    result.ok = true;
  } catch (const std::bad_alloc&) {
    result = CompileResult();
    result.error = "out of memory while compiling the scene";
  } catch (const std::exception& e) {
    result = CompileResult();
    result.error = std::string("internal error: ") + e.what();
  }
  result.report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace ml

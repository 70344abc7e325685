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

  // A section whose elements are several T each (count elements, items.size() / count T per element).
  template <typename T>
  void add_raw(SectionType type, uint32_t count, const std::vector<T>& items) {
    add(type, items);
    sections_.back().count = count;
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

// Index width of a blob: narrow (uint16_t) when every count an index field holds fits.
bool needs_wide(const SceneTables& t, size_t split_pieces) {
  const size_t limit = 0xFFFF;
  return t.vertices.size() > limit || t.batches.size() > limit || t.bsp_nodes.size() > limit ||
         t.bsp_pieces.size() > limit || t.triangles.size() + split_pieces > limit;
}

bool is_whole(const BspPiece& p, const std::vector<Triangle>& triangles) {
  if (p.triangle >= triangles.size()) return false;
  const Triangle& t = triangles[p.triangle];
  return p.v[0] == t.v[0] && p.v[1] == t.v[1] && p.v[2] == t.v[2];
}

// log2 of the smallest power-of-two cell that spans the scene box in at most 256 cells per axis.
int bounds_shift(const SceneInfo& info) {
  int shift = 0;
  for (int a = 0; a < 3; ++a) {
    const int64_t extent = int64_t(info.bounds_max[a]) - info.bounds_min[a];
    while (shift < 31 && (extent >> shift) > 255) ++shift;
  }
  return shift;
}

uint8_t cell_of(int64_t w, int32_t origin, int shift) {
  return uint8_t(std::min<int64_t>(255, std::max<int64_t>(0, (w - origin) >> shift)));
}

template <typename Index>
bool pack_tables(const SceneTables& t, const std::vector<PackedBspCone>& cones, Blob* out, std::string* error) {
  SceneInfo info = t.info;
  const int shift = bounds_shift(info);
  info.flags = (sizeof(Index) == 4 ? kWideIndices : 0u) | (uint32_t(shift) << kBoundsShiftBit);

  std::vector<PackedVertex> vertices(t.vertices.size());
  std::vector<int32_t> uvs(2 * t.vertices.size());
  bool any_uv = false;
  for (size_t i = 0; i < t.vertices.size(); ++i) {
    std::memcpy(vertices[i].position, t.vertices[i].position, sizeof(vertices[i].position));
    std::memcpy(vertices[i].normal, t.vertices[i].normal, sizeof(vertices[i].normal));
    uvs[2 * i] = t.vertices[i].uv[0];
    uvs[2 * i + 1] = t.vertices[i].uv[1];
    any_uv |= uvs[2 * i] != 0 || uvs[2 * i + 1] != 0;
  }
  std::vector<PackedTriangle<Index>> triangles(t.triangles.size());
  for (size_t i = 0; i < t.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) triangles[i].v[k] = Index(t.triangles[i].v[k]);
    triangles[i].batch = Index(t.triangles[i].batch);
  }
  std::vector<Index> pieces;
  std::vector<PackedSplitPiece<Index>> splits;
  for (const BspPiece& p : t.bsp_pieces) {
    if (is_whole(p, t.triangles)) {
      pieces.push_back(Index(p.triangle));
      continue;
    }
    pieces.push_back(Index(t.triangles.size() + splits.size()));
    splits.push_back(PackedSplitPiece<Index>{{Index(p.v[0]), Index(p.v[1]), Index(p.v[2])}, Index(p.triangle)});
  }
  std::vector<PackedBspNode<Index>> nodes(t.bsp_nodes.size());
  for (size_t i = 0; i < t.bsp_nodes.size(); ++i) {
    const BspNode& n = t.bsp_nodes[i];
    PackedBspNode<Index>& o = nodes[i];
    o = PackedBspNode<Index>{};
    for (int a = 0; a < 3; ++a) o.normal[a] = int16_t(std::lround(double(n.normal[a]) / 65536.0));
    const double d = std::nearbyint(double(n.d) / double(1 << 18));
    if (!(d >= -2147483648.0 && d <= 2147483647.0)) {
      *error = "bsp plane offset out of range";
      return false;
    }
    o.d = int32_t(d);
    o.children = uint8_t((n.front != kNone ? kFrontChild : 0) | (n.back != kNone ? kBackChild : 0));
    o.first_child = Index(n.front != kNone ? n.front : (n.back != kNone ? n.back : 0));
    o.first_piece = Index(n.first_piece);
    o.subtree_pieces = Index(n.subtree_pieces);
    for (int a = 0; a < 3; ++a) {
      o.cells[a] = cell_of(n.bounds_min[a], info.bounds_min[a], shift);
      o.cells[3 + a] = cell_of(n.bounds_max[a], info.bounds_min[a], shift);
    }
  }

  BlobWriter writer;
  writer.add(SectionType::Info, std::vector<SceneInfo>{info});
  writer.add(SectionType::Materials, t.materials);
  writer.add(SectionType::Batches, t.batches);
  writer.add(SectionType::Vertices, vertices);
  if (any_uv) writer.add_raw(SectionType::Uvs, uint32_t(t.vertices.size()), uvs);
  writer.add(SectionType::Triangles, triangles);
  writer.add(SectionType::Nodes, t.nodes);
  if (!nodes.empty()) {
    writer.add(SectionType::BspNodes, nodes);
    writer.add(SectionType::BspPieces, pieces);
    if (!splits.empty()) writer.add(SectionType::BspSplits, splits);
    if (!cones.empty()) writer.add(SectionType::BspCones, cones);
  }
  if (!t.textures.empty()) writer.add(SectionType::Textures, t.textures);
  if (!t.texture_texels.empty()) {
    writer.add(SectionType::TextureTexels, t.texture_texels);
    writer.add(SectionType::Texels, t.texels);
  }
  return writer.finish(out, error);
}

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

// One warning per material whose triangles both renderers leave out (scene.h material_hidden): an
// exporter's alpha of 0 would otherwise show only as a part missing from the picture.
void warn_hidden_materials(const SceneMesh& mesh, const std::vector<Material>& materials,
                           std::vector<std::string>* warnings) {
  for (uint32_t m = 0; m < materials.size(); ++m) {
    if (!material_hidden(materials[m])) continue;
    size_t triangles = 0;
    for (const MeshNode& node : mesh.nodes)
      for (const MeshPrimitive& prim : node.primitives)
        if (prim.material == m) triangles += prim.triangles.size();
    if (triangles == 0) continue;
    const bool mask = materials[m].alpha_mode == uint8_t(AlphaMode::Mask);
    warnings->push_back("material " + std::to_string(m) + ": " +
                        (mask ? "alphaMode MASK with base colour alpha below its alphaCutoff"
                              : "alphaMode BLEND with base colour alpha 0") +
                        ": its " + std::to_string(triangles) + " triangle" + (triangles == 1 ? " is" : "s are") +
                        " invisible and not drawn");
  }
}

}  // namespace

bool pack_scene(const SceneTables& tables, Blob* out, std::string* error) {
  size_t split_pieces = 0;
  for (const BspPiece& p : tables.bsp_pieces) split_pieces += is_whole(p, tables.triangles) ? 0 : 1;
  const bool wide = needs_wide(tables, split_pieces);
  auto pack = [&](const std::vector<PackedBspCone>& cones) {
    return wide ? pack_tables<uint32_t>(tables, cones, out, error) : pack_tables<uint16_t>(tables, cones, out, error);
  };
  if (!pack({})) return false;
  if (tables.bsp_nodes.empty()) return true;
  // The cones are computed on the packed scene, with the renderer's decoders; then packed with it.
  Scene scene;
  const Status read = read_scene(out->data(), out->size, &scene, CrcCheck::Skip);
  if (!read.ok()) {
    *error = std::string("packed scene does not read back: ") + read.message;
    return false;
  }
  const std::vector<PackedBspCone> cones = scenec_detail::bsp_cones(scene);
  const bool any = std::any_of(cones.begin(), cones.end(), [](const PackedBspCone& c) { return c.spread != kNoCone; });
  return !any || pack(cones);
}

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
    warn_hidden_materials(mesh, materials, &result.warnings);
    std::vector<TextureRef> textures;
    for (uint32_t image : mesh.texture_images) textures.push_back(TextureRef{image, 0});
    // Texels: each texture encoded from its image (none when the image is missing), 4-aligned.
    std::vector<TextureTexels> texture_texels;
    std::vector<uint8_t> texels;
    bool any_texels = false;
    for (size_t t = 0; t < mesh.texture_images.size(); ++t) {
      const uint32_t image = mesh.texture_images[t];
      const MeshImage none;
      const bool keep = options.texture_format != TextureFormatChoice::None && image < mesh.images.size();
      const MeshImage& img = keep ? mesh.images[image] : none;
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
      if (!scenec_detail::build_bsp(materials, batches, triangles, &vertices, options, &bsp, &result.error)) return result;
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
    SceneTables tables;
    tables.info = info;
    tables.materials = std::move(materials);
    tables.batches = std::move(batches);
    tables.vertices = std::move(vertices);
    tables.triangles = std::move(triangles);
    tables.nodes = std::move(nodes);
    tables.bsp_nodes = std::move(bsp.nodes);
    tables.bsp_pieces = std::move(bsp.pieces);
    tables.textures = std::move(textures);
    if (any_texels) {
      while (texels.size() % 8) texels.push_back(0);  // the blob keeps ending on a multiple of 8
      tables.texture_texels = std::move(texture_texels);
      tables.texels = std::move(texels);
    }
    if (!pack_scene(tables, &result.blob, &result.error)) return result;

    // The reader is the judge: a blob it refuses is a compiler bug, reported rather than returned.
    Scene scene;
    const Status st = read_scene(result.blob.data(), result.blob.size, &scene);
    if (!st.ok()) {
      result.error = std::string("internal error: compiled blob rejected: ") + st.message;
      result.blob = Blob();
      return result;
    }

    CompileReport& r = result.report;
    r.triangles = uint32_t(tables.triangles.size());
    r.vertices = uint32_t(tables.vertices.size());
    r.nodes = uint32_t(tables.nodes.size());
    r.materials = uint32_t(tables.materials.size());
    r.batches = uint32_t(tables.batches.size());
    r.textures = uint32_t(tables.textures.size());
    for (const TextureTexels& t : tables.texture_texels) r.texture_bytes += t.bytes;
    r.bsp_nodes = uint32_t(tables.bsp_nodes.size());
    r.bsp_pieces = uint32_t(tables.bsp_pieces.size());
    r.bsp_depth = bsp.depth;
    r.bsp_split_vertices = bsp.split_vertices;
    r.bsp_split_pieces = scene.bsp_split_count;
    r.split_ratio = tables.bsp_nodes.empty() ? 0.0 : double(tables.bsp_pieces.size()) / double(tables.triangles.size());
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

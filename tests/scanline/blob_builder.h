// A tiny scene-blob builder for the scanline tests: fills the structs of src/scene/blob_format.h
// directly (world positions given as integers, batch scale 1, offset 0), computes the CRC and reads
// the blob back with read_scene. Independent of tools/scenec so the tests pin exact coordinates.
#pragma once
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include "scene/blob_format.h"
#include "scene/scene.h"

namespace scantest {

struct Prim {
  uint32_t material = 0;
  std::vector<std::array<int32_t, 3>> pos;    // world units, |v| < 32768
  std::vector<std::array<double, 3>> normal;  // optional, unit length (empty = none)
  std::vector<std::array<uint32_t, 3>> tris;  // counter-clockwise = front
};

struct Material {
  uint8_t rgba[4] = {200, 200, 200, 255};
  bool double_sided = false;
  ml::AlphaMode mode = ml::AlphaMode::Opaque;
  uint8_t cutoff = 128;
};

struct BuiltScene {
  std::vector<uint64_t> words;
  size_t size = 0;
  ml::Scene scene;
  ml::Status status;
};

inline void build(const std::vector<Material>& mats, const std::vector<Prim>& prims, BuiltScene* out) {
  std::vector<ml::Material> m;
  for (const Material& x : mats) {
    ml::Material e{};
    std::memcpy(e.base_color, x.rgba, 4);
    e.texture = ml::kNone;
    e.double_sided = x.double_sided ? 1 : 0;
    e.alpha_mode = uint8_t(x.mode);
    e.alpha_cutoff = x.cutoff;
    m.push_back(e);
  }
  std::vector<ml::Batch> batches;
  std::vector<ml::PackedVertex> verts;
  std::vector<ml::PackedTriangle<uint16_t>> tris;   // narrow indices (blob_format.h)
  int32_t lo[3] = {1 << 30, 1 << 30, 1 << 30}, hi[3] = {-(1 << 30), -(1 << 30), -(1 << 30)};
  for (const Prim& p : prims) {
    ml::Batch b{};
    b.material = p.material;
    b.node = ml::kNone;
    b.first_vertex = uint32_t(verts.size());
    b.vertex_count = uint32_t(p.pos.size());
    b.first_triangle = uint32_t(tris.size());
    b.triangle_count = uint32_t(p.tris.size());
    for (int a = 0; a < 3; ++a) { b.scale[a] = 1 << 16; b.offset[a] = 0; }
    for (size_t i = 0; i < p.pos.size(); ++i) {
      ml::PackedVertex v{};
      for (int a = 0; a < 3; ++a) {
        v.position[a] = int16_t(p.pos[i][a]);
        lo[a] = std::min(lo[a], p.pos[i][a]);
        hi[a] = std::max(hi[a], p.pos[i][a]);
        v.normal[a] = i < p.normal.size() ? int16_t(std::lround(p.normal[i][a] * 16384.0)) : 0;
      }
      verts.push_back(v);
    }
    for (const auto& t : p.tris) {
      ml::PackedTriangle<uint16_t> tr{};
      for (int k = 0; k < 3; ++k) tr.v[k] = uint16_t(b.first_vertex + t[k]);
      tr.batch = uint16_t(batches.size());
      tris.push_back(tr);
    }
    batches.push_back(b);
  }
  ml::SceneInfo info{};
  double r2 = 0;
  for (int a = 0; a < 3; ++a) {
    info.bounds_min[a] = lo[a];
    info.bounds_max[a] = hi[a];
    info.sphere_center[a] = (lo[a] + hi[a]) / 2;
    const double h = (hi[a] - lo[a]) / 2.0 + 1;
    r2 += h * h;
  }
  info.sphere_radius = int32_t(std::ceil(std::sqrt(r2))) + 1;

  struct Sec { ml::SectionType type; const void* data; uint32_t size, count; };
  const Sec secs[] = {
      {ml::SectionType::Info, &info, uint32_t(sizeof info), 1},
      {ml::SectionType::Materials, m.data(), uint32_t(m.size() * sizeof(ml::Material)), uint32_t(m.size())},
      {ml::SectionType::Batches, batches.data(), uint32_t(batches.size() * sizeof(ml::Batch)), uint32_t(batches.size())},
      {ml::SectionType::Vertices, verts.data(), uint32_t(verts.size() * sizeof(ml::PackedVertex)), uint32_t(verts.size())},
      {ml::SectionType::Triangles, tris.data(), uint32_t(tris.size() * sizeof(tris[0])), uint32_t(tris.size())},
  };
  const uint32_t nsec = 5;
  size_t offset = sizeof(ml::BlobHeader) + nsec * sizeof(ml::SectionEntry);
  offset = (offset + 7) & ~size_t(7);
  std::vector<ml::SectionEntry> entries;
  for (const Sec& s : secs) {
    entries.push_back(ml::SectionEntry{uint32_t(s.type), uint32_t(offset), s.size, s.count});
    offset = (offset + s.size + 7) & ~size_t(7);
  }
  out->size = offset;
  out->words.assign((offset + 7) / 8, 0);
  uint8_t* base = reinterpret_cast<uint8_t*>(out->words.data());
  ml::BlobHeader h{};
  h.magic = ml::kBlobMagic;
  h.version = ml::kBlobVersion;
  h.header_bytes = sizeof(ml::BlobHeader);
  h.total_size = uint32_t(offset);
  h.section_count = nsec;
  std::memcpy(base + sizeof h, entries.data(), entries.size() * sizeof(ml::SectionEntry));
  for (size_t i = 0; i < nsec; ++i)
    if (secs[i].size) std::memcpy(base + entries[i].offset, secs[i].data, secs[i].size);
  h.crc32 = 0;
  std::memcpy(base, &h, sizeof h);
  h.crc32 = ml::crc32(base + 16, offset - 16);
  std::memcpy(base, &h, sizeof h);
  out->status = ml::read_scene(base, offset, &out->scene);
}

}  // namespace scantest

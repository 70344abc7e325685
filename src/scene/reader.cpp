// The validating scene-blob reader. Every check runs before *out is filled; every access below is
// preceded by the bounds check that makes it safe. No heap, no float, no recursion.
#include "scene/scene.h"

#include "core/build.h"

namespace ml {
namespace {

// Validation runs once a blob, at load (boot, on a board): optimized for size up to the end of
// read_scene (crc32, core/crc32.cpp, as well). The accessors after it are the renderers' hot paths.
ML_OPTIMIZE_SIZE_BEGIN

// ---- helpers -------------------------------------------------------------------------------------

// Element size of a section type; index-bearing types depend on the index width.
uint32_t element_size(uint32_t type, bool wide) {
  const uint32_t index = wide ? 4 : 2;
  switch (static_cast<SectionType>(type)) {
    case SectionType::Info: return sizeof(SceneInfo);
    case SectionType::Materials: return sizeof(Material);
    case SectionType::Batches: return sizeof(Batch);
    case SectionType::Vertices: return sizeof(PackedVertex);
    case SectionType::Triangles: return 4 * index;
    case SectionType::Nodes: return sizeof(Node);
    case SectionType::BspNodes: return wide ? sizeof(PackedBspNode<uint32_t>) : sizeof(PackedBspNode<uint16_t>);
    case SectionType::BspPieces: return index;
    case SectionType::Textures: return sizeof(TextureRef);
    case SectionType::BspSplits: return 4 * index;
    case SectionType::Uvs: return 8;
    case SectionType::TextureTexels: return sizeof(TextureTexels);
    case SectionType::Texels: return 1;
    case SectionType::BspCones: return sizeof(PackedBspCone);
  }
  return 0;
}

// [first, first + count) inside [0, limit), without overflow.
bool range_ok(uint32_t first, uint32_t count, uint32_t limit) {
  return uint64_t(first) + uint64_t(count) <= uint64_t(limit);
}

bool in_limit(int32_t v, int32_t limit) { return v > -limit && v < limit; }

Status bad(const char* message) { return error(StatusCode::BadScene, message); }

struct Sections {
  const SectionEntry* entry[kSectionTypeCount + 1] = {};
  const SectionEntry* get(SectionType t) const { return entry[uint32_t(t)]; }
};

template <typename T>
const T* section_data(const uint8_t* base, const SectionEntry* e, uint32_t* count) {
  if (e == nullptr) {
    *count = 0;
    return nullptr;
  }
  *count = e->count;
  return e->count ? reinterpret_cast<const T*>(base + e->offset) : nullptr;
}

Status check_header(const uint8_t* base, size_t size, CrcCheck crc, const BlobHeader** header_out) {
  if (base == nullptr) return bad("blob is null");
  if (size < sizeof(BlobHeader)) return bad("blob too small for header");
  if ((reinterpret_cast<uintptr_t>(base) & 7u) != 0) return bad("blob base not 8-byte aligned");
  const BlobHeader* h = reinterpret_cast<const BlobHeader*>(base);
  if (h->magic != kBlobMagic) return bad("bad magic");
  if (h->version != kBlobVersion) return bad("unsupported blob version");
  if (h->header_bytes != sizeof(BlobHeader)) return bad("bad header size");
  if (uint64_t(h->total_size) != uint64_t(size)) return bad("total size does not match blob size");
  if (crc == CrcCheck::Check && crc32(base + 16, size - 16) != h->crc32) return bad("crc mismatch");
  if (h->reserved != 0) return bad("header reserved field not zero");
  *header_out = h;
  return ok_status();
}

// Places every section (type, uniqueness, alignment, bounds, no overlap), then the Info section, whose
// flags give the index width that the other sections' sizes depend on.
Status check_sections(const uint8_t* base, const BlobHeader& h, Sections* s, bool* wide) {
  const uint64_t table_end = uint64_t(sizeof(BlobHeader)) + uint64_t(h.section_count) * sizeof(SectionEntry);
  if (table_end > h.total_size) return bad("section table outside blob");
  const SectionEntry* table = reinterpret_cast<const SectionEntry*>(base + sizeof(BlobHeader));
  for (uint32_t i = 0; i < h.section_count; ++i) {
    const SectionEntry& e = table[i];
    if (e.type == 0 || e.type > kSectionTypeCount) return bad("unknown section type");
    if (s->entry[e.type] != nullptr) return bad("duplicate section");
    if ((e.offset & 7u) != 0) return bad("section not 8-byte aligned");
    if (uint64_t(e.offset) < table_end || uint64_t(e.offset) + e.size > h.total_size) {
      return bad("section outside blob");
    }
    s->entry[e.type] = &e;
  }
  // Pairwise overlap (at most kSectionTypeCount sections).
  for (uint32_t a = 1; a <= kSectionTypeCount; ++a) {
    const SectionEntry* ea = s->entry[a];
    if (ea == nullptr || ea->size == 0) continue;
    for (uint32_t b = a + 1; b <= kSectionTypeCount; ++b) {
      const SectionEntry* eb = s->entry[b];
      if (eb == nullptr || eb->size == 0) continue;
      const uint64_t a0 = ea->offset, a1 = a0 + ea->size, b0 = eb->offset, b1 = b0 + eb->size;
      if (a0 < b1 && b0 < a1) return bad("sections overlap");
    }
  }
  if (s->get(SectionType::Info) == nullptr) return bad("missing info section");
  if (s->get(SectionType::Materials) == nullptr) return bad("missing materials section");
  if (s->get(SectionType::Batches) == nullptr) return bad("missing batches section");
  if (s->get(SectionType::Vertices) == nullptr) return bad("missing vertices section");
  if (s->get(SectionType::Triangles) == nullptr) return bad("missing triangles section");
  const SectionEntry& info = *s->get(SectionType::Info);
  if (info.count != 1 || info.size != sizeof(SceneInfo)) return bad("info section must hold one entry");
  *wide = (reinterpret_cast<const SceneInfo*>(base + info.offset)->flags & kWideIndices) != 0;
  for (uint32_t t = 1; t <= kSectionTypeCount; ++t) {
    const SectionEntry* e = s->entry[t];
    if (e != nullptr && uint64_t(e->count) * element_size(t, *wide) != e->size)
      return bad("section size does not match count");
  }
  return ok_status();
}

Status check_info(const SceneInfo& info) {
  for (int a = 0; a < 3; ++a) {
    if (info.bounds_min[a] > info.bounds_max[a]) return bad("scene bounds min above max");
    if (!in_limit(info.bounds_min[a], kSceneLimit) || !in_limit(info.bounds_max[a], kSceneLimit)) {
      return bad("scene bounds out of range");
    }
    if (!in_limit(info.sphere_center[a], kSceneLimit)) return bad("bounding sphere centre out of range");
  }
  if (info.sphere_radius <= 0) return bad("sphere radius not positive");
  if (info.sphere_radius >= kRadiusLimit) return bad("sphere radius out of range");
  if (info.bsp_depth > kMaxBspDepth) return bad("bsp depth above limit");
  if ((info.flags & ~kKnownInfoFlags) != 0) return bad("info flags unknown");
  if (((info.flags >> kBoundsShiftBit) & kBoundsShiftMask) > kMaxBoundsShift) return bad("bsp bounds cell too large");
  return ok_status();
}

// Narrow blobs must index everything with 16 bits; a piece reference reaches triangles and splits.
Status check_index_width(const Scene& s) {
  if (s.wide) return ok_status();
  const uint64_t limit = 0xFFFF;
  if (s.vertex_count > limit || s.batch_count > limit || s.bsp_node_count > limit || s.bsp_piece_count > limit ||
      uint64_t(s.triangle_count) + s.bsp_split_count > limit)
    return bad("counts too large for 16-bit indices");
  return ok_status();
}

Status check_materials(const Scene& s) {
  for (uint32_t i = 0; i < s.material_count; ++i) {
    const Material& m = s.materials[i];
    if (m.texture != kNone && m.texture >= s.texture_count) return bad("material texture index out of range");
    if (m.double_sided > 1) return bad("material double_sided not 0 or 1");
    if (m.alpha_mode > uint8_t(AlphaMode::Blend)) return bad("material alpha mode invalid");
  }
  return ok_status();
}

}  // namespace

TextureTexels texture_level_texels(const TextureTexels& t, uint32_t level, uint32_t* offset) {
  TextureTexels l = t;
  *offset = level ? texture_chain_bytes(TexelFormat(t.format), t.width, t.height, t.palette_size, level - 1) : 0u;
  l.offset = t.offset + *offset;
  l.width = uint16_t(level_side(t.width, level));
  l.height = uint16_t(level_side(t.height, level));
  l.bytes = texture_bytes(TexelFormat(t.format), l.width, l.height, t.palette_size);
  l.levels = 0;
  return l;
}

namespace {

bool power_of_two_side(uint32_t v) { return v >= 1 && v <= kMaxTextureDim && (v & (v - 1)) == 0; }

Status check_texture(const TextureTexels& t, uint32_t texel_bytes) {
  if (t.format > uint8_t(TexelFormat::Grey4)) return bad("texture format invalid");
  if (t.wrap_s > uint8_t(TextureWrap::ClampToEdge) || t.wrap_t > uint8_t(TextureWrap::ClampToEdge))
    return bad("texture wrap mode invalid");
  if (t.filter > uint8_t(TextureFilter::Bilinear)) return bad("texture filter invalid");
  if (t.reserved != 0) return bad("texture reserved field not zero");
  const TexelFormat format = TexelFormat(t.format);
  if (format == TexelFormat::None) {
    if (t.width != 0 || t.height != 0 || t.bytes != 0 || t.palette_size != 0 || t.levels != 0)
      return bad("empty texture not zero");
    return ok_status();
  }
  if (!power_of_two_side(t.width) || !power_of_two_side(t.height)) return bad("texture size not a power of two up to limit");
  const bool palette = format == TexelFormat::Palette8;
  if (palette ? (t.palette_size < 1 || t.palette_size > 256) : t.palette_size != 0)
    return bad("texture palette size invalid");
  if (t.levels > texture_max_levels(t.width, t.height)) return bad("texture mip levels invalid");
  if (t.bytes != texture_chain_bytes(format, t.width, t.height, t.palette_size, t.levels))
    return bad("texture byte count wrong");
  if ((t.offset & 3u) != 0) return bad("texture offset not 4-byte aligned");
  if (!range_ok(t.offset, t.bytes, texel_bytes)) return bad("texture texels outside texels section");
  return ok_status();
}

Status check_textures(const Scene& s) {
  if (s.texture_texels == nullptr) return ok_status();
  if (s.texture_texels_count != s.texture_count) return bad("texture texels count differs from textures");
  for (uint32_t i = 0; i < s.texture_texels_count; ++i) {
    const Status st = check_texture(s.texture_texels[i], s.texel_bytes);
    if (!st.ok()) return st;
  }
  return ok_status();
}

Status check_nodes(const Scene& s) {
  for (uint32_t i = 0; i < s.node_count; ++i) {
    const Node& n = s.nodes[i];
    if (n.parent != kNone && n.parent >= i) return bad("node parent not before node");
    if (!range_ok(n.first_batch, n.batch_count, s.batch_count)) return bad("node batch range out of range");
  }
  return ok_status();
}

Status check_batches(const Scene& s) {
  for (uint32_t i = 0; i < s.batch_count; ++i) {
    const Batch& b = s.batches[i];
    if (b.material >= s.material_count) return bad("batch material index out of range");
    if (b.node != kNone) {
      if (b.node >= s.node_count) return bad("batch node index out of range");
      const Node& n = s.nodes[b.node];
      if (i < n.first_batch || i - n.first_batch >= n.batch_count) return bad("batch outside its node's batch range");
    }
    if (!range_ok(b.first_vertex, b.vertex_count, s.vertex_count)) return bad("batch vertex range out of range");
    if (!range_ok(b.first_triangle, b.triangle_count, s.triangle_count)) return bad("batch triangle range out of range");
    for (int a = 0; a < 3; ++a) {
      if (b.scale[a] <= 0) return bad("batch scale not positive");
      // Dequantization is monotonic in q, so the int16 extremes bound every position.
      const int64_t lo = int64_t(b.offset[a]) + ((int64_t(-32768) * b.scale[a]) >> 16);
      const int64_t hi = int64_t(b.offset[a]) + ((int64_t(32767) * b.scale[a]) >> 16);
      if (lo <= -kWorldPositionLimit || hi >= kWorldPositionLimit) return bad("batch positions out of range");
    }
  }
  return ok_status();
}

Status check_vertices(const Scene& s, const SectionEntry* uvs) {
  const int64_t one = int64_t(1) << (2 * kNormalBits);
  for (uint32_t i = 0; i < s.vertex_count; ++i) {
    const int16_t* n = s.vertices[i].normal;
    const int64_t len2 = int64_t(n[0]) * n[0] + int64_t(n[1]) * n[1] + int64_t(n[2]) * n[2];
    if (len2 != 0 && abs64(len2 - one) > one / 16) return bad("vertex normal not unit length");
  }
  if (uvs != nullptr && uvs->count != s.vertex_count) return bad("uv count does not match vertex count");
  return ok_status();
}

Status check_triangles(const Scene& s) {
  for (uint32_t t = 0; t < s.triangle_count; ++t) {
    const Triangle tri = triangle_at(s, t);
    if (tri.batch >= s.batch_count) return bad("triangle batch index out of range");
    const Batch& b = s.batches[tri.batch];
    if (t < b.first_triangle || t - b.first_triangle >= b.triangle_count) {
      return bad("triangle outside its batch's range");
    }
    for (int k = 0; k < 3; ++k) {
      if (tri.v[k] < b.first_vertex || tri.v[k] - b.first_vertex >= b.vertex_count) {
        return bad("triangle vertex index out of range");
      }
    }
  }
  return ok_status();
}

bool inside(const Vec3i& p, const BspNode& n) {
  return p.x >= n.bounds_min[0] && p.x <= n.bounds_max[0] && p.y >= n.bounds_min[1] &&
         p.y <= n.bounds_max[1] && p.z >= n.bounds_min[2] && p.z <= n.bounds_max[2];
}

// The fields of packed node i that the decoder trusts: raw plane and cells, children flags.
template <typename Index>
Status check_packed_node(const Scene& s, uint32_t i) {
  const PackedBspNode<Index>& n = static_cast<const PackedBspNode<Index>*>(s.bsp_nodes)[i];
  if (n.children > (kFrontChild | kBackChild) || n.reserved != 0) return bad("bsp node flags invalid");
  if (n.children == 0 && n.first_child != 0) return bad("bsp leaf has a child index");
  for (int a = 0; a < 3; ++a)
    if (n.cells[a] > n.cells[3 + a]) return bad("bsp bounds min above max");
  if (n.first_piece > s.bsp_piece_count) return bad("bsp piece range out of range");
  if (i == 0 && n.first_piece != 0) return bad("bsp piece ranges not contiguous");
  if (i > 0 && n.first_piece < static_cast<const PackedBspNode<Index>*>(s.bsp_nodes)[i - 1].first_piece)
    return bad("bsp piece ranges not contiguous");
  return ok_status();
}

// Subtree bounds and counts, checked locally per node (own piece vertices and children inside the
// box, counts adding up), which by induction puts every piece of a subtree inside its root's box.
// Runs after the tree shape, piece ranges and indices are known good.
Status check_bsp_subtrees(const Scene& s) {
  for (uint32_t i = 0; i < s.bsp_node_count; ++i) {
    // Decoded boxes lie within the scene box's origin (|.| < 2^18) plus 256 cells of at most 2^12:
    // below kBspBoundsLimit without a check.
    const BspNode n = bsp_node(s, i);
    for (uint32_t p = n.first_piece; p < n.first_piece + n.piece_count; ++p) {
      const BspPiece piece = bsp_piece(s, p);
      const uint32_t batch = triangle_at(s, piece.triangle).batch;
      for (int k = 0; k < 3; ++k)
        if (!inside(vertex_world(s, batch, piece.v[k]), n)) return bad("bsp piece vertex outside node bounds");
    }
    uint64_t total = n.piece_count;
    const uint32_t child[2] = {n.front, n.back};
    for (uint32_t c : child) {
      if (c == kNone) continue;
      const BspNode m = bsp_node(s, c);
      for (int a = 0; a < 3; ++a)
        if (m.bounds_min[a] < n.bounds_min[a] || m.bounds_max[a] > n.bounds_max[a])
          return bad("bsp child bounds outside parent bounds");
      total += m.subtree_pieces;
    }
    if (total != n.subtree_pieces) return bad("bsp subtree piece count wrong");
  }
  return ok_status();
}

// Every piece reference and split piece in range (a reference below the triangle count is a whole
// triangle, already checked; above it, a split piece).
Status check_pieces(const Scene& s) {
  for (uint32_t p = 0; p < s.bsp_piece_count; ++p) {
    const uint32_t ref = s.wide ? static_cast<const uint32_t*>(s.bsp_pieces)[p]
                                : static_cast<const uint16_t*>(s.bsp_pieces)[p];
    if (ref >= s.triangle_count && ref - s.triangle_count >= s.bsp_split_count)
      return bad("bsp piece reference out of range");
    if (ref < s.triangle_count) continue;
    const BspPiece piece = bsp_piece(s, p);
    if (piece.triangle >= s.triangle_count) return bad("bsp piece triangle out of range");
    for (int k = 0; k < 3; ++k) {
      if (piece.v[k] >= s.vertex_count) return bad("bsp piece vertex index out of range");
    }
  }
  return ok_status();
}

// The BSP nodes must be stored breadth-first: reading every node's child references in node order
// (front before back) yields exactly 1, 2, ..., count-1. That makes the nodes a tree rooted at 0
// (each node referenced once, never the root, every child after its parent) and lets the depth be
// counted level by level in one pass with O(1) memory. Piece ranges follow node order contiguously.
Status check_bsp(const Scene& s) {
  if (s.bsp_node_count == 0) {
    if (s.bsp_piece_count != 0 || s.bsp_split_count != 0) return bad("bsp pieces without bsp nodes");
    return ok_status();
  }
  uint32_t next_child = 1;   // the index the next child reference must have
  uint32_t level_end = 1;    // end of the level being scanned
  uint32_t depth = 1;
  const int64_t unit2 = int64_t(1) << (2 * kNormalBits);
  for (uint32_t i = 0; i < s.bsp_node_count; ++i) {
    const Status st = s.wide ? check_packed_node<uint32_t>(s, i) : check_packed_node<uint16_t>(s, i);
    if (!st.ok()) return st;
    const BspNode n = bsp_node(s, i);
    if (i == level_end) {   // first node of a new level; its level ends where the children so far end
      ++depth;
      level_end = next_child;
      if (level_end <= i) return bad("bsp node unreachable");
    }
    const int64_t nx = n.normal[0] >> 16, ny = n.normal[1] >> 16, nz = n.normal[2] >> 16;  // Q1.14
    if (nx < -kNormalOne || nx > kNormalOne || ny < -kNormalOne || ny > kNormalOne || nz < -kNormalOne ||
        nz > kNormalOne)
      return bad("bsp normal out of range");
    if (abs64(nx * nx + ny * ny + nz * nz - unit2) > unit2 / 64) return bad("bsp normal not unit length");
    const uint32_t child[2] = {n.front, n.back};
    for (uint32_t c : child) {
      if (c == kNone) continue;
      if (c >= s.bsp_node_count) return bad("bsp child index out of range");
      if (c == 0) return bad("bsp child is the root");
      if (c < next_child) return bad("bsp node referenced twice");
      if (c > next_child) return bad("bsp nodes not in breadth-first order");
      if (c <= i) return bad("bsp child not after its parent");
      ++next_child;
    }
  }
  if (next_child != s.bsp_node_count) return bad("bsp node unreachable");
  if (depth > s.info->bsp_depth) return bad("bsp deeper than info bsp_depth");
  const Status st = check_pieces(s);
  if (!st.ok()) return st;
  return check_bsp_subtrees(s);
}

}  // namespace

Status read_scene(const void* blob, size_t size, Scene* out, CrcCheck crc) {
  if (out == nullptr) return error(StatusCode::InvalidArgument, "scene output is null");
  *out = Scene{};
  const uint8_t* base = static_cast<const uint8_t*>(blob);
  const BlobHeader* header = nullptr;
  Status st = check_header(base, size, crc, &header);
  if (!st.ok()) return st;
  Sections sec;
  bool wide = false;
  st = check_sections(base, *header, &sec, &wide);
  if (!st.ok()) return st;

  Scene s;
  s.base = base;
  s.size = header->total_size;
  s.wide = wide;
  uint32_t info_count = 0, uv_count = 0;
  s.info = section_data<SceneInfo>(base, sec.get(SectionType::Info), &info_count);
  s.bounds_shift = int((s.info->flags >> kBoundsShiftBit) & kBoundsShiftMask);
  s.materials = section_data<Material>(base, sec.get(SectionType::Materials), &s.material_count);
  s.batches = section_data<Batch>(base, sec.get(SectionType::Batches), &s.batch_count);
  s.vertices = section_data<PackedVertex>(base, sec.get(SectionType::Vertices), &s.vertex_count);
  s.uvs = section_data<int32_t>(base, sec.get(SectionType::Uvs), &uv_count);
  s.triangles = section_data<uint8_t>(base, sec.get(SectionType::Triangles), &s.triangle_count);
  s.nodes = section_data<Node>(base, sec.get(SectionType::Nodes), &s.node_count);
  s.bsp_nodes = section_data<uint8_t>(base, sec.get(SectionType::BspNodes), &s.bsp_node_count);
  s.bsp_pieces = section_data<uint8_t>(base, sec.get(SectionType::BspPieces), &s.bsp_piece_count);
  s.bsp_splits = section_data<uint8_t>(base, sec.get(SectionType::BspSplits), &s.bsp_split_count);
  uint32_t cone_count = 0;
  s.bsp_cones = section_data<PackedBspCone>(base, sec.get(SectionType::BspCones), &cone_count);
  s.textures = section_data<TextureRef>(base, sec.get(SectionType::Textures), &s.texture_count);
  s.texture_texels = section_data<TextureTexels>(base, sec.get(SectionType::TextureTexels), &s.texture_texels_count);
  s.texels = section_data<uint8_t>(base, sec.get(SectionType::Texels), &s.texel_bytes);

  if (!(st = check_info(*s.info)).ok()) return st;
  if (!(st = check_index_width(s)).ok()) return st;
  if (!(st = check_materials(s)).ok()) return st;
  if (!(st = check_textures(s)).ok()) return st;
  if (!(st = check_nodes(s)).ok()) return st;
  if (!(st = check_batches(s)).ok()) return st;
  if (!(st = check_vertices(s, sec.get(SectionType::Uvs))).ok()) return st;
  if (!(st = check_triangles(s)).ok()) return st;
  if (!(st = check_bsp(s)).ok()) return st;
  if (s.bsp_cones && cone_count != s.bsp_node_count) return bad("bsp cone count does not match bsp node count");
  *out = s;
  return ok_status();
}

ML_OPTIMIZE_SIZE_END

BspNode bsp_node_unboxed(const Scene& s, uint32_t i) {
  return s.wide ? scene_detail::node<uint32_t>(s, i) : scene_detail::node<uint16_t>(s, i);
}

void bsp_node_box(const Scene& s, uint32_t i, BspNode* node) {
  if (s.wide) scene_detail::node_box<uint32_t>(s, i, node); else scene_detail::node_box<uint16_t>(s, i, node);
}

// Small rather than fast (a test a node entered, not a piece): the boards' flash is short (on the
// host -O2 is no faster: 2CylinderEngine's frame 55.37 M -> 55.40 M).
ML_OPTIMIZE_SIZE bool bsp_subtree_faces_away(const Scene& s, uint32_t i, const Vec3i& eye) {
  if (!s.bsp_cones || s.bsp_cones[i].spread == kNoCone) return false;
  const PackedBspCone& cone = s.bsp_cones[i];
  BspNode box;
  bsp_node_box(s, i, &box);
  const int32_t e[3] = {eye.x, eye.y, eye.z};
  int64_t near = 0;  // |box - eye| < 2^25 a coordinate: near < 2^34
  int32_t m[3];      // the farthest corner's distances from the eye along each axis
  for (int a = 0; a < 3; ++a) {
    const int32_t lo = box.bounds_min[a] - kConeMarginWorld - e[a], hi = box.bounds_max[a] + kConeMarginWorld - e[a];
    near += int64_t(cone.axis[a]) * (cone.axis[a] >= 0 ? lo : hi);
    m[a] = max_of(lo < 0 ? -lo : lo, hi < 0 ? -hi : hi);
  }
  // |p - E| <= m1 + m2 / 2 + m3 / 4 for m1 >= m2 >= m3 (squared, the cross terms cover the rest).
  auto order = [](int32_t& a, int32_t& b) {
    if (a < b) {
      const int32_t t = a;
      a = b;
      b = t;
    }
  };
  order(m[0], m[1]);
  order(m[1], m[2]);
  order(m[0], m[1]);
  const int64_t far4 = 4 * int64_t(m[0]) + 2 * int64_t(m[1]) + m[2];  // >= 4 |p - E|
  return 8 * near > int64_t(cone.spread) * far4;
}

Vec3i vertex_world(const Scene& scene, uint32_t batch, uint32_t vertex) {
  const Batch& b = scene.batches[batch];
  const int16_t* q = scene.vertices[vertex].position;
  return Vec3i{int32_t(b.offset[0] + ((int64_t(q[0]) * b.scale[0]) >> 16)),
               int32_t(b.offset[1] + ((int64_t(q[1]) * b.scale[1]) >> 16)),
               int32_t(b.offset[2] + ((int64_t(q[2]) * b.scale[2]) >> 16))};
}

const TextureTexels* material_texels(const Scene& scene, const Material& material) {
  if (material.texture == kNone || scene.texture_texels == nullptr) return nullptr;
  const TextureTexels* t = &scene.texture_texels[material.texture];
  return t->format == uint8_t(TexelFormat::None) ? nullptr : t;
}

void vertices_world(const Scene& scene, uint32_t batch, const uint32_t v[3], Vec3i out[3]) {
  ML_HOST_UNROLL for (int k = 0; k < 3; ++k) out[k] = vertex_world(scene, batch, v[k]);
}

void triangle_world(const Scene& scene, uint32_t id, Vec3i out[3]) {
  const Triangle t = triangle_at(scene, id);
  vertices_world(scene, t.batch, t.v, out);
}

}  // namespace ml

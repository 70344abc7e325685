// The scene blob (.mls): the one description of the format. docs/scene-blob.md explains it for
// people; this header is what both the writer (tools/scenec) and the reader (src/scene) compile.
//
// Properties: little-endian; read in place (flash, mmap, buffer), never copied; position-independent
// (all references are offsets from the blob start or indices); the base address must be 8-byte aligned
// and every section starts at a multiple of 8 (no element needs more than 4-byte alignment). Versioned
// (kBlobVersion) and checksummed (CRC-32/IEEE, reflected polynomial 0xEDB88320, init and final xor
// 0xFFFFFFFF, over bytes [16, total_size)); the reader checks the CRC only when asked to.
//
// Packed for flash: indices are 16-bit ("narrow") when every count they index fits, else 32-bit
// ("wide", SceneInfo::flags bit kWideIndices); pieces that are whole triangles are one index; planes
// are an int16 normal and an int32 offset; subtree boxes are byte cells of a grid over the scene box.
// Renderers never read these structs directly: scene/scene.h decodes them (bsp_node, bsp_piece,
// triangle_at, vertex_normal, vertex_uv).
//
// Layout:
//   BlobHeader                      (24 bytes)
//   SectionEntry[section_count]     (16 bytes each)
//   sections, each 8-aligned, in any order, each type at most once
//
// Geometry lives in world space: the compiler applies the (nested) node transforms and normalizes the
// scene so that its bounding box is centred on the origin and fits inside ±2^16 world units
// (fixed.h: kWorldSceneBits). SceneInfo keeps the normalization so host tools can map glTF
// coordinates (e.g. a --eye given by the user) into world units.
//
// Triangle ids: a triangle's index in the Triangles section. The compiler emits triangles nodes
// depth-first in scene order, a mesh's primitives in order, triangles in index order (strips and fans
// triangulated in order). Later stages keep the id, also for pieces of split triangles.
#pragma once
#include <stdint.h>

namespace ml {

constexpr uint32_t kBlobMagic = 0x43534C4D;  // "MLSC" as bytes
constexpr uint16_t kBlobVersion = 2;
constexpr uint32_t kNone = 0xFFFFFFFFu;      // "no index" in any u32 index field

struct BlobHeader {
  uint32_t magic;          // kBlobMagic
  uint16_t version;        // kBlobVersion
  uint16_t header_bytes;   // sizeof(BlobHeader)
  uint32_t total_size;     // bytes in the blob
  uint32_t crc32;          // of bytes [16, total_size)
  uint32_t section_count;
  uint32_t reserved;       // 0
};
static_assert(sizeof(BlobHeader) == 24, "BlobHeader layout");

enum class SectionType : uint32_t {
  Info = 1,        // one SceneInfo
  Materials = 2,   // Material[count]
  Batches = 3,     // Batch[count]
  Vertices = 4,    // PackedVertex[count]
  Triangles = 5,   // PackedTriangle<Index>[count], index = triangle id
  Nodes = 6,       // Node[count], the glTF node hierarchy (for info; geometry is already in world space)
  BspNodes = 7,    // PackedBspNode<Index>[count], node 0 is the root (absent or count 0: no BSP)
  BspPieces = 8,   // Index[count]: the pieces, referenced by BspNode ranges (see kind below)
  Textures = 9,    // TextureRef[count]
  TextureTexels = 10,  // TextureTexels[count], one per TextureRef (same index): size, format, sampler
  Texels = 11,     // uint8[count]: every texture's bytes, where its TextureTexels entry says
  BspSplits = 12,  // PackedSplitPiece<Index>[count]: pieces that are part of a split triangle
  Uvs = 13,        // int32_t[2] per vertex (TEXCOORD_0, Q16.16); absent: every uv is 0
  BspCones = 14,   // PackedBspCone[count], one per BspNodes entry (same index); absent: no cone tests
};
constexpr uint32_t kSectionTypeCount = 14;

struct SectionEntry {
  uint32_t type;     // SectionType
  uint32_t offset;   // from blob start, multiple of 8
  uint32_t size;     // bytes, == count * element size
  uint32_t count;    // elements
};
static_assert(sizeof(SectionEntry) == 16, "SectionEntry layout");

// SceneInfo::flags
constexpr uint32_t kWideIndices = 1u;          // bit 0: index fields are uint32_t, else uint16_t
constexpr int kBoundsShiftBit = 8;             // bits 8..12: log2 of a bounds cell (world units)
constexpr uint32_t kBoundsShiftMask = 31u;
constexpr uint32_t kKnownInfoFlags = kWideIndices | (kBoundsShiftMask << kBoundsShiftBit);

struct SceneInfo {
  int32_t bounds_min[3];       // world units, of every vertex; bounds_min is also the BSP grid origin
  int32_t bounds_max[3];
  int32_t sphere_center[3];    // bounding sphere, world units
  int32_t sphere_radius;       // > 0
  // Host-only metadata, raw IEEE-754 float bits that src/ never interprets:
  //   world = (gltf - gltf_center) * gltf_to_world
  uint32_t gltf_center_bits[3];
  uint32_t gltf_to_world_bits;
  uint32_t bsp_depth;          // longest root-to-leaf path in BspNodes (0 when there is no BSP)
  uint32_t flags;              // kWideIndices, bounds cell shift; other bits 0
};
static_assert(sizeof(SceneInfo) == 64, "SceneInfo layout");

enum class AlphaMode : uint8_t { Opaque = 0, Mask = 1, Blend = 2 };

struct Material {
  uint8_t base_color[4];       // RGBA8 (glTF baseColorFactor, linear values scaled to 0..255)
  uint32_t texture;            // index into Textures, or kNone
  uint8_t double_sided;        // 0 or 1
  uint8_t alpha_mode;          // AlphaMode
  uint8_t alpha_cutoff;        // 0..255 (glTF alphaCutoff * 255), used by Mask
  uint8_t reserved;
};
static_assert(sizeof(Material) == 12, "Material layout");

// A batch is one glTF mesh primitive under one node, flattened to world space. Its vertices are
// quantized to int16 over the batch's own bounding box:
//   world = offset + (q * scale) >> 16        (scale Q16.16, one per axis, > 0)
struct Batch {
  uint32_t material;           // index into Materials
  uint32_t node;               // index into Nodes
  uint32_t first_vertex;       // range in Vertices
  uint32_t vertex_count;
  uint32_t first_triangle;     // range in Triangles
  uint32_t triangle_count;
  int32_t scale[3];            // Q16.16
  int32_t offset[3];           // world units
};
static_assert(sizeof(Batch) == 48, "Batch layout");

// UVs live in their own optional section (Uvs), so untextured scenes do not carry them.
struct PackedVertex {
  int16_t position[3];         // quantized, see Batch
  int16_t normal[3];           // world space, Q1.14 unit vector; (0,0,0) if the mesh had none
};
static_assert(sizeof(PackedVertex) == 12, "PackedVertex layout");

// Index = uint16_t (narrow) or uint32_t (wide), for the whole blob (SceneInfo::flags).
template <typename Index>
struct PackedTriangle {
  Index v[3];                  // indices into Vertices, inside the batch's vertex range
  Index batch;                 // index into Batches
};
static_assert(sizeof(PackedTriangle<uint16_t>) == 8 && sizeof(PackedTriangle<uint32_t>) == 16,
              "PackedTriangle layout");

struct Node {
  uint32_t parent;             // index into Nodes or kNone for roots of the scene
  uint32_t first_batch;        // batches of this node's mesh
  uint32_t batch_count;
  uint32_t reserved;
};
static_assert(sizeof(Node) == 16, "Node layout");

// BSP tree over the scene's pieces, in world space. Plane value of a point p (world units):
//   dot(normal, p) * 2^16 - d * 2^18        (normal Q1.14, d world units * 2^12; the scale is Q1.30)
// Pieces with a positive value are in front. Front-to-back for an eye E: if plane(E) >= 0 visit
// front, own pieces, back; else back, own, front.
// Layout (checked by read_scene): nodes are stored breadth-first — reading every node's children in
// node order, front before back, gives exactly 1, 2, ..., count-1; so a node's children are
// first_child (front if it has one) and the next index. Node i's pieces are [first_piece, next node's
// first_piece) (the last node's end at the piece count); node 0's first_piece is 0.
// Subtree bounds: every piece vertex in the node's subtree (as the renderer dequantizes it) lies in
// the box, cell c of axis a covering world [bounds_min[a] + c * 2^shift, + 2^shift - 1] (origin and
// shift in SceneInfo); a child's cells lie inside its parent's. A subtree without pieces may hold
// any such nesting box (the compiler gives it its parent's). subtree_pieces = own + the children's.
constexpr uint8_t kFrontChild = 1, kBackChild = 2;
template <typename Index>
struct PackedBspNode {
  int32_t d;                   // world units * 2^12
  int16_t normal[3];           // Q1.14
  uint8_t children;            // kFrontChild | kBackChild
  uint8_t reserved;            // 0
  Index first_child;           // index of the first child (0 without children)
  Index first_piece;           // into BspPieces
  Index subtree_pieces;        // pieces in the subtree
  uint8_t cells[6];            // box min x, y, z, max x, y, z in bounds cells (inclusive)
};
static_assert(sizeof(PackedBspNode<uint16_t>) == 24 && sizeof(PackedBspNode<uint32_t>) == 32,
              "PackedBspNode layout");

// A piece is a whole triangle or a part of one that the BSP split. BspPieces holds one Index per
// piece: a value below the triangle count is that triangle (its vertices, in order); value
// triangle_count + k is BspSplits[k]. A split piece's vertices index Vertices (split points are
// appended there by the compiler, quantized with the batch of `triangle`, which need not contain
// them in its vertex range); `triangle` is the id of the triangle it came from.
template <typename Index>
struct PackedSplitPiece {
  Index v[3];
  Index triangle;
};
static_assert(sizeof(PackedSplitPiece<uint16_t>) == 8 && sizeof(PackedSplitPiece<uint32_t>) == 16,
              "PackedSplitPiece layout");

// Normal cone of a BSP subtree, for culling subtrees that face away from the eye as a whole. For the
// eye E and the node's subtree box grown by kConeMarginWorld world units on every side, with
//   near = min over the grown box of dot(axis, p - E)     (a corner per axis: exact, integer)
//   m1 >= m2 >= m3: the farthest corner's distances from E along the three axes
//   far4 = 4 m1 + 2 m2 + m3                                 (>= 4 |p - E| over the grown box)
// every triangle with a piece in the subtree faces away from E (triangle_facing < 0 for its whole
// triangle) and no material there is double-sided when 8 * near > spread * far4. The compiler
// guarantees it: each such triangle's unit normal n has 2 |axis| |n - axis / |axis|| <= spread, and
// every piece vertex lies within kConeMarginWorld of its triangle's plane (docs/scene-blob.md has the
// proof). spread == kNoCone: no test (mixed normals, a double-sided material, a small subtree).
constexpr uint8_t kNoCone = 255;
constexpr int32_t kConeMarginWorld = 4;
struct PackedBspCone {
  int8_t axis[3];              // direction of the cone (any length, |axis| > 0 with a cone)
  uint8_t spread;              // see above; kNoCone: no cone
};
static_assert(sizeof(PackedBspCone) == 4, "PackedBspCone layout");

struct TextureRef {
  uint32_t image;              // glTF image index (for info; the texels are in TextureTexels/Texels)
  uint32_t reserved;
};
static_assert(sizeof(TextureRef) == 8, "TextureRef layout");

// Device formats of texels. A texture's bytes are its palette (Palette8 only) followed by its rows,
// top row first (glTF v = 0), no padding; texture_bytes() gives the count.
enum class TexelFormat : uint8_t {
  None = 0,      // no texels (the compiler could not or would not store the image): base colour
  Rgb565 = 1,    // u16 little-endian per texel, r in the top 5 bits; 8-bit channels by bit replication
                 // (r8 = r5 << 3 | r5 >> 2, g8 = g6 << 2 | g6 >> 4)
  Palette8 = 2,  // palette_size RGB565 colours (u16 each), then one u8 index per texel
  Grey4 = 3,     // two texels per byte, the left one in the low nibble; grey = nibble * 17
};
enum class TextureWrap : uint8_t { Repeat = 0, MirroredRepeat = 1, ClampToEdge = 2 };
enum class TextureFilter : uint8_t { Nearest = 0, Bilinear = 1 };

struct TextureTexels {
  uint32_t offset;             // of the texture's first byte in Texels, a multiple of 4
  uint32_t bytes;              // texture_chain_bytes(format, width, height, palette_size, levels)
  uint16_t width, height;      // powers of two, 1..kMaxTextureDim (core/fixed.h); 0 with format None
  uint8_t format;              // TexelFormat
  uint8_t wrap_s, wrap_t;      // TextureWrap, for u and v
  uint8_t filter;              // TextureFilter (magnification and minification alike)
  uint16_t palette_size;       // Palette8: 1..256 colours; otherwise 0
  uint8_t levels;              // mip levels after the texture's own: 0..texture_max_levels(width, height)
  uint8_t reserved;            // 0
};
static_assert(sizeof(TextureTexels) == 20, "TextureTexels layout");

// Bytes of one texture's data (0 for None). Exact in uint32 for sizes up to kMaxTextureDim.
constexpr uint32_t texture_bytes(TexelFormat format, uint32_t width, uint32_t height, uint32_t palette_size) {
  return format == TexelFormat::Rgb565     ? width * height * 2
         : format == TexelFormat::Palette8 ? palette_size * 2 + width * height
         : format == TexelFormat::Grey4    ? ((width + 1) / 2) * height
                                           : 0;
}

// Mip levels: level L (1..levels) halves the sides L times, down to 1 (level_side), and is stored
// whole after level L - 1, in the texture's format (a Palette8 level with its own copy of the
// palette), so that a level's bytes and its TextureTexels (texture_level_texels) read as a texture
// of their own.
constexpr uint32_t level_side(uint32_t side, uint32_t level) { return side >> level ? side >> level : 1u; }
// The most levels a texture of these sides can have: until both sides are 1.
constexpr uint32_t texture_max_levels(uint32_t width, uint32_t height) {
  uint32_t n = 0;
  while ((width >> n) > 1u || (height >> n) > 1u) ++n;
  return n;
}
// Bytes of a texture and its levels 1..levels; with last = L, the offset of level L + 1 from its
// first byte.
constexpr uint32_t texture_chain_bytes(TexelFormat format, uint32_t width, uint32_t height, uint32_t palette_size,
                                       uint32_t last) {
  uint32_t bytes = 0;
  for (uint32_t l = 0; l <= last; ++l)
    bytes += texture_bytes(format, level_side(width, l), level_side(height, l), palette_size);
  return bytes;
}
// Level `level` (0: the texture itself) of texture t as a texture of its own: its sides and bytes;
// *offset: of its first byte from the texture's.
// (scene/reader.cpp: one copy, for the boards' flash.)
TextureTexels texture_level_texels(const TextureTexels& t, uint32_t level, uint32_t* offset);

}  // namespace ml

// scenec: the host-side scene compiler. glTF 2.0 (.gltf/.glb) and procedural scenes become scene
// blobs (format: src/scene/blob_format.h, docs/scene-blob.md) through one path:
//
//   glTF file ──import──┐
//   procedural scene ───┴─► SceneMesh (world space, source units) ──compile_mesh──► Blob
//                                                   (normalize, quantize, BSP, write, CRC)
//
// Host only: C++17, exceptions, float and the standard library are fine here. Nothing throws out of
// this API: every failure is a CompileResult with ok == false and a one-line error.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/blob_format.h"
#include "scene/scene.h"

namespace ml {

// ---- blob container --------------------------------------------------------------------------------

// Bytes of a scene blob in 8-byte-aligned storage (read_scene requires the alignment).
struct Blob {
  std::vector<uint64_t> words;
  size_t size = 0;   // bytes

  const void* data() const { return words.data(); }
  void* data() { return words.data(); }
  const uint8_t* bytes() const { return reinterpret_cast<const uint8_t*>(words.data()); }
  uint8_t* bytes() { return reinterpret_cast<uint8_t*>(words.data()); }
  // Zero-filled storage for n bytes.
  void resize(size_t n) {
    words.assign((n + 7) / 8, 0);
    size = n;
  }
  void assign(const void* src, size_t n);
};

// Reads a whole regular file of at most max_bytes into *out (devices, pipes and directories are
// refused before any byte is read; the limits are in tools/scenec/limits.h). On failure returns false
// with a one-line *error.
bool read_input_file(const std::string& path, uint64_t max_bytes, std::vector<uint8_t>* out, std::string* error);
// Reads a whole .mls file (read_input_file with kMaxBlobFileBytes) into *out. On failure returns false with a one-line *error.
bool load_blob_file(const std::string& path, Blob* out, std::string* error);
// Writes blob.size bytes to path (replacing it). On failure returns false with a one-line *error.
bool save_blob_file(const std::string& path, const Blob& blob, std::string* error);

// ---- decoded tables -> blob ---------------------------------------------------------------------------

// A scene's tables in the decoded shapes of scene/scene.h, as the compiler (and tests) build them.
struct SceneTables {
  SceneInfo info{};                 // flags are set by pack_scene
  std::vector<Material> materials;
  std::vector<Batch> batches;
  std::vector<Vertex> vertices;
  std::vector<Triangle> triangles;
  std::vector<Node> nodes;
  std::vector<BspNode> bsp_nodes;   // breadth-first; bounds tight or wider (pack_scene widens them to cells)
  std::vector<BspPiece> bsp_pieces;
  std::vector<TextureRef> textures;
  std::vector<TextureTexels> texture_texels;  // empty, or one per texture
  std::vector<uint8_t> texels;                // their bytes (a multiple of 8)
};

// Writes the packed blob (blob_format.h): 16-bit indices when every count fits, planes rounded to
// Q1.14 normals and Q12 offsets, subtree boxes widened to whole grid cells, UVs only when some uv is
// not zero, the CRC. It does not validate: read_scene judges the result. False with a one-line
// *error only when something cannot be represented (a plane offset beyond int32).
bool pack_scene(const SceneTables& tables, Blob* out, std::string* error);

// ---- the in-memory scene (input of compile_mesh) ------------------------------------------------------

// Positions in source units (glTF metres, or whatever a procedural scene uses), already in world
// space: node transforms are applied by whoever fills the mesh.
struct MeshVertex {
  double position[3] = {0, 0, 0};
  double normal[3] = {0, 0, 0};   // unit length, or all zero when the mesh has no normals
  double uv[2] = {0, 0};          // TEXCOORD_0
};

// One glTF primitive under one node: becomes one Batch. Triangles index `vertices`, counter-clockwise
// = front. Triangle ids follow node order, then primitive order, then triangle order.
struct MeshPrimitive {
  uint32_t material = 0;
  std::vector<MeshVertex> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
};

struct MeshNode {
  uint32_t parent = kNone;        // index of an earlier node, or kNone
  std::string name;
  std::vector<MeshPrimitive> primitives;
};

struct MeshMaterial {
  double base_color[4] = {0.8, 0.8, 0.8, 1.0};   // linear 0..1
  uint32_t texture = kNone;                       // index into SceneMesh::texture_images
  bool double_sided = false;
  AlphaMode alpha_mode = AlphaMode::Opaque;
  double alpha_cutoff = 0.5;
};

// A suggested view, e.g. for a procedural scene (source units in SceneMesh, world units in a result).
struct CameraHint {
  bool valid = false;
  double eye[3] = {0, 0, 0};
  double target[3] = {0, 0, 0};
  double up[3] = {0, 1, 0};
};

// A decoded image, RGBA8 rows top first; empty (0 x 0) when it was not or could not be decoded.
struct MeshImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
};

// A glTF texture's sampler.
struct MeshSampler {
  TextureWrap wrap_s = TextureWrap::Repeat, wrap_t = TextureWrap::Repeat;
  TextureFilter filter = TextureFilter::Bilinear;
  bool mipmaps = false;  // glTF minFilter *_MIPMAP_*: the model asks for mip levels
};

struct SceneMesh {
  std::vector<MeshMaterial> materials;
  std::vector<uint32_t> texture_images;   // TextureRef::image per texture (glTF image index)
  std::vector<MeshSampler> texture_samplers;  // per texture (missing entries: the default sampler)
  std::vector<MeshImage> images;          // by image index (missing or empty: the texture has no texels)
  std::vector<MeshNode> nodes;            // depth-first order (a parent before its children)
  CameraHint camera;                      // optional, source units
};

// ---- compiling -------------------------------------------------------------------------------------

// How textures are stored (tools/scenec/textures.cpp, docs/textures.md).
enum class TextureFormatChoice : uint8_t {
  Auto,      // Grey4 for grey images of at most 16 levels, Palette8 for at most 256 colours, else RGB565
  Rgb565,
  Palette8,  // median-cut to at most 256 colours
  Grey4,     // luma, 16 levels (grey panels)
  None,      // no texels: every material in its base colour (for a build without textures, ML_TEXTURES=0)
};

// Which filter textures are sampled with (docs/textures.md, Sampler): what the model's sampler asks, or
// one filter for every texture (nearest is the cheaper on a board: one texel a sample instead of four).
enum class TextureFilterChoice : uint8_t {
  Model,     // the glTF sampler's: NEAREST magnification gives nearest, anything else bilinear
  Nearest,
  Bilinear,
};

// Which textures get mip levels (docs/textures.md).
enum class TextureMipChoice : uint8_t {
  Auto,  // those whose glTF sampler asks for them (minFilter *_MIPMAP_*)
  On,    // all
  Off,   // none
};

struct CompileOptions {
  bool build_bsp = true;
  TextureFormatChoice texture_format = TextureFormatChoice::Auto;
  int texture_max_size = 256;         // longest texture side after resampling, a power of two <= 1024
  TextureMipChoice texture_mips = TextureMipChoice::Auto;
  TextureFilterChoice texture_filter = TextureFilterChoice::Model;
  // BSP plane choice (tools/scenec/bsp.cpp). Defaults measured on the procedural scenes and
  // 2CylinderEngine: lower split ratios cost depth and build time.
  uint32_t bsp_seed = 1;              // plane sampling is deterministic for a given seed
  int bsp_triangle_candidates = 16;   // triangle planes tried per node (more near the root)
  int bsp_axis_positions = 3;         // axis-aligned candidate positions per axis
  int bsp_axis_min_pieces = 32;       // axis-aligned candidates only for at least this many pieces
  int bsp_sample_size = 512;          // pieces each candidate is scored on
  int bsp_split_weight = 16;          // score = 4 * split_weight * splits + balance_weight * |front - back|
  int bsp_balance_weight = 2;
  int bsp_chain_pieces = 0;           // sets up to this size ignore balance (split-free chains)
  // Cells (bsp.cpp): sets of more than bsp_cell_pieces pieces take an axis plane across their box's
  // longest side when it cuts at most bsp_cell_split_permille of the sampled pieces.
  int bsp_cell_pieces = 32;
  int bsp_cell_split_permille = 10;
  // Two more trees, built with bsp_split_weight halved and four times the triangle candidates, and
  // with it doubled and twice the candidates; the tree with the fewest pieces is kept (bsp.cpp,
  // build_bsp).
  bool bsp_more_trees = true;
};

struct CompileReport {
  uint32_t triangles = 0;
  uint32_t vertices = 0;        // including the BSP's split vertices
  uint32_t nodes = 0;
  uint32_t materials = 0;
  uint32_t batches = 0;
  uint32_t textures = 0;
  uint32_t texture_bytes = 0;   // texels and palettes, all textures
  uint32_t bsp_nodes = 0;
  uint32_t bsp_pieces = 0;
  uint32_t bsp_depth = 0;
  uint32_t bsp_split_vertices = 0;
  uint32_t bsp_split_pieces = 0;  // pieces stored as parts of a split triangle (the rest are whole)
  double split_ratio = 0;       // bsp_pieces / triangles (0 without a BSP)
  double seconds = 0;           // wall time of the whole compile
  double bsp_seconds = 0;
  size_t blob_bytes = 0;
};

struct CompileResult {
  bool ok = false;
  std::string error;                  // one line when !ok
  Blob blob;
  std::vector<std::string> warnings;  // one line each
  CompileReport report;
  CameraHint camera;                  // world units; valid for procedural scenes
};

// glTF 2.0 (.gltf with external/embedded buffers, or .glb) -> blob. Uses the file's default scene
// (else scene 0, else every root node). Never throws, never crashes on malformed input.
CompileResult compile_gltf_file(const std::string& path, const CompileOptions& options = CompileOptions());

// glTF 2.0 -> SceneMesh only (no normalization). Returns false with a one-line *error.
bool import_gltf_file(const std::string& path, SceneMesh* mesh, std::vector<std::string>* warnings,
                      std::string* error);

// The same from bytes in memory (.glb when they start with "glTF", else .gltf). External files named
// by the glTF are read from base_dir; with an empty base_dir none is read (data: URIs still work).
bool import_gltf_memory(const unsigned char* bytes, size_t size, const std::string& base_dir, SceneMesh* mesh,
                        std::vector<std::string>* warnings, std::string* error);
// compile_gltf_file on bytes in memory, reading no external file.
CompileResult compile_gltf_memory(const unsigned char* bytes, size_t size,
                                  const CompileOptions& options = CompileOptions());

// The shared back end: validate, normalize (bbox centre -> origin, largest half-extent -> 2^16 world
// units), quantize each batch to int16 over its own box, build the BSP, write and checksum the blob.
CompileResult compile_mesh(const SceneMesh& mesh, const CompileOptions& options = CompileOptions());

// ---- textures (tools/scenec/textures.cpp) ------------------------------------------------------------

// One texture in its device format: TextureTexels (offset 0) and its bytes.
struct EncodedTexture {
  TextureTexels info{};
  std::vector<uint8_t> bytes;
};
// Resamples an RGBA8 image to power-of-two sides of at most options.texture_max_size and encodes it,
// with its mip levels down to 1 x 1 when options.texture_mips and the sampler ask for them. An empty
// image gives format None.
EncodedTexture encode_texture(const MeshImage& image, const MeshSampler& sampler, const CompileOptions& options);

// ---- procedural scenes -------------------------------------------------------------------------------

// The bundled scene (the CLI's default): a checkered ground with a cube, a smooth sphere, a torus and a
// pyramid; about two thousand triangles.
SceneMesh make_default_scene();
CompileResult build_default_scene(const CompileOptions& options = CompileOptions());

// Greene's densely occluded test: `layers` rows of rooms (walls with doorways, furniture-like boxes)
// one behind the other along -z; the camera hint looks down the rows so most triangles are hidden.
SceneMesh make_office_scene(int layers);
CompileResult build_office_scene(int layers = 8, const CompileOptions& options = CompileOptions());

// A smooth, finely tessellated torus knot with at least min_triangles triangles (scanline benchmark).
SceneMesh make_tessellated_scene(uint32_t min_triangles);

// Woo and Chall's Fig. 10 residency test: four textured quads, each a horizontal band of the view
// with its own texture (different sizes and formats), overlapping their neighbours by a few rows.
SceneMesh make_banded_scene();
CompileResult build_banded_scene(const CompileOptions& options = CompileOptions());
CompileResult build_tessellated_scene(uint32_t min_triangles = 100000,
                                      const CompileOptions& options = CompileOptions());

}  // namespace ml

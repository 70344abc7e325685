// The input limits of the host side (scene compiler and file loading), in one place. docs/cli.md
// lists them under "Input limits". Renderer limits (world range, screen size, BSP depth) stay with the
// core in src/. An input beyond any of these is rejected with a one-line error before the work or
// memory it would take is spent.
#pragma once
#include <cstddef>
#include <cstdint>

namespace ml {

// Files are read only when they are regular files (not devices, pipes or directories) and only up to
// these sizes; the size is checked before any byte is read.
constexpr uint64_t kMaxGltfFileBytes = (uint64_t(1) << 31) - 1;   // .gltf/.glb and external buffers
constexpr uint64_t kMaxBlobFileBytes = (uint64_t(1) << 32) - 1;   // .mls (offsets in the blob are 32-bit)

// JSON nesting (arrays and objects inside each other) of a .gltf file or a .glb's JSON chunk, checked
// on the raw bytes before the JSON parser runs (the parsers recurse once per level).
constexpr int kMaxJsonDepth = 64;
// JSON values of a .gltf file or a .glb's JSON chunk, counted on the raw bytes before parsing (each
// ',', ':' and '[' outside strings counts 1, each '{' counts kJsonObjectCost). The glTF parser spends
// up to about 3 KB on an empty object ("materials":[{},{},...]) and 200-400 bytes on a value or member
// in "extras", so this keeps its memory near 100 MB and its time near half a second whatever the file.
// Binary data (a .glb's BIN chunk, base64 buffers, which are strings) does not count. 2CylinderEngine
// has about 10,000; a scene of 10,000 nodes with names and matrices about 400,000.
constexpr uint64_t kMaxJsonValues = uint64_t(1) << 19;
constexpr uint64_t kJsonObjectCost = 16;

// Elements of one accessor. An accessor's count × stride must also fit its buffer view, checked
// before anything is allocated.
constexpr size_t kMaxAccessorCount = size_t(1) << 28;
// Elements of accessors without a buffer view (all zero but for sparse values): at most this many in
// one file, since nothing in the file backs them.
constexpr size_t kMaxUnbackedElements = size_t(1) << 20;
// Node instances reached from the scene's roots (a node reached twice counts twice).
constexpr size_t kMaxNodeInstances = size_t(1) << 20;
// Triangles over the whole scene, after strips and fans are expanded, and vertices over the whole
// scene (each node instance counts its mesh again). Both totals, and the node instances, are
// computed from accessor counts before any accessor is read.
constexpr size_t kMaxTriangles = size_t(1) << 27;
constexpr size_t kMaxVertices = size_t(1) << 27;
// The images of one file are decoded only up to this many pixels in all (each image's size is read
// from its header first); an image beyond the budget is refused with a warning and its textures draw
// the material colour. 2^24 pixels decode to 64 MiB of RGBA.
constexpr uint64_t kMaxImagePixels = uint64_t(1) << 24;

}  // namespace ml

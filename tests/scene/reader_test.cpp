// The blob reader: round trips, CRC, truncation, and one hand-corrupted blob (CRC recomputed) per
// validation rule, each rejected with the message naming that rule.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "tests/scene/scene_test_util.h"

using namespace ml;
using scenetest::cached;
using scenetest::section;

namespace {

// Two boxes through each other (so the BSP splits) with a textured material: every section present.
const Blob& small_blob() {
  static Blob blob = [] {
    const SceneMesh mesh = scenetest::crossing_boxes_mesh();
    CompileResult r = compile_mesh(mesh);
    EXPECT_TRUE(r.ok) << r.error;
    EXPECT_GT(r.report.bsp_pieces, r.report.triangles);   // the boxes cross: something was split
    return r.blob;
  }();
  return blob;
}

std::string reject_message(Blob blob) {
  Scene scene;
  const Status st = read_scene(blob.data(), blob.size, &scene);
  if (st.ok()) return "(accepted)";
  EXPECT_EQ(st.code, StatusCode::BadScene);
  EXPECT_EQ(scene.base, nullptr);        // *out left empty
  EXPECT_EQ(scene.triangle_count, 0u);
  return st.message;
}

// Applies `edit` to a copy of the small blob, recomputes the CRC and returns the reader's message.
std::string corrupt(const std::function<void(Blob*)>& edit, bool fix = true) {
  Blob blob = small_blob();
  edit(&blob);
  if (fix) scenetest::fix_crc(&blob);
  return reject_message(blob);
}

}  // namespace

TEST(SceneReader, Crc32MatchesZlib) {
  EXPECT_EQ(crc32("123456789", 9), 0xCBF43926u);
  EXPECT_EQ(crc32("", 0), 0u);
  // Running CRC: crc(ab) == crc(b, crc(a)).
  const char* text = "The quick brown fox jumps over the lazy dog";
  EXPECT_EQ(crc32(text, 43), 0x414FA339u);
  EXPECT_EQ(crc32(text + 10, 33, crc32(text, 10)), 0x414FA339u);
}

TEST(SceneReader, SmallBlobHasEverySection) {
  Blob blob = small_blob();
  Scene s;
  const Status st = scenetest::read(blob, &s);
  ASSERT_TRUE(st.ok()) << st.message;
  EXPECT_EQ(s.triangle_count, 24u);
  EXPECT_EQ(s.material_count, 2u);
  EXPECT_EQ(s.texture_count, 1u);
  EXPECT_EQ(s.texture_texels_count, 1u);
  EXPECT_EQ(s.texture_texels[0].format, uint8_t(TexelFormat::Palette8));
  EXPECT_EQ(s.texel_bytes, (4u * 4u + 2u * s.texture_texels[0].palette_size + 7u) & ~7u);  // padded to 8
  EXPECT_EQ(s.node_count, 3u);
  EXPECT_GT(s.bsp_node_count, 0u);
  EXPECT_GT(s.bsp_piece_count, 24u);
  EXPECT_EQ(s.materials[0].texture, 0u);
  EXPECT_EQ(s.materials[1].double_sided, 1);
  EXPECT_EQ(s.materials[1].alpha_mode, uint8_t(AlphaMode::Mask));
  EXPECT_EQ(s.base, blob.bytes());   // read in place, never copied
}

TEST(SceneReader, ProceduralScenesRoundTrip) {
  for (const char* name : {"default", "office8", "tessellated"}) {
    const CompileResult& r = cached(name);
    ASSERT_TRUE(r.ok) << name << ": " << r.error;
    Scene s;
    const Status st = scenetest::read(r.blob, &s);
    ASSERT_TRUE(st.ok()) << name << ": " << st.message;
    EXPECT_EQ(s.triangle_count, r.report.triangles) << name;
    EXPECT_EQ(s.vertex_count, r.report.vertices) << name;
    EXPECT_EQ(s.node_count, r.report.nodes) << name;
    EXPECT_EQ(s.material_count, r.report.materials) << name;
    EXPECT_EQ(s.bsp_node_count, r.report.bsp_nodes) << name;
    EXPECT_EQ(s.bsp_piece_count, r.report.bsp_pieces) << name;
    EXPECT_EQ(s.info->bsp_depth, r.report.bsp_depth) << name;
    EXPECT_GT(s.info->sphere_radius, 0) << name;
    // Normalized: the scene fits in +-2^16 (plus quantization slack) and spans most of it.
    int32_t extent = 0;
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(s.info->bounds_min[a], -(1 << 16) - 8) << name;
      EXPECT_LE(s.info->bounds_max[a], (1 << 16) + 8) << name;
      extent = std::max(extent, s.info->bounds_max[a] - s.info->bounds_min[a]);
    }
    EXPECT_GT(extent, (1 << 17) - 64) << name;
    // Every vertex of every triangle is inside the bounds and the sphere.
    for (uint32_t t = 0; t < s.triangle_count; ++t) {
      Vec3i w[3];
      triangle_world(s, t, w);
      for (const Vec3i& p : w) {
        ASSERT_GE(p.x, s.info->bounds_min[0]);
        ASSERT_LE(p.x, s.info->bounds_max[0]);
        ASSERT_GE(p.y, s.info->bounds_min[1]);
        ASSERT_LE(p.z, s.info->bounds_max[2]);
        const double dx = p.x - s.info->sphere_center[0], dy = p.y - s.info->sphere_center[1],
                     dz = p.z - s.info->sphere_center[2];
        ASSERT_LE(std::sqrt(dx * dx + dy * dy + dz * dz), double(s.info->sphere_radius));
      }
    }
    // Saved and loaded through a file, byte for byte.
    const std::string path = scenetest::temp_dir() + "/scene.mls";
    std::string error;
    ASSERT_TRUE(save_blob_file(path, r.blob, &error)) << error;
    Blob loaded;
    ASSERT_TRUE(load_blob_file(path, &loaded, &error)) << error;
    ASSERT_EQ(loaded.size, r.blob.size);
    EXPECT_EQ(std::memcmp(loaded.data(), r.blob.data(), r.blob.size), 0);
    EXPECT_TRUE(scenetest::read(loaded).ok());
    std::remove(path.c_str());
  }
}

TEST(SceneReader, LoadBlobFileMissingGivesOneLineError) {
  Blob blob;
  std::string error;
  EXPECT_FALSE(load_blob_file("/nonexistent/dir/scene.mls", &blob, &error));
  EXPECT_NE(error.find("cannot open"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

TEST(SceneReader, EveryFlippedByteIsRejected) {
  const Blob& good = small_blob();
  ASSERT_TRUE(scenetest::read(good).ok());
  int crc_rejections = 0;
  for (size_t pos = 0; pos < good.size; ++pos) {
    for (uint8_t bit : {uint8_t(0x01), uint8_t(0x80)}) {
      Blob blob = good;
      blob.bytes()[pos] ^= bit;
      const std::string msg = reject_message(blob);
      ASSERT_NE(msg, "(accepted)") << "flip at byte " << pos;
      if (pos >= 16) {
        EXPECT_EQ(msg, "crc mismatch") << "flip at byte " << pos;
        ++crc_rejections;
      }
    }
  }
  EXPECT_GT(crc_rejections, 1000);
}

TEST(SceneReader, FlippedBytesInALargeBlobAreRejected) {
  const CompileResult& r = cached("default");
  ASSERT_TRUE(r.ok);
  uint64_t state = 12345;
  for (int i = 0; i < 200; ++i) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const size_t pos = size_t((state >> 33) % r.blob.size);
    Blob blob = r.blob;
    blob.bytes()[pos] ^= uint8_t(1u << ((state >> 20) & 7));
    EXPECT_NE(reject_message(blob), "(accepted)") << "flip at byte " << pos;
  }
}

TEST(SceneReader, TruncatedBlobsAreRejected) {
  const Blob& good = small_blob();
  for (size_t n = 0; n < good.size; n += (n < 64 ? 1 : 37)) {
    Blob blob;
    blob.assign(good.data(), n);
    EXPECT_NE(reject_message(blob), "(accepted)") << "truncated to " << n;
  }
  // Truncated with the header patched to match (CRC recomputed): the sections no longer fit.
  Blob blob;
  blob.assign(good.data(), good.size - 8);
  scenetest::header(&blob)->total_size = uint32_t(blob.size);
  scenetest::fix_crc(&blob);
  EXPECT_EQ(reject_message(blob), "section outside blob");
}

TEST(SceneReader, HeaderChecks) {
  EXPECT_EQ(corrupt([](Blob* b) { b->size = 10; }, false), "blob too small for header");
  Scene s;
  EXPECT_EQ(std::string(read_scene(nullptr, 100, &s).message), "blob is null");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::header(b)->magic ^= 1; }, false), "bad magic");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::header(b)->version = 2; }, false), "unsupported blob version");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::header(b)->header_bytes = 32; }, false), "bad header size");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::header(b)->total_size += 8; }, false),
            "total size does not match blob size");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::header(b)->crc32 ^= 1; }, false), "crc mismatch");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::header(b)->reserved = 1; }), "header reserved field not zero");
}

TEST(SceneReader, MisalignedBaseIsRejected) {
  const Blob& good = small_blob();
  std::vector<uint64_t> words(good.words.size() + 1);
  uint8_t* shifted = reinterpret_cast<uint8_t*>(words.data()) + 4;
  std::memcpy(shifted, good.data(), good.size);
  Scene s;
  const Status st = read_scene(shifted, good.size, &s);
  EXPECT_EQ(std::string(st.message), "blob base not 8-byte aligned");
}

TEST(SceneReader, SectionTableChecks) {
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::header(b)->section_count = 1000; }), "section table outside blob");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::find_section(b, SectionType::Nodes)->type = 42; }),
            "unknown section type");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::find_section(b, SectionType::Nodes)->type = 0; }),
            "unknown section type");
  EXPECT_EQ(corrupt([](Blob* b) {
              scenetest::find_section(b, SectionType::Nodes)->type = uint32_t(SectionType::Materials);
            }),
            "duplicate section");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::find_section(b, SectionType::Vertices)->offset += 4; }),
            "section not 8-byte aligned");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::find_section(b, SectionType::Vertices)->offset = uint32_t(b->size); }),
            "section outside blob");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::find_section(b, SectionType::Vertices)->offset = 0xFFFFFFF8u; }),
            "section outside blob");
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::find_section(b, SectionType::Info)->offset = 0; }),
            "section outside blob");   // over the header and table
  EXPECT_EQ(corrupt([](Blob* b) { scenetest::find_section(b, SectionType::Triangles)->count += 1; }),
            "section size does not match count");
  EXPECT_EQ(corrupt([](Blob* b) {
              SectionEntry* m = scenetest::find_section(b, SectionType::Materials);
              m->offset = scenetest::find_section(b, SectionType::Vertices)->offset + 8;
            }),
            "sections overlap");
  EXPECT_EQ(corrupt([](Blob* b) {
              SectionEntry* tri = scenetest::find_section(b, SectionType::Triangles);
              SectionEntry* last = reinterpret_cast<SectionEntry*>(b->bytes() + sizeof(BlobHeader)) +
                                   (scenetest::header(b)->section_count - 1);
              std::swap(*tri, *last);
              scenetest::header(b)->section_count -= 1;
            }),
            "missing triangles section");
  EXPECT_EQ(corrupt([](Blob* b) {
              SectionEntry* info = scenetest::find_section(b, SectionType::Info);
              info->count = 0;
              info->size = 0;
            }),
            "info section must hold one entry");
}

TEST(SceneReader, InfoChecks) {
  EXPECT_EQ(corrupt([](Blob* b) { section<SceneInfo>(b, SectionType::Info)->sphere_radius = 0; }),
            "sphere radius not positive");
  EXPECT_EQ(corrupt([](Blob* b) { section<SceneInfo>(b, SectionType::Info)->sphere_radius = 1 << 21; }),
            "sphere radius out of range");
  EXPECT_EQ(corrupt([](Blob* b) {
              SceneInfo* i = section<SceneInfo>(b, SectionType::Info);
              i->bounds_min[1] = i->bounds_max[1] + 1;
            }),
            "scene bounds min above max");
  EXPECT_EQ(corrupt([](Blob* b) { section<SceneInfo>(b, SectionType::Info)->bounds_max[2] = 1 << 20; }),
            "scene bounds out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<SceneInfo>(b, SectionType::Info)->sphere_center[0] = -(1 << 20); }),
            "bounding sphere centre out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<SceneInfo>(b, SectionType::Info)->bsp_depth = kMaxBspDepth + 1; }),
            "bsp depth above limit");
}

TEST(SceneReader, MaterialNodeBatchChecks) {
  EXPECT_EQ(corrupt([](Blob* b) { section<Material>(b, SectionType::Materials)[0].texture = 1; }),
            "material texture index out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Material>(b, SectionType::Materials)[1].double_sided = 2; }),
            "material double_sided not 0 or 1");
  EXPECT_EQ(corrupt([](Blob* b) { section<Material>(b, SectionType::Materials)[1].alpha_mode = 3; }),
            "material alpha mode invalid");
  EXPECT_EQ(corrupt([](Blob* b) { section<Node>(b, SectionType::Nodes)[1].parent = 1; }),
            "node parent not before node");
  EXPECT_EQ(corrupt([](Blob* b) { section<Node>(b, SectionType::Nodes)[2].batch_count = 5; }),
            "node batch range out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Node>(b, SectionType::Nodes)[2].first_batch = 0xFFFFFFFFu; }),
            "node batch range out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Batch>(b, SectionType::Batches)[0].material = 2; }),
            "batch material index out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Batch>(b, SectionType::Batches)[0].node = 3; }),
            "batch node index out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Batch>(b, SectionType::Batches)[0].node = 2; }),
            "batch outside its node's batch range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Batch>(b, SectionType::Batches)[1].vertex_count += 1000000; }),
            "batch vertex range out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Batch>(b, SectionType::Batches)[1].first_triangle = 0xFFFFFFF0u; }),
            "batch triangle range out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Batch>(b, SectionType::Batches)[0].scale[1] = 0; }),
            "batch scale not positive");
  EXPECT_EQ(corrupt([](Blob* b) { section<Batch>(b, SectionType::Batches)[0].scale[2] = -5; }),
            "batch scale not positive");
  EXPECT_EQ(corrupt([](Blob* b) { section<Batch>(b, SectionType::Batches)[0].offset[0] = 1 << 18; }),
            "batch positions out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Batch>(b, SectionType::Batches)[0].scale[0] = 0x7FFFFFFF; }),
            "batch positions out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Batch>(b, SectionType::Batches)[0].offset[2] = INT32_MIN; }),
            "batch positions out of range");
}

TEST(SceneReader, VertexAndTriangleChecks) {
  EXPECT_EQ(corrupt([](Blob* b) {
              Vertex* v = section<Vertex>(b, SectionType::Vertices);
              v[3].normal[0] = 30000;
              v[3].normal[1] = v[3].normal[2] = 0;
            }),
            "vertex normal not unit length");
  EXPECT_EQ(corrupt([](Blob* b) { section<Triangle>(b, SectionType::Triangles)[5].batch = 2; }),
            "triangle batch index out of range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Triangle>(b, SectionType::Triangles)[5].batch = 1; }),
            "triangle outside its batch's range");
  EXPECT_EQ(corrupt([](Blob* b) { section<Triangle>(b, SectionType::Triangles)[5].v[2] = 30; }),
            "triangle vertex index out of range");   // a vertex of the other batch
  EXPECT_EQ(corrupt([](Blob* b) { section<Triangle>(b, SectionType::Triangles)[20].v[0] = 0xFFFFFFFFu; }),
            "triangle vertex index out of range");
}

TEST(SceneReader, BspChecks) {
  Blob good = small_blob();
  Scene s;
  ASSERT_TRUE(scenetest::read(good, &s).ok());
  ASSERT_GE(s.bsp_node_count, 3u);
  // A node with two children, and the last node's parent slot.
  uint32_t two = kNone, parent_of_last = kNone;
  bool last_is_front = false;
  for (uint32_t i = 0; i < s.bsp_node_count; ++i) {
    if (two == kNone && s.bsp_nodes[i].front != kNone && s.bsp_nodes[i].back != kNone) two = i;
    if (s.bsp_nodes[i].front == s.bsp_node_count - 1) { parent_of_last = i; last_is_front = true; }
    if (s.bsp_nodes[i].back == s.bsp_node_count - 1) parent_of_last = i;
  }
  ASSERT_NE(parent_of_last, kNone);
  auto nodes = [](Blob* b) { return section<BspNode>(b, SectionType::BspNodes); };
  const uint32_t count = s.bsp_node_count;
  EXPECT_EQ(corrupt([&](Blob* b) { (last_is_front ? nodes(b)[parent_of_last].front : nodes(b)[parent_of_last].back) = count; }),
            "bsp child index out of range");
  EXPECT_EQ(corrupt([&](Blob* b) { (last_is_front ? nodes(b)[parent_of_last].front : nodes(b)[parent_of_last].back) = 0; }),
            "bsp child is the root");
  // A cycle: the last node points back at node 1.
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[count - 1].front = 1; }), "bsp node referenced twice");
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[count - 1].back = count - 1; }), "bsp node referenced twice");
  EXPECT_EQ(corrupt([&](Blob* b) { (last_is_front ? nodes(b)[parent_of_last].front : nodes(b)[parent_of_last].back) = kNone; }),
            "bsp node unreachable");
  if (two != kNone) {
    EXPECT_EQ(corrupt([&](Blob* b) { std::swap(nodes(b)[two].front, nodes(b)[two].back); }),
              "bsp nodes not in breadth-first order");
  }
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[0].normal[0] = kUnitOne + 1; }), "bsp normal out of range");
  EXPECT_EQ(corrupt([&](Blob* b) {
              nodes(b)[0].normal[0] = kUnitOne / 2;
              nodes(b)[0].normal[1] = 0;
              nodes(b)[0].normal[2] = 0;
            }),
            "bsp normal not unit length");
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[0].d = int64_t(1) << 51; }), "bsp plane offset out of range");
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[1].first_piece += 1; }), "bsp piece ranges not contiguous");
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[count - 1].piece_count += 1; }), "bsp piece range out of range");
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[count - 1].piece_count -= 1; }), "bsp pieces not covered by nodes");
  EXPECT_EQ(corrupt([&](Blob* b) { section<SceneInfo>(b, SectionType::Info)->bsp_depth -= 1; }),
            "bsp deeper than info bsp_depth");
  EXPECT_EQ(corrupt([&](Blob* b) { section<BspPiece>(b, SectionType::BspPieces)[3].v[1] = 1u << 30; }),
            "bsp piece vertex index out of range");
  EXPECT_EQ(corrupt([&](Blob* b) { section<BspPiece>(b, SectionType::BspPieces)[3].triangle = 24; }),
            "bsp piece triangle out of range");
  EXPECT_EQ(corrupt([&](Blob* b) {
              SectionEntry* e = scenetest::find_section(b, SectionType::BspNodes);
              e->count = 0;
              e->size = 0;
            }),
            "bsp pieces without bsp nodes");
  // A larger info.bsp_depth than needed is fine (renderers size stacks by it).
  Blob deeper = good;
  section<SceneInfo>(&deeper, SectionType::Info)->bsp_depth += 3;
  scenetest::fix_crc(&deeper);
  EXPECT_TRUE(scenetest::read(deeper).ok());
}

TEST(SceneReader, BspSubtreeChecks) {
  Blob good = small_blob();
  Scene s;
  ASSERT_TRUE(scenetest::read(good, &s).ok());
  ASSERT_GE(s.bsp_node_count, 3u);
  auto nodes = [](Blob* b) { return section<BspNode>(b, SectionType::BspNodes); };
  // A leaf with pieces whose box has extent along some axis, a child and its parent.
  uint32_t wide = kNone, child = kNone, parent = kNone;
  int axis = 0;
  for (uint32_t i = 0; i < s.bsp_node_count; ++i) {
    const BspNode& n = s.bsp_nodes[i];
    for (int a = 0; a < 3 && wide == kNone; ++a)
      if (n.piece_count > 0 && n.front == kNone && n.back == kNone && n.bounds_min[a] < n.bounds_max[a]) {
        wide = i;
        axis = a;
      }
    if (child == kNone && n.front != kNone) {
      parent = i;
      child = n.front;
    }
  }
  ASSERT_NE(wide, kNone);
  ASSERT_NE(child, kNone);
  const uint32_t last = s.bsp_node_count - 1;
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[last].bounds_min[1] = nodes(b)[last].bounds_max[1] + 1; }),
            "bsp bounds min above max");
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[0].bounds_min[2] = -(1 << 18); }), "bsp bounds out of range");
  // Shrinking a node's box leaves its parent's check intact and strands a vertex at the old face.
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[wide].bounds_max[axis] -= 1; }),
            "bsp piece vertex outside node bounds");
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[child].bounds_max[0] = nodes(b)[parent].bounds_max[0] + 1; }),
            "bsp child bounds outside parent bounds");
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[0].subtree_pieces += 1; }), "bsp subtree piece count wrong");
  EXPECT_EQ(corrupt([&](Blob* b) { nodes(b)[last].subtree_pieces += 1; }), "bsp subtree piece count wrong");
}

TEST(SceneReader, NoBspIsValid) {
  SceneMesh mesh = make_default_scene();
  CompileOptions options;
  options.build_bsp = false;
  CompileResult r = compile_mesh(mesh, options);
  ASSERT_TRUE(r.ok) << r.error;
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  EXPECT_EQ(s.bsp_node_count, 0u);
  EXPECT_EQ(s.bsp_piece_count, 0u);
  EXPECT_EQ(s.info->bsp_depth, 0u);
  EXPECT_EQ(r.report.split_ratio, 0.0);
}

TEST(SceneReader, VertexWorldMatchesBatchFormula) {
  const CompileResult& r = cached("default");
  ASSERT_TRUE(r.ok);
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  for (uint32_t bi = 0; bi < s.batch_count; ++bi) {
    const Batch& b = s.batches[bi];
    for (uint32_t v = b.first_vertex; v < b.first_vertex + b.vertex_count; v += 7) {
      const Vec3i w = vertex_world(s, bi, v);
      const int16_t* q = s.vertices[v].position;
      EXPECT_EQ(w.x, b.offset[0] + int32_t(std::floor(double(q[0]) * b.scale[0] / 65536.0)));
      EXPECT_EQ(w.y, b.offset[1] + int32_t(std::floor(double(q[1]) * b.scale[1] / 65536.0)));
      EXPECT_EQ(w.z, b.offset[2] + int32_t(std::floor(double(q[2]) * b.scale[2] / 65536.0)));
    }
  }
}

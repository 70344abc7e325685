// The glTF front end: every assimp glTF2 model (compiles and reads back, or a one-line error),
// 2CylinderEngine's triangle count from an independent count, bad inputs, and a hand-written glTF that
// pins triangle ids, strip/fan triangulation, TRS and matrix transforms, mirrored winding, normals,
// texture coordinates and materials.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "platform/host/png_io.h"
#include "tests/scene/scene_test_util.h"

using namespace ml;
using scenetest::base64;

namespace {

// TEXCOORD_0 of a vertex through the scene's one UV accessor.
std::array<int32_t, 2> uv_of(const Scene& s, uint32_t v) {
  std::array<int32_t, 2> uv{};
  vertex_uv(s, v, uv.data());
  return uv;
}


float bits_to_float(uint32_t u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

std::string compile_error(const std::string& path) {
  const CompileResult r = compile_gltf_file(path);
  EXPECT_FALSE(r.ok) << path;
  EXPECT_FALSE(r.error.empty()) << path;
  EXPECT_EQ(r.error.find('\n'), std::string::npos) << path << ": " << r.error;
  return r.error;
}

// ---- the hand-written glTF -------------------------------------------------------------------------

using P3 = std::array<double, 3>;

struct Written {
  std::string path;
  std::vector<std::array<P3, 3>> expected;   // glTF world positions per triangle id
};

class BufferBuilder {
 public:
  // Appends floats; returns the bufferView index.
  int floats(const std::vector<float>& v) { return add(v.data(), v.size() * 4); }
  int shorts(const std::vector<uint16_t>& v) { return add(v.data(), v.size() * 2); }
  std::string views_json() const { return views_; }
  std::vector<uint8_t> bytes;

 private:
  int add(const void* p, size_t n) {
    while (bytes.size() % 4) bytes.push_back(0);
    const size_t off = bytes.size();
    bytes.insert(bytes.end(), static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
    if (!views_.empty()) views_ += ",";
    views_ += "{\"buffer\":0,\"byteOffset\":" + std::to_string(off) + ",\"byteLength\":" + std::to_string(n) + "}";
    return count_++;
  }
  std::string views_;
  int count_ = 0;
};

// scene_index selects the "scene" property (0: the nested hierarchy, 1: a single node).
Written write_test_gltf(const std::string& dir, int scene_index) {
  BufferBuilder b;
  const std::vector<P3> quad = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const std::vector<P3> strip = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {2, 0, 0}};
  const std::vector<uint16_t> strip_idx = {4, 3, 2, 1, 0, 0};   // 5 used, padded
  const std::vector<P3> fan = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 1, 0}};
  const std::vector<P3> tri = {{0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
  const std::vector<P3> slanted = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  auto flat = [](const std::vector<P3>& v) {
    std::vector<float> f;
    for (const P3& p : v) f.insert(f.end(), {float(p[0]), float(p[1]), float(p[2])});
    return f;
  };
  const float s = float(std::sqrt(0.5));
  const int v_quad = b.floats(flat(quad));
  const int v_quad_n = b.floats(flat(std::vector<P3>(6, P3{0, 0, 1})));
  const int v_quad_uv = b.floats({0, 0, 1, 0, 0, 1, 1, 0, 1, 1, 0.5f, 2.25f});
  const int v_strip = b.floats(flat(strip));
  const int v_strip_i = b.shorts(strip_idx);
  const int v_fan = b.floats(flat(fan));
  const int v_tri = b.floats(flat(tri));
  const int v_slant = b.floats(flat(slanted));
  const int v_slant_n = b.floats({s, s, 0, s, s, 0, s, s, 0});
  auto acc = [](int view, int count, const char* type, int ctype = 5126) {
    return "{\"bufferView\":" + std::to_string(view) + ",\"componentType\":" + std::to_string(ctype) +
           ",\"count\":" + std::to_string(count) + ",\"type\":\"" + type + "\"}";
  };
  const std::string accessors = "[" + acc(v_quad, 6, "VEC3") + "," + acc(v_quad_n, 6, "VEC3") + "," +
                                acc(v_quad_uv, 6, "VEC2") + "," + acc(v_strip, 5, "VEC3") + "," +
                                acc(v_strip_i, 5, "SCALAR", 5123) + "," + acc(v_fan, 5, "VEC3") + "," +
                                acc(v_tri, 3, "VEC3") + "," + acc(v_slant, 3, "VEC3") + "," +
                                acc(v_slant_n, 3, "VEC3") + "]";
  // accessors: 0 quad pos, 1 quad normal, 2 quad uv, 3 strip pos, 4 strip idx, 5 fan pos, 6 tri pos,
  //            7 slanted pos, 8 slanted normal
  const std::string json = std::string("{\"asset\":{\"version\":\"2.0\"},") +
      "\"scene\":" + std::to_string(scene_index) + "," +
      "\"scenes\":[{\"nodes\":[0]},{\"nodes\":[6]}]," +
      "\"nodes\":[" +
      "{\"name\":\"root\",\"translation\":[10,0,0],\"mesh\":0,\"children\":[1,2,3,5]}," +
      "{\"name\":\"turned\",\"rotation\":[0,0,0.70710678,0.70710678],\"scale\":[2,2,2],\"mesh\":1,\"children\":[4]}," +
      "{\"name\":\"mirror_matrix\",\"matrix\":[-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,5,0,1],\"mesh\":2}," +
      "{\"name\":\"mirror_trs\",\"translation\":[0,5,0],\"scale\":[-1,1,1],\"mesh\":2}," +
      "{\"name\":\"inherits\",\"mesh\":0}," +
      "{\"name\":\"stretched\",\"scale\":[2,1,1],\"mesh\":3}," +
      "{\"name\":\"other_scene\",\"mesh\":0}" +
      "]," +
      "\"meshes\":[" +
      "{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"material\":0}]}," +
      "{\"primitives\":[{\"attributes\":{\"POSITION\":3},\"indices\":4,\"mode\":5}]}," +
      "{\"primitives\":[{\"attributes\":{\"POSITION\":5},\"mode\":6},{\"attributes\":{\"POSITION\":5},\"mode\":0}," +
      "{\"attributes\":{\"POSITION\":6}}]}," +
      "{\"primitives\":[{\"attributes\":{\"POSITION\":7,\"NORMAL\":8}}]}" +
      "]," +
      "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1]},\"doubleSided\":true," +
      "\"alphaMode\":\"MASK\",\"alphaCutoff\":0.25}]," +
      "\"accessors\":" + accessors + "," +
      "\"bufferViews\":[" + b.views_json() + "]," +
      "\"buffers\":[{\"byteLength\":" + std::to_string(b.bytes.size()) +
      ",\"uri\":\"data:application/octet-stream;base64," + base64(b.bytes) + "\"}]}";
  Written w;
  w.path = dir + "/ids" + std::to_string(scene_index) + ".gltf";
  scenetest::write_file(w.path, json);

  // Expected world positions, transforms written out by hand.
  auto f0 = [](P3 p) { return P3{p[0] + 10, p[1], p[2]}; };
  auto f1 = [](P3 p) { return P3{10 - 2 * p[1], 2 * p[0], 2 * p[2]}; };   // T(10) Rz(90) S(2)
  auto f2 = [](P3 p) { return P3{10 - p[0], p[1] + 5, p[2]}; };           // T(10) T(0,5,0) S(-1,1,1)
  auto f5 = [](P3 p) { return P3{10 + 2 * p[0], p[1], p[2]}; };
  auto add = [&](const std::function<P3(P3)>& f, P3 a, P3 b2, P3 c) { w.expected.push_back({f(a), f(b2), f(c)}); };
  if (scene_index == 1) {
    add([](P3 p) { return p; }, quad[0], quad[1], quad[2]);
    add([](P3 p) { return p; }, quad[3], quad[4], quad[5]);
    return w;
  }
  add(f0, quad[0], quad[1], quad[2]);                      // 0, 1: root's triangles
  add(f0, quad[3], quad[4], quad[5]);
  for (int i = 0; i < 3; ++i) {                            // 2..4: strip {v_i, v_(i+1+i%2), v_(i+2-i%2)}
    add(f1, strip[strip_idx[i]], strip[strip_idx[i + 1 + i % 2]], strip[strip_idx[i + 2 - i % 2]]);
  }
  add(f1, quad[0], quad[1], quad[2]);                      // 5, 6: "inherits", child of "turned"
  add(f1, quad[3], quad[4], quad[5]);
  for (int copy = 0; copy < 2; ++copy) {                   // 7..10 matrix, 11..14 TRS: mirrored
    for (int i = 0; i < 3; ++i) add(f2, fan[i + 1], fan[0], fan[i + 2]);   // fan {v_(i+1), v_(i+2), v_0} flipped
    add(f2, tri[0], tri[2], tri[1]);
  }
  add(f5, slanted[0], slanted[1], slanted[2]);             // 15
  return w;
}

// A glTF of one triangle: POSITION and two more float attributes, `a` and then `b` (three elements each,
// of type a_type and b_type), all in one data: buffer.
std::string one_triangle_gltf(const std::vector<float>& a, const std::string& a_semantic, const std::string& a_type,
                              const std::vector<float>& b, const std::string& b_semantic, const std::string& b_type) {
  const std::vector<float> position = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const size_t a_bytes = 4 * a.size(), b_bytes = 4 * b.size();
  std::vector<uint8_t> bytes(36 + a_bytes + b_bytes);
  std::memcpy(bytes.data(), position.data(), 36);
  std::memcpy(bytes.data() + 36, a.data(), a_bytes);
  std::memcpy(bytes.data() + 36 + a_bytes, b.data(), b_bytes);
  const auto n = [](size_t v) { return std::to_string(v); };
  return "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":" + n(bytes.size()) +
         ",\"uri\":\"data:application/octet-stream;base64," + base64(bytes) +
         "\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":" +
         n(a_bytes) + "},{\"buffer\":0,\"byteOffset\":" + n(36 + a_bytes) + ",\"byteLength\":" + n(b_bytes) +
         "}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
         "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"" + a_type + "\"},"
         "{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"" + b_type + "\"}],"
         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"" + a_semantic + "\":1,\"" + b_semantic +
         "\":2}}]}],\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}";
}

}  // namespace

TEST(SceneGltf, EveryAssimpModelCompilesOrFailsCleanly) {
  const std::vector<std::string> files = testfiles::gltf_files_under(scenetest::kModels);
  if (files.empty()) GTEST_SKIP() << "assimp-testmodels not installed";
  int compiled = 0, rejected = 0;
  for (const std::string& path : files) {
    const CompileResult r = compile_gltf_file(path);
    if (r.ok) {
      ++compiled;
      Scene s;
      const Status st = read_scene(r.blob.data(), r.blob.size, &s);
      EXPECT_TRUE(st.ok()) << path << ": " << st.message;
      EXPECT_GT(s.triangle_count, 0u) << path;
      EXPECT_EQ(s.triangle_count, r.report.triangles) << path;
      EXPECT_TRUE(r.error.empty()) << path;
    } else {
      ++rejected;
      EXPECT_FALSE(r.error.empty()) << path;
      EXPECT_EQ(r.error.find('\n'), std::string::npos) << path << ": " << r.error;
      EXPECT_EQ(r.blob.size, 0u) << path;
    }
    for (const std::string& w : r.warnings) EXPECT_EQ(w.find('\n'), std::string::npos) << path;
  }
  EXPECT_GE(files.size(), 40u);
  EXPECT_GE(compiled, 20);
  EXPECT_GE(rejected, 5);
}

TEST(SceneGltf, CylinderEngineTriangleCountMatchesAccessors) {
  const std::string path = scenetest::engine_path();
  if (!scenetest::file_exists(path)) GTEST_SKIP() << "assimp-testmodels not installed";
  // Independent count: tinygltf accessors over the default scene's node instances.
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, path)) << err;
  size_t expected = 0;
  std::function<void(int)> count = [&](int n) {
    const tinygltf::Node& node = model.nodes[size_t(n)];
    if (node.mesh >= 0) {
      for (const tinygltf::Primitive& p : model.meshes[size_t(node.mesh)].primitives) {
        const size_t k = p.indices >= 0 ? model.accessors[size_t(p.indices)].count
                                        : model.accessors[size_t(p.attributes.at("POSITION"))].count;
        if (p.mode == TINYGLTF_MODE_TRIANGLES || p.mode == -1) expected += k / 3;
        else if (p.mode == TINYGLTF_MODE_TRIANGLE_STRIP || p.mode == TINYGLTF_MODE_TRIANGLE_FAN) expected += k >= 2 ? k - 2 : 0;
      }
    }
    for (int c : node.children) count(c);
  };
  const int scene = model.defaultScene >= 0 ? model.defaultScene : 0;
  for (int n : model.scenes[size_t(scene)].nodes) count(n);
  EXPECT_GT(expected, 100000u);

  const CompileResult& r = scenetest::cached("engine");
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.report.triangles, expected);
  Scene s;
  ASSERT_TRUE(read_scene(r.blob.data(), r.blob.size, &s).ok());
  EXPECT_EQ(s.triangle_count, expected);
  EXPECT_GT(s.bsp_node_count, 0u);
  EXPECT_GE(s.bsp_piece_count, s.triangle_count);
  EXPECT_LE(s.info->bsp_depth, kMaxBspDepth);
  std::printf("[   INFO   ] 2CylinderEngine: %u triangles, %u nodes, %u materials, %u bsp nodes, %u pieces, "
              "split ratio %.3f, depth %u, %.2f s (bsp %.2f s)\n",
              r.report.triangles, r.report.nodes, r.report.materials, r.report.bsp_nodes, r.report.bsp_pieces,
              r.report.split_ratio, r.report.bsp_depth, r.report.seconds, r.report.bsp_seconds);
}

TEST(SceneGltf, NonFiniteCoordinatesAreRejectedNamingTheAccessor) {
  const std::string path = std::string(scenetest::kModels) + "/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb";
  if (!scenetest::file_exists(path)) GTEST_SKIP();
  const std::string e = compile_error(path);
  EXPECT_NE(e.find("accessor"), std::string::npos) << e;
  EXPECT_NE(e.find("non-finite"), std::string::npos) << e;
}

TEST(SceneGltf, IndicesOutOfRangeAreRejected) {
  for (const char* name : {"/IndexOutOfRange/IndexOutOfRange.gltf", "/IndexOutOfRange/AllIndicesOutOfRange.gltf"}) {
    const std::string path = std::string(scenetest::kModels) + name;
    if (!scenetest::file_exists(path)) GTEST_SKIP();
    const std::string e = compile_error(path);
    EXPECT_NE(e.find("out of range"), std::string::npos) << e;
  }
}

TEST(SceneGltf, RecursiveNodesAreACycleNotAHang) {
  const std::string path = std::string(scenetest::kModels) + "/RecursiveNodes/RecursiveNodes.gltf";
  if (!scenetest::file_exists(path)) GTEST_SKIP();
  EXPECT_NE(compile_error(path).find("cycle"), std::string::npos);
}

TEST(SceneGltf, MissingFilesAndBuffers) {
  EXPECT_NE(compile_error("/nonexistent/scene.glb").find("cannot open"), std::string::npos);
  const std::string path = std::string(scenetest::kModels) + "/MissingBin/BoxTextured.gltf";
  if (scenetest::file_exists(path)) compile_error(path);
  const std::string dir = scenetest::temp_dir();
  scenetest::write_file(dir + "/empty.gltf", "");
  compile_error(dir + "/empty.gltf");
  scenetest::write_file(dir + "/garbage.gltf", "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":7}]}");
  EXPECT_NE(compile_error(dir + "/garbage.gltf").find("mesh index out of range"), std::string::npos);
  scenetest::write_file(dir + "/notjson.gltf", "{{{{ this is not json");
  compile_error(dir + "/notjson.gltf");
  scenetest::write_file(dir + "/noscene.gltf", "{\"asset\":{\"version\":\"2.0\"}}");
  EXPECT_EQ(compile_error(dir + "/noscene.gltf"), "scene has no triangles: the file has no meshes");
}

TEST(SceneGltf, TruncatedGlbFailsCleanly) {
  const std::string path = std::string(scenetest::kModels) + "/BoxTextured-glTF-Binary/BoxTextured.glb";
  if (!scenetest::file_exists(path)) GTEST_SKIP();
  Blob whole;
  std::string error;
  ASSERT_TRUE(load_blob_file(path, &whole, &error)) << error;
  const std::string dir = scenetest::temp_dir();
  int failures = 0;
  for (size_t n = 0; n < whole.size; n += (n < 64 ? 3 : 97)) {
    Blob part;
    part.assign(whole.data(), n);
    const std::string cut = dir + "/cut.glb";
    ASSERT_TRUE(save_blob_file(cut, part, &error));
    const CompileResult r = compile_gltf_file(cut);
    if (!r.ok) {
      ++failures;
      EXPECT_FALSE(r.error.empty());
      EXPECT_EQ(r.error.find('\n'), std::string::npos) << r.error;
    }
  }
  EXPECT_GT(failures, 10);
  // Flipped bytes in the JSON and binary chunks: compile or fail, never crash.
  for (size_t pos = 20; pos < whole.size; pos += 53) {
    Blob flipped = whole;
    flipped.bytes()[pos] ^= 0x5A;
    const std::string f = dir + "/flip.glb";
    ASSERT_TRUE(save_blob_file(f, flipped, &error));
    const CompileResult r = compile_gltf_file(f);
    if (!r.ok) EXPECT_EQ(r.error.find('\n'), std::string::npos) << r.error;
    else EXPECT_TRUE(scenetest::read(r.blob).ok());
  }
}

TEST(SceneGltf, TriangleIdsFollowNodesPrimitivesAndIndices) {
  const std::string dir = scenetest::temp_dir();
  const Written w = write_test_gltf(dir, 0);
  const CompileResult r = compile_gltf_file(w.path);
  ASSERT_TRUE(r.ok) << r.error;
  Scene s;
  ASSERT_TRUE(scenetest::read(r.blob, &s).ok());
  ASSERT_EQ(s.triangle_count, w.expected.size());
  bool warned_points = false;
  for (const std::string& x : r.warnings) warned_points |= x.find("POINTS") != std::string::npos;
  EXPECT_TRUE(warned_points);

  const double cx = bits_to_float(s.info->gltf_center_bits[0]), cy = bits_to_float(s.info->gltf_center_bits[1]),
               cz = bits_to_float(s.info->gltf_center_bits[2]), k = bits_to_float(s.info->gltf_to_world_bits);
  for (uint32_t t = 0; t < s.triangle_count; ++t) {
    Vec3i got[3];
    triangle_world(s, t, got);
    const Batch& b = s.batches[ml::triangle_at(s, t).batch];
    const double tol = 1.5 + std::max(b.scale[0], std::max(b.scale[1], b.scale[2])) / 65536.0;
    for (int v = 0; v < 3; ++v) {
      const P3& e = w.expected[t][size_t(v)];
      EXPECT_NEAR(got[v].x, (e[0] - cx) * k, tol) << "triangle " << t << " vertex " << v;
      EXPECT_NEAR(got[v].y, (e[1] - cy) * k, tol) << "triangle " << t << " vertex " << v;
      EXPECT_NEAR(got[v].z, (e[2] - cz) * k, tol) << "triangle " << t << " vertex " << v;
    }
  }
  // The matrix node and the TRS node with the same transform give the same positions.
  for (uint32_t t = 7; t < 11; ++t) {
    Vec3i a[3], b[3];
    triangle_world(s, t, a);
    triangle_world(s, t + 4, b);
    for (int v = 0; v < 3; ++v) {
      EXPECT_EQ(a[v].x, b[v].x);
      EXPECT_EQ(a[v].y, b[v].y);
      EXPECT_EQ(a[v].z, b[v].z);
    }
  }
  // Mirrored nodes keep front faces counter-clockwise: the fan still faces +z.
  for (uint32_t t = 7; t < 15; ++t) {
    Vec3i p[3];
    triangle_world(s, t, p);
    const double ux = p[1].x - p[0].x, uy = p[1].y - p[0].y, vx = p[2].x - p[0].x, vy = p[2].y - p[0].y;
    EXPECT_GT(ux * vy - uy * vx, 0) << "triangle " << t;
  }
  // Nodes depth-first: root, turned, inherits, mirror_matrix, mirror_trs, stretched.
  ASSERT_EQ(s.node_count, 6u);
  const uint32_t parents[6] = {kNone, 0, 1, 0, 0, 0};
  for (uint32_t n = 0; n < 6; ++n) EXPECT_EQ(s.nodes[n].parent, parents[n]) << "node " << n;
  // Materials: the glTF one, then the default for primitives without one.
  ASSERT_EQ(s.material_count, 2u);
  EXPECT_EQ(s.materials[0].base_color[0], 255);
  EXPECT_EQ(s.materials[0].base_color[1], 0);
  EXPECT_EQ(s.materials[0].base_color[3], 255);
  EXPECT_EQ(s.materials[0].double_sided, 1);
  EXPECT_EQ(s.materials[0].alpha_mode, uint8_t(AlphaMode::Mask));
  EXPECT_EQ(s.materials[0].alpha_cutoff, 64);
  EXPECT_EQ(s.materials[0].texture, kNone);
  EXPECT_EQ(s.materials[1].double_sided, 0);
  EXPECT_EQ(s.materials[1].alpha_mode, uint8_t(AlphaMode::Opaque));
  EXPECT_EQ(s.materials[1].base_color[0], s.materials[1].base_color[1]);
  EXPECT_GT(s.materials[1].base_color[0], 150);
  EXPECT_EQ(s.batches[ml::triangle_at(s, 0).batch].material, 0u);
  EXPECT_EQ(s.batches[ml::triangle_at(s, 2).batch].material, 1u);
  // Normals: rotated (0,0,1) stays (0,0,1); (1,1,0) under scale (2,1,1) becomes (0.5,1,0) normalized.
  const PackedVertex& turned = s.vertices[ml::triangle_at(s, 5).v[0]];
  EXPECT_EQ(turned.normal[0], 0);
  EXPECT_EQ(turned.normal[1], 0);
  EXPECT_EQ(turned.normal[2], kNormalOne);
  const PackedVertex& stretched = s.vertices[ml::triangle_at(s, 15).v[0]];
  EXPECT_NEAR(stretched.normal[0], 0.5 / std::sqrt(1.25) * kNormalOne, 1.0);
  EXPECT_NEAR(stretched.normal[1], 1.0 / std::sqrt(1.25) * kNormalOne, 1.0);
  EXPECT_EQ(stretched.normal[2], 0);
  const PackedVertex& no_normals = s.vertices[ml::triangle_at(s, 2).v[0]];
  EXPECT_EQ(no_normals.normal[0] | no_normals.normal[1] | no_normals.normal[2], 0);
  // Texture coordinates in Q16.16.
  const Triangle& t1 = ml::triangle_at(s, 1);
  EXPECT_EQ(uv_of(s, t1.v[0])[0], 65536);
  EXPECT_EQ(uv_of(s, t1.v[1])[1], 65536);
  EXPECT_EQ(uv_of(s, t1.v[2])[0], 32768);
  EXPECT_EQ(uv_of(s, t1.v[2])[1], 147456);
}

TEST(SceneGltf, DefaultSceneIsHonoured) {
  const Written w = write_test_gltf(scenetest::temp_dir(), 1);
  const CompileResult r = compile_gltf_file(w.path);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.report.triangles, 2u);
  EXPECT_EQ(r.report.nodes, 1u);
}

TEST(SceneGltf, HostileGraphsAndAccessors) {
  const std::string dir = scenetest::temp_dir();
  const std::string head = "{\"asset\":{\"version\":\"2.0\"},";
  const std::string tri_buffer =   // three float VEC3 positions
      "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"
      "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],";
  struct Case {
    const char* name;
    std::string json;
    const char* expect;   // substring of the error, or nullptr when it must compile
  };
  std::string overflow_chain;   // nine nested scales of 1e38: 1e342 overflows a double
  for (int i = 0; i < 9; ++i) overflow_chain += "{\"children\":[" + std::to_string(i + 1) + "],\"scale\":[1e38,1e38,1e38]},";
  overflow_chain += "{\"mesh\":0}";
  const std::vector<Case> cases = {
      {"cycle", head + "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"children\":[1]},{\"children\":[0]}]}", "cycle"},
      {"self", head + "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"children\":[0]}]}", "cycle"},
      {"child range", head + "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"children\":[5]}]}", "out of range"},
      {"scene node range", head + "\"scenes\":[{\"nodes\":[3]}],\"nodes\":[{}]}", "out of range"},
      {"ok", head + tri_buffer +
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                 "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}",
       nullptr},
      {"view outside buffer", head + tri_buffer +
                 "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":12,\"byteLength\":36}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                 "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}",
       "outside buffer"},
      {"count too big", head + tri_buffer +
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                 "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}",
       "outside its buffer view"},
      {"bad stride", head + tri_buffer +
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36,\"byteStride\":4}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                 "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}",
       "stride"},
      {"wrong type", head + tri_buffer +
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                 "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}",
       "wrong element type"},
      {"accessor range", head + tri_buffer +
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":9}}]}],"
                 "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}",
       nullptr /* tinygltf or we reject; checked below */},
      {"float indices", head + tri_buffer +
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
                 "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
                 "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}",
       "indices must be"},
      {"huge extent", head + tri_buffer +
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                 "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"children\":[1],\"scale\":[1e38,1e38,1e38]},"
                 "{\"children\":[2],\"scale\":[1e38,1e38,1e38]},{\"mesh\":0}]}",
       "cannot be normalized"},
      {"overflowing transform", head + tri_buffer +
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                 "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[" + overflow_chain + "]}",
       "not finite"},
      {"short matrix", head + "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"matrix\":[1,0,0]}]}", "16 values"},
  };
  for (const Case& c : cases) {
    const std::string path = dir + "/case.gltf";
    scenetest::write_file(path, c.json);
    const CompileResult r = compile_gltf_file(path);
    if (std::string(c.name) == "accessor range") {
      EXPECT_FALSE(r.ok) << c.name;
      continue;
    }
    if (c.expect == nullptr) {
      EXPECT_TRUE(r.ok) << c.name << ": " << r.error;
      continue;
    }
    EXPECT_FALSE(r.ok) << c.name;
    EXPECT_NE(r.error.find(c.expect), std::string::npos) << c.name << ": " << r.error;
    EXPECT_EQ(r.error.find('\n'), std::string::npos) << c.name << ": " << r.error;
  }
}

// Attributes a primitive can be drawn without are left out when their element type is wrong, with a
// warning, instead of refusing the model; a TEXCOORD_0 of three components (UVW, as assimp's glTF
// exporter writes a model with UVW channels) keeps its first two. POSITION's type is still checked
// (HostileGraphsAndAccessors, "wrong type").
TEST(SceneGltf, OptionalAttributesOfAnotherTypeAreLeftOutOrTrimmed) {
  const std::vector<float> uvw = {0.25f, 0.5f, 9, 1, 0.75f, 9, 0.5f, 1.5f, 9};
  const std::vector<float> normal2 = {0, 1, 0, 1, 0, 1};  // VEC2: not a normal
  const std::string json = one_triangle_gltf(uvw, "TEXCOORD_0", "VEC3", normal2, "NORMAL", "VEC2");
  const CompileResult r = compile_gltf_memory(reinterpret_cast<const unsigned char*>(json.data()), json.size());
  ASSERT_TRUE(r.ok) << r.error;
  auto warned = [&](const std::string& text) {
    return std::any_of(r.warnings.begin(), r.warnings.end(),
                       [&](const std::string& w) { return w.find(text) != std::string::npos; });
  };
  EXPECT_TRUE(warned("TEXCOORD_0 has 3 components (UVW): the first two used"));
  EXPECT_TRUE(warned("NORMAL has 2 component(s), not 3: normals ignored"));
  Scene s;
  ASSERT_TRUE(read_scene(r.blob.data(), r.blob.size, &s).ok());
  ASSERT_EQ(s.triangle_count, 1u);
  const Triangle& t = ml::triangle_at(s, 0);
  for (int i = 0; i < 3; ++i) {
    const std::array<int32_t, 2> uv = uv_of(s, t.v[i]);
    // Vertex order may be kept or reversed by the compiler: find this vertex's row by its u.
    bool found = false;
    for (int k = 0; k < 3; ++k)
      if (uv[0] == int32_t(uvw[3 * k] * 65536) && uv[1] == int32_t(uvw[3 * k + 1] * 65536)) found = true;
    EXPECT_TRUE(found) << "vertex " << i << ": uv " << uv[0] << ", " << uv[1];
  }
}

// A NaN or infinite NORMAL or TEXCOORD_0 element (an exporter's normal of a degenerate face) leaves that
// element out with a warning instead of refusing the model: the vertex is shaded with its face's normal
// (stored as none) or takes texture coordinates (0, 0); the other vertices keep theirs. POSITION stays
// refused (NonFiniteCoordinatesAreRejectedNamingTheAccessor).
TEST(SceneGltf, NonFiniteNormalsAndTexcoordsAreLeftOutWithAWarning) {
  const float nan = std::nanf(""), inf = INFINITY;
  const std::vector<float> normal = {0, 0, 1, nan, 0, 1, 0, 0, 1};
  const std::vector<float> uv = {0.25f, 0.5f, 0.75f, 0.5f, inf, 1};
  const std::string json = one_triangle_gltf(normal, "NORMAL", "VEC3", uv, "TEXCOORD_0", "VEC2");
  const CompileResult r = compile_gltf_memory(reinterpret_cast<const unsigned char*>(json.data()), json.size());
  ASSERT_TRUE(r.ok) << r.error;
  auto warned = [&](const std::string& text) {
    return std::any_of(r.warnings.begin(), r.warnings.end(),
                       [&](const std::string& w) { return w.find(text) != std::string::npos; });
  };
  EXPECT_TRUE(warned("1 NORMAL element(s) not finite")) << (r.warnings.empty() ? "" : r.warnings[0]);
  EXPECT_TRUE(warned("1 TEXCOORD_0 element(s) not finite"));
  Scene s;
  ASSERT_TRUE(read_scene(r.blob.data(), r.blob.size, &s).ok());
  ASSERT_EQ(s.triangle_count, 1u);
  const Triangle& t = ml::triangle_at(s, 0);
  int without_normal = 0, at_origin = 0;
  for (int i = 0; i < 3; ++i) {
    const int16_t* n = vertex_normal(s, t.v[i]);
    if (n[0] == 0 && n[1] == 0 && n[2] == 0) ++without_normal;
    else EXPECT_GT(n[2], 0) << "vertex " << i;  // (0, 0, 1) kept
    const std::array<int32_t, 2> c = uv_of(s, t.v[i]);
    if (c[0] == 0 && c[1] == 0) ++at_origin;
  }
  EXPECT_EQ(without_normal, 1);
  EXPECT_EQ(at_origin, 1);
}

// "scene has no triangles" says why, in its one line: no meshes, no nodes, meshes no node uses, meshes
// without primitives, primitives all skipped (naming the first), or primitives without a whole triangle.
TEST(SceneGltf, NoTrianglesRefusalsSayWhy) {
  const std::vector<float> position = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::vector<uint8_t> bytes(36);
  std::memcpy(bytes.data(), position.data(), 36);
  const std::string head = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":"
                           "\"data:application/octet-stream;base64," + base64(bytes) + "\"}],\"bufferViews\":"
                           "[{\"buffer\":0,\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,"
                           "\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},{\"bufferView\":0,"
                           "\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"}]";
  const std::string triangle = "{\"attributes\":{\"POSITION\":0}}";
  auto error_of = [](const std::string& json) {
    const CompileResult r = compile_gltf_memory(reinterpret_cast<const unsigned char*>(json.data()), json.size());
    EXPECT_FALSE(r.ok) << json;
    return r.error;
  };
  EXPECT_EQ(error_of(head + "}"), "scene has no triangles: the file has no meshes");
  EXPECT_EQ(error_of(head + ",\"meshes\":[{\"primitives\":[" + triangle + "]}],\"scenes\":[{\"nodes\":[]}]}"),
            "scene has no triangles: the scene has no nodes");
  EXPECT_EQ(error_of(head + ",\"meshes\":[{\"primitives\":[" + triangle + "]}]}"),
            "scene has no triangles: the file has no nodes");
  EXPECT_EQ(error_of(head + ",\"meshes\":[{\"primitives\":[" + triangle + "]}],\"nodes\":[{}]}"),
            "scene has no triangles: no node of the scene has a mesh");
  EXPECT_EQ(error_of(head + ",\"meshes\":[{\"primitives\":[]}],\"nodes\":[{\"mesh\":0}]}"),
            "scene has no triangles: its meshes have no primitives");
  EXPECT_EQ(error_of(head + ",\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":1},"
                            "{\"attributes\":{\"POSITION\":0},\"mode\":0}]}],\"nodes\":[{\"mesh\":0}]}"),
            "scene has no triangles: mesh 0 primitive 0: mode LINES skipped (only triangles are drawn) (and 1 more "
            "primitive(s) skipped)");
  EXPECT_EQ(error_of(head + ",\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":1}}]}],"
                            "\"nodes\":[{\"mesh\":0}]}"),
            "scene has no triangles: its primitives hold no whole triangle (fewer than 3 indices or vertices)");
  // A default scene named where the file has none: every root node is drawn, and the warning says so.
  const std::string json = head + ",\"scene\":0,\"meshes\":[{\"primitives\":[" + triangle +
                           "]}],\"nodes\":[{\"mesh\":0}]}";
  const CompileResult r = compile_gltf_memory(reinterpret_cast<const unsigned char*>(json.data()), json.size());
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(std::any_of(r.warnings.begin(), r.warnings.end(), [](const std::string& w) {
    return w == "default scene 0 named, but the file has no scenes: every root node used";
  }));
}

// Refusals and warnings are printable lines even when they quote bytes that are not (a control
// character in a name): such bytes are written \xNN, while well-formed UTF-8 is kept. (Bytes that are
// not UTF-8 are read as Latin-1 before parsing: ScenecLimits.BytesThatAreNotUtf8AreReadAsLatin1.)
TEST(SceneGltf, ErrorAndWarningLinesEscapeBytesThatAreNotPrintable) {
  const std::string raw = "{\"asset\":{\"version\":\"2.0\"},\"materials\":[{\"name\":\"Terrain\x01\"}],"
                          "\"meshes\":[],\"scenes\":[{\"nodes\":[]}]}";
  const CompileResult r = compile_gltf_memory(reinterpret_cast<const unsigned char*>(raw.data()), raw.size());
  ASSERT_FALSE(r.ok);
  for (unsigned char c : r.error) EXPECT_TRUE(c >= 0x20 && c < 0x7F) << r.error;
  const std::string escaped = "{\"asset\":{\"version\":\"2.0\"},\"materials\":[{\"alphaMode\":\"Bl\\u0001nk\"}],"
                              "\"meshes\":[],\"scenes\":[{\"nodes\":[]}]}";
  const CompileResult quoted =
      compile_gltf_memory(reinterpret_cast<const unsigned char*>(escaped.data()), escaped.size());
  EXPECT_TRUE(std::any_of(quoted.warnings.begin(), quoted.warnings.end(), [](const std::string& w) {
    return w.find("'Bl\\x01nk'") != std::string::npos;
  })) << (quoted.warnings.empty() ? "no warning" : quoted.warnings[0]);
  // Well-formed UTF-8 stays as it is (a warning quoting a material's alpha mode).
  const std::string utf8 = "{\"asset\":{\"version\":\"2.0\"},\"materials\":[{\"alphaMode\":\"Bl\xC3\xA4nk\"}],"
                           "\"meshes\":[],\"scenes\":[{\"nodes\":[]}]}";
  const CompileResult named = compile_gltf_memory(reinterpret_cast<const unsigned char*>(utf8.data()), utf8.size());
  EXPECT_TRUE(std::any_of(named.warnings.begin(), named.warnings.end(), [](const std::string& w) {
    return w.find("'Bl\xC3\xA4nk'") != std::string::npos;
  })) << (named.warnings.empty() ? "no warning" : named.warnings[0]);
}

TEST(SceneGltf, ExponentialNodeSharingIsBounded) {
  // Each node lists the next one twice: 2^40 instances if expanded naively.
  std::string nodes;
  for (int i = 0; i < 40; ++i) {
    if (i) nodes += ",";
    nodes += "{\"children\":[" + std::to_string(i + 1) + "," + std::to_string(i + 1) + "]}";
  }
  nodes += ",{}";
  const std::string dir = scenetest::temp_dir();
  scenetest::write_file(dir + "/wide.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nodes\":[" + nodes + "]}");
  EXPECT_NE(compile_error(dir + "/wide.gltf").find("too many node instances"), std::string::npos);
}

// An image file missing beside the glTF is one warning naming the file (the glTF parser's own two
// lines, one of which does not name it, are not passed on); the model still compiles, untextured.
namespace {

// The current directory changed to `dir` for the object's life (a compile that looks there).
class InDirectory {
 public:
  explicit InDirectory(const std::string& dir) : ok_(getcwd(cwd_, sizeof cwd_) != nullptr && chdir(dir.c_str()) == 0) {}
  ~InDirectory() {
    if (ok_ && chdir(cwd_) != 0) std::abort();
  }
  bool ok() const { return ok_; }

 private:
  char cwd_[4096];
  bool ok_;
};

// A glTF of one triangle (its positions in a data: URI) drawn with material 0, and the images,
// textures and materials given (JSON arrays).
std::string one_textured_triangle(const std::string& images, const std::string& textures, const std::string& materials) {
  const std::vector<float> position = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::vector<uint8_t> bytes(36);
  std::memcpy(bytes.data(), position.data(), 36);
  return "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64," +
         base64(bytes) + "\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,"
         "\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],\"images\":" + images + ",\"textures\":" + textures +
         ",\"materials\":" + materials + ",\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
         "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}";
}

// One image, the base colour texture of material 0.
std::string one_image_at(const std::string& uri) {
  return one_textured_triangle("[{\"uri\":\"" + uri + "\"}]", "[{\"source\":0}]",
                               "[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]");
}

}  // namespace

TEST(SceneGltf, AMissingImageFileIsOneWarningNamingIt) {
  const std::string dir = scenetest::temp_dir();
  scenetest::write_file(dir + "/m.gltf", one_image_at("missing-texture.png"));
  // Files of those names in the current directory are not the models' and are not read (a decodable
  // image there would give the model a texture): "missing-texture.png" for a glTF elsewhere, and for
  // a glTF named "./sub/m.gltf" whose image is "sub/t.png" (beside it: "./sub/sub/t.png", missing),
  // the "./sub/t.png" tinygltf's lookup in the current directory would find.
  const std::string current = scenetest::temp_dir();
  const std::vector<ml::Pixel> blue(4, 0x336699u);
  ASSERT_EQ(mlhost::write_png_rgb(current + "/missing-texture.png", 2, 2, blue), "");
  ASSERT_EQ(mkdir((current + "/sub").c_str(), 0755), 0);
  ASSERT_EQ(mlhost::write_png_rgb(current + "/sub/t.png", 2, 2, blue), "");
  scenetest::write_file(current + "/sub/m.gltf", one_image_at("sub/t.png"));
  CompileResult r, dotted;
  {
    const InDirectory in(current);
    ASSERT_TRUE(in.ok());
    r = compile_gltf_file(dir + "/m.gltf");
    dotted = compile_gltf_file("./sub/m.gltf");
  }
  for (const CompileResult* c : {&r, &dotted}) {
    ASSERT_TRUE(c->ok) << c->error;
    const std::string uri = c == &r ? "missing-texture.png" : "sub/t.png";
    const std::vector<std::string> naming = {"image 0: its file '" + uri +
                                             "' not read (missing beside the glTF, or unreadable), texture ignored"};
    std::vector<std::string> about_the_file;
    for (const std::string& w : c->warnings)
      if (w.find(uri) != std::string::npos || w.find("image[") != std::string::npos) about_the_file.push_back(w);
    EXPECT_EQ(about_the_file, naming);
  }
}

// Exporters on Windows separate a relative URI's parts with backslashes (assimp writes ".\t.png"): the
// file is read from beside the glTF as if they were slashes.
TEST(SceneGltf, BackslashesInAUriAreReadAsSlashes) {
  const std::string dir = scenetest::temp_dir();
  ASSERT_EQ(mkdir((dir + "/maps").c_str(), 0755), 0);
  ASSERT_EQ(mlhost::write_png_rgb(dir + "/maps/base.png", 2, 2, std::vector<ml::Pixel>(4, 0x336699u)), "");
  scenetest::write_file(dir + "/m.gltf", one_image_at(".\\\\maps\\\\base.png"));
  SceneMesh mesh;
  std::vector<std::string> warnings;
  std::string error;
  ASSERT_TRUE(import_gltf_file(dir + "/m.gltf", &mesh, &warnings, &error)) << error;
  EXPECT_EQ(mesh.texture_images, (std::vector<uint32_t>{0}));
  EXPECT_EQ(warnings, std::vector<std::string>{});
}

// Only a drawn primitive's base colour texture is sampled: a normal map and the texture of a material
// no primitive uses keep their places in the texture table (the indices stay) without texels, with one
// warning naming them.
TEST(SceneGltf, TexturesNotSampledAreLeftOutWithOneWarning) {
  const std::string dir = scenetest::temp_dir();
  ASSERT_EQ(mlhost::write_png_rgb(dir + "/base.png", 2, 2, std::vector<ml::Pixel>(4, 0x336699u)), "");
  ASSERT_EQ(mlhost::write_png_rgb(dir + "/normal.png", 2, 2, std::vector<ml::Pixel>(4, 0x8080FFu)), "");
  scenetest::write_file(
      dir + "/m.gltf",
      one_textured_triangle("[{\"uri\":\"base.png\"},{\"uri\":\"normal.png\"}]",
                            "[{\"source\":0},{\"source\":1},{\"source\":0}]",
                            "[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}},\"normalTexture\":{\"index\":1}},"
                            "{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":2}}}]"));
  SceneMesh mesh;
  std::vector<std::string> warnings;
  std::string error;
  ASSERT_TRUE(import_gltf_file(dir + "/m.gltf", &mesh, &warnings, &error)) << error;
  EXPECT_EQ(mesh.texture_images, (std::vector<uint32_t>{0, kNone, kNone}));
  EXPECT_EQ(warnings, (std::vector<std::string>{
                          "textures 1, 2: not the base colour of a drawn primitive's material, texels left out of the scene"}));
  const CompileResult r = compile_gltf_file(dir + "/m.gltf");
  ASSERT_TRUE(r.ok) << r.error;
  Scene s;
  ASSERT_TRUE(read_scene(r.blob.data(), r.blob.size, &s).ok());
  ASSERT_EQ(s.texture_count, 3u);
  EXPECT_NE(s.texture_texels[0].format, uint8_t(TexelFormat::None));
  EXPECT_EQ(s.texture_texels[1].format, uint8_t(TexelFormat::None));
  EXPECT_EQ(s.texture_texels[2].format, uint8_t(TexelFormat::None));
}

// assimp's wrongTypes models: a texture transform that is not an object is named and ignored (the
// texture drawn untransformed); a texture index of -1 or a pbrMetallicRoughness that is not an object
// leave the material untextured, and the texture's texels out (TexturesNotSampledAre...).
TEST(SceneGltf, WrongTypesOfTextureFieldsAreWarnedOrLeftOut) {
  const std::string dir = "/usr/share/assimp/models/glTF2/wrongTypes/";
  if (access((dir + "badExtension.gltf").c_str(), R_OK) != 0) GTEST_SKIP() << "assimp test models not installed";
  const CompileResult transform = compile_gltf_file(dir + "badExtension.gltf");
  ASSERT_TRUE(transform.ok) << transform.error;
  EXPECT_TRUE(std::any_of(transform.warnings.begin(), transform.warnings.end(), [](const std::string& w) {
    return w.find("KHR_texture_transform is not an object, ignored") != std::string::npos;
  }));
  for (const char* name : {"badUint.gltf", "badObject.gltf"}) {
    const CompileResult r = compile_gltf_file(dir + name);
    ASSERT_TRUE(r.ok) << name << ": " << r.error;
    EXPECT_EQ(r.warnings, (std::vector<std::string>{
                              "texture 0: not the base colour of a drawn primitive's material, texels left out of the scene"}))
        << name;
    EXPECT_LT(r.blob.size, 4096u) << name;  // the 90,819 bytes of texels (and mip levels) left out
  }
}

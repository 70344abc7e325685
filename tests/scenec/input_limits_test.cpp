// The compiler against hostile input (tools/scenec/limits.h): deep JSON, accessor counts a small file
// cannot back, special files, degenerate-only geometry. Each input is refused with one line, quickly,
// before the memory it claims is allocated, or compiles when it is legal.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <vector>

#include "tests/scene/scene_test_util.h"
#include "tools/scenec/limits.h"

using namespace ml;
using scenetest::base64;

namespace {

// A .gltf with float VEC3 positions (one primitive, one node) and an optional extra accessor JSON.
std::string positions_gltf(const std::vector<float>& xyz, const std::string& attributes_extra = "",
                           const std::string& accessors_extra = "") {
  std::vector<uint8_t> bytes(xyz.size() * 4);
  std::memcpy(bytes.data(), xyz.data(), bytes.size());
  return "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":" + std::to_string(bytes.size()) +
         ",\"uri\":\"data:application/octet-stream;base64," + base64(bytes) + "\"}]," +
         "\"bufferViews\":[{\"buffer\":0,\"byteLength\":" + std::to_string(bytes.size()) + "}]," +
         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":" + std::to_string(xyz.size() / 3) +
         ",\"type\":\"VEC3\"}" + accessors_extra + "]," +
         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0" + attributes_extra + "}}]}]," +
         "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}";
}

// A .glb holding `json` (padded) and an optional BIN chunk.
std::vector<uint8_t> make_glb(std::string json, std::vector<uint8_t> bin = {}) {
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin.push_back(0);
  std::vector<uint8_t> out;
  auto u32 = [&](uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
  };
  const uint32_t total = uint32_t(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size()));
  out.insert(out.end(), {'g', 'l', 'T', 'F'});
  u32(2);
  u32(total);
  u32(uint32_t(json.size()));
  u32(0x4E4F534Au);
  out.insert(out.end(), json.begin(), json.end());
  if (!bin.empty()) {
    u32(uint32_t(bin.size()));
    u32(0x004E4942u);
    out.insert(out.end(), bin.begin(), bin.end());
  }
  return out;
}

CompileResult compile_text(const std::string& text) {
  return compile_gltf_memory(reinterpret_cast<const unsigned char*>(text.data()), text.size());
}

void expect_refused(const CompileResult& r, const std::string& what, const char* fragment) {
  EXPECT_FALSE(r.ok) << what;
  EXPECT_EQ(r.error.find('\n'), std::string::npos) << what << ": " << r.error;
  EXPECT_NE(r.error.find(fragment), std::string::npos) << what << ": " << r.error;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Peak resident set of this process so far, in MB.
long peak_rss_mb() {
  struct rusage u;
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024;
}

}  // namespace

TEST(ScenecLimits, DeepJsonIsRefusedBeforeParsing) {
  const int d = 30000;
  const std::string nest = std::string(d, '[') + std::string(d, ']');
  const std::string deep_extras = "{\"extras\": " + nest + ", \"asset\": {\"version\": \"2.0\"}}";
  const std::string deep_extension =
      "{\"asset\":{\"version\":\"2.0\"},\"extensions\":{\"EXT_x\":" + std::string(d, '{') + std::string(d, '}') + "}}";
  const auto start = std::chrono::steady_clock::now();
  expect_refused(compile_text(deep_extras), "deep extras", "nested deeper");
  expect_refused(compile_text(deep_extension), "deep extension", "nested deeper");
  const std::vector<uint8_t> glb = make_glb(deep_extras);
  expect_refused(compile_gltf_memory(glb.data(), glb.size()), "deep .glb", "nested deeper");
  // From a file too (the CLI's path).
  const std::string path = scenetest::temp_dir() + "/deep.gltf";
  scenetest::write_file(path, deep_extras);
  expect_refused(compile_gltf_file(path), "deep file", "nested deeper");
  EXPECT_LT(seconds_since(start), 2.0);

  // Exactly at the limit is fine; brackets inside strings (escaped quotes too) do not count.
  const int at = kMaxJsonDepth - 1;   // plus the outer object
  const std::string legal = "{\"asset\":{\"version\":\"2.0\"},\"extras\":" + std::string(size_t(at), '[') +
                            std::string(size_t(at), ']') + "}";
  const CompileResult ok = compile_text(legal);
  EXPECT_EQ(ok.error.find("nested deeper"), std::string::npos) << ok.error;
  const std::string in_string = "{\"asset\":{\"version\":\"2.0\"},\"extras\":\"\\\"" + std::string(1000, '[') + "\"}";
  const CompileResult s = compile_text(in_string);
  EXPECT_EQ(s.error.find("nested deeper"), std::string::npos) << s.error;
}

// glTF 1.0 (meshes as an object, binary files of GLB version 1) is refused by name, not as a file
// with no meshes or a broken chunk; so are Debian's glTF 1.0 test models when installed.
TEST(ScenecLimits, Gltf1IsRefusedByVersion) {
  const std::string v1 = "{\"asset\":{\"version\":\"1.0\"},\"meshes\":{\"m\":{\"primitives\":[]}}}";
  expect_refused(compile_text(v1), "asset version 1.0", "glTF 1.0 is not supported (glTF 2.0 only)");
  // glTF 1.0 files may state it as a number, which the glTF parser refuses before anything else.
  const std::string number = "{\"asset\":{\"version\":1},\"meshes\":{\"m\":{\"primitives\":[]}}}";
  expect_refused(compile_text(number), "asset version 1", "glTF 1.0 is not supported (glTF 2.0 only)");
  std::vector<uint8_t> glb = make_glb(positions_gltf({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  ASSERT_TRUE(compile_gltf_memory(glb.data(), glb.size()).ok);
  glb[4] = 1;  // the header's version
  expect_refused(compile_gltf_memory(glb.data(), glb.size()), "GLB version 1", "GLB version 1 is not supported");
  const std::string dir = "/usr/share/assimp/models/glTF/";
  for (const char* file : {"TwoBoxes/TwoBoxes.gltf", "BoxTextured-glTF-Binary/BoxTextured.glb",
                           "CesiumMilkTruck/CesiumMilkTruck.gltf", "IncorrectVertexArrays/Cube_v1.gltf"}) {
    if (access((dir + file).c_str(), R_OK) != 0) continue;
    expect_refused(compile_gltf_file(dir + file), file, "is not supported (glTF 2.0 only)");
  }
}

TEST(ScenecLimits, VeryLargeJsonIsRefusedBeforeParsing) {
  // Three bytes per empty material, about 3 KB each once parsed; members of "extras" about 400 bytes.
  std::string materials = "{\"asset\":{\"version\":\"2.0\"},\"materials\":[{}";
  for (int i = 1; i < 40000; ++i) materials += ",{}";
  materials += "]}";
  std::string extras = "{\"asset\":{\"version\":\"2.0\"},\"extras\":{\"k0\":\"\"";
  for (int i = 1; i < 300000; ++i) extras += ",\"k" + std::to_string(i) + "\":\"\"";
  extras += "}}";
  const long rss_before = peak_rss_mb();
  const auto start = std::chrono::steady_clock::now();
  expect_refused(compile_text(materials), "40000 materials", "JSON too large");
  expect_refused(compile_text(extras), "300000 extras members", "JSON too large");
  EXPECT_LT(seconds_since(start), 1.0);
  EXPECT_LT(peak_rss_mb() - rss_before, 50);
  // Base64 buffers are strings: a large one does not count.
  const std::vector<float> many(3 * 30000, 0.5f);
  const CompileResult big_buffer = compile_text(positions_gltf(many));
  EXPECT_EQ(big_buffer.error.find("JSON too large"), std::string::npos) << big_buffer.error;
}

TEST(ScenecLimits, AccessorCountIsCheckedBeforeAllocating) {
  const std::vector<float> tri = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const long rss_before = peak_rss_mb();
  const auto start = std::chrono::steady_clock::now();
  // POSITION claims 2^26 elements (1.5 GB as doubles) of a 36-byte view; 2^28 would be refused by
  // the scene's vertex total before the accessor is looked at.
  std::string json = positions_gltf(tri);
  const std::string small = "\"count\":3,";
  json.replace(json.find(small), small.size(), "\"count\":67108864,");
  expect_refused(compile_text(json), "huge POSITION count", "outside its buffer view");
  const std::vector<uint8_t> glb = make_glb(json);
  expect_refused(compile_gltf_memory(glb.data(), glb.size()), "huge POSITION count (.glb)", "outside its buffer view");
  // TEXCOORD_0 claiming 2^28 elements of the same view.
  const std::string uv = positions_gltf(tri, ",\"TEXCOORD_0\":1",
                                        ",{\"bufferView\":0,\"componentType\":5126,\"count\":268435456,\"type\":\"VEC2\"}");
  expect_refused(compile_text(uv), "huge TEXCOORD_0 count", "outside its buffer view");
  // No buffer view at all: zeros nothing in the file backs.
  const std::string unbacked = positions_gltf(tri, ",\"TEXCOORD_0\":1",
                                              ",{\"componentType\":5126,\"count\":268435456,\"type\":\"VEC2\"}");
  expect_refused(compile_text(unbacked), "unbacked accessor", "without a buffer view");
  EXPECT_LT(seconds_since(start), 2.0);
  EXPECT_LT(peak_rss_mb() - rss_before, 200) << "the refused accessors allocated their claimed size";

  // The same file with its true count compiles.
  const CompileResult ok = compile_text(positions_gltf(tri));
  EXPECT_TRUE(ok.ok) << ok.error;
}

TEST(ScenecLimits, SpecialFilesAreNotRead) {
  const std::string dir = scenetest::temp_dir();
  for (const char* name : {"zero.glb", "zero.gltf", "zero.mls"}) {
    const std::string path = dir + "/" + name;
    ASSERT_EQ(symlink("/dev/zero", path.c_str()), 0);
    const auto start = std::chrono::steady_clock::now();
    expect_refused(compile_gltf_file(path), path, "not a regular file");
    Blob blob;
    std::string error;
    EXPECT_FALSE(load_blob_file(path, &blob, &error)) << path;
    EXPECT_NE(error.find("not a regular file"), std::string::npos) << error;
    EXPECT_LT(seconds_since(start), 1.0) << path;
  }
  const std::string fifo = dir + "/pipe.glb";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  expect_refused(compile_gltf_file(fifo), fifo, "not a regular file");
  expect_refused(compile_gltf_file(dir), dir, "not a regular file");
  // An external buffer that is a device is refused the same way.
  const std::string ext = dir + "/external.gltf";
  scenetest::write_file(ext, "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"zero.glb\"}]}");
  const CompileResult r = compile_gltf_file(ext);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error.find('\n'), std::string::npos) << r.error;
}

TEST(ScenecLimits, DegenerateOnlyGeometryCompiles) {
  // Two collinear triangles: no plane separates them.
  const CompileResult collinear = compile_text(positions_gltf({0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 4, 0, 0, 5, 0, 0}));
  ASSERT_TRUE(collinear.ok) << collinear.error;
  EXPECT_EQ(collinear.report.triangles, 2u);
  // One vertex at 3e38: after normalization every other vertex collapses onto one point.
  const CompileResult collapsed =
      compile_text(positions_gltf({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 0, 3e38f, 0, 0}));
  ASSERT_TRUE(collapsed.ok) << collapsed.error;
  EXPECT_EQ(collapsed.report.triangles, 2u);
  for (const CompileResult* r : {&collinear, &collapsed}) {
    Scene scene;
    EXPECT_TRUE(read_scene(r->blob.data(), r->blob.size, &scene).ok());
  }
  // Degenerate triangles among real ones still compile.
  const CompileResult mixed =
      compile_text(positions_gltf({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 0, 1, 1, 0, 1, 0, 1, 1}));
  ASSERT_TRUE(mixed.ok) << mixed.error;
  EXPECT_EQ(mixed.report.triangles, 3u);
}

TEST(ScenecLimits, SharedMeshTotalsAreCheckedBeforeReading) {
  // 18 levels of nodes listing the next one twice: 2^18 instances of a mesh with 2^10 triangles
  // (one index buffer of 3 * 2^10 zeros) = 2^28 triangles from a small file.
  std::string nodes;
  for (int i = 0; i < 18; ++i) nodes += "{\"children\":[" + std::to_string(i + 1) + "," + std::to_string(i + 1) + "]},";
  nodes += "{\"mesh\":0}";
  std::string json = positions_gltf({0, 0, 0, 1, 0, 0, 0, 1, 0});
  json = json.substr(0, json.find("\"scenes\""));
  const std::vector<uint8_t> zeros(3 * 1024 * 2, 0);
  json.replace(json.find("\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}"),
               std::string("\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}").size(),
               "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1");
  json.replace(json.find("\"type\":\"VEC3\"}"), std::string("\"type\":\"VEC3\"}").size(),
               "\"type\":\"VEC3\"},{\"bufferView\":1,\"componentType\":5123,\"count\":3072,\"type\":\"SCALAR\"}");
  json.replace(json.find("}],\"accessors\""), 2,
               "},{\"buffer\":1,\"byteLength\":" + std::to_string(zeros.size()) + "}]");
  json.replace(json.find("}],\"bufferViews\""), 2,
               "},{\"byteLength\":" + std::to_string(zeros.size()) + ",\"uri\":\"data:application/octet-stream;base64," +
                   base64(zeros) + "\"}]");
  json += "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[" + nodes + "]}";
  const long rss_before = peak_rss_mb();
  const auto start = std::chrono::steady_clock::now();
  expect_refused(compile_text(json), "shared mesh", "too many");
  EXPECT_LT(seconds_since(start), 1.0);
  EXPECT_LT(peak_rss_mb() - rss_before, 100);
  // The mesh under a single node is legal and compiles.
  const std::string one = json.substr(0, json.find("\"nodes\":[{\"children\"")) + "\"nodes\":[{\"mesh\":0}]}";
  const CompileResult ok = compile_text(one);
  EXPECT_TRUE(ok.ok) << ok.error;
  EXPECT_EQ(ok.report.triangles, 1024u);
}

TEST(ScenecLimits, NormalsSurviveTinyAndHugeNodeScales) {
  // A triangle with +z normals under a node scale of 1e-110 (the normal's cofactor transform gives
  // 1e-220, whose square underflows) and 1e100 (whose square overflows).
  const std::vector<float> tri = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  for (const char* scale : {"1e-110", "1e100"}) {
    std::string json = positions_gltf(tri, ",\"NORMAL\":1",
                                      ",{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}");
    const std::vector<float> normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    std::vector<uint8_t> nbytes(36);
    std::memcpy(nbytes.data(), normals.data(), 36);
    json.replace(json.find("}],\"accessors\""), 2, "},{\"buffer\":1,\"byteLength\":36}]");
    json.replace(json.find("}],\"bufferViews\""), 2,
                 "},{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64," + base64(nbytes) + "\"}]");
    json.replace(json.find("{\"mesh\":0}"), std::string("{\"mesh\":0}").size(),
                 std::string("{\"mesh\":0,\"scale\":[") + scale + "," + scale + "," + scale + "]}");
    SceneMesh mesh;
    std::vector<std::string> warnings;
    std::string error;
    ASSERT_TRUE(import_gltf_memory(reinterpret_cast<const unsigned char*>(json.data()), json.size(), "", &mesh,
                                   &warnings, &error))
        << scale << ": " << error;
    ASSERT_EQ(mesh.nodes.size(), 1u);
    ASSERT_EQ(mesh.nodes[0].primitives.size(), 1u);
    for (const MeshVertex& v : mesh.nodes[0].primitives[0].vertices) {
      EXPECT_NEAR(v.normal[2], 1.0, 1e-12) << scale;
      EXPECT_EQ(v.normal[0], 0.0) << scale;
    }
  }
}

// JSON must be UTF-8, but exporters write names as they were given (assimp's glTF export of an OBJ
// with a Latin-1 material name): such bytes are read as Latin-1 with a warning, in a .gltf and in a
// .glb (whose JSON chunk grows and whose BIN chunk stays where the lengths say), instead of the JSON
// parser refusing the whole file.
TEST(ScenecLimits, BytesThatAreNotUtf8AreReadAsLatin1) {
  const std::vector<float> tri = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::string gltf = positions_gltf(tri);
  gltf.replace(gltf.find("{\"mesh\":0}"), 10, "{\"mesh\":0,\"name\":\"Terraind\xE4k \xB0\"}");
  std::vector<uint8_t> bin(36);
  std::memcpy(bin.data(), tri.data(), 36);
  const std::vector<uint8_t> glb = make_glb(
      "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36}],\"bufferViews\":[{\"buffer\":0,"
      "\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"scenes\":[{\"nodes\":[0]}],"
      "\"nodes\":[{\"mesh\":0,\"name\":\"Terraind\xE4k \xB0\"}]}",
      bin);
  const std::vector<uint8_t> text(gltf.begin(), gltf.end());
  for (const std::vector<uint8_t>* input : {&text, &glb}) {
    SceneMesh mesh;
    std::vector<std::string> warnings;
    std::string error;
    ASSERT_TRUE(import_gltf_memory(input->data(), input->size(), "", &mesh, &warnings, &error)) << error;
    ASSERT_EQ(mesh.nodes.size(), 1u);
    EXPECT_EQ(mesh.nodes[0].name, "Terraind\xC3\xA4k \xC2\xB0");
    ASSERT_EQ(mesh.nodes[0].primitives.size(), 1u);
    EXPECT_EQ(mesh.nodes[0].primitives[0].triangles.size(), 1u);
    EXPECT_TRUE(std::find(warnings.begin(), warnings.end(),
                          "the JSON holds 2 byte(s) that are not UTF-8: read as Latin-1") != warnings.end())
        << (warnings.empty() ? "no warning" : warnings[0]);
  }
  // Well-formed UTF-8 is left as it is, without a warning.
  std::string utf8 = positions_gltf(tri);
  utf8.replace(utf8.find("{\"mesh\":0}"), 10, "{\"mesh\":0,\"name\":\"Terraind\xC3\xA4k\"}");
  SceneMesh mesh;
  std::vector<std::string> warnings;
  std::string error;
  ASSERT_TRUE(import_gltf_memory(reinterpret_cast<const unsigned char*>(utf8.data()), utf8.size(), "", &mesh,
                                 &warnings, &error))
      << error;
  EXPECT_EQ(mesh.nodes[0].name, "Terraind\xC3\xA4k");
  EXPECT_TRUE(warnings.empty()) << warnings[0];
}

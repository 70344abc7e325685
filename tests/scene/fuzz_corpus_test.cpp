// The fuzzer's committed seed corpus (tests/fuzz/corpus/*.mls) stays valid as the format evolves.
// Regenerate it with: MASKLINE_WRITE_FUZZ_CORPUS=1 build/san/tests --gtest_filter='SceneFuzzCorpus.*'
#include <gtest/gtest.h>

#include <dirent.h>

#include <cstdlib>

#include <random>
#include <string>
#include <vector>

#include "tests/cli/cli_runner.h"
#include "tests/scene/scene_test_util.h"

using namespace ml;

namespace {

std::string corpus_dir() { return clitest::in_source_tree("tests/fuzz/corpus"); }

std::vector<std::pair<std::string, CompileResult>> seeds() {
  std::vector<std::pair<std::string, CompileResult>> out;
  out.emplace_back("boxes.mls", compile_mesh(scenetest::crossing_boxes_mesh()));
  CompileOptions no_bsp;
  no_bsp.build_bsp = false;
  out.emplace_back("boxes_nobsp.mls", compile_mesh(scenetest::crossing_boxes_mesh(), no_bsp));
  SceneMesh soup;
  soup.materials.resize(2);
  soup.nodes.resize(2);
  soup.nodes[1].parent = 0;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 0; n < 2; ++n) {
    MeshPrimitive p;
    p.material = uint32_t(n);
    for (int i = 0; i < 12; ++i) {
      MeshVertex v;
      for (double& c : v.position) c = u(rng);
      for (double& c : v.normal) c = u(rng);
      v.uv[0] = u(rng);
      p.vertices.push_back(v);
    }
    for (uint32_t i = 0; i < 4; ++i) p.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    soup.nodes[size_t(n)].primitives.push_back(p);
  }
  out.emplace_back("soup.mls", compile_mesh(soup));
  return out;
}

}  // namespace

TEST(SceneFuzzCorpus, SeedsAreValidBlobs) {
  const std::string dir = corpus_dir();
  if (const char* w = std::getenv("MASKLINE_WRITE_FUZZ_CORPUS"); w && std::string(w) == "1") {
    for (const auto& [name, r] : seeds()) {
      ASSERT_TRUE(r.ok) << name << ": " << r.error;
      std::string error;
      ASSERT_TRUE(save_blob_file(dir + "/" + name, r.blob, &error)) << error;
    }
  }
  DIR* d = opendir(dir.c_str());
  ASSERT_NE(d, nullptr) << "no corpus at " << dir;
  int count = 0;
  size_t bytes = 0;
  while (dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name.size() < 4 || name.substr(name.size() - 4) != ".mls") continue;
    Blob blob;
    std::string error;
    ASSERT_TRUE(load_blob_file(dir + "/" + name, &blob, &error)) << error;
    Scene s;
    const Status st = read_scene(blob.data(), blob.size, &s);
    EXPECT_TRUE(st.ok()) << name << ": " << st.message;
    bytes += blob.size;
    ++count;
  }
  closedir(d);
  EXPECT_GE(count, 3);
  EXPECT_LT(bytes, 200u * 1024u);
}

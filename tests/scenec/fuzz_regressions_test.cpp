// Every committed glTF regression input (tests/fuzz/gltf_regressions/: audit and fuzzer findings, also
// the glTF fuzzer's seeds) compiles or is refused with one line, and what compiles renders with both
// renderers — in the library and through the CLI, quickly and without a sanitizer report.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "tests/cli/cli_runner.h"
#include "tests/scene/scene_test_util.h"

namespace {

std::string regressions_dir() { return clitest::in_source_tree("tests/fuzz/gltf_regressions"); }

std::vector<std::string> regression_files() {
  std::vector<std::string> out;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(regressions_dir(), ec), end; !ec && it != end; it.increment(ec))
    if (it->is_regular_file(ec)) out.push_back(it->path().string());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST(ScenecFuzzRegressions, EachInputCompilesOrFailsWithOneLine) {
  const std::vector<std::string> files = regression_files();
  ASSERT_FALSE(files.empty()) << regressions_dir();
  for (const std::string& f : files) {
    const auto start = std::chrono::steady_clock::now();
    const ml::CompileResult r = ml::compile_gltf_file(f);
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0) << f;
    if (!r.ok) {
      EXPECT_FALSE(r.error.empty()) << f;
      EXPECT_EQ(r.error.find('\n'), std::string::npos) << f << ": " << r.error;
      continue;
    }
    ml::Scene scene;
    EXPECT_TRUE(ml::read_scene(r.blob.data(), r.blob.size, &scene).ok()) << f;
  }
}

TEST(ScenecFuzzRegressions, TheCliRendersOrRefusesEachWithOneLine) {
  const std::string dir = clitest::make_temp_dir();
  for (const std::string& f : regression_files()) {
    for (const char* renderer : {"tiler", "scanline"}) {
      const clitest::RunResult r = clitest::run_cli({"render", f, "--renderer", renderer, "--size", "24x16", "-o", dir + "/x.png"}, 30);
      EXPECT_FALSE(r.sanitizer_report() || r.signaled || r.timed_out) << f << ": " << r.describe();
      EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 1) << f << ": " << r.describe();
      // The compiler's warnings (a texture ignored, ...) and then, on a refusal, its one line.
      EXPECT_EQ(r.err_lines_besides_warnings().size(), r.exit_code == 0 ? 0u : 1u) << f << ": " << r.describe();
    }
  }
  clitest::remove_tree(dir);
}

// Bad input is normal input: every glTF file Debian's assimp-testmodels ships (good, odd and broken)
// either renders to a PNG or is rejected with one line and exit code 1 -- never a crash, a sanitizer
// report or a hang.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "platform/host/png_io.h"
#include "tests/cli/cli_runner.h"
#include "tests/common/gltf_files.h"

namespace {

TEST(CliModels, EveryAssimpGltfRendersOrFailsWithOneLine) {
  const std::vector<std::string> files = testfiles::gltf_files_under(testfiles::kAssimpGltf2Models);
  if (files.empty()) GTEST_SKIP() << "assimp-testmodels not installed";
  const std::string dir = clitest::make_temp_dir();
  const std::string png = dir + "/out.png";
  int rendered = 0, rejected = 0;
  for (const std::string& file : files) {
    remove(png.c_str());
    // A hang's limit, not a speed target: the sanitized CLI compiles 2CylinderEngine (121,496
    // triangles, three BSP trees) in about 75 s on a busy two-core machine.
    const clitest::RunResult r = clitest::run_cli({"render", file, "--size", "64x48", "-o", png}, 180);
    SCOPED_TRACE(file);
    EXPECT_FALSE(r.timed_out) << r.describe();
    EXPECT_FALSE(r.signaled) << r.describe();
    EXPECT_FALSE(r.sanitizer_report()) << r.describe();
    if (r.exit_code == 0) {
      ++rendered;
      int w = 0, h = 0;
      std::vector<uint32_t> px;
      EXPECT_EQ(mlhost::read_png(png, &w, &h, &px, false), "");
      EXPECT_EQ(w, 64);
      EXPECT_EQ(h, 48);
    } else {
      ++rejected;
      EXPECT_EQ(r.exit_code, 1) << r.describe();
      EXPECT_EQ(r.err_lines().size(), 1u) << r.describe();
      EXPECT_FALSE(clitest::file_exists(png));
    }
  }
  clitest::remove_tree(dir);
  // Most of the collection is valid glTF: a walk that rejects everything is broken, not robust.
  EXPECT_GT(rendered, int(files.size()) / 2) << rendered << " rendered, " << rejected << " rejected";
  RecordProperty("rendered", rendered);
  RecordProperty("rejected", rejected);
}

// A model whose primitives are all points or lines has no triangles: the one line says why (the
// compiler's warning about the skipped primitives), not just that.
TEST(CliModels, ANoTrianglesRefusalNamesTheSkippedPrimitives) {
  const std::string points =
      std::string(testfiles::kAssimpGltf2Models) + "/glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_00.gltf";
  if (!clitest::file_exists(points)) GTEST_SKIP() << "assimp-testmodels not installed";
  const std::string dir = clitest::make_temp_dir();
  const clitest::RunResult r = clitest::run_cli({"render", points, "-o", dir + "/out.png"});
  clitest::remove_tree(dir);
  EXPECT_EQ(r.exit_code, 1) << r.describe();
  ASSERT_EQ(r.err_lines().size(), 1u) << r.describe();
  EXPECT_NE(r.err_lines()[0].find("scene has no triangles"), std::string::npos) << r.describe();
  EXPECT_NE(r.err_lines()[0].find("mode POINTS skipped"), std::string::npos) << r.describe();
}

// A model that renders despite the compiler's warnings: `render` and `info` print them on stderr as
// `compile` does (a user then sees why part of the model is missing), and still succeed.
TEST(CliModels, RenderAndInfoPrintTheCompilerWarnings) {
  const std::string cube = std::string(testfiles::kAssimpGltf2Models) + "/IncorrectVertexArrays/Cube.gltf";
  if (!clitest::file_exists(cube)) GTEST_SKIP() << "assimp-testmodels not installed";
  const std::string dir = clitest::make_temp_dir();
  const clitest::RunResult compiled = clitest::run_cli({"compile", cube, "-o", dir + "/cube.mls"});
  const clitest::RunResult rendered = clitest::run_cli({"render", cube, "--size", "64x48", "-o", dir + "/out.png"});
  const clitest::RunResult info = clitest::run_cli({"info", cube});
  const bool png = clitest::file_exists(dir + "/out.png");
  clitest::remove_tree(dir);
  ASSERT_EQ(compiled.exit_code, 0) << compiled.describe();
  ASSERT_GE(compiled.err_lines().size(), 2u) << compiled.describe();
  for (const clitest::RunResult* r : {&rendered, &info}) {
    EXPECT_EQ(r->exit_code, 0) << r->describe();
    EXPECT_EQ(r->err_lines(), compiled.err_lines()) << r->describe();
    EXPECT_FALSE(r->sanitizer_report()) << r->describe();
  }
  EXPECT_TRUE(rendered.err_lines_besides_warnings().empty()) << rendered.describe();
  EXPECT_TRUE(png);
  EXPECT_NE(info.out.find("compiler warnings: " + std::to_string(compiled.err_lines().size()) + " (on stderr)"),
            std::string::npos) << info.out;
}

}  // namespace

// The CLI's texture options: info lists textures and pool sizes, compile chooses formats, render
// reads texels from the .mls file or through a small pool and gives the same picture.
#include <gtest/gtest.h>

#include "tests/cli/cli_runner.h"

namespace {

using clitest::run_cli;
using clitest::RunResult;

class CliTextures : public clitest::TempDirTest {};

const char* kBoxTextured = "/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb";

TEST_F(CliTextures, InfoListsTexturesAndPoolSizes) {
  const RunResult r = run_cli({"info", "builtin:banded"});
  ASSERT_EQ(r.exit_code, 0) << r.describe();
  EXPECT_NE(r.out.find("texture 0: 64x64 rgb565, 8192 bytes, wrap repeat/repeat, nearest"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("texture 1: 64x64 palette8 (8 colours), 4112 bytes, wrap mirrored/mirrored, nearest"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("texture 2: 128x64 grey4, 4096 bytes, wrap clamp/clamp, nearest"), std::string::npos);
  EXPECT_NE(r.out.find("texture pool bytes: desired 24608 (every texture), minimum 8208 (the largest)"),
            std::string::npos);
  EXPECT_NE(r.out.find("with the minimum texture pool)"), std::string::npos);
}

TEST_F(CliTextures, CompileFormatsAndFileSourceGiveTheSamePicture) {
  if (!clitest::file_exists(kBoxTextured)) GTEST_SKIP() << "assimp-testmodels not installed";
  const RunResult grey = run_cli({"compile", kBoxTextured, "-o", path("grey.mls"), "--texture-format", "grey4",
                                  "--texture-max", "64"});
  ASSERT_EQ(grey.exit_code, 0) << grey.describe();
  const RunResult info = run_cli({"info", path("grey.mls")});
  // BoxTextured's sampler asks for mip levels: 2,048 bytes of texels and 683 of levels.
  EXPECT_NE(info.out.find("texture 0: 64x64 grey4, 2731 bytes with 6 mip levels"), std::string::npos) << info.out;
  const RunResult c = run_cli({"compile", kBoxTextured, "-o", path("box.mls")});
  ASSERT_EQ(c.exit_code, 0) << c.describe();
  const RunResult blob = run_cli({"render", path("box.mls"), "--size", "96x72", "-o", path("blob.png"), "--stats"});
  const RunResult file = run_cli({"render", path("box.mls"), "--size", "96x72", "-o", path("file.png"), "--stats",
                                  "--texture-source", "file", "--texture-pool", "90820"});
  ASSERT_EQ(blob.exit_code, 0) << blob.describe();
  ASSERT_EQ(file.exit_code, 0) << file.describe();
  EXPECT_EQ(clitest::read_bytes(path("blob.png")), clitest::read_bytes(path("file.png")));
  EXPECT_EQ(clitest::json_int(file.out, "texture_loads"), 1);
  EXPECT_EQ(clitest::json_int(file.out, "texture_bytes_loaded"), 90819);  // the texture with its levels
  EXPECT_EQ(clitest::json_int(file.out, "texture_fallbacks"), 0);
  // Too small a pool for the one texture: drawn in the material colour, counted, still exit 0.
  const RunResult tiny = run_cli({"render", path("box.mls"), "--size", "96x72", "--stats", "--texture-pool", "1000"});
  ASSERT_EQ(tiny.exit_code, 0) << tiny.describe();
  EXPECT_EQ(clitest::json_int(tiny.out, "texture_fallbacks"), 1);
}

// --texture-format none: no texels in the blob, each material in its base colour, as a frame draws a
// texture it cannot read (a fallback) and as a build without textures (ML_TEXTURES=0) draws it.
TEST_F(CliTextures, CompileWithoutTexelsDrawsBaseColours) {
  if (!clitest::file_exists(kBoxTextured)) GTEST_SKIP() << "assimp-testmodels not installed";
  const RunResult none = run_cli({"compile", kBoxTextured, "-o", path("none.mls"), "--texture-format", "none"});
  ASSERT_EQ(none.exit_code, 0) << none.describe();
  const RunResult textured = run_cli({"compile", kBoxTextured, "-o", path("box.mls")});
  ASSERT_EQ(textured.exit_code, 0) << textured.describe();
  EXPECT_LT(clitest::read_bytes(path("none.mls")).size(), 2000u);  // the textured blob: 91,856 bytes
  EXPECT_GT(clitest::read_bytes(path("box.mls")).size(), 60000u);
  // info says why the texture has no line of its own.
  const RunResult info = run_cli({"info", path("none.mls")});
  EXPECT_NE(info.out.find("texture 0: no texels stored (images missing or not decodable, or compiled with "
                          "--texture-format none)"),
            std::string::npos)
      << info.out;
  for (const char* renderer : {"tiler", "scanline"}) {
    const RunResult plain = run_cli({"render", path("none.mls"), "--renderer", renderer, "--size", "96x72", "-o",
                                     path("plain.png"), "--stats"});
    const RunResult fallback = run_cli({"render", path("box.mls"), "--renderer", renderer, "--size", "96x72", "-o",
                                        path("fallback.png"), "--texture-pool", "1000"});
    const RunResult texels = run_cli({"render", path("box.mls"), "--renderer", renderer, "--size", "96x72", "-o",
                                      path("texels.png")});
    ASSERT_EQ(plain.exit_code, 0) << plain.describe();
    ASSERT_EQ(fallback.exit_code, 0) << fallback.describe();
    ASSERT_EQ(texels.exit_code, 0) << texels.describe();
    EXPECT_EQ(clitest::json_int(plain.out, "texture_fallbacks"), 0) << renderer;
    EXPECT_EQ(clitest::read_bytes(path("plain.png")), clitest::read_bytes(path("fallback.png"))) << renderer;
    EXPECT_NE(clitest::read_bytes(path("plain.png")), clitest::read_bytes(path("texels.png"))) << renderer;
  }
}

TEST_F(CliTextures, BadTextureOptionsAreUsageErrors) {
  clitest::expect_one_line_error(run_cli({"render", "builtin:banded", "--texture-source", "file"}), 2, "needs a .mls");
  clitest::expect_one_line_error(run_cli({"render", "--texture-source", "flash"}), 2, "--texture-source");
  clitest::expect_one_line_error(run_cli({"render", "--texture-pool", "-3"}), 2, "--texture-pool");
  clitest::expect_one_line_error(run_cli({"compile", kBoxTextured, "-o", path("x.mls"), "--texture-format", "jpeg"}),
                                 2, "--texture-format");
  clitest::expect_one_line_error(run_cli({"compile", kBoxTextured, "-o", path("x.mls"), "--texture-filter", "cubic"}),
                                 2, "--texture-filter");
}

// --texture-filter: every texture sampled nearest or bilinear whatever its glTF sampler asks; model
// (the default) keeps the sampler's.
TEST_F(CliTextures, CompileTextureFilterOverridesTheSamplers) {
  if (!clitest::file_exists(kBoxTextured)) GTEST_SKIP() << "assimp-testmodels not installed";
  const char* const filters[] = {"model", "nearest", "bilinear"};
  for (const char* f : filters) {
    const RunResult c = run_cli({"compile", kBoxTextured, "-o", path(std::string(f) + ".mls"), "--texture-filter", f});
    ASSERT_EQ(c.exit_code, 0) << c.describe();
  }
  const RunResult plain = run_cli({"compile", kBoxTextured, "-o", path("default.mls")});
  ASSERT_EQ(plain.exit_code, 0) << plain.describe();
  EXPECT_EQ(clitest::read_bytes(path("model.mls")), clitest::read_bytes(path("default.mls")));
  // BoxTextured's sampler is bilinear (magFilter LINEAR): nearest changes only the filter.
  const RunResult bilinear = run_cli({"info", path("bilinear.mls")});
  const RunResult nearest = run_cli({"info", path("nearest.mls")});
  EXPECT_NE(bilinear.out.find("wrap repeat/repeat, bilinear"), std::string::npos) << bilinear.out;
  EXPECT_NE(nearest.out.find("wrap repeat/repeat, nearest"), std::string::npos) << nearest.out;
  EXPECT_EQ(clitest::read_bytes(path("bilinear.mls")), clitest::read_bytes(path("model.mls")));
  for (const char* renderer : {"tiler", "scanline"}) {
    const RunResult a = run_cli({"render", path("model.mls"), "--renderer", renderer, "--size", "96x72", "-o",
                                 path("bilinear.png")});
    const RunResult b = run_cli({"render", path("nearest.mls"), "--renderer", renderer, "--size", "96x72", "-o",
                                 path("nearest.png")});
    ASSERT_EQ(a.exit_code, 0) << a.describe();
    ASSERT_EQ(b.exit_code, 0) << b.describe();
    EXPECT_NE(clitest::read_bytes(path("bilinear.png")), clitest::read_bytes(path("nearest.png"))) << renderer;
  }
}

}  // namespace

// The CLI against hostile input and extreme options: every refusal is exit 1 or 2 with one line, fast;
// legal sizes and vectors render with the default camera.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <vector>

#include "tests/cli/cli_runner.h"

namespace {

using clitest::run_cli;
using clitest::RunResult;
using clitest::expect_one_line_error;
using clitest::json_int;

void expect_success(const RunResult& r, const std::string& what) {
  EXPECT_FALSE(r.sanitizer_report()) << what << ": " << r.describe();
  EXPECT_EQ(r.exit_code, 0) << what << ": " << r.describe();
  EXPECT_TRUE(r.err.empty()) << what << ": " << r.err;
}

class CliHostile : public clitest::TempDirTest {
 protected:
  void write_text(const std::string& name, const std::string& text) {
    clitest::write_bytes(path(name), std::vector<unsigned char>(text.begin(), text.end()));
  }
};

TEST_F(CliHostile, DeepJsonIsOneLine) {
  const int d = 30000;
  write_text("deep.gltf", "{\"extras\": " + std::string(d, '[') + std::string(d, ']') + ", \"asset\": {\"version\": \"2.0\"}}");
  const auto start = std::chrono::steady_clock::now();
  expect_one_line_error(run_cli({"compile", path("deep.gltf"), "-o", path("x.mls")}), 1, "compile deep.gltf");
  expect_one_line_error(run_cli({"render", path("deep.gltf"), "-o", path("x.png")}), 1, "render deep.gltf");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
  EXPECT_FALSE(clitest::file_exists(path("x.mls")));
}

TEST_F(CliHostile, SpecialFilesAreNotRead) {
  for (const char* name : {"zero.glb", "zero.gltf", "zero.mls", "zero.bin"}) {
    ASSERT_EQ(symlink("/dev/zero", path(name).c_str()), 0);
    expect_one_line_error(run_cli({"compile", path(name), "-o", path("x.mls")}, 10), 1, std::string("compile ") + name);
    expect_one_line_error(run_cli({"render", path(name), "-o", path("x.png")}, 10), 1, std::string("render ") + name);
  }
  ASSERT_EQ(mkfifo(path("pipe.mls").c_str(), 0600), 0);
  expect_one_line_error(run_cli({"info", path("pipe.mls")}, 10), 1, "info on a FIFO");
  ASSERT_EQ(mkfifo(path("pipe").c_str(), 0600), 0);
  expect_one_line_error(run_cli({"info", path("pipe")}, 10), 1, "info on a FIFO without extension");
}

TEST_F(CliHostile, DefaultCameraFramesEveryLegalSize) {
  for (const std::string size : {"1x1", "1x90", "1x100", "1x4096", "2x4096", "45x4096", "4096x1", "4096x45"}) {
    expect_success(run_cli({"render", "--size", size, "-o", path("x.png")}), "render --size " + size);
    expect_success(run_cli({"render", "--size", size, "--renderer", "scanline", "-o", path("x.png")}),
                   "render scanline --size " + size);
  }
  const RunResult info = run_cli({"info", "--size", "1x100"});
  expect_success(info, "info --size 1x100");
  EXPECT_NE(info.out.find("arena bytes (scanline, 1x100"), std::string::npos) << info.out;
}

TEST_F(CliHostile, UpVectorsOfAnyScaleAreNormalized) {
  for (const std::string up : {"1e300,1e300,0", "0,1e-300,0", "0,1e308,0", "4.9e-324,1e-320,0", "-1e-310,1e-310,0"})
    expect_success(run_cli({"render", "--size", "32x24", "--up", up, "-o", path("x.png")}), "--up " + up);
  expect_one_line_error(run_cli({"render", "--up", "0,0,0"}), 2, "--up 0,0,0");
  expect_one_line_error(run_cli({"render", "--up", "0,-0,0"}), 2, "--up 0,-0,0");
}

TEST_F(CliHostile, HugeArenaIsNotASanitizerReport) {
  const RunResult r = run_cli({"render", "--size", "32x24", "--arena", "1099511627776", "-o", path("x.png")});
  EXPECT_FALSE(r.sanitizer_report()) << r.describe();
  EXPECT_FALSE(r.signaled || r.timed_out) << r.describe();
  EXPECT_LE(r.err_lines().size(), 1u) << r.describe();
  EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 1) << r.describe();
  expect_one_line_error(run_cli({"render", "--size", "32x24", "--arena", "100", "-o", path("x.png")}), 1, "arena 100");
}

TEST_F(CliHostile, DegenerateOnlySceneRendersTheBackground) {
  // Two collinear triangles: six float VEC3 positions on the x axis.
  const std::string b64 =   // 0,0,0 1,0,0 2,0,0 3,0,0 4,0,0 5,0,0
      "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAQAAAAAAAAAAAAABAQAAAAAAAAAAAAACAQAAAAAAAAAAAAACgQAAAAAAAAAAA";
  write_text("line.gltf",
             "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":72,\"uri\":\"data:application/"
             "octet-stream;base64," + b64 + "\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":72}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":6,\"type\":\"VEC3\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}");
  expect_success(run_cli({"compile", path("line.gltf"), "-o", path("line.mls")}), "compile line.gltf");
  for (const char* renderer : {"tiler", "scanline"}) {
    const RunResult r = run_cli({"render", path("line.mls"), "--renderer", renderer, "--size", "40x30", "--stats",
                                 "-o", path("line.png")});
    expect_success(r, std::string("render ") + renderer);
    EXPECT_NE(r.out.find("\"triangles_drawn\":0"), std::string::npos) << r.out;
  }
}

}  // namespace

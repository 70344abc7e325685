// The CLI as a user meets it: help, usage errors (exit 2, one line), read failures (exit 1, one line),
// compile/info on a real model, and render outputs (PNG, ids, work image, stats JSON).
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "platform/host/png_io.h"
#include "tests/cli/cli_runner.h"
#include "view/vertex_cache.h"

namespace {

using clitest::run_cli;
using clitest::RunResult;
using clitest::expect_one_line_error;
using clitest::json_int;

using CliTemp = clitest::TempDirTest;

// The text after `prefix` on the line that starts with it (within `text`), or "".
std::string after(const std::string& text, const std::string& prefix) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (line.compare(0, prefix.size(), prefix) == 0) return line.substr(prefix.size());
  return "";
}

TEST(CliHelp, EveryCommandHasHelpAndExitsZero) {
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"--help"}, {"help"}, {"-h"}, {"compile", "--help"}, {"info", "--help"}, {"render", "--help"}, {"help", "render"}}) {
    const RunResult r = run_cli(args);
    EXPECT_EQ(r.exit_code, 0) << args[0] << ": " << r.describe();
    EXPECT_NE(r.out.find("usage: maskline"), std::string::npos) << args[0];
    EXPECT_TRUE(r.err.empty()) << r.err;
  }
  EXPECT_NE(run_cli({"render", "--help"}).out.find("--renderer"), std::string::npos);
  EXPECT_NE(run_cli({"compile", "--help"}).out.find("-o OUT.mls"), std::string::npos);
}

TEST(CliUsage, UnknownOptionsAndCommandsExitTwoWithOneLine) {
  expect_one_line_error(run_cli({"render", "--bogus"}), 2, "render --bogus");
  expect_one_line_error(run_cli({"info", "--frobnicate", "x"}), 2, "info --frobnicate");
  expect_one_line_error(run_cli({"compile", "--what"}), 2, "compile --what");
  expect_one_line_error(run_cli({"paint"}), 2, "unknown command");
  expect_one_line_error(run_cli({}), 2, "no command");
  expect_one_line_error(run_cli({"render", "--size"}), 2, "missing value");
  expect_one_line_error(run_cli({"compile", "a.glb"}), 2, "compile without -o");
}

TEST(CliUsage, BadSizesAreRejectedWithOneLine) {
  for (const std::string size : {"0x0", "100000x100000", "12", "x5", "5x", "-3x4", "4097x10", "10x99999999999999999999"}) {
    const RunResult r = run_cli({"render", "--size", size});
    ASSERT_TRUE(r.exit_code == 2 || r.exit_code == 1) << size << ": " << r.describe();
    expect_one_line_error(r, r.exit_code, "--size " + size);
  }
}

TEST(CliUsage, BadValuesExitTwoWithOneLine) {
  const std::vector<std::vector<std::string>> cases = {
      {"--aa", "0"},           {"--aa", "9"},          {"--aa", "three"},         {"--fov", "0"},
      {"--fov", "171"},        {"--fov", "nan"},       {"--shading", "phong"},    {"--renderer", "raytracer"},
      {"--background", "zz"},  {"--background", "1234567"}, {"--eye", "1,2"},    {"--eye", "nan,0,0"},
      {"--eye", "inf,0,0"},    {"--eye", "1e30,0,0"},  {"--up", "0,0,0"},         {"--seed", "-1"},
      {"--near", "-1"},        {"--arena", "lots"},    {"--shading", "lines"},    {"--aa", "3"},
      {"--renderer", "scanline", "--work", "w.png"},  {"--eye", "0,0,0", "--target", "0,0,0"},
      {"--filter", "gauss"},   {"--filter", "cosine"}, {"--filter", "cosine", "--aa", "4", "--renderer", "scanline"},
      {"--samples", "random"}, {"--samples", "jittered"}, {"--samples", "jittered", "--aa", "4", "--renderer", "scanline"}};
  for (const auto& c : cases) {
    std::vector<std::string> args{"render"};
    args.insert(args.end(), c.begin(), c.end());
    std::string what;
    for (const auto& a : c) what += a + " ";
    expect_one_line_error(run_cli(args), 2, what);
  }
}

TEST_F(CliTemp, MissingAndUnreadableFilesExitOneWithOneLine) {
  expect_one_line_error(run_cli({"render", path("nope.glb")}), 1, "render missing");
  expect_one_line_error(run_cli({"info", path("nope.mls")}), 1, "info missing");
  expect_one_line_error(run_cli({"compile", path("nope.gltf"), "-o", path("x.mls")}), 1, "compile missing");
  clitest::write_bytes(path("garbage.bin"), {'x', 'y', 'z'});
  expect_one_line_error(run_cli({"info", path("garbage.bin")}), 1, "unknown type");
  clitest::write_bytes(path("empty.mls"), {});
  expect_one_line_error(run_cli({"info", path("empty.mls")}), 1, "empty blob");
  clitest::write_bytes(path("empty.glb"), {});
  expect_one_line_error(run_cli({"info", path("empty.glb")}), 1, "empty glb");
}

TEST_F(CliTemp, TruncatedGlbExitsOne) {
  const std::string glb = clitest::engine_glb();
  if (glb.empty()) GTEST_SKIP() << "assimp-testmodels not installed";
  const auto bytes = clitest::read_bytes(glb);
  ASSERT_GT(bytes.size(), 1000u);
  for (size_t keep : {size_t(11), size_t(20), bytes.size() / 2, bytes.size() - 1}) {
    clitest::write_bytes(path("cut.glb"), std::vector<unsigned char>(bytes.begin(), bytes.begin() + long(keep)));
    expect_one_line_error(run_cli({"compile", path("cut.glb"), "-o", path("cut.mls")}), 1,
                          "truncated to " + std::to_string(keep));
    EXPECT_FALSE(clitest::file_exists(path("cut.mls")));
  }
}

TEST_F(CliTemp, CompileAndInfoOnTheEngine) {
  const std::string glb = clitest::engine_glb();
  if (glb.empty()) GTEST_SKIP() << "assimp-testmodels not installed";
  const RunResult c = run_cli({"compile", glb, "-o", path("engine.mls")}, 120);
  ASSERT_EQ(c.exit_code, 0) << c.describe();
  ASSERT_TRUE(clitest::file_exists(path("engine.mls")));
  const RunResult from_mls = run_cli({"info", path("engine.mls"), "--size", "160x120"});
  const RunResult from_glb = run_cli({"info", glb, "--size", "160x120"}, 120);
  ASSERT_EQ(from_mls.exit_code, 0) << from_mls.describe();
  ASSERT_EQ(from_glb.exit_code, 0) << from_glb.describe();
  const std::string tri_text = after(from_mls.out, "triangles: ");
  ASSERT_FALSE(tri_text.empty()) << from_mls.out;
  const long triangles = std::stol(tri_text);
  EXPECT_GT(triangles, 1000);
  // The blob on disk and the in-memory compile describe the same scene.
  EXPECT_NE(from_glb.out.find("triangles: " + std::to_string(triangles) + "\n"), std::string::npos) << from_glb.out;
  for (const char* key : {"nodes: ", "materials: ", "bounds (world units)", "bounds (glTF units)", "bsp: ",
                          "arena bytes (tiler, 160x120", "arena bytes (scanline, 160x120", "spare bytes (tiler, 160x120",
                          "spare bytes (scanline, 160x120"})
    EXPECT_NE(from_mls.out.find(key), std::string::npos) << key << " in " << from_mls.out;
  // The spare bytes are render_spare_bytes: on a 64-bit host the scanline renderer's vertex cache for the
  // engine's meshes (1,024 entries), none on a 32-bit one.
  const long spare = std::stol(after(from_mls.out, "spare bytes (scanline, 160x120, aa 1): "));
  EXPECT_EQ(spare, sizeof(void*) >= 8 ? long(ml::VertexCache::arena_bytes(ml::VertexCache::kMaxEntries)) : 0L) << from_mls.out;
  const auto blob = clitest::read_bytes(path("engine.mls"));
  EXPECT_NE(from_mls.out.find("(" + std::to_string(blob.size()) + " bytes)"), std::string::npos) << from_mls.out;
}

TEST_F(CliTemp, BlobWithAFlippedByteIsRejected) {
  const std::string glb = clitest::engine_glb();
  if (glb.empty()) GTEST_SKIP() << "assimp-testmodels not installed";
  ASSERT_EQ(run_cli({"compile", glb, "-o", path("ok.mls")}, 120).exit_code, 0);
  auto bytes = clitest::read_bytes(path("ok.mls"));
  ASSERT_GT(bytes.size(), 64u);
  for (size_t at : {size_t(2), size_t(9), size_t(20), bytes.size() / 2, bytes.size() - 1}) {
    auto bad = bytes;
    bad[at] ^= 0x10;
    clitest::write_bytes(path("bad.mls"), bad);
    expect_one_line_error(run_cli({"info", path("bad.mls")}), 1, "flipped byte at " + std::to_string(at));
    expect_one_line_error(run_cli({"render", path("bad.mls"), "--size", "32x24"}), 1,
                          "render flipped byte at " + std::to_string(at));
  }
  // Truncated blob.
  clitest::write_bytes(path("short.mls"), std::vector<unsigned char>(bytes.begin(), bytes.begin() + long(bytes.size() / 3)));
  expect_one_line_error(run_cli({"info", path("short.mls")}), 1, "truncated blob");
}

TEST_F(CliTemp, RenderWritesPngIdsWorkAndStats) {
  const RunResult r = run_cli({"render", "--size", "96x64", "-o", path("c.png"), "--ids", path("i.png"), "--work",
                               path("w.png"), "--stats"});
  ASSERT_EQ(r.exit_code, 0) << r.describe();
  EXPECT_TRUE(r.err.empty()) << r.err;
  int w = 0, h = 0;
  std::vector<uint32_t> colour, ids, work;
  ASSERT_EQ(mlhost::read_png(path("c.png"), &w, &h, &colour, false), "");
  EXPECT_EQ(w, 96);
  EXPECT_EQ(h, 64);
  ASSERT_EQ(mlhost::read_png(path("i.png"), &w, &h, &ids, true), "");
  ASSERT_EQ(mlhost::read_png(path("w.png"), &w, &h, &work, false), "");
  // Stats: one JSON object on one line with every field, pixel writes = pixels (once each).
  ASSERT_EQ(r.out.back(), '\n');
  EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << r.out;
  for (const char* key : {"size", "renderer", "aa", "shading", "triangles_in", "triangles_culled", "triangles_drawn",
                          "pixel_writes", "sink_calls", "shading_calls", "peak_arena_bytes", "cells_visited",
                          "cells_visited_per_pixel", "triangles_tiled", "bsp_nodes", "bsp_pieces", "bsp_split_ratio",
                          "pyramid_bytes", "bsp_subtrees_culled", "bsp_subtrees_back_facing", "texture_planes_reused", "n", "m_max", "geometry_samples", "sort_instructions", "texture_bytes_loaded",
                          "texture_bytes_peak"})
    EXPECT_NE(r.out.find(std::string("\"") + key + "\":"), std::string::npos) << key;
  EXPECT_EQ(json_int(r.out, "pixel_writes"), 96 * 64);
  const long long triangles = json_int(r.out, "triangles_in");
  EXPECT_GT(triangles, 100);
  // Ids are triangle id + 1 or 0; the default scene fills part of the screen and leaves background.
  size_t background = 0, background_colour = 0;
  for (size_t i = 0; i < ids.size(); ++i) {
    EXPECT_LE(ids[i], uint32_t(triangles));
    if (ids[i] == 0) {
      ++background;
      background_colour += colour[i] == 0x202830;
    }
  }
  EXPECT_GT(background, 0u);
  EXPECT_LT(background, ids.size());
  EXPECT_EQ(background_colour, background);
  // The work image is not blank where triangles were tiled.
  size_t lit = 0;
  for (uint32_t p : work) lit += p != 0;
  EXPECT_GT(lit, 0u);
}

TEST_F(CliTemp, ArenaTooSmallNamesTheBytesNeeded) {
  const RunResult info = run_cli({"info", "--size", "80x60", "--renderer", "tiler"});
  ASSERT_EQ(info.exit_code, 0) << info.describe();
  const std::string need = after(info.out, "arena bytes (tiler, 80x60, aa 1): ");
  ASSERT_FALSE(need.empty()) << info.out;
  ASSERT_EQ(need.find_first_not_of("0123456789"), std::string::npos) << need;
  const RunResult r = run_cli({"render", "--size", "80x60", "--arena", "64", "-o", path("x.png")});
  expect_one_line_error(r, 1, "arena 64");
  EXPECT_NE(r.err.find(need + " bytes needed"), std::string::npos) << r.err << " (info says " << need << ")";
  EXPECT_FALSE(clitest::file_exists(path("x.png")));
  // Exactly the reported need is enough.
  const RunResult ok = run_cli({"render", "--size", "80x60", "--arena", need, "-o", path("y.png")});
  EXPECT_EQ(ok.exit_code, 0) << ok.describe();
}

// Without --arena a renderer gets its spare bytes (render_spare_bytes): its peak holds them (on a 64-bit
// host the tiler's bands rendered at once and the triangles' facing bits, the scanline renderer's
// vertex cache), and the picture is the one the least arena gives.
TEST_F(CliTemp, DefaultArenaCarriesTheSpareBytesWithTheSameImage) {
  const std::pair<const char*, const char*> cases[] = {{"tiler", "16"}, {"tiler", "0"}, {"scanline", "16"}, {"scanline", "0"}};
  for (const auto& [renderer, rows] : cases) {
    const std::vector<std::string> common{"render", "--renderer", renderer, "--size", "160x120", "--band-rows", rows, "--stats"};
    // The least arena, from the error a too small one gives.
    std::vector<std::string> tiny = common;
    tiny.insert(tiny.end(), {"--arena", "64", "-o", path("tiny.png")});
    const RunResult t = run_cli(tiny);
    const size_t at = t.err.find("arena too small: ");
    ASSERT_NE(at, std::string::npos) << t.describe();
    const std::string need = std::to_string(std::stoll(t.err.substr(at + 17)));
    std::vector<std::string> planned = common, least = common;
    planned.insert(planned.end(), {"-o", path("planned.png")});
    least.insert(least.end(), {"--arena", need, "-o", path("least.png")});
    const RunResult a = run_cli(planned), b = run_cli(least);
    ASSERT_EQ(a.exit_code, 0) << a.describe();
    ASSERT_EQ(b.exit_code, 0) << b.describe();
    EXPECT_GT(json_int(a.out, "peak_arena_bytes"), json_int(b.out, "peak_arena_bytes")) << a.out << b.out;
    int wa = 0, ha = 0, wb = 0, hb = 0;
    std::vector<uint32_t> pa, pb;
    ASSERT_EQ(mlhost::read_png(path("planned.png"), &wa, &ha, &pa, false), "");
    ASSERT_EQ(mlhost::read_png(path("least.png"), &wb, &hb, &pb, false), "");
    EXPECT_EQ(wa, 160);
    EXPECT_EQ(ha, 120);
    EXPECT_TRUE(pa == pb) << renderer << " band rows " << rows;
  }
}

TEST_F(CliTemp, ScanlineRendersWithAntialiasingAndLines) {
  for (const auto& extra : std::vector<std::vector<std::string>>{{"--aa", "3"}, {"--shading", "lines"}, {"--shading", "gouraud", "--aa", "2"}}) {
    std::vector<std::string> args{"render", "--renderer", "scanline", "--size", "64x48", "-o", path("s.png"), "--stats"};
    args.insert(args.end(), extra.begin(), extra.end());
    const RunResult r = run_cli(args);
    ASSERT_EQ(r.exit_code, 0) << extra[0] << " " << extra[1] << ": " << r.describe();
    EXPECT_EQ(json_int(r.out, "pixel_writes"), 64 * 48) << r.out;
    int w = 0, h = 0;
    std::vector<uint32_t> px;
    EXPECT_EQ(mlhost::read_png(path("s.png"), &w, &h, &px, false), "");
  }
}

// A translucent alpha BLEND material (0 < alpha < 1) is drawn opaque by the tiler and blended by the
// scanline renderer: render and show with the tiler name it in one note on stderr; the scanline
// renderer, an opaque BLEND (alpha 1) and an OPAQUE material of alpha 0.5 get none; info says so of
// each material.
TEST_F(CliTemp, TilerNotesTranslucentBlendsItDrawsOpaque) {
  const std::string b64 =  // two triangles: 0,0,0 1,0,0 0,1,0 and the same at z = -1
      "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIC/AACAPwAAAAAAAIC/AAAAAAAAgD8AAIC/";
  const std::string gltf =
      "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":72,\"uri\":\"data:application/"
      "octet-stream;base64," + b64 + "\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":72}],"
      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
      "{\"bufferView\":0,\"byteOffset\":36,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
      "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1]},\"alphaMode\":\"BLEND\"},"
      "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,0.5]},\"alphaMode\":\"BLEND\"},"
      "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,1,0.5]}}],"
      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":1},"
      "{\"attributes\":{\"POSITION\":1},\"material\":0},{\"attributes\":{\"POSITION\":1},\"material\":2}]}],"
      "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}]}";
  clitest::write_bytes(path("blend.gltf"), std::vector<unsigned char>(gltf.begin(), gltf.end()));
  const std::string note =
      "maskline: note: material 1: alphaMode BLEND, translucent: the tiler draws it opaque (--renderer scanline "
      "blends it)";
  const RunResult info = run_cli({"info", path("blend.gltf")});
  ASSERT_EQ(info.exit_code, 0) << info.describe();
  EXPECT_EQ(after(info.out, "material 0: "), "base colour ffffff, alpha 255/255, BLEND, single-sided, no texture");
  EXPECT_EQ(after(info.out, "material 1: "),
            "base colour ff0000, alpha 128/255, BLEND (the tiler draws it opaque), single-sided, no texture");
  EXPECT_EQ(after(info.out, "material 2: "), "base colour 0000ff, OPAQUE, single-sided, no texture");
  for (const std::string renderer : {"tiler", "scanline"}) {
    for (const std::string command : {"render", "show"}) {
      std::vector<std::string> args{command, path("blend.gltf"), "--renderer", renderer, "-o", path("b.png")};
      if (command == "show") args.insert(args.end(), {"--display", "emu:ili9341"});  // the panel's size
      else args.insert(args.end(), {"--size", "40x30"});
      const RunResult r = run_cli(args);
      ASSERT_EQ(r.exit_code, 0) << command << " " << renderer << ": " << r.describe();
      const std::vector<std::string> lines = r.err_lines_besides_warnings();
      if (renderer == "tiler") {
        ASSERT_EQ(lines.size(), 1u) << command << ": " << r.describe();
        EXPECT_EQ(lines[0], note) << command;
      } else {
        EXPECT_TRUE(lines.empty()) << command << ": " << r.describe();
      }
    }
  }
}

// The tiler's cosine-hump filter (on jittered samples): every pixel once, a different picture from the
// box filter's.
TEST_F(CliTemp, TilerCosineFilterRendersEveryPixelOnce) {
  std::vector<uint32_t> pictures[2];
  int i = 0;
  for (const char* filter : {"box", "cosine"}) {
    const RunResult r = run_cli({"render", "--size", "64x48", "--aa", "4", "--filter", filter, "--band-rows", "3",
                                 "--samples", "jittered", "-o", path("f.png"), "--stats"});
    ASSERT_EQ(r.exit_code, 0) << filter << ": " << r.describe();
    EXPECT_EQ(json_int(r.out, "pixel_writes"), 64 * 48) << r.out;
    int w = 0, h = 0;
    EXPECT_EQ(mlhost::read_png(path("f.png"), &w, &h, &pictures[i++], false), "");
  }
  EXPECT_NE(pictures[0], pictures[1]);
}

TEST_F(CliTemp, CameraOptionsAreInGltfUnits) {
  const std::string glb = clitest::engine_glb();
  if (glb.empty()) GTEST_SKIP() << "assimp-testmodels not installed";
  ASSERT_EQ(run_cli({"compile", glb, "-o", path("e.mls")}, 120).exit_code, 0);
  const RunResult info = run_cli({"info", path("e.mls")});
  std::string bounds = after(info.out, "bounds (glTF units): min ");
  ASSERT_FALSE(bounds.empty()) << info.out;
  for (char& ch : bounds)
    if (ch == ',') ch = ' ';
  std::istringstream in(bounds);
  double lo[3], hi[3], c[3];
  std::string max_word;
  in >> lo[0] >> lo[1] >> lo[2] >> max_word >> hi[0] >> hi[1] >> hi[2];
  ASSERT_TRUE(in && max_word == "max") << bounds;
  for (int i = 0; i < 3; ++i) c[i] = (lo[i] + hi[i]) / 2;
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  auto vec = [](double x, double y, double z) {
    return std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(z);
  };
  // Looking at the model's centre from outside fills some of the screen; looking away shows nothing.
  const std::string eye = vec(c[0], c[1], c[2] + 1.5 * extent);
  const RunResult at = run_cli({"render", path("e.mls"), "--size", "64x48", "--eye", eye, "--target", vec(c[0], c[1], c[2]),
                                "--ids", path("at.png")});
  ASSERT_EQ(at.exit_code, 0) << at.describe();
  const RunResult away = run_cli({"render", path("e.mls"), "--size", "64x48", "--eye", eye, "--target",
                                  vec(c[0], c[1], c[2] + 5 * extent), "--ids", path("away.png")});
  ASSERT_EQ(away.exit_code, 0) << away.describe();
  int w, h;
  std::vector<uint32_t> ids_at, ids_away;
  ASSERT_EQ(mlhost::read_png(path("at.png"), &w, &h, &ids_at, true), "");
  ASSERT_EQ(mlhost::read_png(path("away.png"), &w, &h, &ids_away, true), "");
  size_t hit_at = 0, hit_away = 0;
  for (uint32_t v : ids_at) hit_at += v != 0;
  for (uint32_t v : ids_away) hit_away += v != 0;
  EXPECT_GT(hit_at, ids_at.size() / 20);
  EXPECT_EQ(hit_away, 0u);
}

}  // namespace

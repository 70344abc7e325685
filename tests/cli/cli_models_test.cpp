// Bad input is normal input: every glTF file Debian's assimp-testmodels ships (good, odd and broken)
// either renders to a PNG or is rejected with one line and exit code 1 -- never a crash, a sanitizer
// report or a hang.
#include <dirent.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <string>
#include <vector>

#include "platform/host/png_io.h"
#include "tests/cli/cli_runner.h"

namespace {

const char* const kModels = "/usr/share/assimp/models/glTF2";

void collect(const std::string& dir, std::vector<std::string>* out) {
  DIR* d = opendir(dir.c_str());
  if (!d) return;
  while (dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name == "." || name == "..") continue;
    const std::string path = dir + "/" + name;
    struct stat st;
    if (stat(path.c_str(), &st) != 0) continue;
    if (S_ISDIR(st.st_mode)) {
      collect(path, out);
    } else {
      std::string lower = name;
      std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(tolower(c)); });
      const auto ends = [&](const std::string& ext) {
        return lower.size() > ext.size() && lower.compare(lower.size() - ext.size(), ext.size(), ext) == 0;
      };
      if (ends(".gltf") || ends(".glb")) out->push_back(path);
    }
  }
  closedir(d);
}

TEST(CliModels, EveryAssimpGltfRendersOrFailsWithOneLine) {
  std::vector<std::string> files;
  collect(kModels, &files);
  if (files.empty()) GTEST_SKIP() << "assimp-testmodels not installed";
  std::sort(files.begin(), files.end());
  const std::string dir = clitest::make_temp_dir();
  const std::string png = dir + "/out.png";
  int rendered = 0, rejected = 0;
  for (const std::string& file : files) {
    remove(png.c_str());
    const clitest::RunResult r = clitest::run_cli({"render", file, "--size", "64x48", "-o", png}, 60);
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

}  // namespace

// platform/panels is shared with bare-metal firmware: it must follow the core's rules (no heap, no
// exceptions, no RTTI, no floats, only <stdint.h>/<stddef.h>) and build for a Cortex-M3.
#include <gtest/gtest.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <vector>

namespace {

const std::vector<std::string>& panel_sources() {
  static const std::vector<std::string> files = {"platform/panels/panel.cpp", "platform/panels/panel_sink.cpp"};
  return files;
}

bool in_repo_root() { return access("platform/panels/panel.h", R_OK) == 0; }

bool have(const char* tool) {
  const std::string cmd = std::string("command -v ") + tool + " >/dev/null 2>&1";
  return system(cmd.c_str()) == 0;
}

// Runs a compiler command, returning its exit status and output.
int run(const std::string& cmd, std::string* output) {
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return -1;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) *output += buf;
  return pclose(p);
}

TEST(PanelsPortable, OnlyFreestandingIncludes) {
  if (!in_repo_root()) GTEST_SKIP() << "not run from the repository root";
  for (const char* f : {"platform/panels/transport.h", "platform/panels/panel.h", "platform/panels/panel.cpp",
                        "platform/panels/panel_sink.h", "platform/panels/panel_sink.cpp"}) {
    std::ifstream in(f);
    ASSERT_TRUE(in) << f;
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("#include <", 0) != 0) continue;
      EXPECT_TRUE(line == "#include <stdint.h>" || line == "#include <stddef.h>") << f << ": " << line;
    }
  }
}

TEST(PanelsPortable, BuildsForCortexM3) {
  if (!in_repo_root()) GTEST_SKIP() << "not run from the repository root";
  if (!have("arm-none-eabi-g++")) GTEST_SKIP() << "arm-none-eabi-g++ not installed";
  for (const std::string& src : panel_sources()) {
    std::string out;
    const int rc = run("arm-none-eabi-g++ -std=c++17 -mcpu=cortex-m3 -mthumb -fno-exceptions -fno-rtti -Isrc -I. "
                       "-Wall -Wextra -Werror -O2 -c " + src + " -o /dev/null",
                       &out);
    EXPECT_EQ(rc, 0) << src << ":\n" << out;
  }
}

TEST(PanelsPortable, IntegerOnlyOnTheHost) {
  if (!in_repo_root()) GTEST_SKIP() << "not run from the repository root";
  if (!have("g++")) GTEST_SKIP() << "g++ not installed";
  for (const std::string& src : panel_sources()) {
    std::string out;
    const int rc = run("g++ -std=c++17 -mgeneral-regs-only -fno-exceptions -fno-rtti -Isrc -I. -Wall -Wextra "
                       "-Werror -O2 -c " + src + " -o /dev/null",
                       &out);
    EXPECT_EQ(rc, 0) << src << ":\n" << out;
  }
}

}  // namespace

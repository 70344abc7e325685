// Runs the CLI binary as a child process for the Cli* tests: captures stdout and stderr, enforces a
// timeout, and tells a clean exit from a crash or a sanitizer report.
#pragma once
#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace clitest {

struct RunResult {
  int exit_code = -1;       // valid when !signaled && !timed_out
  bool signaled = false;    // killed by a signal (crash)
  bool timed_out = false;
  std::string out, err;

  std::vector<std::string> err_lines() const;
  // The stderr lines that are not the compiler's warnings ("maskline: warning: ..."), which a glTF
  // input may print before its render or its refusal.
  std::vector<std::string> err_lines_besides_warnings() const;
  // Sanitizer or crash text in stderr.
  bool sanitizer_report() const;
  std::string describe() const;  // for failure messages
};

// Path of `name` relative to this test binary's directory ("" when /proc/self/exe cannot be read).
std::string beside_test_binary(const std::string& name);

// Path of `rel`, a file or folder of the source tree ("tables/mask_tables.h"): `rel` itself when it
// exists from the working directory (the repository root, where `make test` runs), else under the
// nearest folder above this test binary that holds it (BUILD/san/tests inside the tree), so the
// binary run from anywhere finds it; "" when neither.
std::string in_source_tree(const std::string& rel);

// Path of the CLI: $MASKLINE_CLI, else "maskline" next to this test binary.
std::string cli_path();

// Runs the CLI with `args`; kills it after timeout_seconds.
RunResult run_cli(const std::vector<std::string>& args, int timeout_seconds = 60);

// A fresh temporary directory (removed by the caller with remove_tree, or left in /tmp).
std::string make_temp_dir();
void remove_tree(const std::string& dir);

bool file_exists(const std::string& path);
std::vector<unsigned char> read_bytes(const std::string& path);
void write_bytes(const std::string& path, const std::vector<unsigned char>& bytes);

// The assimp test model the issues name, or "" when assimp-testmodels is not installed.
std::string engine_glb();

// GoogleTest checks shared by the CLI suites: exit `code` with exactly one "maskline: ..." line on
// stderr, no crash, no sanitizer report.
void expect_one_line_error(const RunResult& r, int code, const std::string& what);

// Integer field `key` of a flat JSON object (as --stats prints), or -1.
long long json_int(const std::string& json, const std::string& key);

// A test fixture with a fresh temporary directory.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = make_temp_dir(); }
  void TearDown() override { remove_tree(dir_); }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  std::string dir_;
};

}  // namespace clitest

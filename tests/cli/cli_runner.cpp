#include "tests/cli/cli_runner.h"

#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <fstream>
#include <iterator>

extern char** environ;

namespace clitest {

std::vector<std::string> RunResult::err_lines() const {
  std::vector<std::string> lines;
  size_t start = 0;
  while (start < err.size()) {
    size_t nl = err.find('\n', start);
    if (nl == std::string::npos) nl = err.size();
    lines.push_back(err.substr(start, nl - start));
    start = nl + 1;
  }
  return lines;
}

std::vector<std::string> RunResult::err_lines_besides_warnings() const {
  std::vector<std::string> lines;
  for (const std::string& line : err_lines())
    if (line.rfind("maskline: warning: ", 0) != 0) lines.push_back(line);
  return lines;
}

bool RunResult::sanitizer_report() const {
  return err.find("Sanitizer") != std::string::npos || err.find("runtime error:") != std::string::npos ||
         err.find("==ERROR") != std::string::npos;
}

std::string RunResult::describe() const {
  std::string s = timed_out ? "timed out" : signaled ? "killed by a signal" : "exit " + std::to_string(exit_code);
  return s + "; stderr: [" + err.substr(0, 2000) + "]";
}

std::string beside_test_binary(const std::string& name) {
  char buf[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "";
  const std::string self(buf, size_t(n));
  return self.substr(0, self.find_last_of('/') + 1) + name;
}

std::string in_source_tree(const std::string& rel) {
  if (access(rel.c_str(), F_OK) == 0) return rel;
  // From the binary's folder up: "/a/b/" then "/a/" (find_last_of gives npos + 1 = 0 at the top).
  for (std::string dir = beside_test_binary(""); dir.size() > 1; dir.resize(dir.find_last_of('/', dir.size() - 2) + 1))
    if (access((dir + rel).c_str(), F_OK) == 0) return dir + rel;
  return "";
}

std::string cli_path() {
  if (const char* env = getenv("MASKLINE_CLI")) return env;
  const std::string beside = beside_test_binary("maskline");
  return beside.empty() ? "maskline" : beside;
}

RunResult run_cli(const std::vector<std::string>& args, int timeout_seconds) {
  RunResult r;
  int out_pipe[2], err_pipe[2];
  if (pipe(out_pipe) != 0 || pipe(err_pipe) != 0) {
    r.err = "pipe failed";
    return r;
  }
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, out_pipe[1], 1);
  posix_spawn_file_actions_adddup2(&fa, err_pipe[1], 2);
  posix_spawn_file_actions_addclose(&fa, out_pipe[0]);
  posix_spawn_file_actions_addclose(&fa, err_pipe[0]);
  const std::string path = cli_path();
  std::vector<std::string> all{path};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  // Sanitizer reports get exit codes of their own so they can never pass for a clean "exit 1".
  std::vector<std::string> env_store;
  for (char** e = environ; *e; ++e) {
    if (strncmp(*e, "ASAN_OPTIONS=", 13) != 0 && strncmp(*e, "UBSAN_OPTIONS=", 14) != 0) env_store.push_back(*e);
  }
  env_store.push_back("ASAN_OPTIONS=exitcode=86:detect_leaks=1");
  env_store.push_back("UBSAN_OPTIONS=exitcode=87:print_stacktrace=1");
  std::vector<char*> envp;
  for (auto& e : env_store) envp.push_back(const_cast<char*>(e.c_str()));
  envp.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, path.c_str(), &fa, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&fa);
  close(out_pipe[1]);
  close(err_pipe[1]);
  if (rc != 0) {
    close(out_pipe[0]);
    close(err_pipe[0]);
    r.err = std::string("cannot start ") + path + ": " + strerror(rc);
    return r;
  }
  struct pollfd fds[2] = {{out_pipe[0], POLLIN, 0}, {err_pipe[0], POLLIN, 0}};
  bool open_fd[2] = {true, true};
  timespec start;
  clock_gettime(CLOCK_MONOTONIC, &start);
  char buf[65536];
  while (open_fd[0] || open_fd[1]) {
    timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    const double elapsed = double(now.tv_sec - start.tv_sec) + double(now.tv_nsec - start.tv_nsec) * 1e-9;
    if (elapsed > timeout_seconds) {
      kill(pid, SIGKILL);
      r.timed_out = true;
      break;
    }
    for (auto& f : fds) f.revents = 0;
    fds[0].fd = open_fd[0] ? out_pipe[0] : -1;
    fds[1].fd = open_fd[1] ? err_pipe[0] : -1;
    if (poll(fds, 2, 200) < 0) continue;
    for (int i = 0; i < 2; ++i) {
      if (!open_fd[i] || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      const ssize_t n = read(fds[i].fd, buf, sizeof buf);
      if (n <= 0) {
        open_fd[i] = false;
      } else {
        (i == 0 ? r.out : r.err).append(buf, size_t(n));
      }
    }
  }
  close(out_pipe[0]);
  close(err_pipe[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!r.timed_out) {
    if (WIFSIGNALED(status)) r.signaled = true;
    else r.exit_code = WEXITSTATUS(status);
  }
  return r;
}

std::string make_temp_dir() {
  char tmpl[] = "/tmp/maskline-test-XXXXXX";
  const char* d = mkdtemp(tmpl);
  return d ? d : "/tmp";
}

void remove_tree(const std::string& dir) {
  if (dir.compare(0, 19, "/tmp/maskline-test-") != 0) return;
  const std::string cmd = "rm -rf '" + dir + "'";
  if (system(cmd.c_str()) != 0) {
    // Leaving a temp dir behind is harmless.
  }
}

bool file_exists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::vector<unsigned char> read_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::vector<unsigned char>(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

void write_bytes(const std::string& path, const std::vector<unsigned char>& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

std::string engine_glb() {
  const std::string p = "/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  return file_exists(p) ? p : "";
}

void expect_one_line_error(const RunResult& r, int code, const std::string& what) {
  EXPECT_FALSE(r.sanitizer_report()) << what << ": " << r.describe();
  EXPECT_FALSE(r.signaled || r.timed_out) << what << ": " << r.describe();
  EXPECT_EQ(r.exit_code, code) << what << ": " << r.describe();
  const auto lines = r.err_lines();
  ASSERT_EQ(lines.size(), 1u) << what << ": " << r.describe();
  EXPECT_EQ(lines[0].rfind("maskline: ", 0), 0u) << what << ": " << lines[0];
}

long long json_int(const std::string& json, const std::string& key) {
  const std::string k = "\"" + key + "\":";
  const size_t at = json.find(k);
  if (at == std::string::npos) return -1;
  return std::stoll(json.substr(at + k.size()));
}

}  // namespace clitest

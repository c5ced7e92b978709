#pragma once
// Test support: runs the kinetic program as users and scripts do (a shell command line, standard
// input closed) and reads what it wrote. Header-only, tests only; KINETIC_CLI_PATH is the
// program's path, set by tests/CMakeLists.txt.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace kinetic::test {

struct CliOutcome {
  int status = -1;  ///< the exit status; -1 when the program did not exit normally
  std::string out, err;
};

inline std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

inline void write_file(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

/// Runs the kinetic program with `args` (a shell-quoted string), its standard output and error
/// sent to the two files, then read back.
inline CliOutcome run_cli_to(const std::string& args, const std::string& out_path,
                             const std::string& err_path) {
  const std::string cmd = std::string(KINETIC_CLI_PATH) + " " + args + " >" + out_path + " 2>" +
                          err_path + " </dev/null";
  const int raw = std::system(cmd.c_str());
  CliOutcome o;
  o.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  o.out = read_file(out_path);
  o.err = read_file(err_path);
  return o;
}

/// A test file's scratch files and program runs: files in the test temporary directory under
/// `prefix` (one per test file, so that files running in parallel never share a name), each
/// run's output in `<tag>.stdout` and `<tag>.stderr`.
struct CliScratch {
  std::string prefix;

  [[nodiscard]] std::string path(const std::string& name) const {
    return ::testing::TempDir() + prefix + name;
  }
  /// Runs the kinetic program with `args` (a shell-quoted string); `tag` names its output files.
  [[nodiscard]] CliOutcome run(const std::string& args, const std::string& tag) const {
    return run_cli_to(args, path(tag + ".stdout"), path(tag + ".stderr"));
  }
};

}  // namespace kinetic::test

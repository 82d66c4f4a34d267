// Helpers for tests that run the clothsim binary: shell quoting, running a command, temporary
// folders and reading captured output.
#pragma once

#include <stdlib.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace clothsim::testing {

// `s` as one single-quoted shell word.
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The whole file as bytes (empty if it cannot be read).
inline std::string read_file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs `command` with /bin/sh; its exit status, or -1 if it did not exit normally.
inline int run_shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
}

// Whether /usr/bin/python3 can import matplotlib (the plotting scripts need it).
inline bool has_matplotlib() { return run_shell("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0; }

// A fresh folder <temp>/<prefix>XXXXXX (mkdtemp); throws std::runtime_error if it cannot be made.
inline std::filesystem::path make_temp_dir(const std::string& prefix) {
  std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "XXXXXX")).string();
  if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed for " + pattern);
  return pattern;
}

}  // namespace clothsim::testing

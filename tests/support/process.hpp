// Helpers for tests that run the clothsim binary: shell quoting and reading captured output.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
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

}  // namespace clothsim::testing

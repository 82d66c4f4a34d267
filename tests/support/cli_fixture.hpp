// A fixture for tests that run the built clothsim binary: a fresh temporary folder per test,
// files written into it, and `clothsim <args>` run with stdout, stderr and the exit code captured.
#pragma once

#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace clothsim::testing {

struct CliResult {
  int exit_code = -1;
  std::string out, err;  // stdout, stderr
};

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

class CliFixture : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = make_temp_dir("clothsim_cli_fixture_"); }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }

  // Writes `text` to dir_/`name` (creating folders) and returns the path.
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const std::filesystem::path path = dir_ / name;
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  // Runs `clothsim <args>` (`args` already shell-quoted where needed) with the output captured.
  CliResult run(const std::string& args) const {
    const std::filesystem::path out = dir_ / ".stdout.txt", err = dir_ / ".stderr.txt";
    CliResult r;
    r.exit_code = run_shell(shell_quote(CLOTHSIM_BINARY) + " " + args + " >" + shell_quote(out.string()) + " 2>" +
                            shell_quote(err.string()));
    r.out = read_file_bytes(out);
    r.err = read_file_bytes(err);
    std::error_code ec;
    std::filesystem::remove(out, ec);
    std::filesystem::remove(err, ec);
    return r;
  }

  // `p` as one shell word.
  static std::string q(const std::filesystem::path& p) { return shell_quote(p.string()); }

  std::filesystem::path dir_;
};

}  // namespace clothsim::testing

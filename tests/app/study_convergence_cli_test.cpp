// `clothsim study convergence --quick`: runs the built binary into a fresh temporary folder and
// checks the published report (results.csv with the documented header and one row per run,
// results.md, the PNG when /usr/bin/python3 has matplotlib), that a rerun replaces the older
// report, and that no temporary folder is left behind.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using clothsim::testing::read_file_bytes;
using clothsim::testing::shell_quote;

const char* const kHeader =
    "case,method,series,window,setting,vertices,dofs,h,dt,steps,wall_seconds,solver_iterations,error,order,quantity,"
    "value,reference_value,reference_precision,reference,note";

// Runs a shell command; returns its exit status (-1 if it did not exit normally).
int run_shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
}

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

class StudyConvergenceCli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "clothsim_convergence_cli_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // `clothsim study convergence --quick --out <dir>/out <extra>`; stderr kept in err_.
  int study(const std::string& extra) {
    const fs::path err = dir_ / "stderr.txt";
    const int code = run_shell(shell_quote(CLOTHSIM_BINARY) + " study convergence --quick --out " +
                               shell_quote((dir_ / "out").string()) + " " + extra + " >/dev/null 2>" +
                               shell_quote(err.string()));
    err_ = read_file_bytes(err);
    return code;
  }

  fs::path report() const { return dir_ / "out" / "study_convergence"; }

  void expect_only_the_report_in_out() const {
    for (const fs::directory_entry& e : fs::directory_iterator(dir_ / "out"))
      EXPECT_EQ(e.path().filename(), "study_convergence") << "left behind: " << e.path();
  }

  fs::path dir_;
  std::string err_;
};

TEST_F(StudyConvergenceCli, QuickWithoutPlotWritesTheCsv) {
  ASSERT_EQ(study("--no-plot"), 0) << err_;
  EXPECT_NE(err_.find("clothsim: convergence: case plate_ss_uniform method loop_one_point setting 4x4 error "),
            std::string::npos)
      << err_;
  const std::string csv = read_file_bytes(report() / "results.csv");
  EXPECT_EQ(first_line(csv), kHeader);
  // Quick plan: 1 plate case × 2 methods × 3 grids, and 1 sleeve: reference + 2 methods × (2 meshes + 3 steps).
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 6 + 1 + 10);
  EXPECT_TRUE(fs::exists(report() / "results.md"));
  EXPECT_FALSE(fs::exists(report() / "error_vs_time.png"));
  expect_only_the_report_in_out();
}

TEST_F(StudyConvergenceCli, QuickWithPlotWritesAPngAndReplacesAnOlderReport) {
  if (run_shell("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no matplotlib (scripts/install_deps.sh installs python3-matplotlib)";
  fs::create_directories(report());
  std::ofstream(report() / "stale.txt") << "from an older run\n";
  ASSERT_EQ(study(""), 0) << err_;
  const std::string png = read_file_bytes(report() / "error_vs_time.png");
  ASSERT_GE(png.size(), 8u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(first_line(read_file_bytes(report() / "results.csv")), kHeader);
  EXPECT_FALSE(fs::exists(report() / "stale.txt")) << "the older report was not replaced";
  expect_only_the_report_in_out();
}

}  // namespace

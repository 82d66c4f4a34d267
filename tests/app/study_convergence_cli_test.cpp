// `clothsim study convergence --quick`: runs the built binary into a fresh temporary folder and
// checks the published report (results.csv with the documented header and one row per run,
// results.md, the PNG when /usr/bin/python3 has matplotlib), that a rerun replaces the older
// report, and that no temporary folder is left behind.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using clothsim::testing::read_file_bytes;
using clothsim::testing::shell_quote;

const char* const kHeader =
    "case,method,series,window,setting,vertices,dofs,h,dt,steps,wall_seconds,solver_iterations,error,order,quantity,"
    "value,reference_value,reference_precision,reference,note,elastic_energy,reference_elastic_energy,energy_error,"
    "folds_circumferential,folds_axial,reference_folds_circumferential,reference_folds_axial,"
    "fold_difference_circumferential,fold_difference_axial,tolerance,solver_error,discretization_error,"
    "solver_energy_error,discretization_energy_error,solver_reference_folds_circumferential,"
    "solver_reference_folds_axial";

// Runs a shell command; returns its exit status (-1 if it did not exit normally).
int run_shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
}

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

// The error field (the 13th, before any quoted field) of every CSV line that starts with `prefix`.
std::vector<std::string> errors_of(const std::string& csv, const std::string& prefix) {
  std::vector<std::string> out;
  std::istringstream in(csv);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(prefix, 0) != 0) continue;
    size_t start = 0;
    for (int field = 0; field < 12; ++field) start = line.find(',', start) + 1;
    out.push_back(line.substr(start, line.find(',', start) - start));
  }
  return out;
}

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
  // Quick plan: 1 plate case × 3 static methods (mass_spring is dynamic only) × 3 grids, and 1 sleeve:
  // reference + 2 Loop rules × (2 meshes + 3 steps) + 2 baselines × 2 meshes (mesh series only) +
  // 2 Loop rules × 6 tolerances (tolerance series).
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 9 + 1 + 10 + 4 + 12);
  for (const std::string prefix : {"sleeve_twist,loop_one_point,tolerance,", "sleeve_twist,loop_three_point,tolerance,"})
    EXPECT_EQ(errors_of(csv, prefix).size(), 6u) << prefix;
  // The baselines' rows have finite errors.
  for (const std::string prefix : {"plate_ss_uniform,linear_fe,mesh,", "sleeve_twist,linear_fe,mesh,",
                                   "sleeve_twist,mass_spring,mesh,"}) {
    const std::vector<std::string> errors = errors_of(csv, prefix);
    EXPECT_EQ(errors.size(), prefix[0] == 'p' ? 3u : 2u) << prefix;
    for (const std::string& e : errors) {
      char* end = nullptr;
      const double value = std::strtod(e.c_str(), &end);
      EXPECT_TRUE(end != e.c_str() && *end == '\0' && std::isfinite(value) && value > 0) << prefix << " error " << e;
    }
  }
  const std::string md = read_file_bytes(report() / "results.md");
  EXPECT_NE(md.find("\n## Solver tolerance\n"), std::string::npos) << md;
  EXPECT_NE(md.find("\nRecommended tolerance by the rule: "), std::string::npos) << md;
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

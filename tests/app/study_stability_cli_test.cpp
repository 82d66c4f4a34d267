// `clothsim study stability --quick`: runs the built binary into a fresh temporary folder and
// checks the published report (results.csv with the documented header and one passing row per
// quick case, table.md, the cases' scene files), that it replaces an older report and leaves no
// temporary folder; draws the heat map from that CSV when /usr/bin/python3 has matplotlib; and
// that an unusable output root is an error that writes nothing.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <stdlib.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using clothsim::testing::read_file_bytes;
using clothsim::testing::run_shell;
using clothsim::testing::shell_quote;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class StudyStabilityCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = clothsim::testing::make_temp_dir("clothsim_stability_cli_");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // `clothsim study stability --quick --out <out> <extra>`; stdout and stderr kept.
  int study(const fs::path& out, const std::string& extra) {
    const fs::path out_file = dir_ / "stdout.txt", err_file = dir_ / "stderr.txt";
    const int code = run_shell(shell_quote(CLOTHSIM_BINARY) + " study stability --quick --out " +
                               shell_quote(out.string()) + " " + extra + " >" + shell_quote(out_file.string()) +
                               " 2>" + shell_quote(err_file.string()));
    out_ = read_file_bytes(out_file);
    err_ = read_file_bytes(err_file);
    return code;
  }

  fs::path dir_;
  std::string out_, err_;
};

TEST_F(StudyStabilityCli, QuickWithoutPlotWritesTheReport) {
  const fs::path out = dir_ / "out";
  fs::create_directories(out / "study_stability");
  std::ofstream(out / "study_stability" / "old.txt") << "older report";

  ASSERT_EQ(study(out, "--no-plot"), 0) << err_;
  const fs::path report = out / "study_stability";
  EXPECT_FALSE(fs::exists(report / "old.txt")) << "the older report was not replaced";
  for (const fs::directory_entry& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename(), "study_stability") << "left behind: " << e.path();
  EXPECT_FALSE(fs::exists(report / "heatmap.png"));
  EXPECT_NE(out_.find("cases pass"), std::string::npos) << out_;
  EXPECT_NE(err_.find("clothsim: [1/"), std::string::npos) << err_;

  const std::vector<std::string> lines = lines_of(read_file_bytes(report / "results.csv"));
  ASSERT_GE(lines.size(), 6u);
  EXPECT_EQ(lines[0].rfind("case,finished,nan,energy_rise,max_strain,max_iterations,residual,verdict,", 0), 0u)
      << lines[0];
  const std::string table = read_file_bytes(report / "table.md");
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::string name = lines[i].substr(0, lines[i].find(','));
    EXPECT_NE(lines[i].find(",true,false,"), std::string::npos) << lines[i];  // finished, no NaN
    EXPECT_NE(lines[i].find(",pass,"), std::string::npos) << lines[i];
    EXPECT_NE(table.find("| `" + name + "` | pass |"), std::string::npos) << name;
    EXPECT_TRUE(fs::exists(report / "scenes" / (name + ".json"))) << name;
  }

  // The heat map from this CSV (skipped without Debian's python3-matplotlib).
  if (!clothsim::testing::has_matplotlib()) GTEST_SKIP() << "no matplotlib";
  const fs::path png = dir_ / "heatmap.png";
  ASSERT_EQ(run_shell("/usr/bin/python3 " + shell_quote(std::string(CLOTHSIM_SOURCE_DIR) + "/scripts/plot_stability.py") +
                      " " + shell_quote((report / "results.csv").string()) + " " + shell_quote(png.string())),
            0);
  const std::string bytes = read_file_bytes(png);
  ASSERT_GT(bytes.size(), 8u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
}

TEST_F(StudyStabilityCli, UnusableOutputRootIsAnErrorAndWritesNothing) {
  const fs::path file = dir_ / "a_file";
  std::ofstream(file) << "not a folder";
  EXPECT_EQ(study(file / "sub", "--no-plot"), 1);
  EXPECT_NE(err_.find("clothsim: error: "), std::string::npos) << err_;
  EXPECT_NE(err_.find(file.string() + " is not a folder"), std::string::npos) << err_;
  EXPECT_EQ(err_.find("[1/"), std::string::npos) << "a case ran before the error: " << err_;
  EXPECT_EQ(read_file_bytes(file), "not a folder");
}

}  // namespace

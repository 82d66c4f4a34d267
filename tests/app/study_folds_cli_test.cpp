// `clothsim study folds --quick`: runs the built binary into a fresh temporary folder and checks
// the published report (results.csv with the documented header, one row per case × method × mesh
// × seed of the quick plan, each finished with finite counts and the theory band of its case;
// results.md), that it replaces an older report and leaves no temporary folder; that the rerun
// options reach the plan (--meshes, --seeds, --methods, --cases, --preset, --amplitude); that bad
// options are errors naming the option and the item, and write nothing; draws the plot from the
// CSV when /usr/bin/python3 has matplotlib.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <stdlib.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using clothsim::testing::read_file_bytes;
using clothsim::testing::run_shell;
using clothsim::testing::shell_quote;

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, separator)) parts.push_back(part);
  if (!text.empty() && text.back() == separator) parts.push_back("");
  return parts;
}

// The CSV's rows as column → value maps (the quick rows have no quoted fields with commas).
std::vector<std::map<std::string, std::string>> csv_rows(const std::string& text, std::string& header) {
  const std::vector<std::string> lines = split(text, '\n');
  std::vector<std::map<std::string, std::string>> rows;
  if (lines.empty()) return rows;
  header = lines[0];
  const std::vector<std::string> columns = split(lines[0], ',');
  for (size_t i = 1; i < lines.size(); ++i) {
    if (lines[i].empty()) continue;
    const std::vector<std::string> cells = split(lines[i], ',');
    std::map<std::string, std::string> row;
    for (size_t c = 0; c < columns.size() && c < cells.size(); ++c) row[columns[c]] = cells[c];
    row["#cells"] = std::to_string(cells.size());
    rows.push_back(row);
  }
  return rows;
}

class StudyFoldsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = clothsim::testing::make_temp_dir("clothsim_folds_cli_");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // `clothsim study folds --quick --out <out> <extra>`; stdout and stderr kept.
  int study(const fs::path& out, const std::string& extra) {
    const fs::path out_file = dir_ / "stdout.txt", err_file = dir_ / "stderr.txt";
    const int code = run_shell(shell_quote(CLOTHSIM_BINARY) + " study folds --quick --out " + shell_quote(out.string()) +
                               " " + extra + " >" + shell_quote(out_file.string()) + " 2>" +
                               shell_quote(err_file.string()));
    out_ = read_file_bytes(out_file);
    err_ = read_file_bytes(err_file);
    return code;
  }

  fs::path dir_;
  std::string out_, err_;
};

const char* kHeader =
    "case,method,segments,rings,vertices,seed,amplitude,dt,steps,end_time,wall_seconds,circumferential_median,"
    "axial_median,circumferential_theory_lo,circumferential_theory_hi,axial_theory_lo,axial_theory_hi,t_eff,preset,"
    "status,note";

double number(const std::string& s) {
  try {
    return std::stod(s);
  } catch (...) {
    return std::nan("");
  }
}

TEST_F(StudyFoldsCli, QuickWithoutPlotWritesOneFiniteRowPerRun) {
  const fs::path out = dir_ / "out";
  fs::create_directories(out / "study_folds");
  std::ofstream(out / "study_folds" / "old.txt") << "older report";

  ASSERT_EQ(study(out, "--no-plot"), 0) << err_;
  const fs::path report = out / "study_folds";
  EXPECT_FALSE(fs::exists(report / "old.txt")) << "the older report was not replaced";
  for (const fs::directory_entry& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename(), "study_folds") << "left behind: " << e.path();
  EXPECT_FALSE(fs::exists(report / "folds_vs_vertices.png"));
  EXPECT_NE(out_.find("fold study: 12 runs (0 failed or unstable)"), std::string::npos) << out_;

  std::string header;
  const auto rows = csv_rows(read_file_bytes(report / "results.csv"), header);
  EXPECT_EQ(header, kHeader);
  // Quick plan: 2 cases × 3 methods × 2 meshes (13x9, 18x13) × 1 seed, 0.1 s at 5 ms = 20 steps.
  ASSERT_EQ(rows.size(), 12u);
  std::set<std::string> seen;
  for (const auto& r : rows) {
    SCOPED_TRACE(r.at("case") + " " + r.at("method") + " " + r.at("segments") + "x" + r.at("rings"));
    EXPECT_EQ(r.at("#cells"), "21");
    seen.insert(r.at("case") + "/" + r.at("method") + "/" + r.at("segments") + "x" + r.at("rings"));
    EXPECT_EQ(number(r.at("vertices")), number(r.at("segments")) * number(r.at("rings")));
    EXPECT_EQ(r.at("status"), "ok");
    EXPECT_EQ(r.at("steps"), "20");
    EXPECT_NEAR(number(r.at("end_time")), 0.1, 1e-9);
    EXPECT_EQ(r.at("seed"), "1");
    EXPECT_EQ(r.at("preset"), "cotton");
    // Default amplitude: half of cotton's t_eff = sqrt(12 · 1.157e-5 / 5000) = 0.16664 mm.
    EXPECT_NEAR(number(r.at("amplitude")), 0.5 * 1.66637e-4, 1e-8);
    const double c = number(r.at("circumferential_median")), a = number(r.at("axial_median"));
    EXPECT_TRUE(std::isfinite(c) && c >= 0 && c == std::floor(2 * c) / 2) << c;  // a median of counts
    EXPECT_TRUE(std::isfinite(a) && a >= 0 && a == std::floor(2 * a) / 2) << a;
    if (r.at("case") == "twist") {
      EXPECT_NEAR(number(r.at("circumferential_theory_lo")), 6.035, 1e-3);
      EXPECT_NEAR(number(r.at("circumferential_theory_hi")), 7.908, 1e-3);
      EXPECT_EQ(r.at("axial_theory_lo"), "nan");
    } else {
      EXPECT_EQ(number(r.at("circumferential_theory_lo")), 0.0);
      EXPECT_NEAR(number(r.at("circumferential_theory_hi")), 15.862, 1e-3);
      EXPECT_NEAR(number(r.at("axial_theory_lo")), 10.098, 1e-3);
      EXPECT_NEAR(number(r.at("axial_theory_hi")), 20.196, 1e-3);
    }
  }
  EXPECT_EQ(seen.size(), 12u);
  const std::string table = read_file_bytes(report / "results.md");
  EXPECT_NE(table.find("| twist | loop_kl | 13×9 | 117 |"), std::string::npos) << table;
  EXPECT_NE(table.find("| compress | mass_spring | 18×13 | 234 |"), std::string::npos) << table;

  // The plot from this CSV (skipped without Debian's python3-matplotlib).
  if (!clothsim::testing::has_matplotlib()) GTEST_SKIP() << "no matplotlib";
  const fs::path png = dir_ / "folds.png";
  ASSERT_EQ(run_shell("/usr/bin/python3 " + shell_quote(std::string(CLOTHSIM_SOURCE_DIR) + "/scripts/plot_folds.py") +
                      " " + shell_quote((report / "results.csv").string()) + " " + shell_quote(png.string())),
            0);
  const std::string bytes = read_file_bytes(png);
  ASSERT_GT(bytes.size(), 8u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
}

TEST_F(StudyFoldsCli, RerunOptionsReachThePlan) {
  const fs::path out = dir_ / "out";
  ASSERT_EQ(study(out, "--no-plot --meshes 12x9 --seeds 4,7 --methods linear_fe --cases compress "
                       "--preset wool_tropical --amplitude 0.0001 --end 0.05"),
            0)
      << err_;
  std::string header;
  const auto rows = csv_rows(read_file_bytes(out / "study_folds" / "results.csv"), header);
  ASSERT_EQ(rows.size(), 2u);
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    EXPECT_EQ(r.at("case"), "compress");
    EXPECT_EQ(r.at("method"), "linear_fe");
    EXPECT_EQ(r.at("vertices"), "108");
    EXPECT_EQ(r.at("seed"), i == 0 ? "4" : "7");
    EXPECT_EQ(number(r.at("amplitude")), 1e-4);
    EXPECT_EQ(r.at("preset"), "wool_tropical");
    EXPECT_EQ(r.at("steps"), "10");
    // wool_tropical: t_eff = sqrt(12 · 6.57e-6 / 5000) = 0.125570 mm.
    EXPECT_NEAR(number(r.at("t_eff")), 1.25570e-4, 1e-9);
  }
}

TEST_F(StudyFoldsCli, BadOptionsAreErrorsThatWriteNothing) {
  const fs::path out = dir_ / "out";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--meshes 26x19,abc", "--meshes: \"abc\" is not SEGMENTSxRINGS"},
      {"--methods loop_kl,fem", "--methods: unknown method \"fem\""},
      {"--seeds 1,x", "--seeds: \"x\" is not a non-negative integer"},
      {"--cases bend", "--cases: unknown case \"bend\""},
      {"--preset silk", "unknown material preset \"silk\""},
      {"--dt -1", "time step"},
  };
  for (const auto& [option, message] : cases) {
    SCOPED_TRACE(option);
    EXPECT_EQ(study(out, "--no-plot " + option), 1);
    EXPECT_NE(err_.find("clothsim: error: "), std::string::npos) << err_;
    EXPECT_NE(err_.find(message), std::string::npos) << err_;
    EXPECT_FALSE(fs::exists(out)) << "wrote output";
  }
  // The fold options belong to `study folds` only.
  EXPECT_EQ(run_shell(shell_quote(CLOTHSIM_BINARY) + " study stability --quick --no-plot --meshes 26x19 --out " +
                      shell_quote(out.string()) + " 2>" + shell_quote((dir_ / "err.txt").string())),
            1);
  EXPECT_NE(read_file_bytes(dir_ / "err.txt").find("--meshes applies to `clothsim study folds` only"), std::string::npos);
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace

// Golden images: runs clothsim on the scenes listed in tests/golden/goldens.txt (the same commands
// as scripts/update_goldens.sh) and compares each rendered PNG with its stored golden within a
// small tolerance, keeping the rendered and difference images of a mismatch; also checks that
// rendering a static scene twice gives byte-identical PNG files.
#include "render/image_compare.hpp"
#include "render/png_io.hpp"

#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <stdlib.h>
#include <sys/wait.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

// A pixel counts as different if one of its channels differs from the golden by more than
// kChannelTolerance (of 255); a golden fails if more than kMaxFractionOver of its pixels differ
// (0.5 % = 96 of the 160 × 120 pixels). Enough for small floating-point differences across
// machines (a shifted edge pixel, a slightly different shade) while catching real changes of the
// shape, the shading or the camera. Documented in tests/golden/README.md.
constexpr int kChannelTolerance = 8;
constexpr double kMaxFractionOver = 0.005;

// One line of tests/golden/goldens.txt: `clothsim SCENE --out DIR OPTIONS...` renders RENDERED
// (relative to DIR), which is compared with tests/golden/FILE.
struct Golden {
  std::string file;
  std::string scene;
  std::string rendered;
  std::vector<std::string> options;
};

// Names a golden in test output (ctest lists it after the test name).
void PrintTo(const Golden& g, std::ostream* os) {
  *os << g.file << " (" << g.scene;
  for (const std::string& option : g.options) *os << ' ' << option;
  *os << ')';
}

struct Manifest {
  std::vector<Golden> goldens;
  std::string error;  // empty if the manifest was read without problems
};

fs::path source_dir() { return fs::path(CLOTHSIM_SOURCE_DIR); }
fs::path golden_dir() { return source_dir() / "tests" / "golden"; }
fs::path manifest_path() { return golden_dir() / "goldens.txt"; }

// Kept across test runs: the rendered and difference images of failed comparisons.
fs::path failure_dir() { return fs::temp_directory_path() / "clothsim_golden_failures"; }

Manifest load_manifest() {
  Manifest m;
  std::ifstream in(manifest_path());
  if (!in) {
    m.error = "cannot read " + manifest_path().string();
    return m;
  }
  int line_number = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    if (w.empty() || w[0].front() == '#') continue;
    if (w.size() < 3 || fs::path(w[0]).extension() != ".png") {
      m.error += manifest_path().string() + ":" + std::to_string(line_number) +
                 ": expected GOLDEN.png SCENE RENDERED OPTIONS...\n";
      continue;
    }
    m.goldens.push_back({w[0], w[1], w[2], std::vector<std::string>(w.begin() + 3, w.end())});
  }
  return m;
}

const Manifest& manifest() {
  static const Manifest m = load_manifest();
  return m;
}

std::string read_bytes(const fs::path& path) { return clothsim::testing::read_file_bytes(path); }
using clothsim::testing::shell_quote;

// A test name from a golden's file name: "sleeve_compress_t0.1.png" → "sleeve_compress_t0_1".
std::string test_name(const Golden& g) {
  std::string name = fs::path(g.file).stem().string();
  for (char& c : name)
    if (std::isalnum(static_cast<unsigned char>(c)) == 0) c = '_';
  return name;
}

class GoldenRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "clothsim_golden_test_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // Runs `clothsim SCENE --out OUT OPTIONS...` (SCENE relative to the source root) with stdout and
  // stderr captured; returns the exit code and sets `err` to stderr.
  int run(const std::string& scene, const fs::path& out, const std::vector<std::string>& options,
          std::string& err) const {
    std::string command = shell_quote(CLOTHSIM_BINARY) + " " + shell_quote((source_dir() / scene).string()) +
                          " --out " + shell_quote(out.string());
    for (const std::string& option : options) {
      command += ' ';
      command += shell_quote(option);
    }
    const fs::path out_file = dir_ / "stdout.txt";
    const fs::path err_file = dir_ / "stderr.txt";
    command += " >" + shell_quote(out_file.string()) + " 2>" + shell_quote(err_file.string());
    const int status = std::system(command.c_str());
    err = read_bytes(err_file);
    return (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
  }

  fs::path dir_;
};

class GoldenTest : public GoldenRunTest, public ::testing::WithParamInterface<Golden> {};

TEST_P(GoldenTest, MatchesGolden) {
  const Golden& g = GetParam();
  const fs::path out = dir_ / "out";
  std::string err;
  ASSERT_EQ(run(g.scene, out, g.options, err), 0) << err;
  const fs::path rendered = out / g.rendered;
  ASSERT_TRUE(fs::exists(rendered)) << "clothsim did not write " << rendered << "\n" << err;
  const render::Image actual = render::read_png(rendered.string());

  const std::string stem = fs::path(g.file).stem().string();
  const fs::path kept_actual = failure_dir() / (stem + ".actual.png");
  const fs::path kept_diff = failure_dir() / (stem + ".diff.png");
  std::error_code ec;
  fs::remove(kept_actual, ec);  // left over from an earlier failed run
  fs::remove(kept_diff, ec);

  const fs::path golden = golden_dir() / g.file;
  if (!fs::exists(golden)) {
    fs::create_directories(failure_dir());
    render::write_png(kept_actual.string(), actual);
    FAIL() << "missing golden " << golden << " (scripts/update_goldens.sh writes it); rendered image kept at "
           << kept_actual;
  }
  const render::Image expected = render::read_png(golden.string());
  if (expected.width != actual.width || expected.height != actual.height) {
    fs::create_directories(failure_dir());
    render::write_png(kept_actual.string(), actual);
    FAIL() << "size mismatch: golden " << golden << " is " << expected.width << "x" << expected.height
           << ", rendered " << actual.width << "x" << actual.height << "; rendered image kept at " << kept_actual;
  }

  render::Image diff;
  const render::CompareResult r = render::compare_images(expected, actual, kChannelTolerance, &diff);
  if (r.fraction_over > kMaxFractionOver) {
    fs::create_directories(failure_dir());
    render::write_png(kept_actual.string(), actual);
    render::write_png(kept_diff.string(), diff);
    ADD_FAILURE() << "rendered image differs from golden " << golden << ": " << 100 * r.fraction_over
                  << " % of the pixels differ by more than " << kChannelTolerance << " (allowed "
                  << 100 * kMaxFractionOver << " %), largest channel difference " << r.max_abs << ", PSNR "
                  << r.psnr_db << " dB\n  rendered image: " << kept_actual << "\n  difference image (4 x |golden - rendered|): "
                  << kept_diff << "\n  if the change is intended, run scripts/update_goldens.sh";
  }
}

std::string param_name(const ::testing::TestParamInfo<Golden>& param) { return test_name(param.param); }

INSTANTIATE_TEST_SUITE_P(Goldens, GoldenTest, ::testing::ValuesIn(manifest().goldens), param_name);
// An unreadable or empty manifest is reported by GoldenManifest.ListsEveryGolden.
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(GoldenTest);

TEST(GoldenManifest, ListsEveryGolden) {
  const Manifest& m = manifest();
  ASSERT_TRUE(m.error.empty()) << m.error;
  ASSERT_FALSE(m.goldens.empty()) << manifest_path() << " lists no goldens";
  std::set<std::string> listed;
  std::set<std::string> names;
  for (const Golden& g : m.goldens) {
    EXPECT_TRUE(listed.insert(g.file).second) << g.file << " is listed twice";
    EXPECT_TRUE(names.insert(test_name(g)).second) << g.file << ": test name " << test_name(g) << " is taken";
    EXPECT_TRUE(fs::exists(golden_dir() / g.file)) << "missing golden " << golden_dir() / g.file;
    EXPECT_TRUE(fs::exists(source_dir() / g.scene)) << "missing scene " << source_dir() / g.scene;
  }
  for (const auto& e : fs::directory_iterator(golden_dir())) {
    if (e.path().extension() == ".png") {
      EXPECT_TRUE(listed.count(e.path().filename().string()) == 1)
          << e.path() << " is not listed in " << manifest_path();
    }
  }
}

TEST_F(GoldenRunTest, StaticRenderIsByteIdentical) {
  const std::vector<std::string> options = {"--size", "160x120"};
  std::string err;
  ASSERT_EQ(run("scenes/plate_ss.json", dir_ / "first", options, err), 0) << err;
  ASSERT_EQ(run("scenes/plate_ss.json", dir_ / "second", options, err), 0) << err;
  const std::string first = read_bytes(dir_ / "first" / "plate_ss" / "limit.png");
  const std::string second = read_bytes(dir_ / "second" / "plate_ss" / "limit.png");
  ASSERT_FALSE(first.empty()) << "no limit.png written";
  EXPECT_TRUE(first == second) << "two runs of scenes/plate_ss.json wrote different limit.png files ("
                               << first.size() << " and " << second.size() << " bytes)";
}

}  // namespace
}  // namespace clothsim

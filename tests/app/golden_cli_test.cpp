// clothsim golden check|update MANIFEST on a user's own manifest in a temporary folder, through
// the built binary: update writes the goldens (new, then unchanged and untouched), check passes,
// fails on a changed, resized or missing golden and on a failing run (keeping the rendered and
// difference images and a report in the --failures folder, removed again once all pass), the
// tolerance options, and the manifest and usage errors (exit code 2, naming the file and line).
#include "render/image.hpp"
#include "render/png_io.hpp"

#include "tests/support/cli_fixture.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::contains;
using testing::read_file_bytes;

// A 1 m plate of 4 × 4 cells under a surface load, drawn at 64 × 48 (a fraction of a second).
const char* const kPlate = R"({"name": "plate",
  "mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [4, 4]},
  "material": {"youngs_modulus": 1e7, "poisson_ratio": 0.3, "thickness": 0.01},
  "boundary": [{"select": {"box": [[-0.51, -0.51, -1], [0.51, -0.49, 1]]}},
               {"select": {"box": [[-0.51, 0.49, -1], [0.51, 0.51, 1]]}}],
  "loads": {"surface_load": [0, 0, -10]}, "render": {"width": 64, "height": 48}})";

class GoldenCliTest : public testing::CliFixture {
 protected:
  void SetUp() override {
    CliFixture::SetUp();
    write("scenes/plate.json", kPlate);
    manifest_ = write("goldens/list.txt",
                      "# my goldens\n"
                      "\n"
                      "plate.png      ../scenes/plate.json  plate/limit.png\n"
                      "big/plate.png  ../scenes/plate.json  plate/limit.png  --size 80x60\n");
    failures_ = dir_ / "failures";
  }
  CliResult check(const std::string& more = "") const {
    return run("golden check " + q(manifest_) + " --failures " + q(failures_) + more);
  }
  fs::path manifest_, failures_;
};

TEST_F(GoldenCliTest, UpdateThenCheck) {
  CliResult r = run("golden update " + q(manifest_));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "golden plate.png: new, wrote " + (dir_ / "goldens/plate.png").string())) << r.out;
  EXPECT_TRUE(contains(r.out, "golden big/plate.png: new")) << r.out;
  const render::Image small = render::read_png((dir_ / "goldens/plate.png").string());
  const render::Image big = render::read_png((dir_ / "goldens/big/plate.png").string());
  EXPECT_EQ(small.width, 64);
  EXPECT_EQ(small.height, 48);
  EXPECT_EQ(big.width, 80);
  EXPECT_EQ(big.height, 60);

  // Unchanged goldens are not rewritten (same bytes, same modification time).
  const auto mtime = fs::last_write_time(dir_ / "goldens/plate.png");
  const std::string bytes = read_file_bytes(dir_ / "goldens/plate.png");
  r = run("golden update " + q(manifest_));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "golden plate.png: unchanged")) << r.out;
  EXPECT_TRUE(contains(r.out, "2 golden(s), 0 written")) << r.out;
  EXPECT_EQ(fs::last_write_time(dir_ / "goldens/plate.png"), mtime);
  EXPECT_EQ(read_file_bytes(dir_ / "goldens/plate.png"), bytes);

  r = check();
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "golden plate.png: ok (64x48, largest channel difference 0")) << r.out;
  EXPECT_TRUE(contains(r.out, "golden big/plate.png: ok (80x60")) << r.out;
  EXPECT_TRUE(contains(r.out, "golden: 2 golden(s): 2 passed, 0 failed")) << r.out;
  EXPECT_FALSE(fs::exists(failures_));
}

// A changed golden fails with the rendered and difference images kept; the tolerance options can
// accept it; a resized or missing golden fails; once all pass the failures folder goes away.
TEST_F(GoldenCliTest, CheckFailuresKeepImagesAndReport) {
  ASSERT_EQ(run("golden update " + q(manifest_)).exit_code, 0);
  const fs::path golden = dir_ / "goldens/plate.png";
  const std::string original = read_file_bytes(golden);
  render::Image image = render::read_png(golden.string());
  for (std::uint8_t& v : image.rgb) v = static_cast<std::uint8_t>(255 - v);  // every pixel differs
  render::write_png(golden.string(), image);

  CliResult r = check();
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "golden plate.png: FAILED: 64x48, largest channel difference")) << r.out;
  EXPECT_TRUE(contains(r.out, "golden big/plate.png: ok")) << r.out;
  EXPECT_TRUE(contains(r.out, "golden: 2 golden(s): 1 passed, 1 failed; report and images in " + failures_.string()))
      << r.out;
  EXPECT_TRUE(contains(r.out, "clothsim golden update " + manifest_.string())) << r.out;
  EXPECT_EQ(render::read_png((failures_ / "plate.actual.png").string()).width, 64);
  EXPECT_EQ(render::read_png((failures_ / "plate.diff.png").string()).width, 64);
  EXPECT_TRUE(contains(read_file_bytes(failures_ / "golden_failures.txt"), "golden plate.png: FAILED"));
  EXPECT_EQ(read_file_bytes(failures_ / "plate.actual.png"), original);  // the rendered image, byte for byte

  r = check(" --tolerance 255");  // no channel differs by more than 255
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_FALSE(fs::exists(failures_)) << "the failures of the earlier check were not removed";
  r = check(" --max-differing 100");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;

  render::write_png(golden.string(), render::Image{32, 24, std::vector<std::uint8_t>(32 * 24 * 3, 255)});
  r = check();
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "golden plate.png: FAILED: size: golden 32x24, rendered 64x48")) << r.out;
  EXPECT_TRUE(fs::exists(failures_ / "plate.actual.png"));
  EXPECT_FALSE(fs::exists(failures_ / "plate.diff.png"));

  fs::remove(dir_ / "goldens/big/plate.png");
  r = check();
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "golden big/plate.png: FAILED: no golden " + (dir_ / "goldens/big/plate.png").string()))
      << r.out;
  EXPECT_TRUE(fs::exists(failures_ / "big_plate.actual.png"));

  ASSERT_EQ(run("golden update " + q(manifest_)).exit_code, 0);
  EXPECT_EQ(read_file_bytes(golden), original);
  r = check();
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_FALSE(fs::exists(failures_));
}

// A run that fails is a failed golden for check, and update then writes no golden at all.
TEST_F(GoldenCliTest, FailingRun) {
  ASSERT_EQ(run("golden update " + q(manifest_)).exit_code, 0);
  const std::string before = read_file_bytes(dir_ / "goldens/plate.png");
  write("goldens/list.txt",
        "plate.png      ../scenes/plate.json  plate/limit.png  --size 96x72\n"
        "big/plate.png  ../scenes/plate.json  plate/limit.png  --end 1\n");
  CliResult r = run("golden update " + q(manifest_));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "golden big/plate.png: FAILED: the run failed (exit code 1):")) << r.out;
  EXPECT_TRUE(contains(r.out, "--end: only applies to dynamic scenes")) << r.out;
  EXPECT_TRUE(contains(r.out, "no golden was written")) << r.out;
  EXPECT_EQ(read_file_bytes(dir_ / "goldens/plate.png"), before);

  r = check();
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "golden plate.png: FAILED: size: golden 64x48, rendered 96x72")) << r.out;
  EXPECT_TRUE(contains(r.out, "golden big/plate.png: FAILED: the run failed")) << r.out;

  write("goldens/list.txt", "plate.png  ../scenes/plate.json  plate/other.png\n");
  r = check();
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "golden plate.png: FAILED: the run wrote no plate/other.png")) << r.out;
}

TEST_F(GoldenCliTest, ManifestErrorsExitTwoNamingTheLine) {
  const std::string m = q(manifest_);
  auto expect_error = [&](const std::string& text, const std::string& message) {
    write("goldens/list.txt", text);
    const CliResult r = run("golden check " + m + " --failures " + q(failures_));
    EXPECT_EQ(r.exit_code, 2) << text << "\n" << r.out << r.err;
    EXPECT_TRUE(contains(r.err, "clothsim: error: " + message)) << text << "\n" << r.err;
    EXPECT_EQ(r.out, "") << text;
  };
  const std::string where = manifest_.string() + ":2: ";
  expect_error("# c\nplate.png ../scenes/plate.json\n", where + "expected GOLDEN.png SCENE RENDERED OPTIONS...");
  expect_error("# c\nplate.jpg ../scenes/plate.json plate/limit.png\n", where + "GOLDEN must be a .png file");
  expect_error("# c\nplate.png ../scenes/none.json plate/limit.png\n",
               where + "scene " + (dir_ / "scenes/none.json").string() + ": no such file");
  expect_error("# c\nplate.png ../scenes/plate.json ../limit.png\n", where + "RENDERED must be a .png path");
  expect_error("# c\nplate.png ../scenes/plate.json plate/limit.png --out x\n", where + "--out is chosen by clothsim golden");
  expect_error("plate.png ../scenes/plate.json plate/limit.png\n./plate.png ../scenes/plate.json plate/limit.png\n",
               where + "golden ./plate.png is listed twice");
  expect_error("# nothing\n", manifest_.string() + ": lists no goldens");
  const fs::path missing = dir_ / "none.txt";
  CliResult r = run("golden check " + q(missing));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, missing.string() + ": cannot read the manifest")) << r.err;
  r = run("golden verify " + m);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "clothsim: error: ")) << r.err;
  r = run("golden update " + m + " --tolerance 3");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "--tolerance applies to `clothsim golden check` only")) << r.err;
  r = run("golden --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(contains(r.out, "GOLDEN.png  SCENE.json  RENDERED  OPTIONS")) << r.out;
}

// A --failures folder that golden check did not write is refused before anything runs.
TEST_F(GoldenCliTest, RefusesAForeignFailuresFolder) {
  write("failures/notes.txt", "keep me");
  const CliResult r = check();
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "--failures: " + failures_.string() + " exists and was not written by clothsim golden check"))
      << r.err;
  EXPECT_EQ(read_file_bytes(failures_ / "notes.txt"), "keep me");
}

}  // namespace
}  // namespace clothsim

// clothsim render DIR through the built binary: a run's saved OBJ frames drawn again with the
// render settings the run saved in summary.json (a run at --size 64x48 gives 64x48 pictures
// without --size), overrides (--size, --refine, --surface), the new output folder (default
// DIR/render/, or --out; replaced only if an earlier render wrote it; the run's own files
// untouched), a static run's limit.obj, old runs without saved settings (defaults and a notice),
// and errors naming the folder, file, key or option.
#include "render/image.hpp"
#include "render/png_io.hpp"

#include "tests/support/cli_fixture.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <string>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::contains;
using testing::read_file_bytes;

// A 0.2 m square of 4 × 4 cells pinned along y = +0.1 m, falling under gravity; OBJ frames at
// 250 fps, 3 frames with --frames 3.
const char* const kCloth = R"({
  "name": "cloth", "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "cotton"},
  "boundary": [{"select": {"box": [[-0.11, 0.09, -1], [0.11, 0.11, 1]]}, "fix": ["x", "y", "z"]}],
  "loads": {"gravity": [0, 0, -9.81]},
  "time": {"dt": 0.002, "end": 0.008, "output_fps": 250},
  "output": {"obj": true},
  "render": {"refine": 1, "background": [0.9, 0.9, 1]}
})";

// Every file in `dir` (recursively) with its bytes.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = read_file_bytes(e.path());
  return files;
}

class RenderCliTest : public testing::CliFixture {
 protected:
  // Runs the cloth at 64x48 for 3 frames into dir_/out/cloth.
  void SetUp() override {
    CliFixture::SetUp();
    const CliResult r = run(q(write("cloth.json", kCloth)) + " --out " + q(dir_ / "out") + " --size 64x48 --frames 3");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    run_ = dir_ / "out" / "cloth";
  }
  fs::path run_;
};

TEST_F(RenderCliTest, UsesTheRunsSavedSettingsIntoANewFolder) {
  const nlohmann::json summary = nlohmann::json::parse(read_file_bytes(run_ / "summary.json"));
  EXPECT_EQ(summary["render"]["width"], 64);
  EXPECT_EQ(summary["render"]["height"], 48);
  EXPECT_EQ(summary["render"]["refine"], 1);
  const auto before = snapshot(run_);

  CliResult r = run("render " + q(run_));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(contains(r.out, "rendered 3 picture(s) of 64x48 from")) << r.out;
  for (const char* name : {"frame_0000.png", "frame_0001.png", "frame_0002.png"}) {
    const render::Image image = render::read_png((run_ / "render" / name).string());
    EXPECT_EQ(image.width, 64) << name;
    EXPECT_EQ(image.height, 48) << name;
  }
  EXPECT_FALSE(fs::exists(run_ / "render" / "frame_0003.png"));
  const nlohmann::json record = nlohmann::json::parse(read_file_bytes(run_ / "render" / "render.json"));
  EXPECT_EQ(record["pictures"], 3);
  EXPECT_EQ(record["render"]["width"], 64);
  EXPECT_EQ(record["render"]["surface"], "loop_limit");  // "method" resolved for loop_kl
  EXPECT_EQ(record["render"]["background"], nlohmann::json::parse("[0.9, 0.9, 1.0]"));
  EXPECT_EQ(record["camera"], "framed on the whole sequence");

  // The run's own files are untouched; the new folder is all that was added.
  auto after = snapshot(run_);
  for (auto it = after.begin(); it != after.end();)
    it = it->first.rfind("render/", 0) == 0 ? after.erase(it) : std::next(it);
  EXPECT_EQ(after, before);

  // Drawn again: replaced, byte-identical (deterministic).
  const auto first = snapshot(run_ / "render");
  r = run("render " + q(run_));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(snapshot(run_ / "render"), first);
}

TEST_F(RenderCliTest, OverridesAndOut) {
  const fs::path out = dir_ / "elsewhere" / "big";
  CliResult r = run("render " + q(run_) + " --out " + q(out) + " --size 80x60 --refine 0 --surface flat");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const render::Image image = render::read_png((out / "frame_0002.png").string());
  EXPECT_EQ(image.width, 80);
  EXPECT_EQ(image.height, 60);
  const nlohmann::json record = nlohmann::json::parse(read_file_bytes(out / "render.json"));
  EXPECT_EQ(record["render"]["refine"], 0);
  EXPECT_EQ(record["render"]["surface"], "flat");
  EXPECT_FALSE(fs::exists(run_ / "render"));
  // The run's own picture (the run's camera) and the re-rendered one are both 64x48 at the saved size.
  EXPECT_EQ(render::read_png((run_ / "frame_0002.png").string()).width, 64);
}

TEST_F(RenderCliTest, OldRunWithoutSettingsUsesTheDefaults) {
  nlohmann::json summary = nlohmann::json::parse(read_file_bytes(run_ / "summary.json"));
  summary.erase("render");
  write("out/cloth/summary.json", summary.dump(2));
  const CliResult r = run("render " + q(run_) + " --size 32x24");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "clothsim: " + (run_ / "summary.json").string() +
                                  " has no \"render\" settings (a run made before they were saved): drawing with the defaults"))
      << r.err;
  const nlohmann::json record = nlohmann::json::parse(read_file_bytes(run_ / "render" / "render.json"));
  EXPECT_EQ(record["render"]["refine"], 2);  // the default, not the run's 1
  EXPECT_EQ(record["render"]["width"], 32);
}

TEST_F(RenderCliTest, StaticRunLimitObj) {
  const CliResult run_static =
      run(q(write("plate.json", R"({"name": "plate",
        "mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [4, 4]},
        "material": {"youngs_modulus": 1e7, "poisson_ratio": 0.3, "thickness": 0.01},
        "boundary": [{"select": {"box": [[-0.51, -0.51, -1], [0.51, -0.49, 1]]}},
                     {"select": {"box": [[-0.51, 0.49, -1], [0.51, 0.51, 1]]}}],
        "loads": {"surface_load": [0, 0, -1]}, "render": {"width": 48, "height": 32}})")) +
          " --out " + q(dir_ / "out"));
  ASSERT_EQ(run_static.exit_code, 0) << run_static.err;
  EXPECT_EQ(nlohmann::json::parse(read_file_bytes(dir_ / "out/plate/result.json"))["render"]["width"], 48);
  const CliResult r = run("render " + q(dir_ / "out/plate"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const render::Image image = render::read_png((dir_ / "out/plate/render/limit.png").string());
  EXPECT_EQ(image.width, 48);
  EXPECT_EQ(image.height, 32);
}

TEST_F(RenderCliTest, ErrorsNameTheProblem) {
  const fs::path missing = dir_ / "missing";
  CliResult r = run("render " + q(missing));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "clothsim: error: " + missing.string() + ": no such folder")) << r.err;

  fs::create_directories(dir_ / "empty");
  r = run("render " + q(dir_ / "empty"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, (dir_ / "empty").string() + ": no saved geometry")) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "empty" / "render"));

  r = run("render " + q(run_) + " --size 64x48abc");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "--size: expected WxH with 16 <= W, H <= 8192 (got \"64x48abc\")")) << r.err;
  r = run("render " + q(run_) + " --refine 5");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "--refine")) << r.err;
  r = run("render " + q(run_) + " --surface smooth");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "--surface")) << r.err;

  // An output folder that clothsim render did not write (here: the run folder itself).
  const auto before = snapshot(run_);
  r = run("render " + q(run_) + " --out " + q(run_));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "--out: " + run_.string() + " exists and was not written by this command")) << r.err;
  EXPECT_EQ(snapshot(run_), before);

  // Bad saved settings: the error names the file and the key.
  nlohmann::json summary = nlohmann::json::parse(read_file_bytes(run_ / "summary.json"));
  summary["render"]["width"] = 8;
  write("out/cloth/summary.json", summary.dump(2));
  r = run("render " + q(run_));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, (run_ / "summary.json").string() + ": render.width: must be an integer >= 16")) << r.err;
  write("out/cloth/summary.json", "{\"render\": ");
  r = run("render " + q(run_));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, (run_ / "summary.json").string() + ": malformed JSON")) << r.err;
  EXPECT_FALSE(fs::exists(run_ / "render"));
}

}  // namespace
}  // namespace clothsim

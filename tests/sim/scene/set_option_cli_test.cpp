// `clothsim SCENE --set KEY=VALUE`: the run uses the overridden scene (its outputs, and the
// output folder when the name is overridden), a bad override or an overridden value the loader
// refuses exits 1 naming the --set argument and writes nothing, and --set is repeatable in any
// position.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using clothsim::testing::read_file_bytes;
using clothsim::testing::shell_quote;

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// A clamped 0.2 m strip under a tip load: the probe's deflection is proportional to the load.
const char* const kStrip = R"({
  "name": "strip",
  "mesh": {"primitive": "grid", "size": [0.2, 0.04], "divisions": [10, 2]},
  "material": {"youngs_modulus": 1e7, "poisson_ratio": 0.0, "thickness": 0.002},
  "boundary": [{"select": {"box": [[-0.11, -1, -1], [-0.099, 1, 1]]}, "rotation": "clamped"}],
  "loads": {"point_loads": [{"at": [0.1, 0.02, 0], "force": [0, 0, -0.001]}]},
  "probes": [{"name": "tip", "at": [0.1, 0.02, 0]}]
})";

class SetOption : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = clothsim::testing::make_temp_dir("clothsim_set_option_");
    out_ = dir_ / "out";
    scene_ = dir_ / "strip.json";
    std::ofstream(scene_) << kStrip;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  // Runs clothsim with `args` (shell words); exit code, stderr in err_.
  int run(const std::string& args) {
    const int code = clothsim::testing::run_shell(shell_quote(CLOTHSIM_BINARY) + " " + args + " --no-render --out " +
                                                  shell_quote(out_.string()) + " >/dev/null 2>" +
                                                  shell_quote((dir_ / "err.txt").string()));
    err_ = read_file_bytes(dir_ / "err.txt");
    return code;
  }
  double tip_deflection(const std::string& name) const {
    const auto result = nlohmann::json::parse(read_file_bytes(out_ / name / "result.json"));
    return result["probes"]["tip"]["displacement"][2].get<double>();
  }
  fs::path dir_, out_, scene_;
  std::string err_;
};

TEST_F(SetOption, OverridesReachTheRunsOutputs) {
  ASSERT_EQ(run(shell_quote(scene_.string())), 0) << err_;
  const double base = tip_deflection("strip");
  ASSERT_LT(base, 0);
  // Twice the load, under another name (so in another folder), --set before and after the scene.
  ASSERT_EQ(run("--set name=strip2 " + shell_quote(scene_.string()) +
                " --set 'loads.point_loads[0].force=[0, 0, -0.002]'"),
            0)
      << err_;
  EXPECT_NEAR(tip_deflection("strip2") / base, 2.0, 1e-9);
  EXPECT_TRUE(contains(err_, "clothsim: --set name = \"strip2\"")) << err_;
  EXPECT_TRUE(contains(err_, "clothsim: --set loads.point_loads[0].force = [0,0,-0.002]")) << err_;
  // The other form of an index; the last of two overrides of one key wins.
  ASSERT_EQ(run(shell_quote(scene_.string()) + " --set name=strip3 --set loads.point_loads.0.force=[0,0,-0.004] "
                "--set loads.point_loads.0.force=[0,0,-0.003]"),
            0)
      << err_;
  EXPECT_NEAR(tip_deflection("strip3") / base, 3.0, 1e-9);
  // result.json records the overrides, in order.
  const auto result = nlohmann::json::parse(read_file_bytes(out_ / "strip3" / "result.json"));
  EXPECT_EQ(result["overrides"], nlohmann::json::array({"name=strip3", "loads.point_loads.0.force=[0,0,-0.004]",
                                                        "loads.point_loads.0.force=[0,0,-0.003]"}));
  EXPECT_EQ(nlohmann::json::parse(read_file_bytes(out_ / "strip" / "result.json"))["overrides"], nlohmann::json::array());
  // The scene file is unchanged.
  EXPECT_EQ(read_file_bytes(scene_), kStrip);
}

TEST_F(SetOption, BadOverridesExitOneAndWriteNothing) {
  EXPECT_EQ(run(shell_quote(scene_.string()) + " --set loads.point_loads.0.force.2.x=1"), 1);
  EXPECT_TRUE(contains(err_, "clothsim: error: --set loads.point_loads.0.force.2.x=1: loads.point_loads[0].force[2] is "
                             "-0.001, not an object or array, so it has no key \"x\"\n"))
      << err_;
  EXPECT_FALSE(fs::exists(out_));
  EXPECT_EQ(run(shell_quote(scene_.string()) + " --set material.thicknes=0.001"), 1);
  EXPECT_TRUE(contains(err_, scene_.string() + ": material.thicknes: unknown key (allowed: ")) << err_;
  EXPECT_TRUE(contains(err_, "; did you mean \"thickness\"? (set by --set material.thicknes=0.001)")) << err_;
  EXPECT_FALSE(fs::exists(out_));
  EXPECT_EQ(run(shell_quote(scene_.string()) + " --set material.thickness=-1"), 1);
  EXPECT_TRUE(contains(err_, "material.thickness: must be > 0 [m] (got -1) (set by --set material.thickness=-1)")) << err_;
  EXPECT_EQ(run(shell_quote(scene_.string()) + " --set mesh.max_vertices=20"), 1);
  EXPECT_TRUE(contains(err_, "mesh.divisions: a 10 x 2 grid has 33 vertices, more than mesh.max_vertices = 20")) << err_;
  EXPECT_EQ(run(shell_quote(scene_.string()) + " --set noequals"), 1);
  EXPECT_TRUE(contains(err_, "clothsim: error: --set noequals: expected KEY=VALUE")) << err_;
  EXPECT_EQ(run(shell_quote(scene_.string()) + " --set"), 1);
  EXPECT_FALSE(fs::exists(out_));
}

}  // namespace

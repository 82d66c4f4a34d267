// Runs that start in a state contact cannot resolve say so and run at normal speed: a panel rolled
// to almost a full turn, whose two borders touch at rest, is taken to be joined there.
#include "tests/support/cli_fixture.hpp"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using testing::CliFixture;
using testing::contains;

std::string rolled_panel(const std::string& angle) {
  return R"({"name": "rolled", "analysis": "dynamic",
    "mesh": {"primitive": "cylinder", "radius": 0.05, "length": 0.1, "segments": 16, "rings": 4, "angle_deg": )" +
         angle + R"(},
    "material": {"preset": "cotton"}, "loads": {"gravity": [0, -9.81, 0]},
    "boundary": [{"select": {"box": [[-1, -0.0001, -1], [1, 0.0001, 1]]}, "fix": ["x", "y", "z"]}],
    "time": {"dt": 0.001, "end": 0.01, "output_fps": 100},
    "collision": {"self": true, "thickness": 0.001}})";
}

using ContactWarningsCli = CliFixture;

TEST_F(ContactWarningsCli, BordersTouchingAtRestAreJoinedWithAWarning) {
  const fs::path scene = write("rolled.json", rolled_panel("359.9999999999"));
  const testing::CliResult r = run(q(scene) + " --out " + q(dir_ / "out") + " --no-render");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "warning: contact: ")) << r.err;
  EXPECT_TRUE(contains(r.err, "touch at rest without being neighbours in the mesh")) << r.err;
  std::ifstream in(dir_ / "out" / "rolled" / "summary.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  bool warned = false;
  for (const auto& w : j["warnings"]) warned = warned || contains(w.get<std::string>(), "taken to be joined there");
  EXPECT_TRUE(warned) << j["warnings"].dump();
  // Nothing left colliding: the touching borders make no pairs (before, every step ended with
  // thousands of unresolved pairs and took seconds).
  EXPECT_EQ(j["contact"]["unresolved_pairs"], 0);
  EXPECT_EQ(j["contact"]["impact_zones"], 0);
}

TEST_F(ContactWarningsCli, APanelWithAGapHasNoSuchWarning) {
  const fs::path scene = write("open.json", rolled_panel("340"));
  const testing::CliResult r = run(q(scene) + " --out " + q(dir_ / "out") + " --no-render");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(contains(r.err, "touch at rest")) << r.err;
}

}  // namespace
}  // namespace clothsim

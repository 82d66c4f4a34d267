// A pattern garment's run through the command line: its OBJ frames carry the pattern coordinates
// as texture coordinates (vt), at the control connectivity and on the refined surface, so the
// frames can be textured in other tools; summary.json reports the settling.
#include "sim/mesh/obj_io.hpp"

#include "tests/support/cli_fixture.hpp"
#include "tests/support/skirt_scene.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

namespace clothsim {
namespace {

class PatternCli : public testing::CliFixture {};

// The tube skirt of scenes/README.md, no body, a few steps.
const std::string kSkirt = std::string(R"({"name": "skirt", "analysis": "dynamic", )") + testing::kCoarseTubeSkirtMesh +
                          R"(, "material": {"preset": "cotton"}, "settle": {"time": 0.05},
  "time": {"dt": 0.01, "end": 0.02, "output_fps": 50}, "output": {"obj": true, "obj_level": LEVEL}})";

double uv_area(const TriMesh& m) {
  double a = 0;
  for (const auto& t : m.uv) {
    const Eigen::Vector2d e1 = t[1] - t[0], e2 = t[2] - t[0];
    a += 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
  }
  return a;
}

TEST_F(PatternCli, ObjFramesCarryThePatternCoordinates) {
  for (const int level : {0, 1}) {
    std::string text = kSkirt;
    text.replace(text.find("LEVEL"), 5, std::to_string(level));
    const auto scene = write("skirt.json", text);
    const testing::CliResult r = run(q(scene) + " --no-render --out " + q(dir_ / "out"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const TriMesh frame = read_obj((dir_ / "out/skirt/frames/mesh_0001.obj").string());
    ASSERT_EQ(frame.uv.size(), frame.triangles.size()) << "level " << level;
    // Two pieces of 0.5 m x 0.5 m: their pattern area, whatever the refinement.
    EXPECT_NEAR(uv_area(frame), 0.5, 1e-12) << "level " << level;
    const auto summary = nlohmann::json::parse(testing::read_file_bytes(dir_ / "out/skirt/summary.json"));
    ASSERT_TRUE(summary.contains("settle")) << summary.dump();
    EXPECT_EQ(summary["settle"]["steps"], 5);
    EXPECT_GT(summary["settle"]["membrane_strain_start"].get<double>(), summary["settle"]["membrane_strain_end"].get<double>());
  }
}

// The settle's steps are booked as a run's (issue 44): summary.json's "settle" holds their time,
// Newton solves and parts, the parts adding up to at most the steps' time; the log says it.
TEST_F(PatternCli, TheSettleReportsWhereItsTimeWent) {
  std::string text = kSkirt;
  text.replace(text.find("LEVEL"), 5, "0");
  text.replace(text.find(R"("settle")"), 0, R"("collision": {"self": true, "thickness": 0.002}, )");
  const auto scene = write("skirt.json", text);
  const testing::CliResult r = run(q(scene) + " --no-render --out " + q(dir_ / "out"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto settle = nlohmann::json::parse(testing::read_file_bytes(dir_ / "out/skirt/summary.json"))["settle"];
  EXPECT_EQ(settle["steps"], 5);
  EXPECT_GE(settle["newton_iterations"].get<long long>(), 5) << settle.dump();  // (a potential solve per step at least)
  const double steps = settle["step_seconds"].get<double>();
  EXPECT_GT(steps, 0.0);
  double parts = 0.0;
  for (const char* key : {"first_solve_seconds", "newton_solve_seconds", "barrier_evaluation_seconds", "line_search_seconds",
                          "candidates_seconds", "failsafe_seconds"}) {
    ASSERT_TRUE(settle.contains(key)) << key;
    EXPECT_GE(settle[key].get<double>(), 0.0) << key;
    parts += settle[key].get<double>();
  }
  EXPECT_LE(parts, steps * (1 + 1e-9));
  // (barrier_seconds, as the run's, holds the barrier's candidate search and line search too.)
  EXPECT_NEAR(settle["barrier_seconds"].get<double>(),
              settle["barrier_evaluation_seconds"].get<double>() + settle["line_search_seconds"].get<double>() +
                  settle["candidates_seconds"].get<double>(),
              1e-9 * steps + 1e-12);
  EXPECT_GT(settle["first_solve_seconds"].get<double>(), 0.0);
  EXPECT_NE(r.err.find("settle: "), std::string::npos) << r.err;
}

}  // namespace
}  // namespace clothsim

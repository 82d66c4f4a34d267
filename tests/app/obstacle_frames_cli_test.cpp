// With "output": {"obj": true}, a dynamic run writes beside each cloth frame the obstacles (all but
// planes) where they stand at that frame: frames/obstacles_NNNN.obj.
#include "sim/mesh/obj_io.hpp"
#include "tests/support/cli_fixture.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>

#include <filesystem>
#include <string>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using testing::CliFixture;

// A small sheet above a ball that moves 0.1 m along +x over the first 0.1 s, over a ground plane.
const char* const kMovingBall = R"({"name": "ball_frames", "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "cotton"}, "loads": {"gravity": [0, -9.81, 0]},
  "time": {"dt": 0.01, "end": 0.1, "output_fps": 20},
  "collision": {"thickness": 0.002},
  "obstacles": [{"name": "ground", "primitive": "plane", "point": [0, -0.5, 0], "normal": [0, 1, 0]},
                {"name": "ball", "primitive": "sphere", "center": [0, -0.2, 0], "radius": 0.1,
                 "motion": [{"type": "translate", "displacement": [0.1, 0, 0], "start": 0, "end": 0.1}]}],
  "output": {"obj": true}})";

using ObstacleFramesCli = CliFixture;

TEST_F(ObstacleFramesCli, EachFrameHasTheObstaclesWhereTheyStand) {
  const fs::path scene = write("ball.json", kMovingBall);
  const testing::CliResult r = run(q(scene) + " --out " + q(dir_ / "out") + " --no-render");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path frames = dir_ / "out" / "ball_frames" / "frames";
  for (int k = 0; k <= 2; ++k) {  // t = 0, 0.05, 0.1 s
    const std::string n = std::string(k < 10 ? "000" : "00") + std::to_string(k);
    ASSERT_TRUE(fs::exists(frames / ("mesh_" + n + ".obj"))) << n;
    const TriMesh ball = read_obj((frames / ("obstacles_" + n + ".obj")).string());
    // The ball's tessellation (planes are not written) ...
    EXPECT_EQ(ball.num_triangles(), 5120);
    // ... centred where its motion has taken it (vertices spread evenly over the sphere).
    const Eigen::Vector3d centre = ball.vertices.colwise().mean().transpose();
    const double x = 0.1 * std::min(1.0, 0.05 * k / 0.1);
    EXPECT_NEAR(centre.x(), x, 1e-9) << n;
    EXPECT_NEAR(centre.y(), -0.2, 1e-9) << n;
    EXPECT_NEAR((ball.vertices.row(0).transpose() - centre).norm(), 0.1, 1e-9) << n;
  }
  EXPECT_FALSE(fs::exists(frames / "obstacles_0003.obj"));
}

TEST_F(ObstacleFramesCli, PlanesAloneWriteNoObstacleFrames) {
  std::string text = kMovingBall;
  const std::string ball = R"(,
                {"name": "ball", "primitive": "sphere", "center": [0, -0.2, 0], "radius": 0.1,
                 "motion": [{"type": "translate", "displacement": [0.1, 0, 0], "start": 0, "end": 0.1}]})";
  text.erase(text.find(ball), ball.size());
  const fs::path scene = write("plane.json", text);
  const testing::CliResult r = run(q(scene) + " --out " + q(dir_ / "out") + " --no-render");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path frames = dir_ / "out" / "ball_frames" / "frames";
  EXPECT_TRUE(fs::exists(frames / "mesh_0000.obj"));
  EXPECT_FALSE(fs::exists(frames / "obstacles_0000.obj"));
}

}  // namespace
}  // namespace clothsim

// The scene key "method": its default, the linear_fe method (mesh used as given, static and dynamic
// scenes), the error for an unknown value, and the borders linear_fe refuses, reported with the
// file and the key path.
#include "sim/scene/scene.hpp"

#include "tests/support/scene_files.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

namespace clothsim {
namespace {

const char* const kGrid4 = R"("mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [4, 4]})";
const char* const kClampedLeft =
    R"("boundary": [{"select": {"box": [[-1, -1, -1], [-0.49, 1, 1]]}, "fix": ["x", "y", "z"], "rotation": "clamped"}])";

class MethodKey : public testing::SceneFileTest {};

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

TEST_F(MethodKey, DefaultsToLoopKl) {
  EXPECT_EQ(load(std::string("{") + kGrid4 + "}").problem.method, "loop_kl");
  EXPECT_EQ(load(std::string(R"({"method": "loop_kl", )") + kGrid4 + "}").problem.method, "loop_kl");
}

TEST_F(MethodKey, LinearFeUsesTheMeshAsGiven) {
  // A 1 × 1 grid: two triangles, each with more than one irregular vertex, which loop_kl refines.
  const char* const grid1 = R"("mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [1, 1]})";
  std::vector<std::string> log;
  const LogFn say = [&](const std::string& line) { log.push_back(line); };
  const Scene loop = load_scene(write("loop.json", std::string("{") + grid1 + "}"), nullptr);
  const Scene flat = load_scene(write("flat.json", std::string(R"({"method": "linear_fe", )") + grid1 + "}"), say);
  EXPECT_EQ(flat.problem.method, "linear_fe");
  EXPECT_EQ(flat.problem.mesh.num_vertices(), 4);
  EXPECT_EQ(flat.problem.mesh.num_triangles(), 2);
  std::printf("1 x 1 grid: loop_kl prepares %d vertices, linear_fe %d\n", loop.problem.mesh.num_vertices(),
              flat.problem.mesh.num_vertices());
  EXPECT_GT(loop.problem.mesh.num_vertices(), 4);
  bool said = false;
  for (const std::string& line : log) said = said || line.find("linear_fe uses the mesh as given") != std::string::npos;
  EXPECT_TRUE(said);
  // Dynamic scenes take it too, with hinged borders.
  const Scene dynamic = load(std::string(R"({"analysis": "dynamic", "method": "linear_fe", )") + kGrid4 +
                             R"(, "boundary": [{"select": {"box": [[-1, -1, -1], [-0.49, 1, 1]]}, "rotation": "free"}],
      "loads": {"gravity": [0, 0, -9.81]}, "time": {"dt": 0.01, "end": 0.1}})");
  EXPECT_EQ(dynamic.problem.method, "linear_fe");
  EXPECT_EQ(dynamic.problem.mesh.num_vertices(), 25);
}

TEST_F(MethodKey, UnknownMethodIsAnErrorListingTheAllowedOnes) {
  EXPECT_EQ(error(std::string(R"({"method": "fem", )") + kGrid4 + "}"),
            expected(R"(method: unknown method "fem" (allowed: "loop_kl", "linear_fe", "mass_spring"))"));
  EXPECT_EQ(error(std::string(R"({"method": 3, )") + kGrid4 + "}"),
            expected(R"(method: expected a string (got 3; allowed: "loop_kl", "linear_fe", "mass_spring"))"));
}

TEST_F(MethodKey, LinearFeRefusesClampedAndSymmetryBorders) {
  const std::string clamped = error(std::string(R"({"method": "linear_fe", )") + kGrid4 + ", " + kClampedLeft + "}");
  std::printf("%s\n", clamped.c_str());
  EXPECT_TRUE(starts_with(clamped, expected(R"(boundary[0].rotation: "clamped" is not supported by the linear_fe method)")))
      << clamped;
  EXPECT_NE(clamped.find(R"(use "free")"), std::string::npos) << clamped;
  std::string symmetry_scene = std::string(R"({"method": "linear_fe", )") + kGrid4 + ", " + kClampedLeft + "}";
  symmetry_scene.replace(symmetry_scene.find("clamped"), 7, "symmetry");
  EXPECT_TRUE(starts_with(error(symmetry_scene),
                          expected(R"(boundary[0].rotation: "symmetry" is not supported by the linear_fe method)")))
      << error(symmetry_scene);
  // The same border is fine for loop_kl, and a hinged one for linear_fe.
  EXPECT_EQ(error(std::string("{") + kGrid4 + ", " + kClampedLeft + "}"), "no error");
  std::string hinged = std::string(R"({"method": "linear_fe", )") + kGrid4 + ", " + kClampedLeft + "}";
  hinged.replace(hinged.find("clamped"), 7, "free");
  EXPECT_EQ(error(hinged), "no error");
}

}  // namespace
}  // namespace clothsim

// The scene key "method": "mass_spring": a dynamic scene takes it (the mesh used as given, springs
// built by the Simulator), a static one is refused at the key "method", and so are clamped and
// symmetry borders, each reported with the file and the key path.
#include "sim/dynamics/simulator.hpp"
#include "sim/flat_fe/mass_spring.hpp"
#include "sim/scene/scene.hpp"

#include "tests/support/scene_files.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

namespace clothsim {
namespace {

const char* const kGrid4 = R"("mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [4, 4]})";
const char* const kDynamic = R"("analysis": "dynamic", "method": "mass_spring", "time": {"dt": 0.01, "end": 0.1})";
const char* const kLeftBorder = R"("boundary": [{"select": {"box": [[-1, -1, -1], [-0.49, 1, 1]]}, "rotation": "free"}])";

class MassSpringMethodKey : public testing::SceneFileTest {};

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

TEST_F(MassSpringMethodKey, DynamicScenesTakeItWithTheMeshAsGiven) {
  std::vector<std::string> log;
  const LogFn say = [&](const std::string& line) { log.push_back(line); };
  const Scene scene = load_scene(write("scene.json", std::string("{") + kDynamic + ", " + kGrid4 + ", " + kLeftBorder +
                                                         R"(, "loads": {"gravity": [0, 0, -9.81]}})"),
                                 say);
  EXPECT_EQ(scene.problem.method, "mass_spring");
  EXPECT_EQ(scene.problem.mesh.num_vertices(), 25);
  EXPECT_EQ(scene.problem.mesh.num_triangles(), 32);
  bool said = false;
  for (const std::string& line : log) said = said || line.find("mass_spring uses the mesh as given") != std::string::npos;
  EXPECT_TRUE(said);
  // The Simulator builds the springs: 56 edges and 40 hinges on 4 × 4 cells.
  Simulator sim(scene.problem);
  const auto& d = dynamic_cast<const MassSpringDiscretization&>(sim.discretization());
  EXPECT_EQ(d.method(), "mass_spring");
  EXPECT_EQ(d.stretch_springs().size(), 56u);
  EXPECT_EQ(d.bending_springs().size(), 40u);
  for (int i = 0; i < sim.num_steps(); ++i) sim.step();
  EXPECT_TRUE(sim.state().x.allFinite());
  std::printf("mass_spring scene: %zu stretch and %zu bending springs, kappa_ref %.2f 1/m; after %.2f s the free edge "
              "has fallen %.4f m\n",
              d.stretch_springs().size(), d.bending_springs().size(), d.reference_curvature(), sim.state().t,
              -(sim.state().positions().col(2).minCoeff()));
  EXPECT_LT(sim.state().positions().col(2).minCoeff(), -0.01);  // it swings down from the held border
}

TEST_F(MassSpringMethodKey, StaticScenesAreRefusedAtTheMethodKey) {
  const std::string message = error(std::string(R"({"method": "mass_spring", )") + kGrid4 + ", " + kLeftBorder + "}");
  std::printf("%s\n", message.c_str());
  EXPECT_TRUE(starts_with(message, expected(R"(method: "mass_spring" needs "analysis": "dynamic")"))) << message;
  EXPECT_NE(message.find("no stiffness against out-of-plane displacements"), std::string::npos) << message;
}

TEST_F(MassSpringMethodKey, ClampedAndSymmetryBordersAreRefused) {
  std::string scene = std::string("{") + kDynamic + ", " + kGrid4 + ", " + kLeftBorder + "}";
  scene.replace(scene.find("\"free\""), 6, "\"clamped\"");
  const std::string clamped = error(scene);
  std::printf("%s\n", clamped.c_str());
  EXPECT_TRUE(starts_with(clamped, expected(R"(boundary[0].rotation: "clamped" is not supported by the mass_spring method)")))
      << clamped;
  scene.replace(scene.find("\"clamped\""), 9, "\"symmetry\"");
  EXPECT_TRUE(starts_with(error(scene), expected(R"(boundary[0].rotation: "symmetry" is not supported by the mass_spring method)")))
      << error(scene);
}

}  // namespace
}  // namespace clothsim

// Shell benchmarks through scene files (MacNeal & Harder 1985): the Scordelis–Lo roof (reference
// vertical deflection 0.3024 at the midpoint of a free edge; deep-shell Kirchhoff solutions
// converge near 0.300) and the pinched cylinder (quarter model with symmetry planes, reference
// 1.8248e-5 under the load); and a quarter plate with symmetry edges against Kirchhoff theory.
#include "sim/scene/scene.hpp"
#include "sim/static/static_solve.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <fstream>

namespace clothsim {
namespace {

// Runs a shipped scene with `edit` applied to its JSON; returns the first probe's displacement.
Eigen::Vector3d run_scene(const std::string& name, const std::function<void(nlohmann::json&)>& edit) {
  std::ifstream in(std::string(CLOTHSIM_SOURCE_DIR) + "/scenes/" + name + ".json");
  nlohmann::json j = nlohmann::json::parse(in);
  edit(j);
  const auto file = std::filesystem::temp_directory_path() / ("clothsim_benchmark_" + name + ".json");
  std::ofstream(file) << j.dump();
  const Scene scene = load_scene(file, nullptr);
  std::filesystem::remove(file);
  const StaticResult r = solve_static(scene.problem);
  return r.limit_displacement.row(scene.probes.at(0).vertex).transpose();
}

double roof_deflection(int divisions, const std::string& quadrature) {
  return -run_scene("scordelis_lo", [&](nlohmann::json& j) {
    j["mesh"]["segments"] = divisions;
    j["mesh"]["rings"] = divisions + 1;
    j["numerics"]["quadrature"] = quadrature;
  })(2);
}

TEST(ShellBenchmarks, ScordelisLoRoofConverges) {
  const double reference = 0.3024;
  for (const std::string q : {"one_point", "three_point"}) {
    const double coarse = roof_deflection(16, q), medium = roof_deflection(32, q), fine = roof_deflection(64, q);
    std::printf("Scordelis-Lo %s: 16: %.4f  32: %.4f  64: %.4f (reference %.4f)\n", q.c_str(), coarse, medium, fine,
                reference);
    EXPECT_NEAR(medium / reference, 1.0, 0.02) << q;
    EXPECT_NEAR(fine / reference, 1.0, 0.012) << q;
    // Successive differences shrink: the sequence converges.
    EXPECT_LT(std::abs(fine - medium), std::abs(medium - coarse)) << q;
  }
}

TEST(ShellBenchmarks, PinchedCylinderWithSymmetryPlanesConverges) {
  const double reference = 1.8248e-5;
  double previous = 1.0;
  for (int n : {32, 64, 128}) {
    const double w = -run_scene("pinched_cylinder", [&](nlohmann::json& j) {
      j["mesh"]["segments"] = n;
      j["mesh"]["rings"] = n / 2 + 1;
    })(2);
    const double error = std::abs(w / reference - 1.0);
    std::printf("pinched cylinder %d x %d: %.5e (error %.2f %%)\n", n, n / 2, w, 100 * error);
    EXPECT_LT(error, previous) << n;
    previous = error;
  }
  EXPECT_LT(previous, 0.02);
}

TEST(ShellBenchmarks, QuarterPlateWithSymmetryEdgesMatchesKirchhoff) {
  // Simply supported 1 m plate modelled by the quarter [0, 0.5]²: hinged at x = 0.5 and y = 0.5,
  // symmetry planes x = 0 (fix x) and y = 0 (fix y); quarter of the load at the centre corner.
  nlohmann::json scene = {
      {"mesh", {{"primitive", "grid"}, {"size", {0.5, 0.5}}, {"divisions", {16, 16}}}},
      {"material", {{"youngs_modulus", 1e7}, {"poisson_ratio", 0.3}, {"thickness", 0.01}}},
      {"boundary",
       {{{"select", {{"box", {{0.249, -1, -1}, {0.251, 1, 1}}}}}, {"fix", {"x", "y", "z"}}},
        {{"select", {{"box", {{-1, 0.249, -1}, {1, 0.251, 1}}}}}, {"fix", {"x", "y", "z"}}},
        {{"select", {{"box", {{-0.251, -1, -1}, {-0.249, 1, 1}}}}}, {"fix", {"x"}}, {"rotation", "symmetry"}},
        {{"select", {{"box", {{-1, -0.251, -1}, {1, -0.249, 1}}}}}, {"fix", {"y"}}, {"rotation", "symmetry"}}}},
      {"loads", {{"surface_load", {0, 0, -1}}}},
      {"probes", {{{"name", "centre"}, {"at", {-0.25, -0.25, 0}}}}}};
  const auto file = std::filesystem::temp_directory_path() / "clothsim_quarter_plate.json";
  std::ofstream(file) << scene.dump();
  const Scene loaded = load_scene(file, nullptr);
  std::filesystem::remove(file);
  const StaticResult r = solve_static(loaded.problem);
  const double d = 1e7 * 1e-6 / (12 * (1 - 0.09));
  const double expected = 0.00406235 / d;
  const double w = -r.limit_displacement(loaded.probes.at(0).vertex, 2);
  std::printf("quarter plate: %.6e expected %.6e error %.3f %%\n", w, expected, 100 * (w / expected - 1));
  EXPECT_NEAR(w / expected, 1.0, 0.01);
}

}  // namespace
}  // namespace clothsim

// Curved-shell benchmark through the scene file: the Scordelis–Lo roof (MacNeal & Harder 1985),
// reference vertical deflection 0.3024 at the midpoint of a free edge (deep-shell Kirchhoff
// solutions converge near 0.300).
#include "sim/scene/scene.hpp"
#include "sim/static/static_solve.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace clothsim {
namespace {

double roof_deflection(int divisions, const std::string& quadrature) {
  std::ifstream in(std::string(CLOTHSIM_SOURCE_DIR) + "/scenes/scordelis_lo.json");
  nlohmann::json j = nlohmann::json::parse(in);
  j["mesh"]["segments"] = divisions;
  j["mesh"]["rings"] = divisions + 1;
  j["numerics"]["quadrature"] = quadrature;
  const auto file = std::filesystem::temp_directory_path() / ("clothsim_roof_" + std::to_string(divisions) + ".json");
  std::ofstream(file) << j.dump();
  const Scene scene = load_scene(file, nullptr);
  std::filesystem::remove(file);
  const StaticResult r = solve_static(scene.problem);
  return -r.limit_displacement(scene.probes.at(0).vertex, 2);
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

}  // namespace
}  // namespace clothsim

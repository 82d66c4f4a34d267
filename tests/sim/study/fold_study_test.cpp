// The fold study's library (sim/study/fold_study.hpp): the theory band against values computed by
// hand for the cotton preset (E·t = 5000 N/m, B = 1.157e-5 N·m, ν = 0.25, R = 5 cm, L = 20 cm);
// the counting on a run's drawn surface (count_drawn_folds) for node positions placed on analytic
// sleeves with a known number of folds (7 lobes around the axis, 5 bellows rings along it), for
// each method; the option parsers' accepted and rejected strings; the plans' sizes.
#include "sim/study/fold_study.hpp"

#include "sim/scene/scene.hpp"
#include "sim/setup/setup.hpp"
#include "sim/shell/material_presets.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <functional>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#ifndef CLOTHSIM_SOURCE_DIR
#error "CLOTHSIM_SOURCE_DIR must be defined (tests/CMakeLists.txt)"
#endif

namespace clothsim {
namespace {

constexpr double kRadius = 0.05;  // [m]
constexpr double kLength = 0.2;   // [m]

TEST(FoldStudyTheory, CottonBandsMatchHandComputedValues) {
  const ShellMaterial cotton = *material_preset("cotton");
  // t_eff = sqrt(12 · 1.157e-5 / 5000) = sqrt(2.7768e-8) m = 0.166637 mm.
  const double t = effective_thickness(cotton);
  EXPECT_NEAR(t, 1.666373e-4, 1e-9);
  // Twist: (R/L)^½ = 0.5, (R/t)^¼ = 300.05^¼ = 4.16191; c = 2.9 and 3.8 give 6.0349 and 7.9078.
  const FoldBand twist = twist_circumferential_band(kRadius, kLength, t);
  EXPECT_NEAR(twist.lo, 6.03486, 1e-4);
  EXPECT_NEAR(twist.hi, 7.90775, 1e-4);
  // λ = 2π sqrt(0.05 · 1.666373e-4) / (12 · 0.9375)^¼ = 2π · 2.886497e-3 / 1.831422 = 9.90291 mm.
  const double lambda = axisymmetric_buckling_wavelength(kRadius, t, cotton.poisson_ratio);
  EXPECT_NEAR(lambda, 9.902911e-3, 1e-8);
  // Axial count: L/(2λ) = 10.098 to L/λ = 20.196; circumferential: 0 to πR/λ = 15.862.
  const FoldBand axial = compression_axial_band(kRadius, kLength, t, cotton.poisson_ratio);
  EXPECT_NEAR(axial.lo, 10.09804, 1e-4);
  EXPECT_NEAR(axial.hi, 20.19608, 1e-4);
  const FoldBand circumferential = compression_circumferential_band(kRadius, t, cotton.poisson_ratio);
  EXPECT_EQ(circumferential.lo, 0.0);
  EXPECT_NEAR(circumferential.hi, 15.86196, 1e-4);
  // At ν = 0.3 the wavelength is 2π / 10.92^¼ = 2π / 1.817837 = 3.45640 sqrt(R t).
  EXPECT_NEAR(axisymmetric_buckling_wavelength(1.0, 1.0, 0.3), 3.45640, 1e-5);
  EXPECT_THROW(effective_thickness(ShellMaterial{0.0, 1e-5, 0.25, 0.1}), std::invalid_argument);
  EXPECT_THROW(axisymmetric_buckling_wavelength(0.05, 0.0, 0.25), std::invalid_argument);
  EXPECT_TRUE(twist.known());
  EXPECT_FALSE((FoldBand{std::nan(""), std::nan("")}.known()));
}

// The twist scene with its mesh and method replaced, as the study loads it.
Problem sleeve_problem(const std::string& method, int segments, int rings) {
  const std::string file = std::string(CLOTHSIM_SOURCE_DIR) + "/scenes/sleeve_twist.json";
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  nlohmann::json j = nlohmann::json::parse(text.str());
  j["method"] = method;
  j["mesh"]["segments"] = segments;
  j["mesh"]["rings"] = rings;
  return load_scene_text(j.dump(), file, LogFn()).problem;
}

// Node positions (3·#nodes) [m]: every node of the rest cylinder (axis y) moved radially to
// radius(θ, y).
Eigen::VectorXd radially_moved(const Discretization& d, const std::function<double(double, double)>& radius) {
  Eigen::VectorXd x = d.rest();
  for (int n = 0; n < d.num_nodes(); ++n) {
    const double px = x[3 * n], py = x[3 * n + 1], pz = x[3 * n + 2];
    const double theta = std::atan2(pz, px), r = radius(theta, py);
    x[3 * n] = r * std::cos(theta);
    x[3 * n + 2] = r * std::sin(theta);
  }
  return x;
}

TEST(FoldStudyCounting, DrawnSurfaceOfLobedAndBelledSleevesGivesTheirFoldCounts) {
  const double a = 0.06 * kRadius;  // lobe/ring amplitude: prominence 2a = 6 × the 2 % threshold
  for (const std::string method : {"loop_kl", "linear_fe", "mass_spring"}) {
    SCOPED_TRACE(method);
    const Problem problem = sleeve_problem(method, 52, 37);
    const std::shared_ptr<Discretization> d = make_discretization(problem);
    // 7 lobes around the axis, the same at every height: 7 circumferential folds, none along it.
    const FoldCounts lobes = count_drawn_folds(
        *d, radially_moved(*d, [&](double theta, double) { return kRadius + a * std::cos(7 * theta); }),
        Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY());
    ASSERT_TRUE(lobes.circumferential_median && lobes.axial_median);
    EXPECT_EQ(*lobes.circumferential_median, 7.0);
    EXPECT_EQ(*lobes.axial_median, 0.0);
    // Bellows with troughs at both rims, r = R − a cos(2π·5 y/L): 5 rings along every meridian,
    // a circular section at every height (0 circumferential folds).
    const FoldCounts rings = count_drawn_folds(
        *d,
        radially_moved(*d,
                       [&](double, double y) { return kRadius - a * std::cos(2 * std::numbers::pi * 5 * y / kLength); }),
        Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY());
    ASSERT_TRUE(rings.circumferential_median && rings.axial_median);
    EXPECT_EQ(*rings.circumferential_median, 0.0);
    EXPECT_EQ(*rings.axial_median, 5.0);
    // The threshold is 2 % of the mean radius (R up to the shapes' small effect on the mean).
    EXPECT_NEAR(lobes.prominence_threshold, 0.02 * kRadius, 0.02 * kRadius * 0.03);
  }
}

TEST(FoldStudyOptions, ParsersAcceptListsAndNameWhatIsWrong) {
  const std::vector<FoldMesh> meshes = parse_fold_meshes("26x19, 38x27,76x55");
  ASSERT_EQ(meshes.size(), 3u);
  EXPECT_EQ(meshes[1].segments, 38);
  EXPECT_EQ(meshes[1].rings, 27);
  EXPECT_EQ(meshes[2].vertices(), 4180);
  EXPECT_EQ(parse_fold_seeds("1,2,3"), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(parse_fold_methods("linear_fe,loop_kl"), (std::vector<std::string>{"linear_fe", "loop_kl"}));
  EXPECT_EQ(parse_fold_cases("compress"), (std::vector<std::string>{"compress"}));

  auto message = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_NE(message([] { parse_fold_meshes("26x"); }).find("--meshes: \"26x\" is not SEGMENTSxRINGS"), std::string::npos);
  EXPECT_NE(message([] { parse_fold_meshes("26x19,,38x27"); }).find("--meshes: empty item"), std::string::npos);
  EXPECT_NE(message([] { parse_fold_meshes("2x19"); }).find("needs 3 <= segments"), std::string::npos);
  EXPECT_NE(message([] { parse_fold_meshes("26.5x19"); }).find("is not SEGMENTSxRINGS"), std::string::npos);
  EXPECT_NE(message([] { parse_fold_seeds("1,-2"); }).find("--seeds: \"-2\" is not a non-negative integer"),
            std::string::npos);
  EXPECT_NE(message([] { parse_fold_seeds("1,1"); }).find("given twice"), std::string::npos);
  EXPECT_NE(message([] { parse_fold_methods("loop_kl,fem"); }).find("--methods: unknown method \"fem\" (allowed: loop_kl"),
            std::string::npos);
  EXPECT_NE(message([] { parse_fold_cases("shear"); }).find("--cases: unknown case \"shear\""), std::string::npos);

  FoldStudyPlan plan = quick_fold_plan("scenes");
  EXPECT_NO_THROW(validate_fold_plan(plan));
  plan.preset = "silk";
  EXPECT_NE(message([&] { validate_fold_plan(plan); }).find("unknown material preset \"silk\""), std::string::npos);
  plan = quick_fold_plan("scenes");
  plan.dt = 0.0;
  EXPECT_NE(message([&] { validate_fold_plan(plan); }).find("time step"), std::string::npos);
  plan = quick_fold_plan("scenes");
  plan.amplitude = -1e-4;
  EXPECT_NE(message([&] { validate_fold_plan(plan); }).find("amplitude"), std::string::npos);
}

TEST(FoldStudyPlan, FullPlanSpansEightTimesTheVerticesWithThreeSeeds) {
  const FoldStudyPlan plan = full_fold_plan("scenes");
  EXPECT_EQ(plan.cases, (std::vector<std::string>{"twist", "compress"}));
  EXPECT_EQ(plan.methods, (std::vector<std::string>{"loop_kl", "linear_fe", "mass_spring"}));
  ASSERT_GE(plan.meshes.size(), 4u);
  EXPECT_EQ(plan.meshes.front().vertices(), 26 * 19);
  EXPECT_GE(plan.meshes.back().vertices(), 8 * plan.meshes.front().vertices());
  EXPECT_EQ(plan.seeds.size(), 3u);
  EXPECT_FALSE(plan.self_collision);
}

}  // namespace
}  // namespace clothsim

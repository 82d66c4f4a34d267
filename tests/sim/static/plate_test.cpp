// Linear static analysis against Kirchhoff plate theory (docs/formulas.md §9, Analytic
// references): simply supported and clamped square plates under uniform and centre point loads,
// convergence under refinement, and a cantilever strip's small-deflection tip (P L³ / 3EI).
#include "tests/support/plates.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace clothsim {
namespace {

using PlateCase = AnalyticPlate;  // the coefficients live in sim/study/plates.hpp
const PlateCase& kSimplySupportedUniform = kAnalyticPlates[0];
const PlateCase& kClampedUniform = kAnalyticPlates[1];
const PlateCase& kSimplySupportedPoint = kAnalyticPlates[2];
const PlateCase& kClampedPoint = kAnalyticPlates[3];

// Relative error of the centre deflection (limit surface at the centre vertex).
double centre_error(const PlateCase& c, int divisions, Quadrature rule, StaticResult* out = nullptr) {
  Problem p = testing::square_plate(divisions, c.clamped, rule);
  const int centre = testing::nearest_vertex(p.mesh, Eigen::Vector3d::Zero());
  if (!c.point_load)
    p.surface_load = Eigen::Vector3d(0, 0, -1.0);
  else
    p.point_loads = {{centre, Eigen::Vector3d(0, 0, -1.0)}};
  const StaticResult r = solve_static(p);
  if (out) *out = r;
  const double expected = c.coefficient / testing::plate_rigidity(p);
  return -r.limit_displacement(centre, 2) / expected - 1.0;
}

TEST(AnalyticPlates, WithinOnePercentOn32x32) {
  for (Quadrature rule : {Quadrature::one_point, Quadrature::three_point}) {
    EXPECT_LT(std::abs(centre_error(kSimplySupportedUniform, 32, rule)), 0.01) << to_string(rule);
    EXPECT_LT(std::abs(centre_error(kClampedUniform, 32, rule)), 0.01) << to_string(rule);
    EXPECT_LT(std::abs(centre_error(kSimplySupportedPoint, 32, rule)), 0.01) << to_string(rule);
    EXPECT_LT(std::abs(centre_error(kClampedPoint, 32, rule)), 0.01) << to_string(rule);
  }
}

TEST(AnalyticPlates, ErrorFallsUnderRefinementAtSecondOrder) {
  for (const PlateCase& c : {kSimplySupportedUniform, kClampedUniform, kSimplySupportedPoint, kClampedPoint}) {
    double previous = 0.0;
    for (int n : {8, 16, 32, 64}) {
      const double err = std::abs(centre_error(c, n, Quadrature::one_point));
      std::printf("%s n=%d error=%.4f%%\n", c.id, n, 100 * err);
      if (n > 8) {
        EXPECT_LT(err, previous) << "n = " << n;
        // Each halving of the element size should cut the error by about 4 (O(h²)).
        EXPECT_GT(previous / err, 3.0) << "n = " << n;
      }
      previous = err;
    }
  }
}

TEST(AnalyticPlates, HingedAndClampedBordersHoldTheLimitSurface) {
  for (const PlateCase& c : {kSimplySupportedUniform, kClampedUniform}) {
    StaticResult r;
    centre_error(c, 32, Quadrature::one_point, &r);
    const double centre = r.limit_displacement.col(2).cwiseAbs().maxCoeff();
    double border = 0.0;
    for (int v = 0; v < r.limit_rest.rows(); ++v)
      if (std::abs(r.limit_rest(v, 0)) > 0.499 || std::abs(r.limit_rest(v, 1)) > 0.499)
        border = std::max(border, r.limit_displacement.row(v).norm());
    EXPECT_LT(border, 2e-3 * centre) << (c.clamped ? "clamped" : "hinged");
  }
}

TEST(AnalyticPlates, CantileverTipUnderEndLoad) {
  // Strip L × b, ν = 0 (plate bending = beam bending), clamped at x = −L/2, tip force P shared
  // by the tip-row vertices with trapezoidal weights.
  const double length = 1.0, width = 0.1, thickness = 0.01, youngs = 1e7, force = 1e-3;
  Problem p;
  p.mesh = make_grid(length, width, 40, 4);
  p.material = ShellMaterial::from_solid(youngs, 0.0, thickness, 1000);
  BoundaryCondition clamp;
  clamp.vertices = testing::select_vertices(p.mesh, [&](const auto& x) { return x(0) < -length / 2 + 1e-9; });
  clamp.clamped = true;
  p.boundary = {clamp};
  const std::vector<int> tip = testing::select_vertices(p.mesh, [&](const auto& x) { return x(0) > length / 2 - 1e-9; });
  ASSERT_EQ(tip.size(), 5u);
  for (size_t i = 0; i < tip.size(); ++i) {
    const double share = (i == 0 || i + 1 == tip.size()) ? 0.125 : 0.25;
    p.point_loads.push_back({tip[i], Eigen::Vector3d(0, 0, -share * force)});
  }
  const StaticResult r = solve_static(p);
  const double inertia = width * thickness * thickness * thickness / 12.0;
  const double expected = force * length * length * length / (3.0 * youngs * inertia);
  const int probe = testing::nearest_vertex(p.mesh, Eigen::Vector3d(length / 2, 0, 0));
  const double tip_deflection = -r.limit_displacement(probe, 2);
  std::printf("cantilever tip %.6e expected %.6e error %.3f%%\n", tip_deflection, expected,
              100 * (tip_deflection / expected - 1));
  EXPECT_NEAR(tip_deflection / expected, 1.0, 0.02);
}

TEST(AnalyticPlates, SolveIsBitwiseDeterministic) {
  // Colour-parallel assembly and the threaded factorisation must give the same bits each time.
  Problem p = testing::square_plate(48, true, Quadrature::three_point);
  p.surface_load = Eigen::Vector3d(0.1, -0.2, -1.0);
  const StaticResult a = solve_static(p), b = solve_static(p);
  EXPECT_TRUE((a.displacement.array() == b.displacement.array()).all());
  EXPECT_TRUE((a.limit_displacement.array() == b.limit_displacement.array()).all());
}

TEST(AnalyticPlates, UnsupportedStructureIsReported) {
  Problem p = testing::square_plate(4, false, Quadrature::one_point);
  p.boundary.clear();
  p.surface_load = Eigen::Vector3d(0, 0, -1);
  try {
    solve_static(p);
    FAIL() << "a free plate must not solve";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("rigid"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace clothsim

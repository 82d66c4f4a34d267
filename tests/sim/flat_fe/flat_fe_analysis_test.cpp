// linear_fe through the two analyses: static solves of a long hinged plate against cylindrical
// bending and of a free-edged strip against beam theory as the mesh is refined, the static solve's
// support check, a strip hung under gravity in a damped dynamic run settling on its static
// deflection without creating energy, and a free sleeve spinning without deforming (the
// corotation in the dynamics).
#include "sim/dynamics/simulator.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/setup/setup.hpp"
#include "sim/static/static_solve.hpp"
#include "tests/support/analysis_runs.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace clothsim {
namespace {

using testing::mid_deflection;
using testing::rigid_residual;

constexpr double kLength = 0.2, kWidth = 0.04;  // strip [m], along x and y, centred at the origin

// A strip of n × n/5 cells, hinged at x = −L/2 (all components held) and on a roller at x = +L/2
// (y and z held, x free, so no membrane tension builds up), with the linear_fe method.
Problem strip(int n, double bending_rigidity) {
  Problem p;
  p.method = "linear_fe";
  p.mesh = prepare_mesh("linear_fe", make_grid(kLength, kWidth, n, n / 5), {});
  p.material.stretch_modulus = 5000.0;
  p.material.bending_rigidity = bending_rigidity;
  p.material.poisson_ratio = 0.25;
  p.material.areal_density = 0.12;
  BoundaryCondition left, right;
  for (int v = 0; v < p.mesh.num_vertices(); ++v) {
    if (std::abs(p.mesh.vertices(v, 0) + 0.5 * kLength) < 1e-9) left.vertices.push_back(v);
    if (std::abs(p.mesh.vertices(v, 0) - 0.5 * kLength) < 1e-9) right.vertices.push_back(v);
  }
  right.fix = {false, true, true};
  p.boundary = {left, right};
  return p;
}

// A long plate (L = 10 W) hinged on all four edges under a uniform load q bends cylindrically
// across its width away from the short ends, w(y) with w_xx = w_xy = 0: the hinges' energy density
// is then exactly B w_yy²/2 (docs/linear_fe.md), so the centre deflection tends to the strip's
// 5 q W⁴ / (384 B). (The hinges' twist coupling makes the ends' boundary layer long: at L = 5 W the
// centre still lies in it, 4.9 % stiff on the finest mesh; at L = 10 W the middle is flat along x
// to 1e-4.)
TEST(LinearFeAnalysis, StaticLongPlateMatchesCylindricalBendingUnderRefinement) {
  const double b = 1e-3, q = 1.0, length = 1.0, width = 0.1;
  const double strip_theory = 5.0 * q * std::pow(width, 4) / (384.0 * b);
  std::vector<double> errors;
  for (int n : {4, 8, 16}) {
    Problem p;
    p.method = "linear_fe";
    p.mesh = prepare_mesh("linear_fe", make_grid(length, width, 10 * n, n), {});
    p.material.stretch_modulus = 5000.0;
    p.material.bending_rigidity = b;
    p.material.poisson_ratio = 0.25;
    p.material.areal_density = 0.12;
    BoundaryCondition border;
    for (int v = 0; v < p.mesh.num_vertices(); ++v)
      if (std::abs(std::abs(p.mesh.vertices(v, 0)) - 0.5 * length) < 1e-9 ||
          std::abs(std::abs(p.mesh.vertices(v, 1)) - 0.5 * width) < 1e-9)
        border.vertices.push_back(v);
    p.boundary = {border};
    p.surface_load = Eigen::Vector3d(0, 0, -q);
    const StaticResult r = solve_static(p);
    EXPECT_EQ(r.discretization->method(), "linear_fe");
    double w = 0.0;
    for (int v = 0; v < r.limit_rest.rows(); ++v)
      if (r.limit_rest.row(v).norm() < 1e-9) w = -r.limit_displacement(v, 2);
    errors.push_back(w / strip_theory - 1.0);
    std::printf("static long plate %3d x %2d cells: centre deflection %.6e m, 5qW^4/(384B) %.6e m, error %+.5f\n", 10 * n,
                n, w, strip_theory, errors.back());
  }
  EXPECT_LT(std::abs(errors.back()), 0.004);
  EXPECT_LT(std::abs(errors[1]), 0.4 * std::abs(errors[0]));  // second order
  EXPECT_LT(std::abs(errors[2]), 0.4 * std::abs(errors[1]));
}

// A strip with free long edges, simply supported at its ends, under a uniform load: on the
// generator's grid the hinges couple twist and curvature (energy density B/2 [(w_xx + w_xy)² +
// (w_yy + w_xy)² + 4 w_xy²]), so the strip relaxes into a slightly twisted shape and is softer
// than beam theory — by at most 1/0.8 (w_yy = w_xy = −w_xx/5 everywhere). Measured: the midspan
// deflection converges to about 1.04 × the beam's.
TEST(LinearFeAnalysis, StaticStripWithFreeEdgesIsAsSoftAsTheHingeCouplingAllows) {
  const double b = 1e-3, q = 1.0;
  const double beam = 5.0 * q * std::pow(kLength, 4) / (384.0 * b);
  std::vector<double> ratios;
  for (int n : {10, 20, 40}) {
    Problem p = strip(n, b);
    p.surface_load = Eigen::Vector3d(0, 0, -q);
    const StaticResult r = solve_static(p);
    const double w = -mid_deflection(r.limit_rest, r.limit_displacement);
    ratios.push_back(w / beam);
    std::printf("static strip, free edges, %2d x %d cells: mid deflection %.6e m = %.5f x beam (5qL^4/(384B) = %.6e m)\n", n,
                n / 5, w, ratios.back(), beam);
    EXPECT_GT(ratios.back(), 1.0);
    EXPECT_LT(ratios.back(), 1.0 / 0.8);
  }
  EXPECT_LT(std::abs(ratios[2] - ratios[1]), 0.5 * std::abs(ratios[1] - ratios[0]));  // converging
}

TEST(LinearFeAnalysis, StaticSolveNamesTheRigidMotionsLeftFree) {
  Problem p = strip(10, 1e-3);
  p.boundary[0].fix = {false, false, true};  // left end held in z only, right end in y and z
  p.surface_load = Eigen::Vector3d(0, 0, -1.0);
  try {
    solve_static(p);
    FAIL() << "an unsupported strip was solved";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    std::printf("%s\n", what.c_str());
    EXPECT_NE(what.find("2 rigid motion(s) free"), std::string::npos) << what;
    EXPECT_NE(what.find("translation along x"), std::string::npos) << what;
  }
}

// The strip under its own weight, released from rest with mass damping (ζ ≈ 0.4 for the first
// mode), settles on the static solution of the same problem (small deflection, δ/L ≈ 1 %: the
// corotated dynamics and the linear statics agree to second order), and the run never creates
// energy: the loads' work covers kinetic plus elastic energy.
TEST(LinearFeAnalysis, DampedStripUnderGravitySettlesOnItsStaticDeflection) {
  const double b = 1e-2;
  Problem p = strip(20, b);
  p.gravity = Eigen::Vector3d(0, 0, -9.81);
  const StaticResult reference = solve_static(p);
  const double w_static = -mid_deflection(reference.limit_rest, reference.limit_displacement);

  p.damping.mass = 60.0;  // [1/s]; ω₁ = π²/L² √(B/ρ_A) = 71 rad/s
  p.time.dt = 2e-3;
  p.time.end = 0.5;
  p.solver.type = LinearSolverType::cholmod;
  Simulator sim(p);
  EXPECT_EQ(sim.discretization().method(), "linear_fe");
  testing::DampedRun run;
  ASSERT_NO_FATAL_FAILURE(testing::run_to_the_end(sim, run));
  const auto [peak_kinetic, lowest_balance, deepest, w] = run;
  const double beam = 5.0 * p.material.areal_density * 9.81 * std::pow(kLength, 4) / (384.0 * b);
  std::printf("damped strip after %.2f s: mid deflection %.6e m (deepest %.6e m), static linear_fe %.6e m (%+.2e), "
              "beam %.6e m; kinetic energy %.2e J (peak %.2e J), energy balance >= %.2e of the work\n",
              p.time.end, w, deepest, w_static, w / w_static - 1.0, beam, sim.kinetic_energy(), peak_kinetic, lowest_balance);
  EXPECT_NEAR(w, w_static, 0.003 * w_static);
  EXPECT_GT(deepest, w);                               // it swung past its rest position first
  EXPECT_LT(sim.kinetic_energy(), 1e-8 * peak_kinetic);  // and came to rest
  EXPECT_GT(lowest_balance, -1e-9);                    // no energy created
}

// A free sleeve spun at 10 rad/s about its axis for 0.3 s (three Newton iterations per step, as
// the loop_kl test): the corotated element keeps it rigid, the linear one distorts it.
TEST(LinearFeAnalysis, SpinningFreeSleeveStaysUndeformed) {
  Problem p = testing::spinning_sleeve("linear_fe");
  double residuals[2] = {0.0, 0.0};
  for (bool corotational : {true, false}) {
    p.corotational = corotational;
    Simulator sim(p);
    for (int i = 0; i < sim.num_steps(); ++i) sim.step();
    residuals[corotational ? 0 : 1] = rigid_residual(p.mesh.vertices, sim.state().positions());
    EXPECT_GT((sim.state().positions() - p.mesh.vertices).rowwise().norm().maxCoeff(), 0.05);  // it turned (3 rad)
  }
  std::printf("spinning sleeve, 0.3 s: rigid residual %.3e (corotated), %.3e (linear)\n", residuals[0], residuals[1]);
  EXPECT_LT(residuals[0], 1e-6);
  EXPECT_GT(residuals[1], 1e-3);
}

}  // namespace
}  // namespace clothsim

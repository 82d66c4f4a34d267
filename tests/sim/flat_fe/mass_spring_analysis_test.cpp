// mass_spring through the analyses: a cloth strip held at both ends, released under gravity with
// mass damping, settles on an equilibrium with the sag of a cable of the springs' stretch modulus,
// without creating energy; a free sleeve spinning stays rigid with either value of `corotational`
// (springs need no rotation); the static analysis refuses the method, naming the key.
#include "sim/dynamics/simulator.hpp"
#include "sim/flat_fe/mass_spring.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/problem/validate.hpp"
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

constexpr double kLength = 0.2, kWidth = 0.04;  // strip [m], along x and y, centred at the origin

// A cloth strip of n × n/5 cells with both ends held (all components), the mass_spring method.
Problem strip(int n) {
  Problem p;
  p.method = "mass_spring";
  p.mesh = prepare_mesh("mass_spring", make_grid(kLength, kWidth, n, n / 5), {});
  p.material.stretch_modulus = 5000.0;
  p.material.bending_rigidity = 1e-5;
  p.material.poisson_ratio = 0.25;
  p.material.areal_density = 0.12;
  BoundaryCondition ends;
  for (int v = 0; v < p.mesh.num_vertices(); ++v)
    if (std::abs(std::abs(p.mesh.vertices(v, 0)) - 0.5 * kLength) < 1e-9) ends.vertices.push_back(v);
  p.boundary = {ends};
  return p;
}

// The strip under its own weight q = ρ_A g hangs like a cable: the bending springs are negligible
// (κ ≈ 8δ/L² ≈ 0.5 1/m against κ_ref ≈ 49 1/m, and quartic), the stretch springs carry it. A
// shallow parabolic cable of span L with axial stiffness E_x [N/m] sags by
//     δ = (3 q L⁴ / (64 E_x))^(1/3)
// (tension qL²/(8δ) = E_x · 8δ²/(3L²)). On the grid the springs' uniaxial stiffness along x is
// E_x = E·t when the cells may shear and 1.2 E·t when they may not (docs/mass_spring.md), so δ lies
// between the two values. Released from rest with mass damping (ζ ≈ 0.4 for the first mode, ω₁ ≈
// 70 rad/s), the strip settles there on an equilibrium (the springs' force balances the weight),
// and the run never creates energy.
TEST(MassSpringAnalysis, DampedStripUnderGravitySettlesWithTheSagOfACable) {
  Problem p = strip(20);
  p.gravity = Eigen::Vector3d(0, 0, -9.81);
  p.damping.mass = 60.0;  // [1/s]
  p.time.dt = 2e-3;
  p.time.end = 0.5;
  p.solver.type = LinearSolverType::cholmod;
  Simulator sim(p);
  EXPECT_EQ(sim.discretization().method(), "mass_spring");
  testing::DampedRun run;
  ASSERT_NO_FATAL_FAILURE(testing::run_to_the_end(sim, run));
  const auto [peak_kinetic, lowest_balance, deepest, w] = run;
  const double q = p.material.areal_density * 9.81;
  const double sheared = std::cbrt(3.0 * q * std::pow(kLength, 4) / (64.0 * p.material.stretch_modulus));
  const double unsheared = sheared / std::cbrt(1.2);

  // The residual force of the final state at the free DOFs, against the largest nodal weight.
  const Discretization& d = sim.discretization();
  std::unique_ptr<ForceTerm> springs = d.elastic_term(true, true);
  springs->update(sim.state().x, sim.state().x - d.rest(), sim.state().t);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(sim.state().x.size());
  springs->add_force(f);
  double residual = 0.0;
  for (int v = 0; v < d.num_nodes(); ++v) {
    f(3 * v + 2) -= sim.vertex_mass()(v) * 9.81;
    for (int c = 0; c < 3; ++c)
      if (d.status(3 * v + c) == DofStatus::free) residual = std::max(residual, std::abs(f(3 * v + c)));
  }
  const double weight = sim.vertex_mass().maxCoeff() * 9.81;
  std::printf("damped strip after %.2f s: mid deflection %.6e m (deepest %.6e m); cable with E_x = 1.2 E t %.6e m, "
              "E_x = E t %.6e m; residual force %.2e of a node's weight; kinetic energy %.2e J (peak %.2e J), energy "
              "balance >= %.2e of the work\n",
              p.time.end, w, deepest, unsheared, sheared, residual / weight, sim.kinetic_energy(), peak_kinetic,
              lowest_balance);
  EXPECT_GT(w, 0.98 * unsheared);
  EXPECT_LT(w, 1.02 * sheared);
  EXPECT_GT(deepest, w);                                 // it swung past its rest position first
  EXPECT_LT(sim.kinetic_energy(), 1e-8 * peak_kinetic);  // and came to rest
  EXPECT_LT(residual, 1e-4 * weight);                    // on an equilibrium
  EXPECT_GT(lowest_balance, -1e-9);                      // no energy created
}

// A free sleeve spun at 10 rad/s about its axis for 0.3 s (three Newton iterations per step, as
// the loop_kl and linear_fe tests): the springs keep it rigid, and `corotational` changes nothing.
TEST(MassSpringAnalysis, SpinningFreeSleeveStaysUndeformedWhateverCorotational) {
  Problem p = testing::spinning_sleeve("mass_spring");
  Eigen::MatrixX3d final[2];
  for (bool corotational : {true, false}) {
    p.corotational = corotational;
    Simulator sim(p);
    for (int i = 0; i < sim.num_steps(); ++i) sim.step();
    final[corotational ? 0 : 1] = sim.state().positions();
    EXPECT_GT((sim.state().positions() - p.mesh.vertices).rowwise().norm().maxCoeff(), 0.05);  // it turned (3 rad)
  }
  const double residual = testing::rigid_residual(p.mesh.vertices, final[0]);
  std::printf("spinning sleeve, 0.3 s: rigid residual %.3e; corotational false differs by %.1e m\n", residual,
              (final[0] - final[1]).cwiseAbs().maxCoeff());
  EXPECT_LT(residual, 1e-6);
  EXPECT_EQ(final[0], final[1]);
}

// The static analysis refuses the method (a flat spring network has no stiffness across the sheet
// at rest), naming the key; the dynamic analysis takes the same problem. Clamped borders are
// refused as for linear_fe.
TEST(MassSpringAnalysis, StaticAnalysisAndClampedBordersAreRefused) {
  Problem p = strip(10);
  p.surface_load = Eigen::Vector3d(0, 0, -1.0);
  try {
    solve_static(p);
    FAIL() << "a static mass_spring problem was solved";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    std::printf("%s\n", what.c_str());
    EXPECT_EQ(what.rfind("method: \"mass_spring\" needs \"analysis\": \"dynamic\"", 0), 0u) << what;
  }
  EXPECT_FALSE(find_issue(p, Analysis::dynamics).has_value());
  // The rest matrix indeed has no out-of-plane stiffness: its z rows are zero.
  const std::shared_ptr<Discretization> d = make_discretization(p);
  std::unique_ptr<ForceTerm> term = d->elastic_term(false, false);
  term->update(d->rest(), Eigen::VectorXd::Zero(d->rest().size()), 0.0);
  Eigen::SparseMatrix<double> k = d->matrix_pattern();
  term->add_matrix({1.0, 0.0}, k);
  double z = 0.0, in_plane = 0.0;
  for (Eigen::Index col = 0; col < k.cols(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(k, col); it; ++it) {
      double& largest = it.row() % 3 == 2 || col % 3 == 2 ? z : in_plane;
      largest = std::max(largest, std::abs(it.value()));
    }
  std::printf("rest matrix of the flat strip: largest in-plane entry %.3e N/m, largest entry in a z row or column %.1e N/m\n",
              in_plane, z);
  EXPECT_GT(in_plane, 1000.0);
  EXPECT_EQ(z, 0.0);

  p.boundary[0].clamped = true;
  const auto issue = find_issue(p, Analysis::dynamics);
  ASSERT_TRUE(issue.has_value());
  EXPECT_EQ(issue->key, "boundary[0].rotation");
  EXPECT_NE(issue->message.find("not supported by the mass_spring method"), std::string::npos) << issue->message;
}

}  // namespace
}  // namespace clothsim

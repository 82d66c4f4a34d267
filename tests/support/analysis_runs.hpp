// What the analysis tests of the methods share: measurements on node positions (#nodes × 3) — the
// mean deflection along a strip's middle line and how far a moved body is from a rigid motion of
// its rest shape —, a damped dynamic run of a strip measured at every step, and a free sleeve
// spinning about its axis.
#pragma once

#include "sim/dynamics/simulator.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/problem/problem.hpp"

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace clothsim::testing {

// Mean z displacement of the nodes on the middle line x = 0 [m] (#nodes × 3 displacements).
inline double mid_deflection(const Eigen::MatrixX3d& rest, const Eigen::MatrixX3d& displacement) {
  double sum = 0.0;
  int count = 0;
  for (Eigen::Index v = 0; v < rest.rows(); ++v)
    if (std::abs(rest(v, 0)) < 1e-9) {
      sum += displacement(v, 2);
      ++count;
    }
  return sum / count;
}

// RMS distance between x and the best rigid image of rest (Kabsch), relative to the size.
inline double rigid_residual(const Eigen::MatrixX3d& rest, const Eigen::MatrixX3d& x) {
  const Eigen::RowVector3d c0 = rest.colwise().mean(), c1 = x.colwise().mean();
  const Eigen::MatrixX3d a = rest.rowwise() - c0, bm = x.rowwise() - c1;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(a.transpose() * bm, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixV() * svd.matrixU().transpose();
  if (r.determinant() < 0) {
    Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
    fix(2, 2) = -1;
    r = svd.matrixV() * fix * svd.matrixU().transpose();
  }
  return std::sqrt(((a * r.transpose()) - bm).rowwise().squaredNorm().mean()) / a.rowwise().norm().maxCoeff();
}

// What a dynamic run of a strip showed over its steps and at its end.
struct DampedRun {
  double peak_kinetic = 0.0;    // the largest kinetic energy [J]
  double lowest_balance = 0.0;  // the least (work in − energy stored) / work in: below 0 if energy was created
  double deepest = 0.0;         // the largest downward deflection of the middle line x = 0 [m]
  double deflection = 0.0;      // the downward deflection of the middle line at the end [m]
};

// Runs `sim` to its end, every step finite (a fatal failure otherwise: call through
// ASSERT_NO_FATAL_FAILURE), measuring what DampedRun holds.
inline void run_to_the_end(Simulator& sim, DampedRun& run) {
  for (int i = 0; i < sim.num_steps(); ++i) {
    sim.step();
    ASSERT_TRUE(sim.state().x.allFinite()) << "step " << i;
    run.peak_kinetic = std::max(run.peak_kinetic, sim.kinetic_energy());
    // Dissipated so far = work in − energy stored; it must never be negative.
    const double dissipated = sim.external_work() + sim.boundary_work() - sim.kinetic_energy() - sim.elastic_energy();
    run.lowest_balance = std::min(run.lowest_balance, dissipated / std::max(sim.external_work(), 1e-300));
    const Eigen::MatrixX3d u = sim.node_points() - sim.node_points_rest();
    run.deepest = std::max(run.deepest, -mid_deflection(sim.node_points_rest(), u));
  }
  const Eigen::MatrixX3d u = sim.node_points() - sim.node_points_rest();
  run.deflection = -mid_deflection(sim.node_points_rest(), u);
}

// A free sleeve (radius 0.05 m, length 0.2 m along y, E·t = 1e5 N/m, B = 1e-4 N·m, ν = 0.25,
// ρ_A = 0.1 kg/m²) of the given method spinning at 10 rad/s about its axis, for 0.3 s in steps of
// 1 ms with three Newton iterations each (CHOLMOD).
inline Problem spinning_sleeve(const std::string& method) {
  Problem p;
  p.method = method;
  p.mesh = make_cylinder(0.05, 0.2, 12, 7);
  p.material.stretch_modulus = 1e5;
  p.material.bending_rigidity = 1e-4;
  p.material.poisson_ratio = 0.25;
  p.material.areal_density = 0.1;
  p.initial.angular_velocity = Eigen::Vector3d(0, 10.0, 0);
  p.initial.center = Eigen::Vector3d(0, 0.1, 0);
  p.time.dt = 1e-3;
  p.time.end = 0.3;
  p.solver.type = LinearSolverType::cholmod;
  p.solver.newton_iterations = 3;
  return p;
}

}  // namespace clothsim::testing

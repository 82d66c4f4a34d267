// What the elastic-term tests of the flat discretisations (linear_fe and mass_spring,
// tests/sim/flat_fe) share: their material, the structures the terms are checked on, the check of
// the force against the energy over a set of states, the convergence check of a calibration as the
// mesh is refined, and the check of the damping wrappers around the term.
#pragma once

#include "sim/boundary/boundary_condition.hpp"
#include "sim/discretization/discretization.hpp"
#include "sim/forces/damping.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/shell/material.hpp"
#include "tests/support/fd_check.hpp"
#include "tests/support/term_states.hpp"
#include "tests/support/test_meshes.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace clothsim::testing {

// Stretch modulus E·t [N/m] and bending rigidity B [N·m] as given, ν = 0.3, ρ_A = 0.12 kg/m².
inline ShellMaterial sheet_material(double stretch_modulus, double bending_rigidity) {
  ShellMaterial m;
  m.stretch_modulus = stretch_modulus;
  m.bending_rigidity = bending_rigidity;
  m.poisson_ratio = 0.3;
  m.areal_density = 0.12;
  return m;
}

// A discretisation of type D (constructed from a mesh, boundary conditions and a material) and
// its name.
template <class D>
struct Structure {
  std::string name;
  std::unique_ptr<D> d;
};

// The jittered grid (flat at rest) and a short sleeve (curved at rest), free, each in three
// materials — "cloth" (E·t = 5000 N/m, B = 1e-4 N·m), "bending only" (E·t = 1e-6 N/m) and
// `membrane_name` (B = 1e-12 N·m) — so that each part of the term is checked where it dominates
// the force. Named "grid, <material>" and "sleeve, <material>".
template <class D>
std::vector<Structure<D>> grid_and_sleeve(const std::string& membrane_name) {
  std::vector<Structure<D>> out;
  const std::pair<std::string, ShellMaterial> materials[] = {{"cloth", sheet_material(5000.0, 1e-4)},
                                                             {"bending only", sheet_material(1e-6, 1e-4)},
                                                             {membrane_name, sheet_material(5000.0, 1e-12)}};
  for (const auto& [name, m] : materials) {
    out.push_back({"grid, " + name, std::make_unique<D>(jittered_grid(), std::vector<BoundaryCondition>{}, m)});
    out.push_back({"sleeve, " + name, std::make_unique<D>(make_cylinder(0.03, 0.06, 8, 4), std::vector<BoundaryCondition>{}, m)});
  }
  return out;
}

// The term's force against −∂E/∂x (check_force_against_energy, step `eps` [m]) at each of `all`,
// the errors measured against at least the largest force at all[1] (the first random state: at
// rest the force is zero). Expects a relative error below 1e-6 at each state, `label` naming the
// case; returns the worst.
inline double expect_force_is_the_gradient(ForceTerm& term, const Discretization& d, const std::vector<State>& all,
                                           double eps, const std::string& label) {
  double worst = 0.0;
  const double floor = force_at(term, d, all[1].x).cwiseAbs().maxCoeff();
  for (const State& state : all) {
    FdReport r = check_force_against_energy(term, d, state.x, eps);
    r.floor = floor;
    worst = std::max(worst, r.relative());
    EXPECT_LT(r.relative(), 1e-6) << label << ", " << state.name << ": " << r.describe();
  }
  return worst;
}

// Relative errors of a calibration on successively refined meshes: each refinement at least halves
// the error (to below 0.55 times the previous one), or the error is already (nearly) exact, below
// 1e-3. `name` names the case.
inline void expect_halved_by_each_refinement(const std::vector<double>& errors, const std::string& name) {
  for (std::size_t k = 1; k < errors.size(); ++k)
    if (std::abs(errors[k - 1]) > 1e-3) {
      EXPECT_LT(std::abs(errors[k]), 0.55 * std::abs(errors[k - 1])) << name << " at refinement " << k;
    } else {
      EXPECT_LT(std::abs(errors[k]), 1e-3) << name << " at refinement " << k;
    }
}

// Kelvin–Voigt damping wraps d's elastic term: the same force and energy, the matrix (w_K + c w_D) K;
// mass damping finds every diagonal entry in the pattern. At a seeded random state.
inline void expect_damping_wrappers_work(const Discretization& d) {
  const Eigen::VectorXd x = perturbed_rest(d, 2e-3, 9);
  std::unique_ptr<ForceTerm> plain = d.elastic_term(true, true);
  KelvinVoigtDamping damped(d.elastic_term(true, true), 0.01);
  const Eigen::VectorXd f = force_at(*plain, d, x), fd = force_at(damped, d, x);
  EXPECT_EQ(f, fd);
  EXPECT_EQ(plain->energy(), damped.energy());
  const double h = 2e-3;
  const Eigen::MatrixXd k = matrix_at(*plain, d, x, {1.0, 0.0});
  const Eigen::MatrixXd a = matrix_at(damped, d, x, {h * h, h});
  EXPECT_LT((a - (h * h + 0.01 * h) * k).cwiseAbs().maxCoeff(), 1e-13 * a.cwiseAbs().maxCoeff());
  const Eigen::VectorXd mass = d.lumped_mass(0.12);
  MassDamping drag(mass, 2.0, d.matrix_pattern());
  Eigen::SparseMatrix<double> m = d.matrix_pattern();
  drag.add_matrix({h * h, h}, m);
  for (int v = 0; v < d.num_nodes(); ++v) EXPECT_DOUBLE_EQ(m.coeff(3 * v + 1, 3 * v + 1), 2.0 * h * mass(v));
}

}  // namespace clothsim::testing

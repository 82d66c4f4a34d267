// One finite-difference helper for every force term (sim/core/force_term.hpp), used by the
// tests of every term: the force against the central-difference gradient of the energy
// (f = −∂E/∂x), and the matrix against the central-difference Jacobian of the force
// (K = −∂f/∂x), column by column over the DOFs that are not derived from others.
//
// A perturbed state is made as the integrator makes one: positions x + ε e_j, displacements from
// the rest state with the dependent components re-derived (Discretization::make_consistent); the
// term is updated there and read. Central differences have an error O(ε²); the checks compare
// against the largest entry of the reference, so a relative tolerance of ~1e-6 separates a right
// derivative from a wrong one by many orders of magnitude.
#pragma once

#include "sim/discretization/discretization.hpp"
#include "sim/core/force_term.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace clothsim::testing {

// The worst difference between an analytic quantity and its finite-difference reference.
struct FdReport {
  double max_error = 0.0;  // max |analytic − fd| over the entries compared
  double scale = 0.0;      // max |fd| over the entries compared
  int worst_entry = -1;    // flat index of the worst entry (row + rows·column for matrices)
  double floor = 0.0;      // smallest scale the error is measured against (round-off level)
  double relative() const { return max_error / std::max({scale, floor, 1e-300}); }
  std::string describe() const {
    return "max error " + std::to_string(max_error) + " against a scale of " + std::to_string(scale) + " (relative " +
           std::to_string(relative()) + ") at entry " + std::to_string(worst_entry);
  }
};

// The term at positions x (3·#nodes), with u = x − X made consistent; time t.
inline void update_at(ForceTerm& term, const Discretization& d, const Eigen::VectorXd& x, double t = 0.0) {
  Eigen::VectorXd u = x - d.rest();
  d.make_consistent(u);
  term.update(x, u, t);
}

inline Eigen::VectorXd force_at(ForceTerm& term, const Discretization& d, const Eigen::VectorXd& x, double t = 0.0) {
  update_at(term, d, x, t);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  term.add_force(f);
  return f;
}

inline double energy_at(ForceTerm& term, const Discretization& d, const Eigen::VectorXd& x, double t = 0.0) {
  update_at(term, d, x, t);
  return term.energy();
}

// The term's matrix with weights w at positions x, as a dense matrix.
inline Eigen::MatrixXd matrix_at(ForceTerm& term, const Discretization& d, const Eigen::VectorXd& x, MatrixWeights w,
                                 double t = 0.0) {
  update_at(term, d, x, t);
  Eigen::SparseMatrix<double> a = d.matrix_pattern();
  if (term.has_matrix()) term.add_matrix(w, a);
  return Eigen::MatrixXd(a);
}

// The DOFs a perturbation may move: free and fixed ones (dependent ones follow them).
inline std::vector<int> independent_dofs(const Discretization& d) {
  std::vector<int> out;
  for (int dof = 0; dof < 3 * d.num_nodes(); ++dof)
    if (d.status(dof) != DofStatus::dependent) out.push_back(dof);
  return out;
}

// f against −∂E/∂x by central differences of step `eps` [m], over the independent DOFs.
inline FdReport check_force_against_energy(ForceTerm& term, const Discretization& d, const Eigen::VectorXd& x, double eps,
                                           double t = 0.0) {
  const Eigen::VectorXd f = force_at(term, d, x, t);
  FdReport r;
  for (int dof : independent_dofs(d)) {
    Eigen::VectorXd xp = x, xm = x;
    xp(dof) += eps;
    xm(dof) -= eps;
    const double fd = -(energy_at(term, d, xp, t) - energy_at(term, d, xm, t)) / (2 * eps);
    r.scale = std::max(r.scale, std::abs(fd));
    if (std::abs(f(dof) - fd) > r.max_error) {
      r.max_error = std::abs(f(dof) - fd);
      r.worst_entry = dof;
    }
  }
  update_at(term, d, x, t);
  return r;
}

// The matrix with weights {1, 0} (the stiffness K) against −∂f/∂x by central differences of
// step `eps` [m], column by column over the independent DOFs, rows over the independent DOFs.
// `force` (default: the term's own force) gives the force whose Jacobian is compared, e.g. a part
// of the term's force.
template <class ForceFn>
FdReport check_matrix_against_force(const Eigen::MatrixXd& k, const Discretization& d, const Eigen::VectorXd& x, double eps,
                                    ForceFn&& force) {
  const std::vector<int> dofs = independent_dofs(d);
  FdReport r;
  for (int j : dofs) {
    Eigen::VectorXd xp = x, xm = x;
    xp(j) += eps;
    xm(j) -= eps;
    const Eigen::VectorXd column = -(force(xp) - force(xm)) / (2 * eps);
    for (int i : dofs) {
      r.scale = std::max(r.scale, std::abs(column(i)));
      const double error = std::abs(k(i, j) - column(i));
      if (error > r.max_error) {
        r.max_error = error;
        r.worst_entry = i + static_cast<int>(k.rows()) * j;
      }
    }
  }
  return r;
}

inline FdReport check_matrix_against_force(ForceTerm& term, const Discretization& d, const Eigen::VectorXd& x, double eps,
                                           double t = 0.0) {
  const Eigen::MatrixXd k = matrix_at(term, d, x, {1.0, 0.0}, t);
  FdReport r = check_matrix_against_force(k, d, x, eps, [&](const Eigen::VectorXd& y) { return force_at(term, d, y, t); });
  update_at(term, d, x, t);
  return r;
}

// Seeded random perturbation of the rest positions: each independent component moved by a
// uniform amount in [−amplitude, amplitude] [m].
inline Eigen::VectorXd perturbed_rest(const Discretization& d, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-amplitude, amplitude);
  Eigen::VectorXd x = d.rest();
  for (int dof : independent_dofs(d)) x(dof) += uniform(rng);
  return x;
}

}  // namespace clothsim::testing

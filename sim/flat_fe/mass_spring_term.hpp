// The elastic force term of the mass_spring discretisation (sim/flat_fe/mass_spring.hpp): the sum
// of its stretch and bending springs, each a linear spring between nodes i and j,
//     d = x_i − x_j,   l = |d|,   n = d / l,
//     E = ½ k (l − L₀)²,   f_i = −k (l − L₀) n = −f_j,
// (Provot 1995; the implicit treatment of Baraff & Witkin 1998 and Choi & Ko 2002). The spring's
// Hessian ∂²E/∂x_i² is
//     H = k n nᵀ + k (1 − L₀/l) (I − n nᵀ),
// and the spring adds [[H, −H], [−H, H]] to the matrix at (i, j). The second part, the geometric
// stiffness of the spring's tension, is negative for a compressed spring (l < L₀) and makes the
// matrix indefinite; the solver's matrix drops it there (Choi & Ko 2002), so it is symmetric
// positive semidefinite at every state. It keeps it for stretched springs when
// `tension_stiffening` is on (the scene default), and drops it everywhere when it is off. The
// exact Hessian is behind a switch (set_exact_hessian, for derivative checks).
//
// Springs are invariant under rigid motions as they stand: there is no rotation to extract.
// No damping of its own (Kelvin–Voigt damping wraps it, sim/forces/damping.hpp). Units: [m], [N],
// [J], matrix [N/m].
#pragma once

#include "sim/core/force_term.hpp"

#include <Eigen/Core>

#include <vector>

namespace clothsim {

class MassSpringDiscretization;
struct Spring;

class MassSpringElastic final : public ForceTerm {
 public:
  // Refers to `d`, which must outlive the term.
  MassSpringElastic(const MassSpringDiscretization& d, bool tension_stiffening);

  std::string name() const override { return "mass-spring (edge and bending springs)"; }
  // Evaluates the springs at x; a call with the same x as the last one (exactly) reuses them.
  // Throws std::runtime_error when the two nodes of a spring coincide (its direction is undefined).
  void update(const Eigen::VectorXd& x, const Eigen::VectorXd& u, double t) override;
  bool has_energy() const override { return true; }
  double energy() const override { return stretch_energy_ + bending_energy_; }
  void add_force(Eigen::VectorXd& f) const override { f += force_; }
  bool has_matrix() const override { return true; }
  // a += w.stiffness · Σ spring matrices; the term has no damping matrix.
  void add_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const override;

  // The two parts of energy() [J]: the stretch (edge) springs' and the bending springs'.
  double stretch_energy() const { return stretch_energy_; }
  double bending_energy() const { return bending_energy_; }
  // The exact Hessian in the matrix instead of the solver's (for derivative checks; it may be
  // indefinite).
  void set_exact_hessian(bool on) { exact_hessian_ = on; }

 private:
  // Length and unit direction of each spring at the last update.
  struct SpringState {
    double length = 0.0;
    Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  };
  double evaluate(const std::vector<Spring>& springs, const Eigen::VectorXd& x, std::vector<SpringState>& state);
  void add_springs(const std::vector<Spring>& springs, const std::vector<SpringState>& state, double weight,
                   double* values) const;

  const MassSpringDiscretization& d_;
  bool tension_stiffening_;
  bool exact_hessian_ = false;
  bool evaluated_ = false;
  Eigen::VectorXd x_;
  std::vector<SpringState> stretch_state_, bending_state_;
  Eigen::VectorXd force_;
  double stretch_energy_ = 0.0, bending_energy_ = 0.0;
};

}  // namespace clothsim

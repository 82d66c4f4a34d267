// The corotated subdivision shell as a force term (paper §4.3, eqs. 21 and 29–31): membrane and
// bending forces f = −Σ R K_e (Rᵀ x_e − X_e) with the element rotations R extracted at the
// state, energy Σ ½ dᵀ K_e d, and the matrix Σ R K_e Rᵀ with R frozen, plus (optionally) the
// tension-stiffening term, the membrane geometric stiffness of the tensile stress (see
// sim/corotation/corotational_elements.hpp, which does the element work). With `corotational`
// false, R = I: the plain linear element. It has no damping of its own: Kelvin–Voigt damping
// wraps it (sim/forces/damping.hpp).
#pragma once

#include "sim/corotation/corotational_elements.hpp"
#include "sim/core/force_term.hpp"

namespace clothsim {

class CorotatedShell final : public ForceTerm {
 public:
  CorotatedShell(const ShellModel& model, bool corotational, bool tension_stiffening);

  std::string name() const override { return corotational_ ? "corotated shell" : "linear shell"; }
  // Re-extracts the rotations and forces when the displacement differs from the last call's
  // (exactly): the integrator evaluates at the end of a step and linearises there next step.
  void update(const Eigen::VectorXd& x, const Eigen::VectorXd& u, double t) override;
  bool has_energy() const override { return true; }
  double energy() const override { return elements_.energy(); }
  void add_force(Eigen::VectorXd& f) const override { f += elements_.force(); }
  double frame_turn() const override { return turn_; }
  bool has_matrix() const override { return true; }
  void add_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const override;
  void set_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const override;

  // The element work underneath: rotations, strains, timings of the last evaluation.
  const CorotationalElements& elements() const { return elements_; }
  // Keep the current rotations in later updates (the frozen-R forces whose exact Jacobian is the
  // matrix without tension stiffening: for derivative checks).
  void freeze_rotations(bool on) { elements_.set_frozen_rotations(on); }
  // Time of the last update()'s rotation and force passes [ms] (0 when it reused the last state).
  double last_rotate_ms() const { return rotate_ms_; }
  double last_force_ms() const { return force_ms_; }

 private:
  CorotationalElements elements_;
  bool corotational_;
  bool evaluated_ = false;
  Eigen::VectorXd last_u_;
  double rotate_ms_ = 0.0, force_ms_ = 0.0;
  double turn_ = 0.0;  // the elements' largest turn in the last update() [rad]
};

}  // namespace clothsim

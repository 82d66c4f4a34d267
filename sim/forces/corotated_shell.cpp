#include "sim/forces/corotated_shell.hpp"

namespace clothsim {

CorotatedShell::CorotatedShell(const ShellModel& model, bool corotational, bool tension_stiffening)
    : elements_(model, corotational), corotational_(corotational) {
  elements_.set_geometric_stiffness(tension_stiffening);
}

void CorotatedShell::update(const Eigen::VectorXd& /*x*/, const Eigen::VectorXd& u, double /*t*/) {
  rotate_ms_ = force_ms_ = 0.0;
  turn_ = 0.0;
  if (evaluated_ && u.size() == last_u_.size() && u == last_u_) return;
  elements_.evaluate(u);
  turn_ = elements_.last_rotation_change();
  last_u_ = u;
  evaluated_ = true;
  rotate_ms_ = elements_.last_rotate_ms();
  force_ms_ = elements_.last_force_ms();
}

void CorotatedShell::add_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const {
  if (w.stiffness != 0.0) elements_.add_stiffness(w.stiffness, a);
}

void CorotatedShell::set_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const {
  elements_.set_stiffness(w.stiffness, a);
}

}  // namespace clothsim

#include "sim/forces/damping.hpp"

#include <stdexcept>
#include <string>

namespace clothsim {

KelvinVoigtDamping::KelvinVoigtDamping(std::unique_ptr<ForceTerm> elastic, double coefficient)
    : elastic_(std::move(elastic)), coefficient_(coefficient) {
  if (!(coefficient >= 0)) throw std::invalid_argument("Kelvin–Voigt damping: the coefficient must be >= 0 [s]");
}

std::string KelvinVoigtDamping::name() const { return "Kelvin–Voigt damping of the " + elastic_->name(); }

void KelvinVoigtDamping::add_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const {
  elastic_->add_matrix({w.stiffness + w.damping * coefficient_, w.damping}, a);
}

void KelvinVoigtDamping::set_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const {
  elastic_->set_matrix({w.stiffness + w.damping * coefficient_, w.damping}, a);
}

MassDamping::MassDamping(const Eigen::VectorXd& node_mass, double coefficient, const Eigen::SparseMatrix<double>& pattern)
    : dof_mass_(3 * node_mass.size()), coefficient_(coefficient), diagonal_(diagonal_offsets(pattern)) {
  if (!(coefficient >= 0)) throw std::invalid_argument("mass damping: the coefficient must be >= 0 [1/s]");
  for (Eigen::Index v = 0; v < node_mass.size(); ++v) dof_mass_.segment<3>(3 * v).setConstant(node_mass(v));
}

void MassDamping::add_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const {
  const double scale = w.damping * coefficient_;
  double* values = a.valuePtr();
  for (size_t i = 0; i < diagonal_.size(); ++i) values[diagonal_[i]] += scale * dof_mass_(static_cast<Eigen::Index>(i));
}

}  // namespace clothsim

#include "sim/solver/direct_solver.hpp"

#include <Eigen/CholmodSupport>

namespace clothsim {

struct DirectSolver::Impl {
  // LLᵀ, so that a matrix that is not positive definite fails the factorisation.
  Eigen::CholmodSimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
};

DirectSolver::DirectSolver() : impl_(std::make_unique<Impl>()) {}
DirectSolver::~DirectSolver() = default;

bool DirectSolver::factorize(const Eigen::SparseMatrix<double>& a) {
  impl_->llt.compute(a);
  return impl_->llt.info() == Eigen::Success;
}

Eigen::VectorXd DirectSolver::solve(const Eigen::VectorXd& b) const { return impl_->llt.solve(b); }

}  // namespace clothsim

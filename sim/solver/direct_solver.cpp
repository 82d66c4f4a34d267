#include "sim/solver/direct_solver.hpp"

#include <Eigen/CholmodSupport>

namespace clothsim {

void set_dirichlet_identity(Eigen::SparseMatrix<double>& a, const std::vector<char>& free) {
  for (Eigen::Index col = 0; col < a.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, col); it; ++it)
      if (!free[col] || !free[it.row()]) it.valueRef() = it.row() == col ? 1.0 : 0.0;
}

struct DirectSolver::Impl {
  // LLᵀ (a matrix that is not positive definite fails the factorisation), AMD ordering:
  // measured fastest on shell stiffness matrices with OpenBLAS (docs/performance.md).
  Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  bool analysed = false;
};

DirectSolver::DirectSolver(bool supernodal) : impl_(std::make_unique<Impl>()) {
  impl_->llt.setMode(supernodal ? Eigen::CholmodSupernodalLLt : Eigen::CholmodSimplicialLLt);
  impl_->llt.cholmod().nmethods = 1;
  impl_->llt.cholmod().method[0].ordering = CHOLMOD_AMD;
  impl_->llt.cholmod().postorder = 1;
  impl_->llt.cholmod().print = 0;  // failures are reported by factorize()'s return value
}
DirectSolver::~DirectSolver() = default;

bool DirectSolver::factorize(const Eigen::SparseMatrix<double>& a) {
  impl_->llt.compute(a);
  return impl_->llt.info() == Eigen::Success;
}

bool DirectSolver::refactorize(const Eigen::SparseMatrix<double>& a) {
  if (!impl_->analysed) {
    impl_->llt.analyzePattern(a);
    impl_->analysed = true;
  }
  impl_->llt.factorize(a);
  return impl_->llt.info() == Eigen::Success;
}

Eigen::VectorXd DirectSolver::solve(const Eigen::VectorXd& b) const { return impl_->llt.solve(b); }

}  // namespace clothsim

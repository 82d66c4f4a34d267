// Sparse symmetric positive-definite direct solver (CHOLMOD through Eigen's CholmodSupport).
// The SuiteSparse headers stay inside the .cpp.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <vector>

namespace clothsim {

// The Dirichlet form of a symmetric matrix's constrained components, in place: the rows and
// columns of the entries with free[i] == 0 become those of the identity (pattern kept).
void set_dirichlet_identity(Eigen::SparseMatrix<double>& a, const std::vector<char>& free);

class DirectSolver {
 public:
  // `supernodal`: CHOLMOD's supernodal Cholesky (BLAS-3, best for large matrices); otherwise
  // its simplicial one (less overhead for the small systems of a dynamic run).
  explicit DirectSolver(bool supernodal = true);
  ~DirectSolver();
  DirectSolver(const DirectSolver&) = delete;
  DirectSolver& operator=(const DirectSolver&) = delete;

  // Analyses and factorises A (symmetric; the lower triangle is read). Returns false when A
  // is not positive definite (e.g. a structure with an unrestrained rigid motion).
  bool factorize(const Eigen::SparseMatrix<double>& a);
  // Numeric factorisation of a matrix with the same pattern as the last one analysed (the
  // symbolic analysis is done on the first call only). Returns false when not positive definite.
  bool refactorize(const Eigen::SparseMatrix<double>& a);
  // Solves A x = b with the last factorisation.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothsim

// A Cholesky factor of an earlier step's system matrix, used as the preconditioner of the
// conjugate gradients (solver.preconditioner = "cholesky").
//
// CHOLMOD computes the supernodal factor P A Pᵀ = L Lᵀ in double precision; a copy of L in single
// precision serves the triangular solves. A preconditioner needs no more than single precision
// (the conjugate gradients still converge to the double-precision tolerance: measured on the
// 2542-vertex sleeve, the same iteration counts), and the solves are bound by memory traffic, so
// halving the factor's bytes (3.1 M entries: 25 MB → 12.5 MB) halves their time: 0.85 ms against
// CHOLMOD's 1.7 ms (docs/performance.md).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>

namespace clothsim {

class CholeskyPreconditioner {
 public:
  // `vector_kernels`: use the AVX2 + FMA kernels where the processor has them (false: the
  // portable Eigen ones, for comparison).
  explicit CholeskyPreconditioner(bool vector_kernels = true);
  ~CholeskyPreconditioner();
  CholeskyPreconditioner(const CholeskyPreconditioner&) = delete;
  CholeskyPreconditioner& operator=(const CholeskyPreconditioner&) = delete;

  // Factorises A (symmetric, full storage; the lower triangle is read). The symbolic analysis
  // (AMD ordering, supernodes) is done on the first call; later matrices must have the same
  // pattern. Returns false, and keeps no factor, when A is not positive definite.
  bool factorize(const Eigen::SparseMatrix<double>& a);
  bool ready() const;
  // z = A⁻¹ r with the single-precision factor (z is resized).
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;
  // Entries of L (0 before the first factorisation).
  long factor_entries() const;
  // Floating-point operations of one factorisation (CHOLMOD's count; 0 before the first).
  double factor_flops() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothsim

// A Cholesky factor of an earlier step's system matrix, used as the preconditioner of the
// conjugate gradients (solver.preconditioner = "cholesky").
//
// The supernodal factor P A Pᵀ = L Lᵀ in single precision. CHOLMOD does the symbolic analysis
// (AMD ordering, supernodes) once; the numeric factorisation is our own: left-looking over the
// supernodes, single-precision BLAS for the dense blocks (SYRK/GEMM updates, POTRF, TRSM), disjoint
// subtrees of the elimination tree on concurrent threads. A preconditioner needs no more than
// single precision (the conjugate gradients still converge to the double-precision tolerance), and
// both the factorisation and the solves run about twice as fast as in double: on the 2542-vertex
// sleeve (3.1 M entries, 1.8 GFlop) 31 ms against CHOLMOD's 105–125 ms, and the solves, bound by
// memory traffic (12.5 MB instead of 25 MB), 0.6 ms against CHOLMOD's 1.7 ms
// (docs/performance.md). A pivot that is not positive in single precision (a matrix too
// ill-conditioned for it) makes it fall back to CHOLMOD's double-precision factorisation, copied
// to single precision.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <vector>

namespace clothsim {

class CholeskyPreconditioner {
 public:
  // `vector_kernels`: use the AVX2 + FMA kernels where the processor has them (false: the
  // portable Eigen ones, for comparison).
  // `single_precision_factorization`: factorise in single precision (false: always CHOLMOD in
  // double precision, copied; for comparison).
  explicit CholeskyPreconditioner(bool vector_kernels = true, bool single_precision_factorization = true);
  ~CholeskyPreconditioner();
  CholeskyPreconditioner(const CholeskyPreconditioner&) = delete;
  CholeskyPreconditioner& operator=(const CholeskyPreconditioner&) = delete;

  // Factorises A (symmetric, full storage; the lower triangle is read). The symbolic analysis
  // (AMD ordering, supernodes) is done on the first call; later matrices must have the same
  // pattern. Returns false, and keeps no factor, when A is not positive definite.
  // With `free` (one flag per row), the factor is of A's Dirichlet form: the rows and columns of the
  // components with free[i] == 0 replaced by those of the identity (A itself is not copied).
  bool factorize(const Eigen::SparseMatrix<double>& a, const std::vector<char>* free = nullptr);
  bool ready() const;
  // Whether the current factor was computed in single precision (false: by CHOLMOD, in double).
  bool factored_in_single_precision() const;
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

// A Cholesky factor of an earlier step's system matrix, used as the preconditioner of the
// conjugate gradients (solver.preconditioner = "cholesky").
//
// The supernodal factor P A Pᵀ = L Lᵀ in single precision. CHOLMOD does the symbolic analysis
// (nested-dissection ordering by METIS, AMD without it; supernodes) once; the numeric
// factorisation is our own: left-looking over the supernodes, single-precision BLAS for the dense
// blocks (SYRK/GEMM updates, POTRF, TRSM), disjoint subtrees of the elimination tree on concurrent
// threads. A preconditioner needs no more than single precision (the conjugate gradients still
// converge to the double-precision tolerance): on the 2542-vertex sleeve (2.96 M entries,
// 1.54 GFlop) about 20 ms against CHOLMOD's 105–125 ms in double (docs/performance.md). A pivot
// that is not positive in single precision (a matrix too ill-conditioned for it) makes it fall
// back to CHOLMOD's double-precision factorisation, copied to single precision.
//
// The solves are bound by memory traffic: with the vector kernels they read a copy of the factor
// in half precision (IEEE binary16) with its rows scaled to unit norm, S L with
// S = diag(A)^-½ in P's order, whose entries then lie in [−1, 1]; the diagonal is kept apart in
// single precision. Half the bytes of single precision; the preconditioner's relative error grows
// from ~1e-7 to ~5e-4, which costs the sleeve's conjugate gradients 6 % more iterations
// over a run (a fresh factor: 3–4 instead of 2) but each one, with its product by A, runs 30 %
// faster: 12.3 -> 11.1 ms of solve per step (docs/performance.md).
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
  // `half_precision_storage`: with the vector kernels, the solves read a copy of the factor in
  // half precision (rows scaled to unit norm), half the memory traffic of single precision
  // (false: single precision; for comparison).
  explicit CholeskyPreconditioner(bool vector_kernels = true, bool single_precision_factorization = true,
                                  bool half_precision_storage = true);
  ~CholeskyPreconditioner();
  CholeskyPreconditioner(const CholeskyPreconditioner&) = delete;
  CholeskyPreconditioner& operator=(const CholeskyPreconditioner&) = delete;

  // Factorises A (symmetric, full storage; the lower triangle is read). The symbolic analysis
  // (ordering, supernodes) is done on the first call; later matrices must have the same
  // pattern. Returns false, and keeps no factor, when A is not positive definite.
  // With `free` (one flag per row), the factor is of A's Dirichlet form: the rows and columns of the
  // components with free[i] == 0 replaced by those of the identity (A itself is not copied).
  bool factorize(const Eigen::SparseMatrix<double>& a, const std::vector<char>* free = nullptr);
  bool ready() const;
  // Whether the current factor was computed in single precision (false: by CHOLMOD, in double).
  bool factored_in_single_precision() const;
  // Whether the solves read the half-precision copy of the current factor.
  bool stored_in_half_precision() const;
  // z = A⁻¹ r with the factor (single- or half-precision copy; z is resized).
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

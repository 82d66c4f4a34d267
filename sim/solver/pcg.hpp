// Preconditioned conjugate gradients for the implicit-Euler system (paper §4.2: "solved using
// the conjugate gradient method"), with constrained entries filtered out: they keep the values
// given in x (prescribed velocities) and the iteration runs on the free entries only.
// Preconditioner: the inverse of each vertex's 3 × 3 diagonal block (block Jacobi).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <vector>

namespace clothsim {

struct PcgResult {
  int iterations = 0;
  double residual = 0.0;  // ‖b − A x‖ / ‖b‖ over the free entries (‖b‖ → 1 when b = 0)
  bool converged = false;
};

// z = P⁻¹ r for a residual r that is zero at the constrained entries (z must be zero there too).
using Preconditioner = std::function<void(const Eigen::VectorXd& r, Eigen::VectorXd& z)>;

// Solves A x = b on the entries with free[i] != 0 (A symmetric positive definite there, stored
// in full, 3 × 3 vertex blocks); x holds the warm start and, at constrained entries, their fixed
// values, which enter the right-hand side. Without `preconditioner`, block Jacobi.
PcgResult solve_pcg(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& b, const std::vector<char>& free,
                    Eigen::VectorXd& x, double tolerance, int max_iterations,
                    const Preconditioner& preconditioner = nullptr);

// y = A x on the free entries (zero at the others), for a matrix given as an operation.
using LinearOperator = std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd& y)>;

// The same iteration for an operator A (symmetric positive definite on the free entries) and a
// preconditioner (required here): x holds the warm start; b and x are zero at the constrained
// entries (the operator does not see their values). `initial_residual`, when given, is b − A x for
// the warm start, which the caller had (one product less). `forcing` η ∈ [0, 1): the solve is also
// converged once ‖b − A x‖ ≤ η ‖b − A x₀‖ (an inexact Newton step's forcing term; 0: only the
// tolerance relative to ‖b‖).
PcgResult solve_pcg(const LinearOperator& a, const Eigen::VectorXd& b, const std::vector<char>& free, Eigen::VectorXd& x,
                    double tolerance, int max_iterations, const Preconditioner& preconditioner,
                    const Eigen::VectorXd* initial_residual = nullptr, double forcing = 0.0);

// 1 for the free entries, 0 for the others.
Eigen::VectorXd free_mask(const std::vector<char>& free);

// y = A x (A symmetric, compressed, full storage) times the mask entry by entry (1 for free
// entries, 0 for the others), in parallel over the columns, in a fixed order.
void symmetric_product(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& x, const Eigen::VectorXd& mask,
                       Eigen::VectorXd& y);

// The block-Jacobi preconditioner of A on the free entries: the inverse of each vertex's 3 × 3
// diagonal block (its constrained rows and columns zero).
Preconditioner block_jacobi(const Eigen::SparseMatrix<double>& a, const std::vector<char>& free);

}  // namespace clothsim

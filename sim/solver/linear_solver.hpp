// The linear solver of the implicit step: one object that owns the choice of method (conjugate
// gradients or a direct Cholesky factorisation), the preconditioner and the rule for refreshing
// it. The integrator hands it the assembled system and the mask of unknowns; nothing about the
// factorisations (CHOLMOD, the single/half-precision supernodal preconditioner, their BLAS and
// vector kernels) leaks through this header.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "sim/solver/pcg.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace clothsim {

// `automatic` (the default of both) is resolved by resolve_automatic() from the size of the
// system; the LinearSolver resolves it on construction.
enum class LinearSolverType { automatic, pcg, cholmod };
enum class PreconditionerType {
  automatic,
  block_jacobi,  // inverse 3 × 3 diagonal blocks
  cholesky,      // a Cholesky factor of an earlier step's matrix, refreshed when PCG slows down
};

struct LinearSolverSettings {
  LinearSolverType type = LinearSolverType::automatic;
  // Relative residual of the linear system (pcg). 1e-5: the loosest tolerance whose solver error
  // stays at most 1/10 of the discretisation error in the convergence study's tolerance series
  // (docs/convergence.md, "Solver tolerance"; the twisted sleeve on 52 x 37 decides it).
  double tolerance = 1e-5;
  int max_iterations = 2000;  // pcg
  PreconditionerType preconditioner = PreconditionerType::automatic;  // pcg
  int refresh_iterations = 50;  // cholesky preconditioner: refactor after a solve that needed more
};

// The scene-file names: "auto", "pcg", "cholmod"; "auto", "block_jacobi", "cholesky".
const char* to_string(LinearSolverType type);
const char* to_string(PreconditionerType preconditioner);

// `settings` with `automatic` replaced by the choice for a system of `unknowns` rows (3 per
// vertex); the other fields unchanged. The rule and the measurements behind it:
// scenes/README.md ("solver") and docs/performance.md ("Automatic solver choice").
LinearSolverSettings resolve_automatic(const LinearSolverSettings& settings, Eigen::Index unknowns);

struct LinearSolveReport {
  bool converged = false;
  int iterations = 0;       // pcg iterations, a failed first attempt included (1 per direct solve)
  double residual = 0.0;    // final relative residual
  int factorizations = 0;   // Cholesky factorisations in this solve (direct, or the preconditioner's)
  double factor_ms = 0.0;   // their time [ms]
  std::string failure;      // why it did not converge (a sentence with advice), when !converged
  // Conjugate-gradient solves that failed (after the refactorised retry) and were finished by the
  // direct solver (CHOLMOD) on the same matrix (0 or 1), and the failure that made them necessary
  // (the sentence `failure` would have held).
  int direct_fallbacks = 0;
  std::string fallback_reason;
};

// What a run must save to continue later with bit-identical solves: the Cholesky preconditioner's
// factor is of an earlier step's matrix, so the values of that matrix (on the integrator's fixed
// pattern) and the refresh counters are kept, and the factor is computed again from them.
struct LinearSolverCheckpoint {
  Eigen::VectorXd factored_values;  // the matrix's values when it was last factorised (empty: no factor)
  int solves_since_factor = 0;
  double iterations_since_factor = 0.0;
  bool refactor_next = false;
};

class LinearSolver {
 public:
  // `size`: rows of the systems to come (`automatic` settings are resolved for it).
  LinearSolver(const LinearSolverSettings& settings, Eigen::Index size);
  ~LinearSolver();
  LinearSolver(const LinearSolver&) = delete;
  LinearSolver& operator=(const LinearSolver&) = delete;

  // Solves A x = b on the entries with free[i] != 0 (A symmetric positive definite there, full
  // storage, the pattern of every call the same); x holds the start (pcg) and, at the other
  // entries, their fixed values. A and b may be overwritten (the direct solver's Dirichlet form).
  // A pcg solve that does not converge (after a refactorised retry with the Cholesky
  // preconditioner) is solved once more by the direct solver (CHOLMOD) and counted in the
  // report's direct_fallbacks; it fails only if that fails too.
  LinearSolveReport solve(Eigen::SparseMatrix<double>& a, Eigen::VectorXd& b, const std::vector<char>& free,
                          Eigen::VectorXd& x);

  // The same solve for a matrix given as an operation: `product` gives y = A x at every entry
  // (x's constrained entries hold their fixed values and enter the product as the matrix form's
  // do), `product_entries` its cost in stored entries of a matrix (for the refresh rule), and
  // `assemble` gives A as a matrix, called only when the preconditioner needs a new factor. For systems whose matrix costs more to assemble than to apply (the step potential's
  // contact blocks, each over the 12–50 nodes of its surface points' stencils: assembling them
  // every Newton iteration cost more than the rest of the crushed sleeve's step). Only for
  // conjugate gradients with the Cholesky preconditioner (solves_operators()); its factor is of
  // the last assembled matrix, kept while it serves (the same refresh rule as solve()).
  using MatrixSource = std::function<Eigen::SparseMatrix<double>&()>;
  bool solves_operators() const;
  // `initial_residual`, when given, is b − A x for the start x; `forcing`, the fraction of the
  // start's residual that also ends the solve (solve_pcg: an inexact Newton step).
  LinearSolveReport solve(const LinearOperator& product, double product_entries, const MatrixSource& assemble,
                          const Eigen::VectorXd& b, const std::vector<char>& free, Eigen::VectorXd& x,
                          const Eigen::VectorXd* initial_residual = nullptr, double forcing = 0.0);

  // An approximate inverse of the matrix of the last solve, `a` (as solve() left it) on the
  // entries with free[i] != 0, for further systems with that matrix or one close to it (the
  // contact stage's implicit response): the direct solver's factorisation (exact), the Cholesky
  // preconditioner's factor (of an earlier step's matrix) or block Jacobi. Valid until the next
  // solve().
  Preconditioner preconditioner(const Eigen::SparseMatrix<double>& a, const std::vector<char>& free) const;

  const LinearSolverSettings& settings() const { return settings_; }  // resolved (never automatic)

  // The state that later solves depend on (see LinearSolverCheckpoint).
  LinearSolverCheckpoint checkpoint() const;
  // Puts the solver into the state `c` was taken in: refactorises the matrix with `pattern`'s
  // pattern and c's values, on the entries with free[i] != 0 (as solve() did). Throws
  // std::invalid_argument if the values do not fit the pattern.
  void restore(const LinearSolverCheckpoint& c, const Eigen::SparseMatrix<double>& pattern, const std::vector<char>& free);

 private:
  struct Impl;
  // Conjugate gradients with the Cholesky preconditioner, for both forms: `pcg(limit, factor)` runs
  // the iteration from x, `refactor()` makes a new factor (of the matrix the form gives), `entries`
  // the stored entries of the system's matrix (the cost of one iteration's product).
  LinearSolveReport pcg_with_factor(const std::function<PcgResult(int, const Preconditioner&)>& pcg,
                                    const std::function<void(LinearSolveReport&)>& refactor, double entries,
                                    Eigen::VectorXd& x);
  // After a conjugate-gradient solve that failed (`report`): A x = b solved by a direct
  // factorisation of A, counted in `report` (direct_fallbacks; still not converged, with the
  // reason added to its failure, when A is not positive definite on the free entries).
  void solve_directly(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& b, const std::vector<char>& free,
                      Eigen::VectorXd& x, LinearSolveReport& report) const;
  LinearSolverSettings settings_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothsim

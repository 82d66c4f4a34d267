#include "sim/solver/linear_solver.hpp"

#include "sim/solver/cholesky_preconditioner.hpp"
#include "sim/solver/direct_solver.hpp"
#include "sim/solver/pcg.hpp"

#include <algorithm>
#include <chrono>
#include <sstream>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {
double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The Dirichlet form of A x = b, in place: the constrained columns (their fixed values, x's entries
// with free[i] == 0) moved to the right-hand side, unit diagonal in their rows and columns, so
// that a direct solve gives the free entries and returns the fixed ones unchanged.
void to_dirichlet_form(Eigen::SparseMatrix<double>& a, Eigen::VectorXd& b, const std::vector<char>& free,
                       const Eigen::VectorXd& x) {
  Eigen::VectorXd fixed_values = Eigen::VectorXd::Zero(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (!free[i]) fixed_values(i) = x(i);
  b -= a * fixed_values;
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (!free[i]) b(i) = fixed_values(i);
  set_dirichlet_identity(a, free);
}
}  // namespace

const char* to_string(LinearSolverType type) {
  switch (type) {
    case LinearSolverType::automatic: return "auto";
    case LinearSolverType::pcg: return "pcg";
    case LinearSolverType::cholmod: return "cholmod";
  }
  return "?";
}

const char* to_string(PreconditionerType preconditioner) {
  switch (preconditioner) {
    case PreconditionerType::automatic: return "auto";
    case PreconditionerType::block_jacobi: return "block_jacobi";
    case PreconditionerType::cholesky: return "cholesky";
  }
  return "?";
}

LinearSolverSettings resolve_automatic(const LinearSolverSettings& settings, Eigen::Index unknowns) {
  LinearSolverSettings s = settings;
  (void)unknowns;  // every size measured (205 to 5856 vertices) gave the same choice
  // Conjugate gradients: a direct factorisation every step costs 5-7 times as much as PCG with a
  // refreshed factor on every shipped scene (docs/performance.md, "Automatic solver choice").
  if (s.type == LinearSolverType::automatic) s.type = LinearSolverType::pcg;
  // The Cholesky-factor preconditioner: fastest on every shipped scene measured (same section).
  if (s.preconditioner == PreconditionerType::automatic) s.preconditioner = PreconditionerType::cholesky;
  return s;
}

struct LinearSolver::Impl {
  std::unique_ptr<DirectSolver> direct;             // type "cholmod"
  std::unique_ptr<CholeskyPreconditioner> factor;   // "pcg" with the "cholesky" preconditioner
  bool supernodal = false;
  // The pattern the factorisations were analysed for (outer and inner indices): a system with
  // another pattern (a step potential's couplings, sim/solver/coupled_matrix.hpp) needs a new
  // analysis, so both factorisations are made anew for it.
  std::vector<int> outer, inner;
  bool same_pattern(const Eigen::SparseMatrix<double>& a) const {
    return static_cast<Eigen::Index>(outer.size()) == a.outerSize() + 1 &&
           static_cast<Eigen::Index>(inner.size()) == a.nonZeros() &&
           std::equal(outer.begin(), outer.end(), a.outerIndexPtr()) &&
           std::equal(inner.begin(), inner.end(), a.innerIndexPtr());
  }
  // Starts afresh for a's pattern when it is not the one analysed; returns whether it was new.
  bool adopt_pattern(const Eigen::SparseMatrix<double>& a) {
    if (same_pattern(a)) return false;
    outer.assign(a.outerIndexPtr(), a.outerIndexPtr() + a.outerSize() + 1);
    inner.assign(a.innerIndexPtr(), a.innerIndexPtr() + a.nonZeros());
    direct = std::make_unique<DirectSolver>(supernodal);
    factor = std::make_unique<CholeskyPreconditioner>();
    return true;
  }
  // When to refresh `factor` (counted in conjugate-gradient iterations, see solve()).
  int solves_since_factor = 0;
  double iterations_since_factor = 0.0;
  bool refactor_next = false;
  Eigen::VectorXd factored_values;  // of the matrix last factorised for the preconditioner (checkpoints)
  // A new preconditioner factor of a (the pattern adopted), counted in `report`.
  void factorize(const Eigen::SparseMatrix<double>& a, const std::vector<char>& free, LinearSolveReport& report) {
    const auto f0 = std::chrono::steady_clock::now();
    factor->factorize(a, &free);  // of the Dirichlet form
    factored_values = Eigen::Map<const Eigen::VectorXd>(a.valuePtr(), a.nonZeros());
    ++report.factorizations;
    report.factor_ms += ms_since(f0);
    solves_since_factor = 0;
    iterations_since_factor = 0.0;
  }
  // The report of a conjugate-gradient solve r.
  static void finish(const PcgResult& r, const LinearSolverSettings& s, LinearSolveReport& report) {
    report.iterations += r.iterations;
    report.residual = r.residual;
    report.converged = r.converged;
    if (!r.converged) {
      std::ostringstream text;
      text << "the conjugate gradient solver did not converge: relative residual " << r.residual << " after "
           << r.iterations << " iterations (tolerance " << s.tolerance
           << "); try a smaller time step, more iterations or \"solver\": {\"type\": \"cholmod\"}";
      report.failure = text.str();
    }
  }
  explicit Impl(bool supernodal_factor)
      : direct(std::make_unique<DirectSolver>(supernodal_factor)),
        factor(std::make_unique<CholeskyPreconditioner>()),
        supernodal(supernodal_factor) {}
};

LinearSolver::LinearSolver(const LinearSolverSettings& settings, Eigen::Index size)
    : settings_(resolve_automatic(settings, size)), impl_(std::make_unique<Impl>(/*supernodal=*/size > 3000)) {}

LinearSolver::~LinearSolver() = default;

LinearSolveReport LinearSolver::solve(Eigen::SparseMatrix<double>& a, Eigen::VectorXd& b, const std::vector<char>& free,
                                      Eigen::VectorXd& x) {
  Impl& m = *impl_;
  const LinearSolverSettings& s = settings_;
  LinearSolveReport report;
  if (!a.isCompressed()) throw std::invalid_argument("LinearSolver::solve: the matrix must be compressed");
  if (m.adopt_pattern(a)) m.refactor_next = false;  // (a new factor is made below)
  if (s.type == LinearSolverType::cholmod) {
    to_dirichlet_form(a, b, free, x);
    const auto f0 = std::chrono::steady_clock::now();
    const bool factored = m.direct->refactorize(a);
    ++report.factorizations;
    report.factor_ms += ms_since(f0);
    if (!factored) {
      report.failure = "the system matrix is not positive definite (CHOLMOD)";
      return report;
    }
    x = m.direct->solve(b);
    report.iterations = 1;
    report.residual = (a * x - b).norm() / std::max(b.norm(), 1e-300);
    report.converged = true;
    return report;
  }

  if (s.preconditioner != PreconditionerType::cholesky) {
    const PcgResult r = solve_pcg(a, b, free, x, s.tolerance, s.max_iterations);
    m.finish(r, s, report);
  } else {
    report = pcg_with_factor(
        [&](int limit, const Preconditioner& factor) { return solve_pcg(a, b, free, x, s.tolerance, limit, factor); },
        [&](LinearSolveReport& r) { m.factorize(a, free, r); }, static_cast<double>(a.nonZeros()), x);
  }
  if (!report.converged) solve_directly(a, b, free, x, report);
  return report;
}

void LinearSolver::solve_directly(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& b,
                                  const std::vector<char>& free, Eigen::VectorXd& x, LinearSolveReport& report) const {
  // Conjugate gradients can stall where a factorisation does not: PCG with the Cholesky
  // preconditioner once ended step 1 at relative residuals of 0.09-0.57 after 1,850 iterations with
  // thousands of active barrier pairs, and could not be reproduced. The matrix is solved once more
  // by CHOLMOD, on a copy in the Dirichlet form (the caller's A and b stay as they are: the
  // integrator reads them after the solve), with a factorisation of its own (this is rare; the
  // solver's factors and refresh counters, which checkpoints hold, are left alone).
  Eigen::SparseMatrix<double> dirichlet = a;
  Eigen::VectorXd rhs = b;
  to_dirichlet_form(dirichlet, rhs, free, x);
  DirectSolver direct(impl_->supernodal);
  const auto f0 = std::chrono::steady_clock::now();
  const bool factored = direct.factorize(dirichlet);
  ++report.factorizations;
  report.factor_ms += ms_since(f0);
  if (!factored) {
    report.failure += "; the direct solver (CHOLMOD) it fell back to failed too: the system matrix is not positive definite";
    return;
  }
  x = direct.solve(rhs);
  report.iterations += 1;
  report.residual = (dirichlet * x - rhs).norm() / std::max(rhs.norm(), 1e-300);
  report.converged = true;
  report.direct_fallbacks = 1;
  report.fallback_reason = std::move(report.failure);
  report.failure.clear();
}

bool LinearSolver::solves_operators() const {
  return settings_.type == LinearSolverType::pcg && settings_.preconditioner == PreconditionerType::cholesky;
}

LinearSolveReport LinearSolver::solve(const LinearOperator& product, double product_entries, const MatrixSource& assemble,
                                      const Eigen::VectorXd& b, const std::vector<char>& free, Eigen::VectorXd& x,
                                      const Eigen::VectorXd* initial_residual, double forcing) {
  if (!solves_operators())
    throw std::logic_error("LinearSolver::solve: a matrix given as an operation needs pcg with the cholesky preconditioner");
  Impl& m = *impl_;
  const Eigen::SparseMatrix<double>* assembled = nullptr;
  auto refactor = [&](LinearSolveReport& r) {
    Eigen::SparseMatrix<double>& a = assemble();
    if (!a.isCompressed()) throw std::invalid_argument("LinearSolver::solve: the matrix must be compressed");
    m.adopt_pattern(a);
    m.factorize(a, free, r);
    assembled = &a;
  };
  // (A second solve, after a refactorisation, starts again from the same x: the same residual.)
  const Eigen::VectorXd start = x;
  auto pcg = [&](int limit, const Preconditioner& factor) {
    const Eigen::VectorXd* r0 = initial_residual != nullptr && x == start ? initial_residual : nullptr;
    if (factor) return solve_pcg(product, b, free, x, settings_.tolerance, limit, factor, r0, forcing);
    // (no factor: its factorisation, just made, failed; block Jacobi of the matrix it was of)
    if (assembled == nullptr) throw std::logic_error("LinearSolver::solve: no factor and no matrix");
    return solve_pcg(product, b, free, x, settings_.tolerance, limit, block_jacobi(*assembled, free), r0, forcing);
  };
  LinearSolveReport report = pcg_with_factor(pcg, refactor, product_entries, x);
  // (A failed solve was refactorised, so the matrix is assembled already.)
  if (!report.converged) solve_directly(assembled != nullptr ? *assembled : assemble(), b, free, x, report);
  return report;
}

LinearSolveReport LinearSolver::pcg_with_factor(const std::function<PcgResult(int, const Preconditioner&)>& pcg,
                                                const std::function<void(LinearSolveReport&)>& refactor, double entries,
                                                Eigen::VectorXd& x) {
  Impl& m = *impl_;
  const LinearSolverSettings& s = settings_;
  LinearSolveReport report;
  if (!m.factor->ready() || m.refactor_next) {
    m.refactor_next = false;
    refactor(report);
  }
  const Preconditioner factor = [&m](const Eigen::VectorXd& r, Eigen::VectorXd& z) { m.factor->apply(r, z); };
  const Eigen::VectorXd start = x;
  // With a stale factor a solve is cut off after 3 × refresh_iterations (a fresh factor is cheaper
  // than that) and, below, refactorised and solved again.
  const int first_limit = m.factor->ready() ? std::min(s.max_iterations, 3 * s.refresh_iterations) : s.max_iterations;
  PcgResult r = pcg(first_limit, m.factor->ready() ? factor : Preconditioner());
  // The factor is of an earlier matrix, and the iterations grow as the matrix drifts from it
  // (about one more per step in the buckling sleeve). Refactor when this solve cost more than
  // the average per solve since the last factorisation, the factorisation included (for a cost
  // that grows steadily this minimises the long-run average), or when it exceeded
  // refresh_iterations. The new factor is of the next step's matrix (taken at the start of that
  // step), not of this one, which is solved already: a factor of the matrix being solved needs
  // 3–4 iterations (half-precision solves), one a step old 5–6 in the sleeve's slow phases and
  // 9–60 while it snaps into folds. The factorisation's cost in iterations is estimated from its
  // flop count against the flops of one iteration (two triangular solves and a product with A),
  // scaled by 0.17, fitted on the 2542-vertex sleeve (2 cores): first with single-precision
  // solves (factorisation 22 ms ≙ 21 iterations of 1.05 ms), checked again with half-precision
  // solves (21.5 ms, 0.75 ms per iteration). The optimum is flat: 0.12 / 0.17 / 0.25 / 0.35 /
  // 0.5 model to 11.4 / 11.3 / 11.7 / 12.0 / 12.5 ms of solve per step (docs/performance.md).
  // Decided on counts, never on timings: runs are repeatable.
  ++m.solves_since_factor;
  m.iterations_since_factor += r.iterations;
  const double iteration_work = 4.0 * static_cast<double>(m.factor->factor_entries()) + 2.0 * entries;
  const double factor_cost = 0.17 * m.factor->factor_flops() / std::max(iteration_work, 1.0);
  const bool pays = r.iterations * m.solves_since_factor > factor_cost + m.iterations_since_factor;
  if (!r.converged) {  // refactor now and solve again from the same start
    refactor(report);
    if (m.factor->ready()) {
      report.iterations += r.iterations;
      x = start;
      r = pcg(std::max(1, s.max_iterations - report.iterations), factor);
    }
  } else if (r.iterations > s.refresh_iterations || pays) {
    m.refactor_next = true;
  }
  m.finish(r, s, report);
  return report;
}

LinearSolverCheckpoint LinearSolver::checkpoint() const {
  const Impl& m = *impl_;
  LinearSolverCheckpoint c;
  if (m.factor->ready()) c.factored_values = m.factored_values;
  c.solves_since_factor = m.solves_since_factor;
  c.iterations_since_factor = m.iterations_since_factor;
  c.refactor_next = m.refactor_next;
  return c;
}

void LinearSolver::restore(const LinearSolverCheckpoint& c, const Eigen::SparseMatrix<double>& pattern,
                           const std::vector<char>& free) {
  Impl& m = *impl_;
  if (c.factored_values.size() > 0) {
    if (c.factored_values.size() != pattern.nonZeros())
      throw std::invalid_argument("LinearSolver::restore: " + std::to_string(c.factored_values.size()) +
                                  " matrix values for a pattern of " + std::to_string(pattern.nonZeros()));
    if (settings_.type != LinearSolverType::pcg || settings_.preconditioner != PreconditionerType::cholesky)
      throw std::invalid_argument("LinearSolver::restore: a factor for a solver without the Cholesky preconditioner");
    Eigen::SparseMatrix<double> a = pattern;
    Eigen::Map<Eigen::VectorXd>(a.valuePtr(), a.nonZeros()) = c.factored_values;
    m.adopt_pattern(a);
    m.factor->factorize(a, &free);
    m.factored_values = c.factored_values;
  }
  m.solves_since_factor = c.solves_since_factor;
  m.iterations_since_factor = c.iterations_since_factor;
  m.refactor_next = c.refactor_next;
}

Preconditioner LinearSolver::preconditioner(const Eigen::SparseMatrix<double>& a, const std::vector<char>& free) const {
  const Impl& m = *impl_;
  if (settings_.type == LinearSolverType::cholmod)
    return [&m](const Eigen::VectorXd& r, Eigen::VectorXd& z) { z = m.direct->solve(r); };
  if (settings_.preconditioner == PreconditionerType::cholesky && m.factor->ready())
    return [&m](const Eigen::VectorXd& r, Eigen::VectorXd& z) { m.factor->apply(r, z); };
  return block_jacobi(a, free);
}

}  // namespace clothsim

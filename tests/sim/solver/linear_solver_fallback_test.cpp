// A conjugate-gradient solve that fails (after the Cholesky preconditioner's refactorised retry) is
// solved once more by the direct solver (CHOLMOD) on the same matrix: the report says so
// (direct_fallbacks, fallback_reason) and the solution is the direct solve's. Only a matrix the
// direct solver cannot factorise (not positive definite) still fails. PCG is made to fail by
// allowing it one iteration towards a tolerance of 1e-12 on a clamped plate's stiffness matrix.
#include "sim/shell/shell_model.hpp"
#include "sim/solver/linear_solver.hpp"
#include "sim/study/plates.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace clothsim {
namespace {

// The clamped plate's stiffness on 8 × 8 cells (E = 1e7 Pa, t = 1 cm), its clamped components
// as identity rows; a real shell system, symmetric positive definite.
Eigen::SparseMatrix<double> plate_matrix() {
  const Problem p = square_plate(8, /*clamped=*/true, Quadrature::one_point);
  const ShellModel model(p.mesh, p.material, p.boundary, p.quadrature);
  Eigen::SparseMatrix<double> k = model.stiffness();
  model.restrict_to_free(k);
  k.makeCompressed();
  return k;
}

// A system with three prescribed components (one interior node, moved by the given values).
struct System {
  Eigen::SparseMatrix<double> a = plate_matrix();
  Eigen::VectorXd b, start;
  std::vector<char> free;
  System() {
    const Eigen::Index n = a.rows();
    b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0).array().sin();
    start = Eigen::VectorXd::Zero(n);
    free.assign(static_cast<size_t>(n), 1);
    const Eigen::Index node = n / 6;  // (well inside the plate's list of nodes)
    for (int c = 0; c < 3; ++c) {
      free[static_cast<size_t>(3 * node + c)] = 0;
      start(3 * node + c) = 1e-3 * (c + 1);
    }
  }
};

LinearSolverSettings one_iteration(PreconditionerType preconditioner) {
  LinearSolverSettings s;
  s.type = LinearSolverType::pcg;
  s.preconditioner = preconditioner;
  s.tolerance = 1e-12;
  s.max_iterations = 1;
  return s;
}

// The reference: the same system solved by the "cholmod" solver.
Eigen::VectorXd direct_solution(const System& sys) {
  LinearSolverSettings s;
  s.type = LinearSolverType::cholmod;
  LinearSolver solver(s, sys.a.rows());
  Eigen::SparseMatrix<double> a = sys.a;
  Eigen::VectorXd b = sys.b, x = sys.start;
  const LinearSolveReport r = solver.solve(a, b, sys.free, x);
  EXPECT_TRUE(r.converged) << r.failure;
  return x;
}

void expect_direct_solution(const Eigen::VectorXd& x, const Eigen::VectorXd& expected, const System& sys) {
  EXPECT_LE((x - expected).cwiseAbs().maxCoeff(), 1e-10 * expected.cwiseAbs().maxCoeff());
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (!sys.free[static_cast<size_t>(i)]) EXPECT_EQ(x(i), sys.start(i)) << "prescribed component " << i;
}

TEST(LinearSolverFallback, AFailedPcgSolveIsSolvedByTheDirectSolverOnce) {
  const System sys;
  const Eigen::VectorXd expected = direct_solution(sys);
  for (const PreconditionerType preconditioner : {PreconditionerType::cholesky, PreconditionerType::block_jacobi}) {
    SCOPED_TRACE(to_string(preconditioner));
    LinearSolver solver(one_iteration(preconditioner), sys.a.rows());
    Eigen::SparseMatrix<double> a = sys.a;
    Eigen::VectorXd b = sys.b, x = sys.start;
    const LinearSolveReport r = solver.solve(a, b, sys.free, x);
    ASSERT_TRUE(r.converged) << r.failure;
    EXPECT_EQ(r.direct_fallbacks, 1);
    EXPECT_NE(r.fallback_reason.find("the conjugate gradient solver did not converge"), std::string::npos)
        << r.fallback_reason;
    EXPECT_TRUE(r.failure.empty()) << r.failure;
    EXPECT_LT(r.residual, 1e-10);
    expect_direct_solution(x, expected, sys);
    // The caller's system is left as it was (the integrator reads A and b after the solve).
    EXPECT_EQ((a - sys.a).norm(), 0.0);
    EXPECT_EQ(b, sys.b);
  }
}

TEST(LinearSolverFallback, AConvergedPcgSolveDoesNotFallBack) {
  const System sys;
  LinearSolverSettings s = one_iteration(PreconditionerType::cholesky);
  s.tolerance = 1e-8;
  s.max_iterations = 2000;
  LinearSolver solver(s, sys.a.rows());
  Eigen::SparseMatrix<double> a = sys.a;
  Eigen::VectorXd b = sys.b, x = sys.start;
  const LinearSolveReport r = solver.solve(a, b, sys.free, x);
  ASSERT_TRUE(r.converged) << r.failure;
  EXPECT_EQ(r.direct_fallbacks, 0);
  EXPECT_TRUE(r.fallback_reason.empty());
}

// The operator form (Newton with the contact potential): the matrix the MatrixSource gives is the
// one the direct solver factorises.
TEST(LinearSolverFallback, TheOperatorFormFallsBackOnTheAssembledMatrix) {
  const System sys;
  const Eigen::VectorXd expected = direct_solution(sys);
  LinearSolver solver(one_iteration(PreconditionerType::cholesky), sys.a.rows());
  Eigen::SparseMatrix<double> matrix = sys.a;
  int assembled = 0;
  const LinearOperator product = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) { y = sys.a * x; };
  const LinearSolver::MatrixSource assemble = [&]() -> Eigen::SparseMatrix<double>& {
    ++assembled;
    return matrix;
  };
  Eigen::VectorXd x = sys.start;
  const LinearSolveReport r = solver.solve(product, static_cast<double>(sys.a.nonZeros()), assemble, sys.b, sys.free, x);
  ASSERT_TRUE(r.converged) << r.failure;
  EXPECT_EQ(r.direct_fallbacks, 1);
  EXPECT_GE(assembled, 1);
  expect_direct_solution(x, expected, sys);
  EXPECT_EQ((matrix - sys.a).norm(), 0.0);
}

// A matrix that is not positive definite defeats both: the solve fails, as before, and says so.
TEST(LinearSolverFallback, FailsWhenTheDirectSolverFailsToo) {
  const System sys;
  LinearSolver solver(one_iteration(PreconditionerType::cholesky), sys.a.rows());
  Eigen::SparseMatrix<double> a = -sys.a;
  Eigen::VectorXd b = sys.b, x = sys.start;
  const LinearSolveReport r = solver.solve(a, b, sys.free, x);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.direct_fallbacks, 0);
  EXPECT_NE(r.failure.find("the conjugate gradient solver did not converge"), std::string::npos) << r.failure;
  EXPECT_NE(r.failure.find("the direct solver (CHOLMOD) it fell back to failed too: the system matrix is not positive definite"),
            std::string::npos)
      << r.failure;
}

}  // namespace
}  // namespace clothsim

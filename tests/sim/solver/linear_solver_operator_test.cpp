// The linear solver with the matrix given as an operation (LinearSolver::solve with a product and
// a MatrixSource): the solution of A x = b on the free entries against a dense solve, fixed entries
// entering as in the matrix form, the matrix assembled only when a factor is made, and the
// settings it refuses.
#include "sim/solver/linear_solver.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace clothsim {
namespace {

// A symmetric positive definite 3·n × 3·n matrix: a chain of nodes (full 3 × 3 blocks between
// neighbours) plus a rank-3 coupling of nodes 0 and n − 1, far apart in the chain (as a contact
// pair's block couples two parts of a cloth).
struct Problem {
  int n3 = 0;
  Eigen::SparseMatrix<double> chain;    // A's fixed pattern
  Eigen::MatrixXd coupling;             // dense, 3·n × 3·n, the far block Bᵀ H B
  Eigen::SparseMatrix<double> full;     // chain + coupling, with the coupling's pattern
};

Problem make_problem(int n) {
  Problem p;
  p.n3 = 3 * n;
  std::vector<Eigen::Triplet<double>> t;
  for (int a = 0; a < n; ++a)
    for (int b = std::max(0, a - 1); b <= std::min(n - 1, a + 1); ++b)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const double value = a == b ? (i == j ? 6.0 : 0.5) : -1.0 - 0.1 * (i == j);
          t.emplace_back(3 * a + i, 3 * b + j, value);
        }
  p.chain.resize(p.n3, p.n3);
  p.chain.setFromTriplets(t.begin(), t.end());
  p.chain = 0.5 * (p.chain + Eigen::SparseMatrix<double>(p.chain.transpose()));
  p.chain.makeCompressed();
  // B = [I at node 0, −I at node n−1], H = k n nᵀ + small tangential part.
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(3, p.n3);
  b.middleCols(0, 3) = Eigen::Matrix3d::Identity();
  b.middleCols(p.n3 - 3, 3) = -Eigen::Matrix3d::Identity();
  const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
  const Eigen::Matrix3d h = 40.0 * normal * normal.transpose() + 0.5 * Eigen::Matrix3d::Identity();
  p.coupling = b.transpose() * h * b;
  p.full = (Eigen::MatrixXd(p.chain) + p.coupling).sparseView();
  p.full.makeCompressed();
  return p;
}

LinearSolverSettings cholesky_pcg() {
  LinearSolverSettings s;
  s.type = LinearSolverType::pcg;
  s.preconditioner = PreconditionerType::cholesky;
  s.tolerance = 1e-10;
  return s;
}

TEST(LinearSolverOperator, SolvesTheFreeEntriesWithFixedOnesAsTheMatrixFormDoes) {
  const int n = 12;
  Problem p = make_problem(n);
  std::vector<char> free(static_cast<size_t>(p.n3), 1);
  free[3] = free[4] = 0;  // node 1 partly prescribed
  free[static_cast<size_t>(p.n3 - 1)] = 0;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd b(p.n3), start = Eigen::VectorXd::Zero(p.n3);
  for (Eigen::Index i = 0; i < p.n3; ++i) b(i) = u(rng);
  start(3) = 0.7;  // the prescribed values
  start(4) = -0.2;
  start(p.n3 - 1) = 0.4;

  // The reference: the dense system on the free entries, fixed values moved to the right.
  const Eigen::MatrixXd dense = Eigen::MatrixXd(p.chain) + p.coupling;
  std::vector<int> f;
  for (int i = 0; i < p.n3; ++i)
    if (free[static_cast<size_t>(i)]) f.push_back(i);
  Eigen::MatrixXd aff(f.size(), f.size());
  Eigen::VectorXd rhs(f.size());
  for (size_t r = 0; r < f.size(); ++r) {
    rhs(static_cast<Eigen::Index>(r)) = b(f[r]);
    for (int c = 0; c < p.n3; ++c)
      if (!free[static_cast<size_t>(c)]) rhs(static_cast<Eigen::Index>(r)) -= dense(f[r], c) * start(c);
    for (size_t c = 0; c < f.size(); ++c) aff(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = dense(f[r], f[c]);
  }
  const Eigen::VectorXd expected = aff.ldlt().solve(rhs);

  LinearSolver solver(cholesky_pcg(), p.n3);
  int assembled = 0;
  Eigen::SparseMatrix<double> matrix = p.full;
  const LinearOperator product = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
    y = p.chain * x + p.coupling * x;
  };
  const LinearSolver::MatrixSource assemble = [&]() -> Eigen::SparseMatrix<double>& {
    ++assembled;
    return matrix;
  };
  Eigen::VectorXd x = start;
  const LinearSolveReport r = solver.solve(product, static_cast<double>(p.full.nonZeros()), assemble, b, free, x);
  ASSERT_TRUE(r.converged) << r.failure;
  EXPECT_EQ(r.factorizations, 1);
  EXPECT_EQ(assembled, 1);
  for (size_t k = 0; k < f.size(); ++k) EXPECT_NEAR(x(f[k]), expected(static_cast<Eigen::Index>(k)), 1e-8) << f[k];
  EXPECT_EQ(x(3), 0.7);  // fixed entries keep their values
  EXPECT_EQ(x(4), -0.2);
  EXPECT_EQ(x(p.n3 - 1), 0.4);

  // The matrix form of the same system gives the same solution.
  LinearSolver matrix_solver(cholesky_pcg(), p.n3);
  Eigen::SparseMatrix<double> a = p.full;
  Eigen::VectorXd b_copy = b, y = start;
  ASSERT_TRUE(matrix_solver.solve(a, b_copy, free, y).converged);
  EXPECT_LT((x - y).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(LinearSolverOperator, AssemblesOnlyWhenAFactorIsMade) {
  Problem p = make_problem(10);
  const std::vector<char> free(static_cast<size_t>(p.n3), 1);
  LinearSolver solver(cholesky_pcg(), p.n3);
  int assembled = 0;
  Eigen::SparseMatrix<double> matrix = p.full;
  const LinearOperator product = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) { y = p.chain * x + p.coupling * x; };
  const LinearSolver::MatrixSource assemble = [&]() -> Eigen::SparseMatrix<double>& {
    ++assembled;
    return matrix;
  };
  int factorizations = 0;
  for (int k = 0; k < 4; ++k) {  // the same system again: the factor serves, no assembly
    Eigen::VectorXd b = Eigen::VectorXd::Constant(p.n3, 1.0 + k), x = Eigen::VectorXd::Zero(p.n3);
    const LinearSolveReport r = solver.solve(product, static_cast<double>(p.full.nonZeros()), assemble, b, free, x);
    ASSERT_TRUE(r.converged) << r.failure;
    factorizations += r.factorizations;
    EXPECT_LT((Eigen::MatrixXd(p.full) * x - b).norm(), 1e-8 * b.norm());
  }
  EXPECT_EQ(assembled, factorizations);
  EXPECT_EQ(assembled, 1);
  EXPECT_TRUE(solver.solves_operators());
}

// A start's residual given by the caller replaces the solver's product at the start: one product
// less, the same solution; and a wrong one is not ignored (the solver trusts it).
TEST(LinearSolverOperator, TakesTheStartsResidualFromTheCaller) {
  Problem p = make_problem(10);
  const std::vector<char> free(static_cast<size_t>(p.n3), 1);
  int products = 0;
  const LinearOperator product = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
    ++products;
    y = p.chain * x + p.coupling * x;
  };
  Eigen::SparseMatrix<double> matrix = p.full;
  const LinearSolver::MatrixSource assemble = [&]() -> Eigen::SparseMatrix<double>& { return matrix; };
  Eigen::VectorXd b(p.n3), start(p.n3);
  for (Eigen::Index i = 0; i < p.n3; ++i) b(i) = std::sin(0.7 * static_cast<double>(i)), start(i) = 0.1 * std::cos(1.3 * static_cast<double>(i));
  const Eigen::VectorXd expected = Eigen::MatrixXd(p.full).ldlt().solve(b);

  LinearSolver plain(cholesky_pcg(), p.n3), given(cholesky_pcg(), p.n3), wrong(cholesky_pcg(), p.n3);
  Eigen::VectorXd x = start;
  products = 0;
  ASSERT_TRUE(plain.solve(product, 1.0, assemble, b, free, x).converged);
  const int plain_products = products;
  EXPECT_LT((x - expected).cwiseAbs().maxCoeff(), 1e-8);

  const Eigen::VectorXd r0 = b - Eigen::MatrixXd(p.full) * start;
  Eigen::VectorXd y = start;
  products = 0;
  ASSERT_TRUE(given.solve(product, 1.0, assemble, b, free, y, &r0).converged);
  EXPECT_EQ(products, plain_products - 1);
  EXPECT_LT((y - expected).cwiseAbs().maxCoeff(), 1e-8);

  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(p.n3);  // "the start solves it": nothing to do
  Eigen::VectorXd z = start;
  ASSERT_TRUE(wrong.solve(product, 1.0, assemble, b, free, z, &zero).converged);
  EXPECT_EQ(z, start);
}

TEST(LinearSolverOperator, RefusesSolversWithoutTheCholeskyFactor) {
  Problem p = make_problem(4);
  const std::vector<char> free(static_cast<size_t>(p.n3), 1);
  const LinearOperator product = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) { y = p.full * x; };
  Eigen::SparseMatrix<double> matrix = p.full;
  const LinearSolver::MatrixSource assemble = [&]() -> Eigen::SparseMatrix<double>& { return matrix; };
  for (const auto& [type, preconditioner] :
       {std::pair{LinearSolverType::cholmod, PreconditionerType::cholesky},
        std::pair{LinearSolverType::pcg, PreconditionerType::block_jacobi}}) {
    LinearSolverSettings s = cholesky_pcg();
    s.type = type;
    s.preconditioner = preconditioner;
    LinearSolver solver(s, p.n3);
    EXPECT_FALSE(solver.solves_operators());
    Eigen::VectorXd b = Eigen::VectorXd::Ones(p.n3), x = Eigen::VectorXd::Zero(p.n3);
    EXPECT_THROW(solver.solve(product, 1.0, assemble, b, free, x), std::logic_error);
  }
}

}  // namespace
}  // namespace clothsim

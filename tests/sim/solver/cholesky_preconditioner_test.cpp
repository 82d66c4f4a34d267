// The single-precision supernodal Cholesky preconditioner against CHOLMOD's double-precision
// solve on a plate stiffness matrix (supernodal size: 24 × 24 cells, 1587 free DOFs).
#include "sim/shell/shell_model.hpp"
#include "sim/solver/cholesky_preconditioner.hpp"
#include "sim/solver/direct_solver.hpp"
#include "sim/study/plates.hpp"

#include <gtest/gtest.h>

namespace clothsim {
namespace {

Eigen::SparseMatrix<double> plate_matrix(int divisions) {
  const StaticProblem p = square_plate(divisions, /*clamped=*/true, Quadrature::one_point);
  const ShellModel model(p.mesh, p.material, p.boundary, p.quadrature);
  Eigen::SparseMatrix<double> k = model.stiffness();
  model.restrict_to_free(k);
  return k;
}

class CholeskyPreconditionerKernels : public ::testing::TestWithParam<bool> {};

// Both kernel sets: the AVX2 + FMA ones (where the processor has them) and the portable ones.
TEST_P(CholeskyPreconditionerKernels, MatchesTheDoublePrecisionSolve) {
  const Eigen::SparseMatrix<double> a = plate_matrix(24);
  CholeskyPreconditioner pre(GetParam());
  EXPECT_FALSE(pre.ready());
  ASSERT_TRUE(pre.factorize(a));
  EXPECT_TRUE(pre.ready());
  EXPECT_GT(pre.factor_entries(), a.nonZeros() / 2);
  DirectSolver direct;
  ASSERT_TRUE(direct.factorize(a));
  const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(a.rows(), -1.0, 2.0).array().sin();
  Eigen::VectorXd z;
  pre.apply(r, z);
  const Eigen::VectorXd exact = direct.solve(r);
  ASSERT_EQ(z.size(), a.rows());
  EXPECT_LT((z - exact).norm(), 1e-4 * exact.norm());  // single precision, not a coincidence
  EXPECT_GT((z - exact).norm(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Kernels, CholeskyPreconditionerKernels, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& p) { return p.param ? "vector" : "portable"; });

TEST(CholeskyPreconditioner, RefactorisesWithTheSamePattern) {
  const Eigen::SparseMatrix<double> a = plate_matrix(16);
  CholeskyPreconditioner pre;
  ASSERT_TRUE(pre.factorize(a));
  const Eigen::VectorXd r = Eigen::VectorXd::Ones(a.rows());
  Eigen::VectorXd z1, z2;
  pre.apply(r, z1);
  const Eigen::SparseMatrix<double> doubled = 2.0 * a;
  ASSERT_TRUE(pre.factorize(doubled));
  pre.apply(r, z2);
  EXPECT_LT((2.0 * z2 - z1).norm(), 1e-5 * z1.norm());
}

TEST(CholeskyPreconditioner, RejectsAMatrixThatIsNotPositiveDefinite) {
  Eigen::SparseMatrix<double> a = plate_matrix(8);
  CholeskyPreconditioner pre;
  ASSERT_TRUE(pre.factorize(a));
  a.coeffRef(a.rows() / 2, a.rows() / 2) = -1.0;
  EXPECT_FALSE(pre.factorize(a));
  EXPECT_FALSE(pre.ready());
  EXPECT_EQ(pre.factor_entries(), 0);
}

}  // namespace
}  // namespace clothsim

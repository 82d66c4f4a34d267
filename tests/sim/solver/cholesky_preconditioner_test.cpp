// The single-precision supernodal Cholesky preconditioner against CHOLMOD's double-precision
// solve on a plate stiffness matrix (supernodal size: 24 × 24 cells, 1587 free DOFs).
#include "sim/shell/shell_model.hpp"
#include "sim/solver/cholesky_preconditioner.hpp"
#include "sim/solver/direct_solver.hpp"
#include "sim/study/plates.hpp"

#include <gtest/gtest.h>

#include <string>
#include <tuple>

namespace clothsim {
namespace {

Eigen::SparseMatrix<double> plate_matrix(int divisions) {
  const StaticProblem p = square_plate(divisions, /*clamped=*/true, Quadrature::one_point);
  const ShellModel model(p.mesh, p.material, p.boundary, p.quadrature);
  Eigen::SparseMatrix<double> k = model.stiffness();
  model.restrict_to_free(k);
  return k;
}

// (vector kernels, single-precision factorisation)
class CholeskyPreconditionerKernels : public ::testing::TestWithParam<std::tuple<bool, bool>> {};

// Both kernel sets: the AVX2 + FMA ones (where the processor has them) and the portable ones;
// both factorisations: our single-precision one and CHOLMOD's in double, copied.
TEST_P(CholeskyPreconditionerKernels, MatchesTheDoublePrecisionSolve) {
  const Eigen::SparseMatrix<double> a = plate_matrix(24);
  const auto [vector, single] = GetParam();
  CholeskyPreconditioner pre(vector, single);
  EXPECT_FALSE(pre.ready());
  ASSERT_TRUE(pre.factorize(a));
  EXPECT_TRUE(pre.ready());
  EXPECT_EQ(pre.factored_in_single_precision(), single);
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

INSTANTIATE_TEST_SUITE_P(Kernels, CholeskyPreconditionerKernels, ::testing::Combine(::testing::Bool(), ::testing::Bool()),
                         [](const ::testing::TestParamInfo<std::tuple<bool, bool>>& p) {
                           return std::string(std::get<0>(p.param) ? "vector" : "portable") +
                                  (std::get<1>(p.param) ? "_single" : "_cholmod");
                         });

// Both factorisations of the same matrix give the same factor up to single-precision round-off.
TEST(CholeskyPreconditioner, SingleAndDoublePrecisionFactorsAgree) {
  const Eigen::SparseMatrix<double> a = plate_matrix(20);
  CholeskyPreconditioner single(true, true), copied(true, false);
  ASSERT_TRUE(single.factorize(a));
  ASSERT_TRUE(copied.factorize(a));
  EXPECT_EQ(single.factor_entries(), copied.factor_entries());
  const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(a.rows(), 0.0, 3.0).array().cos();
  Eigen::VectorXd z1, z2;
  single.apply(r, z1);
  copied.apply(r, z2);
  EXPECT_LT((z1 - z2).norm(), 1e-4 * z2.norm());
  EXPECT_GT((z1 - z2).norm(), 0.0);  // computed, not copied
}

// A matrix positive definite in double precision but not in single (a free plate, singular up to
// a shift of 1e-10 of its largest diagonal entry): the factorisation falls back to CHOLMOD.
TEST(CholeskyPreconditioner, FallsBackToDoublePrecisionForAnIllConditionedMatrix) {
  StaticProblem p = square_plate(12, /*clamped=*/true, Quadrature::one_point);
  p.boundary.clear();
  const ShellModel model(p.mesh, p.material, p.boundary, p.quadrature);
  Eigen::SparseMatrix<double> a = model.stiffness();
  const double shift = 1e-10 * a.diagonal().maxCoeff();
  for (Eigen::Index i = 0; i < a.rows(); ++i) a.coeffRef(i, i) += shift;
  CholeskyPreconditioner pre;
  ASSERT_TRUE(pre.factorize(a));
  EXPECT_FALSE(pre.factored_in_single_precision());
  const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(a.rows(), -1.0, 2.0).array().sin();
  Eigen::VectorXd z;
  pre.apply(r, z);
  EXPECT_TRUE(z.allFinite());
  // The next, well-conditioned matrix with the same pattern is factorised in single precision again.
  for (Eigen::Index i = 0; i < a.rows(); ++i) a.coeffRef(i, i) += 1e-2 * a.diagonal().maxCoeff();
  ASSERT_TRUE(pre.factorize(a));
  EXPECT_TRUE(pre.factored_in_single_precision());
}

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

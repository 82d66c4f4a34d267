// The single-precision supernodal Cholesky preconditioner against CHOLMOD's double-precision
// solve on clamped-plate stiffness matrices.
#include "sim/shell/shell_model.hpp"
#include "sim/solver/cholesky_preconditioner.hpp"
#include "sim/solver/direct_solver.hpp"
#include "sim/solver/supernodal_kernels.hpp"
#include "sim/study/plates.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>
#include <tuple>

namespace clothsim {
namespace {

Eigen::SparseMatrix<double> plate_matrix(int divisions) {
  const Problem p = square_plate(divisions, /*clamped=*/true, Quadrature::one_point);
  const ShellModel model(p.mesh, p.material, p.boundary, p.quadrature);
  Eigen::SparseMatrix<double> k = model.stiffness();
  model.restrict_to_free(k);
  return k;
}

// (vector kernels, single-precision factorisation, half-precision storage)
using Variant = std::tuple<bool, bool, bool>;
class CholeskyPreconditionerKernels : public ::testing::TestWithParam<Variant> {};

// Both kernel sets: the AVX2 + FMA ones (where the processor has them) and the portable ones;
// both factorisations: our single-precision one and CHOLMOD's in double, copied; with the vector
// kernels, the solves on the single- or the half-precision copy of the factor.
// 32 × 32 cells: its largest supernodes (402 columns; 132 columns over 435 rows) take the
// parallel blocked path of the single-precision factorisation (≥ 128 columns), the others the
// serial one.
TEST_P(CholeskyPreconditionerKernels, MatchesTheDoublePrecisionSolve) {
  const Eigen::SparseMatrix<double> a = plate_matrix(32);
  const auto [vector, single, half] = GetParam();
  CholeskyPreconditioner pre(vector, single, half);
  EXPECT_FALSE(pre.ready());
  ASSERT_TRUE(pre.factorize(a));
  EXPECT_TRUE(pre.ready());
  EXPECT_EQ(pre.factored_in_single_precision(), single);
  const bool stored_half = half && vector && supernodal_avx2::supported();
  EXPECT_EQ(pre.stored_in_half_precision(), stored_half);
  EXPECT_GT(pre.factor_entries(), a.nonZeros() / 2);
  DirectSolver direct;
  ASSERT_TRUE(direct.factorize(a));
  const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(a.rows(), -1.0, 2.0).array().sin();
  Eigen::VectorXd z;
  pre.apply(r, z);
  const Eigen::VectorXd exact = direct.solve(r);
  ASSERT_EQ(z.size(), a.rows());
  // Round-off amplified by the stiffness matrix's conditioning. Measured (METIS ordering):
  // factorised in single precision 6.9e-5, in double and rounded to single 8e-8; stored in half
  // precision (unit round-off 4.9e-4) 5.3e-4. A wrong factor would be off by O(1).
  const double bound = stored_half ? 3e-3 : 3e-4;
  EXPECT_LT((z - exact).norm(), bound * exact.norm());
  EXPECT_GT((z - exact).norm(), 0.0);  // not a coincidence
}

INSTANTIATE_TEST_SUITE_P(Kernels, CholeskyPreconditionerKernels,
                         ::testing::Values(Variant{false, true, false}, Variant{false, false, false}, Variant{true, true, false},
                                           Variant{true, false, false}, Variant{true, true, true}, Variant{true, false, true}),
                         [](const ::testing::TestParamInfo<Variant>& p) {
                           return std::string(std::get<0>(p.param) ? "vector" : "portable") +
                                  (std::get<1>(p.param) ? "_single" : "_cholmod") + (std::get<2>(p.param) ? "_half" : "");
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
  Problem p = square_plate(12, /*clamped=*/true, Quadrature::one_point);
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

// factorize(a, &free) factorises the Dirichlet form without a copy: the same factor as of the
// matrix with those rows and columns replaced by the identity's, in both precisions.
TEST(CholeskyPreconditioner, DirichletFormFromAMask) {
  const Eigen::SparseMatrix<double> a = plate_matrix(16);
  std::vector<char> free(static_cast<size_t>(a.rows()), 1);
  for (size_t i = 0; i < free.size(); i += 7) free[i] = 0;
  Eigen::SparseMatrix<double> dirichlet = a;
  for (Eigen::Index col = 0; col < dirichlet.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(dirichlet, col); it; ++it)
      if (!free[col] || !free[it.row()]) it.valueRef() = it.row() == col ? 1.0 : 0.0;
  const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(a.rows(), -2.0, 1.0).array().sin();
  for (bool single : {true, false}) {
    CholeskyPreconditioner masked(true, single), copied(true, single), plain(true, single);
    ASSERT_TRUE(masked.factorize(a, &free));
    ASSERT_TRUE(copied.factorize(dirichlet));
    ASSERT_TRUE(plain.factorize(a));
    Eigen::VectorXd z1, z2, z3;
    masked.apply(r, z1);
    copied.apply(r, z2);
    plain.apply(r, z3);
    EXPECT_EQ(z1, z2) << (single ? "single" : "cholmod");
    EXPECT_GT((z1 - z3).norm(), 1e-3 * z3.norm());  // the mask did change the matrix
    for (size_t i = 0; i < free.size(); i += 7) EXPECT_NEAR(z1(static_cast<Eigen::Index>(i)), r(static_cast<Eigen::Index>(i)), 1e-6);
  }
  std::vector<char> wrong_size(3, 1);
  CholeskyPreconditioner pre;
  EXPECT_FALSE(pre.factorize(a, &wrong_size));
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

// Box-spline basis and subdivision-element basis: partition of unity, derivatives against finite
// differences, limit-mask values, reproduction of linear fields, subdivided == direct for N = 6.
#include "sim/subdivision/box_spline.hpp"
#include "sim/subdivision/loop.hpp"
#include "sim/subdivision/patch.hpp"
#include "tests/support/test_meshes.hpp"

#include <gtest/gtest.h>

#include <random>

namespace clothsim {
namespace {

const std::vector<std::array<double, 2>> kPoints = {
    {1.0 / 3, 1.0 / 3}, {0.1, 0.2}, {0.7, 0.15}, {0.05, 0.9}, {0.45, 0.45}, {0.0, 0.0}, {0.25, 0.0}};

TEST(BoxSpline, PartitionOfUnityAndDerivativeSums) {
  for (auto [v, w] : kPoints) {
    const BoxSplineBasis b = box_spline_basis(v, w);
    EXPECT_NEAR(b.row(kValue).sum(), 1.0, 1e-14);
    for (int r = 1; r < 6; ++r) EXPECT_NEAR(b.row(r).sum(), 0.0, 1e-13) << "row " << r;
    EXPECT_GE(b.row(kValue).minCoeff(), 0.0);
  }
}

TEST(BoxSpline, DerivativesMatchFiniteDifferences) {
  const double h = 1e-5;
  for (auto [v, w] : kPoints) {
    const BoxSplineBasis b = box_spline_basis(v, w);
    const BoxSplineBasis bv_p = box_spline_basis(v + h, w), bv_m = box_spline_basis(v - h, w);
    const BoxSplineBasis bw_p = box_spline_basis(v, w + h), bw_m = box_spline_basis(v, w - h);
    for (int i = 0; i < 12; ++i) {
      EXPECT_NEAR(b(kDv, i), (bv_p(kValue, i) - bv_m(kValue, i)) / (2 * h), 1e-8);
      EXPECT_NEAR(b(kDw, i), (bw_p(kValue, i) - bw_m(kValue, i)) / (2 * h), 1e-8);
      EXPECT_NEAR(b(kDvv, i), (bv_p(kDv, i) - bv_m(kDv, i)) / (2 * h), 1e-7);
      EXPECT_NEAR(b(kDww, i), (bw_p(kDw, i) - bw_m(kDw, i)) / (2 * h), 1e-7);
      EXPECT_NEAR(b(kDvw, i), (bw_p(kDv, i) - bw_m(kDv, i)) / (2 * h), 1e-7);
      EXPECT_NEAR(b(kDvw, i), (bv_p(kDw, i) - bv_m(kDw, i)) / (2 * h), 1e-7);
    }
  }
}

TEST(BoxSpline, LimitMaskAtVertexAndCentroid) {
  const BoxSplineBasis b = box_spline_basis(0.0, 0.0);  // vertex 4
  for (int i = 0; i < 12; ++i) {
    const int label = i + 1;
    const bool neighbour = label == 1 || label == 2 || label == 3 || label == 5 || label == 7 || label == 8;
    EXPECT_NEAR(b(kValue, i), label == 4 ? 6.0 / 12 : neighbour ? 1.0 / 12 : 0.0, 1e-15) << "N" << label;
  }
  EXPECT_NEAR(6.0 / 12, 1.0 - 6 * limit_neighbour_weight(6), 1e-15);
  EXPECT_NEAR(1.0 / 12, limit_neighbour_weight(6), 1e-15);
  EXPECT_NEAR(loop_beta(6), 1.0 / 16, 1e-15);
  const BoxSplineBasis c = box_spline_basis(1.0 / 3, 1.0 / 3);
  for (int label : {4, 7, 8}) EXPECT_NEAR(c(kValue, label - 1) * 12, 3.4074, 1e-4);
}

TEST(BoxSpline, ReproducesLinearFields) {
  // The layout of box_spline.hpp on an equilateral lattice (any affine image works).
  const double h = std::sqrt(3.0) / 2;
  const Eigen::Matrix<double, 12, 2> X = (Eigen::Matrix<double, 12, 2>() << 1, 2 * h, 2, 2 * h, 0.5, h, 1.5, h, 2.5,
                                          h, 0, 0, 1, 0, 2, 0, 3, 0, 0.5, -h, 1.5, -h, 2.5, -h)
                                             .finished();
  for (auto [v, w] : kPoints) {
    const BoxSplineBasis b = box_spline_basis(v, w);
    const Eigen::RowVector2d x = b.row(kValue) * X;
    const Eigen::RowVector2d expect = (1 - v - w) * X.row(3) + v * X.row(6) + w * X.row(7);
    EXPECT_NEAR((x - expect).norm(), 0.0, 1e-14);
    EXPECT_NEAR((b.row(kDv) * X - (X.row(6) - X.row(3))).norm(), 0.0, 1e-13);
    EXPECT_NEAR((b.row(kDw) * X - (X.row(7) - X.row(3))).norm(), 0.0, 1e-13);
    EXPECT_NEAR((b.bottomRows(3) * X).norm(), 0.0, 1e-12);
  }
}

// Value of Σ N_i f_i from a patch evaluation, for a field given per mesh vertex.
Eigen::Matrix<double, 6, 1> apply(const PatchEvaluation& e, const Eigen::VectorXd& f) {
  Eigen::Matrix<double, 6, 1> out = Eigen::Matrix<double, 6, 1>::Zero();
  for (size_t k = 0; k < e.vertices.size(); ++k) out += e.basis.col(static_cast<Eigen::Index>(k)) * f(e.vertices[k]);
  return out;
}

TEST(SubdivisionPatch, SubdividedEvaluationEqualsDirectForValence6) {
  const TriMesh lattice = testing::make_lattice(10);
  const Topology top(lattice.num_vertices(), lattice.triangles);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> dist(-1.0, 1.0);
  Eigen::VectorXd f(lattice.num_vertices());
  for (int i = 0; i < f.size(); ++i) f(i) = dist(rng);
  const Triangle tri = lattice.triangles[2 * (4 * 9 + 4)];  // well inside
  for (auto [v, w] : kPoints) {
    if (v == 0.0 && w == 0.0) continue;
    const auto direct = apply(evaluate_patch(top, tri, v, w), f);
    for (int levels : {1, 2, 3}) {
      const auto sub = apply(evaluate_patch(top, tri, v, w, levels), f);
      EXPECT_NEAR((direct - sub).norm(), 0.0, 1e-11) << "levels " << levels << " at (" << v << ", " << w << ")";
    }
  }
}

class IrregularPatch : public ::testing::TestWithParam<int> {};

TEST_P(IrregularPatch, PartitionOfUnityLinearReproductionAndFiniteDifferences) {
  const int valence = GetParam();
  TriMesh disc = testing::make_fan_disc(valence, 4);
  const Topology top(disc.num_vertices(), disc.triangles);
  ASSERT_EQ(top.valence(0), valence);
  // An element at the irregular centre vertex 0.
  Triangle tri = disc.triangles[0];
  ASSERT_EQ(tri[0], 0);
  // A smooth non-linear field and a linear one.
  Eigen::VectorXd lin(disc.num_vertices()), f(disc.num_vertices());
  for (int i = 0; i < disc.num_vertices(); ++i) {
    const auto p = disc.vertices.row(i);
    lin(i) = 0.3 + 2.0 * p(0) - 1.5 * p(1);
    f(i) = std::sin(2 * p(0)) * std::cos(3 * p(1)) + p(0) * p(1);
  }
  // Interior points off the dyadic lines of the sub-patches (where third derivatives jump),
  // down to the innermost rings around the irregular vertex.
  const std::vector<std::array<double, 2>> points = {{0.13, 0.21}, {0.31, 0.37}, {0.07, 0.05}, {0.6, 0.17},
                                                     {0.2, 0.66}, {0.013, 0.021}, {1.0 / 3, 1.0 / 3}};
  const double h = 1e-6;
  for (auto [v, w] : points) {
    const PatchEvaluation e = evaluate_patch(top, tri, v, w);
    EXPECT_EQ(static_cast<int>(e.vertices.size()), valence + 6);
    EXPECT_NEAR(e.basis.row(kValue).sum(), 1.0, 1e-12);
    for (int r = 1; r < 6; ++r) EXPECT_NEAR(e.basis.row(r).sum(), 0.0, 1e-10);
    const auto g = apply(e, f);
    const auto gv_p = apply(evaluate_patch(top, tri, v + h, w), f), gv_m = apply(evaluate_patch(top, tri, v - h, w), f);
    const auto gw_p = apply(evaluate_patch(top, tri, v, w + h), f), gw_m = apply(evaluate_patch(top, tri, v, w - h), f);
    EXPECT_NEAR(g(kDv), (gv_p(kValue) - gv_m(kValue)) / (2 * h), 1e-6);
    EXPECT_NEAR(g(kDw), (gw_p(kValue) - gw_m(kValue)) / (2 * h), 1e-6);
    const double tol2 = 1e-5 * (1.0 + g.tail(3).cwiseAbs().maxCoeff());
    EXPECT_NEAR(g(kDvv), (gv_p(kDv) - gv_m(kDv)) / (2 * h), tol2);
    EXPECT_NEAR(g(kDww), (gw_p(kDw) - gw_m(kDw)) / (2 * h), tol2);
    EXPECT_NEAR(g(kDvw), (gw_p(kDv) - gw_m(kDv)) / (2 * h), tol2);
    // Subdivision is affine invariant: a field that is an affine function L of the control
    // positions interpolates to L of the surface point, with derivatives ∇L · x_,α.
    const auto l = apply(e, lin);
    Eigen::Matrix<double, 6, 1> px = apply(e, disc.vertices.col(0)), py = apply(e, disc.vertices.col(1));
    EXPECT_NEAR(l(kValue), 0.3 + 2.0 * px(kValue) - 1.5 * py(kValue), 1e-12);
    for (int r = 1; r < 6; ++r) EXPECT_NEAR(l(r), 2.0 * px(r) - 1.5 * py(r), 1e-10);
  }
}

INSTANTIATE_TEST_SUITE_P(Valences, IrregularPatch, ::testing::Values(3, 4, 5, 7, 8, 9, 10, 11, 12));

}  // namespace
}  // namespace clothsim

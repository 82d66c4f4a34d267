// The potential's weighted block sum (sim/solver/block_sum.hpp) against dense arithmetic: for a
// linearisation with rows on points (sharing points and nodes), a row over the nodes, a row per
// DOF and a row given twice (an energy block and a dissipation block on one row), the product
// equals Σ w Bᵀ H B x with w = h² or h, the merged rows are counted once, and node_blocks() gives
// the same matrix.
#include "sim/solver/block_sum.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

namespace clothsim {
namespace {

constexpr int kNodes = 8;

Eigen::MatrixXd dense(const NodeRow& row) {  // B: 3 × 3·#nodes
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(3, 3 * kNodes);
  for (const auto& [node, w] : row.nodes) b.middleCols(3 * node, 3) += w * Eigen::Matrix3d::Identity();
  for (const auto& [dof, v] : row.dofs) b.col(dof) += v;
  return b;
}

Eigen::Matrix3d symmetric(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = u(rng);
  return m * m.transpose() + Eigen::Matrix3d::Identity();
}

TEST(BlockSum, ProductIsTheWeightedSumOfBtHBAndRowsMergeOnce) {
  std::mt19937 rng(17);
  PointMap map;  // 5 points over 8 nodes, stencils overlapping
  const std::vector<std::vector<std::pair<int, double>>> stencils = {
      {{0, 0.5}, {1, 0.3}, {2, 0.2}}, {{1, 0.6}, {2, 0.4}}, {{2, 0.1}, {3, 0.6}, {4, 0.3}}, {{5, 0.7}, {6, 0.3}}, {{4, 0.5}, {7, 0.5}}};
  for (const auto& stencil : stencils) {
    for (const auto& [node, w] : stencil) {
      map.nodes.push_back(node);
      map.weights.push_back(w);
    }
    map.offsets.push_back(static_cast<int>(map.nodes.size()));
  }
  PotentialLinearisation lin;
  lin.point_map = &map;
  auto on_points = [](std::vector<int> points, std::vector<double> coefs) {
    PotentialLinearisation::Block b;
    b.on_points.count = static_cast<int>(points.size());
    for (size_t k = 0; k < points.size(); ++k) {
      b.on_points.points[k] = points[k];
      b.on_points.coefs[k] = coefs[k];
    }
    return b;
  };
  lin.blocks.push_back(on_points({0, 1, 2, 4}, {0.6, 0.4, -0.3, -0.7}));  // an edge–edge pair
  lin.blocks.push_back(on_points({3}, {1.0}));                            // a point on an obstacle
  lin.blocks.push_back(on_points({1, 2, 3, 4}, {-1.0, 0.2, 0.5, 0.3}));  // a point–triangle pair
  lin.blocks.push_back(on_points({3}, {1.0}));                            // the same point's friction
  lin.blocks.back().dissipative = true;
  PotentialLinearisation::Block node_form;
  node_form.row.nodes = {{6, 0.25}, {1, -0.5}};
  lin.blocks.push_back(node_form);
  PotentialLinearisation::Block per_dof;
  per_dof.row.dofs = {{4, Eigen::Vector3d(0.2, -0.1, 0.4)}, {22, Eigen::Vector3d(-0.3, 0.5, 0.1)}};
  lin.blocks.push_back(per_dof);
  for (auto& b : lin.blocks) b.hessian = symmetric(rng);

  const double h = 0.01;
  BlockSum sum;
  sum.build(lin, h);
  EXPECT_EQ(sum.size(), 5u);  // the point's obstacle and friction blocks are one
  // The dense reference: Σ w Bᵀ H B, each block's B from its node form (PointRow::node_row is
  // checked against hand-made rows in coupled_matrix_test.cpp).
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(3 * kNodes, 3 * kNodes);
  for (const auto& b : lin.blocks) {
    const Eigen::MatrixXd bm = dense(lin.node_row(b));
    expected += (b.dissipative ? h : h * h) * bm.transpose() * b.hessian * bm;
  }
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd x(3 * kNodes), y = Eigen::VectorXd::Constant(3 * kNodes, 0.5);
    for (Eigen::Index i = 0; i < x.size(); ++i) x(i) = u(rng);
    const Eigen::VectorXd want = Eigen::VectorXd::Constant(3 * kNodes, 0.5) + expected * x;
    sum.add_product(x, y);  // adds to y
    EXPECT_LT((y - want).cwiseAbs().maxCoeff(), 1e-15 * (1.0 + expected.cwiseAbs().maxCoeff())) << trial;
  }
  Eigen::MatrixXd from_blocks = Eigen::MatrixXd::Zero(3 * kNodes, 3 * kNodes);
  for (const auto& [row, hw] : sum.node_blocks()) {
    const Eigen::MatrixXd bm = dense(row);
    from_blocks += bm.transpose() * hw * bm;
  }
  EXPECT_LT((from_blocks - expected).cwiseAbs().maxCoeff(), 1e-14 * expected.cwiseAbs().maxCoeff());
  EXPECT_GT(sum.product_entries(), 0.0);

  // A rebuild with no blocks: empty, and the product adds nothing.
  PotentialLinearisation none;
  none.point_map = &map;
  sum.build(none, h);
  EXPECT_TRUE(sum.empty());
  Eigen::VectorXd y = Eigen::VectorXd::Ones(3 * kNodes);
  sum.add_product(Eigen::VectorXd::Ones(3 * kNodes), y);
  EXPECT_EQ(y, Eigen::VectorXd::Ones(3 * kNodes));

  // Rows on points need the points' map.
  PotentialLinearisation no_map = lin;
  no_map.point_map = nullptr;
  EXPECT_THROW(sum.build(no_map, h), std::invalid_argument);
}

}  // namespace
}  // namespace clothsim

// The coupled matrix (sim/solver/coupled_matrix.hpp) against dense arithmetic: A's values kept,
// each added block equal to Bᵀ H B for rows in node form, per DOF and mixed; covers() true exactly
// when every coupling is in the pattern; a rebuild that keeps the previous couplings; a restore from
// a saved adjacency gives the same pattern.
#include "sim/solver/coupled_matrix.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace clothsim {
namespace {

// A 3·n × 3·n symmetric matrix coupling each node with its neighbours in a chain (full blocks).
Eigen::SparseMatrix<double> chain(int n) {
  std::vector<Eigen::Triplet<double>> t;
  for (int p = 0; p < n; ++p)
    for (int q = std::max(0, p - 1); q <= std::min(n - 1, p + 1); ++q)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) t.emplace_back(3 * p + i, 3 * q + j, p == q && i == j ? 4.0 : 0.1 * (i + 1) + 0.01 * (j + q));
  Eigen::SparseMatrix<double> a(3 * n, 3 * n);
  a.setFromTriplets(t.begin(), t.end());
  Eigen::SparseMatrix<double> sym = 0.5 * (a + Eigen::SparseMatrix<double>(a.transpose()));
  sym.makeCompressed();
  return sym;
}

Eigen::MatrixXd dense_row(const NodeRow& row, int n3) {  // B: 3 × n3
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(3, n3);
  for (const auto& [node, w] : row.nodes) b.middleCols(3 * node, 3) += w * Eigen::Matrix3d::Identity();
  for (const auto& [dof, v] : row.dofs) b.col(dof) += v;
  return b;
}

TEST(CoupledMatrix, HoldsAPlusEachBlockBtHB) {
  const int n = 9;
  const Eigen::SparseMatrix<double> a = chain(n);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  NodeRow node_form;  // couples nodes 0, 4 and 8 (far apart in the chain)
  node_form.nodes = {{4, 0.5}, {0, -0.25}, {8, 0.75}};
  NodeRow per_dof;    // nodes 2 and 6, per DOF
  per_dof.dofs = {{6, Eigen::Vector3d(u(rng), u(rng), u(rng))}, {7, Eigen::Vector3d(u(rng), u(rng), u(rng))},
                  {20, Eigen::Vector3d(u(rng), u(rng), u(rng))}};
  NodeRow mixed = per_dof;  // and node 1 in node form
  mixed.nodes = {{1, 0.3}};
  const std::vector<NodeRow> rows{node_form, per_dof, mixed};
  std::vector<std::vector<int>> groups;
  for (const NodeRow& r : rows) groups.push_back(r.node_list());
  CoupledMatrix m;
  EXPECT_FALSE(m.covers(a, groups));
  m.rebuild(a, groups);
  EXPECT_TRUE(m.covers(a, groups));
  m.set_base(a);
  Eigen::MatrixXd expected = Eigen::MatrixXd(a);
  for (const NodeRow& r : rows) {
    Eigen::Matrix3d h;
    h << 2, 0.3, -0.1, 0.3, 1, 0.2, -0.1, 0.2, 3;
    m.add_block(r, h);
    const Eigen::MatrixXd b = dense_row(r, 3 * n);
    expected += b.transpose() * h * b;
  }
  EXPECT_LE((Eigen::MatrixXd(m.matrix()) - expected).cwiseAbs().maxCoeff(), 1e-14);
  // apply / scatter are B x and Bᵀ f.
  const Eigen::VectorXd x = Eigen::VectorXd::Random(3 * n);
  const Eigen::Vector3d f(0.2, -1.0, 0.4);
  for (const NodeRow& r : rows) {
    const Eigen::MatrixXd b = dense_row(r, 3 * n);
    EXPECT_LE((r.apply(x) - b * x).norm(), 1e-14);
    Eigen::VectorXd y = Eigen::VectorXd::Zero(3 * n);
    r.scatter(f, y);
    EXPECT_LE((y - b.transpose() * f).norm(), 1e-14);
  }
}

TEST(CoupledMatrix, CoversOnlyItsCouplingsAndARebuildCanKeepThem) {
  const int n = 9;
  const Eigen::SparseMatrix<double> a = chain(n);
  CoupledMatrix m;
  m.rebuild(a, {{0, 5}});
  EXPECT_TRUE(m.covers(a, {{0, 5}}));
  EXPECT_TRUE(m.covers(a, {{3, 4}}));      // A's own coupling
  EXPECT_FALSE(m.covers(a, {{0, 6}}));
  EXPECT_FALSE(m.covers(a, {{0, 5, 7}}));  // 5–7 and 0–7 are missing
  m.rebuild(a, {{2, 7}}, /*keep_previous=*/true);
  EXPECT_TRUE(m.covers(a, {{0, 5}, {2, 7}}));
  m.rebuild(a, {{2, 7}});
  EXPECT_FALSE(m.covers(a, {{0, 5}}));
  // A restore from the adjacency gives the same pattern.
  CoupledMatrix copy;
  copy.restore(a, m.adjacency());
  ASSERT_EQ(copy.matrix().nonZeros(), m.matrix().nonZeros());
  for (Eigen::Index k = 0; k < m.matrix().nonZeros(); ++k) ASSERT_EQ(copy.matrix().innerIndexPtr()[k], m.matrix().innerIndexPtr()[k]);
  // A matrix with another pattern is not covered.
  EXPECT_FALSE(m.covers(chain(8), {}));
}

// A row on points against the same row written out over the nodes: p_i = Σ_j w_ij x_j with
// points sharing nodes (as neighbouring surface points share their stencils).
// add_blocks gives add_block's sums, block by block, bit for bit: many overlapping node-form rows
// (sorted, as node_row makes them; one unsorted), and the per-DOF fallback.
TEST(CoupledMatrix, AddBlocksEqualsAddBlockOneByOneBitForBit) {
  const int n = 40;
  const Eigen::SparseMatrix<double> a = chain(n);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> node(0, n - 1);
  std::vector<std::pair<NodeRow, Eigen::Matrix3d>> blocks;
  for (int r = 0; r < 200; ++r) {
    NodeRow row;
    for (int k = 0; k < 12; ++k) row.nodes.emplace_back(node(rng), u(rng));
    std::sort(row.nodes.begin(), row.nodes.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    row.nodes.erase(std::unique(row.nodes.begin(), row.nodes.end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
                    row.nodes.end());
    if (r == 7) std::reverse(row.nodes.begin(), row.nodes.end());  // (add_block sorts a copy)
    Eigen::Matrix3d h = Eigen::Matrix3d::NullaryExpr([&](Eigen::Index, Eigen::Index) { return u(rng); });
    blocks.emplace_back(row, h + h.transpose());
  }
  std::vector<std::vector<int>> groups;
  for (const auto& [row, h] : blocks) groups.push_back(row.node_list());
  for (const bool with_dofs : {false, true}) {
    std::vector<std::pair<NodeRow, Eigen::Matrix3d>> these = blocks;
    if (with_dofs) these[3].first.dofs = {{3 * these[3].first.nodes[0].first + 1, Eigen::Vector3d(u(rng), u(rng), u(rng))}};
    CoupledMatrix one, all;
    one.rebuild(a, groups);
    all.rebuild(a, groups);
    one.set_base(a);
    all.set_base(a);
    for (const auto& [row, h] : these) one.add_block(row, h);
    all.add_blocks(these);
    ASSERT_EQ(one.matrix().nonZeros(), all.matrix().nonZeros());
    for (Eigen::Index k = 0; k < one.matrix().nonZeros(); ++k)
      ASSERT_EQ(one.matrix().valuePtr()[k], all.matrix().valuePtr()[k]) << "entry " << k << (with_dofs ? " (with a per-DOF row)" : "");
    // and not merely equal to each other: A plus the blocks
    const Eigen::MatrixXd dense = Eigen::MatrixXd(all.matrix());
    Eigen::MatrixXd expected = Eigen::MatrixXd(a);
    for (const auto& [row, h] : these) {
      const Eigen::MatrixXd b = dense_row(row, 3 * n);
      expected += b.transpose() * h * b;
    }
    EXPECT_LT((dense - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  }
}

TEST(PointRow, ActsAsItsNodeFormAndMergesSharedNodes) {
  PointMap map;
  const std::vector<std::vector<std::pair<int, double>>> stencils = {
      {{0, 0.5}, {1, 0.25}, {2, 0.25}}, {{1, 0.5}, {2, 0.5}}, {{2, 0.2}, {3, 0.3}, {4, 0.5}}, {{5, 1.0}}, {{4, 0.6}, {6, 0.4}}};
  for (const auto& stencil : stencils) {
    for (const auto& [node, w] : stencil) {
      map.nodes.push_back(node);
      map.weights.push_back(w);
    }
    map.offsets.push_back(static_cast<int>(map.nodes.size()));
  }
  ASSERT_EQ(map.num_points(), 5);
  PointRow row;  // an edge–edge pair: (1 − a) p0 + a p1 − (1 − b) p2 − b p4
  row.count = 4;
  row.points = {0, 1, 2, 4};
  row.coefs = {0.7, 0.3, -0.4, -0.6};
  // Its node form by hand: node 0: 0.35; 1: 0.175 + 0.15; 2: 0.175 + 0.15 − 0.08; 3: −0.12;
  // 4: −0.2 − 0.36; 6: −0.24.
  const std::vector<std::pair<int, double>> expected = {{0, 0.35}, {1, 0.325}, {2, 0.245}, {3, -0.12}, {4, -0.56}, {6, -0.24}};
  const NodeRow nodes = row.node_row(map);
  ASSERT_EQ(nodes.nodes.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(nodes.nodes[k].first, expected[k].first);
    EXPECT_NEAR(nodes.nodes[k].second, expected[k].second, 1e-15);
  }
  EXPECT_TRUE(nodes.dofs.empty());
  EXPECT_EQ(row.entries(map), 3 + 2 + 3 + 2);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd x(21), y0 = Eigen::VectorXd::Zero(21), y1 = Eigen::VectorXd::Zero(21);
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) = u(rng);
  EXPECT_LT((row.apply(map, x) - nodes.apply(x)).norm(), 1e-14);
  const Eigen::Vector3d f(0.3, -1.2, 2.0);
  row.scatter(map, f, y0);
  nodes.scatter(f, y1);
  EXPECT_LT((y0 - y1).norm(), 1e-14);
  EXPECT_EQ(y0.segment<3>(15), Eigen::Vector3d::Zero());  // node 5 is not in the row
  PointRow other = row;
  EXPECT_TRUE(other == row);
  other.coefs[2] = -0.5;
  EXPECT_FALSE(other == row);
}

}  // namespace
}  // namespace clothsim

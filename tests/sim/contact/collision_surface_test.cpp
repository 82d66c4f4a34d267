// The contact stage's collision surface (sim/contact/collision_surface.hpp), built directly on
// the flat ("linear_fe") discretisation of small grids, against independent expectations: the
// refined surface is an affine function of the nodes (an affine motion of the nodes moves its
// points by the same map, and the midpoints of the first refinement sit halfway between their
// nodes); the end points through J are the points of the moved nodes; the rows of J in node form
// carry weights that sum to one per point and give a pair's relative velocity; a DOF list that is
// not of node shape stays per DOF; two triangles' distance by hand; and two sheets stacked 0.5 mm
// and 5 µm apart are near at rest (and the second joined), 5 mm apart neither.
//
// Conventions: grids lie in z = 0 (sim/mesh/generators.hpp); lengths [m], times [s].
#include "tests/support/test_meshes.hpp"
#include "sim/contact/collision_surface.hpp"

#include "sim/flat_fe/flat_fe.hpp"
#include "sim/loop_shell/loop_shell.hpp"
#include "sim/shell/material_presets.hpp"
#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace clothsim::contact {
namespace {

// The cotton preset (the material does not matter here: the surface is the mesh's geometry).
ShellMaterial cloth() { return *material_preset("cotton"); }

Eigen::VectorXd random_vector(Eigen::Index n, unsigned seed, double scale) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x(i) = u(rng);
  return x;
}

TEST(ContactSurface, AnAffineMotionOfTheNodesMovesEveryPointByTheSameMap) {
  const TriMesh grid = make_grid(0.1, 0.08, 4, 3);
  const LinearFeDiscretization d(grid, {}, cloth());
  for (int level : {0, 1, 2}) {
    const CollisionSurface s(d, level);
    ASSERT_EQ(s.triangles().size(), grid.triangles.size() << (2 * level));
    EXPECT_EQ(s.fine_per_patch(), 1 << (2 * level));
    Eigen::Matrix3d a;
    a << 1.1, 0.2, -0.1, 0.05, 0.9, 0.3, -0.2, 0.1, 1.3;
    const Eigen::RowVector3d c(0.01, -0.02, 0.5);
    Eigen::VectorXd x(3 * d.num_nodes());
    for (int i = 0; i < d.num_nodes(); ++i) x.segment<3>(3 * i) = a * d.rest().segment<3>(3 * i) + c.transpose();
    const Eigen::MatrixX3d moved = s.points(x);
    const Eigen::MatrixX3d expected = (s.rest_points() * a.transpose()).rowwise() + c;
    EXPECT_LT((moved - expected).cwiseAbs().maxCoeff(), 1e-14) << "level " << level;
  }
}

TEST(ContactSurface, TheFirstRefinementsNewPointsAreTheMidpointsOfGridEdges) {
  const TriMesh grid = make_grid(0.1, 0.08, 4, 3);
  const LinearFeDiscretization d(grid, {}, cloth());
  const CollisionSurface s(d, 1);
  // Every point is a grid vertex or the midpoint of a grid edge (its nodes' mean, weights ½).
  const Eigen::MatrixX3d& p = s.rest_points();
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    bool found = false;
    for (int v = 0; v < grid.num_vertices() && !found; ++v) found = (p.row(i) - grid.vertices.row(v)).norm() < 1e-15;
    for (const Triangle& t : grid.triangles)
      for (int k = 0; k < 3 && !found; ++k)
        found = (p.row(i) - 0.5 * (grid.vertices.row(t[k]) + grid.vertices.row(t[(k + 1) % 3]))).norm() < 1e-15;
    EXPECT_TRUE(found) << "point " << i;
  }
  // A disc: V − E + F = 1; and each triangle's edge k joins its corners k and k + 1.
  EXPECT_EQ(static_cast<long long>(s.edges().size()), s.num_points() + static_cast<long long>(s.triangles().size()) - 1);
  for (size_t t = 0; t < s.triangles().size(); ++t)
    for (int k = 0; k < 3; ++k) {
      std::array<int, 2> e = s.edges()[static_cast<size_t>(s.triangle_edges()[t][static_cast<size_t>(k)])];
      std::array<int, 2> want = {s.triangles()[t][static_cast<size_t>(k)], s.triangles()[t][static_cast<size_t>((k + 1) % 3)]};
      std::sort(e.begin(), e.end());
      std::sort(want.begin(), want.end());
      EXPECT_EQ(e, want);
    }
}

TEST(ContactSurface, EndPointsThroughTheJacobianAreThePointsOfTheMovedNodes) {
  const TriMesh grid = make_grid(0.1, 0.08, 4, 3);
  const LinearFeDiscretization d(grid, {}, cloth());
  CollisionSurface s(d, 2);
  const Eigen::VectorXd x = d.rest() + random_vector(3 * d.num_nodes(), 3, 0.01);
  const Eigen::VectorXd v = random_vector(3 * d.num_nodes(), 4, 0.5);
  const double h = 0.01;
  const Eigen::MatrixX3d p0 = s.points(x), expected = s.points(x + h * v);
  EXPECT_FALSE(s.point_rows_in_node_form());
  EXPECT_LT((s.end_points(p0, h, v) - expected).cwiseAbs().maxCoeff(), 1e-15);  // through J
  s.make_point_rows();
  ASSERT_TRUE(s.point_rows_in_node_form());  // all nodes free: J = S ⊗ I₃
  EXPECT_LT((s.end_points(p0, h, v) - expected).cwiseAbs().maxCoeff(), 1e-15);  // through the rows
}

// The surface is linear in the nodes, ghost layer and tied borders included: the rest points
// moved by J (x − x_rest) are the points at x, on a Loop plate with hinged and free borders (its
// ghost layer) and a large deformation.
TEST(ContactSurface, PointsThroughTheRowsAreThePointsOfTheNodes) {
  const TriMesh grid = make_grid(0.1, 0.08, 6, 5);
  std::vector<BoundaryCondition> bc(2);
  for (int v = 0; v < grid.num_vertices(); ++v) {
    if (grid.vertices(v, 0) < 1e-9) bc[0].vertices.push_back(v);
    if (grid.vertices(v, 1) < 1e-9) bc[1].vertices.push_back(v);
  }
  // (both hinged, all components held; clamped and symmetric borders tie components of a ghost
  // node to others unevenly, and their rows are not of node form: the stage keeps points() there)
  const LoopShellDiscretization d(grid, bc, cloth(), Quadrature::one_point);
  CollisionSurface s(d, 2);
  s.make_point_rows();
  ASSERT_TRUE(s.point_rows_in_node_form());
  Eigen::VectorXd u = random_vector(3 * d.num_nodes(), 5, 0.02);
  d.make_consistent(u);  // (tied components follow their rule, as in every state the stage sees)
  const Eigen::VectorXd x = d.rest() + u;
  const Eigen::MatrixX3d expected = s.points(x), through = s.points_through_rows(x);
  ASSERT_EQ(through.rows(), expected.rows());
  EXPECT_LT((through - expected).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_GT((expected - s.rest_points()).cwiseAbs().maxCoeff(), 1e-3);  // (and it did move)
}

TEST(ContactSurface, PointRowsArePartitionsOfUnityAndPairRowsGiveRelativeVelocities) {
  const TriMesh grid = make_grid(0.1, 0.08, 4, 3);
  const LinearFeDiscretization d(grid, {}, cloth());
  CollisionSurface s(d, 1);
  s.make_point_rows();
  for (Eigen::Index p = 0; p < s.num_points(); ++p) {
    const NodeRow row = s.point_row(static_cast<int>(p));
    EXPECT_TRUE(row.dofs.empty());
    double sum = 0.0;
    for (const auto& [node, w] : row.nodes) sum += w;
    EXPECT_NEAR(sum, 1.0, 1e-15) << "point " << p;
    EXPECT_LE(row.nodes.size(), 2u);  // a vertex, or the midpoint of an edge
  }
  // A pair of point 0 with triangle 5's corners: relative velocity = v₀ − Σ w_k v_k.
  const Triangle& t = s.triangles()[5];
  PairGeometry g;
  g.num = 4;
  g.point = {0, t[0], t[1], t[2]};
  g.coef = {1.0, -0.2, -0.3, -0.5};
  const Eigen::VectorXd v = random_vector(3 * d.num_nodes(), 7, 1.0);
  const Eigen::MatrixX3d zero = Eigen::MatrixX3d::Zero(s.num_points(), 3);
  const Eigen::MatrixX3d pv = s.end_points(zero, 1.0, v);  // the points' velocities
  Eigen::Vector3d expected = pv.row(0).transpose();
  for (int k = 1; k < 4; ++k) expected += g.coef[static_cast<size_t>(k)] * pv.row(g.point[static_cast<size_t>(k)]).transpose();
  const NodeRow row = s.pair_row(g);
  EXPECT_LT((row.apply(v) - expected).cwiseAbs().maxCoeff(), 1e-14);
  // The same relative velocity per DOF (the rows of J merged, before the node form).
  Eigen::Vector3d per_dof = Eigen::Vector3d::Zero();
  for (const auto& [dof, b] : s.rows(g)) per_dof += b * v(dof);
  EXPECT_LT((per_dof - expected).cwiseAbs().maxCoeff(), 1e-14);
  // An obstacle point adds nothing to the rows.
  g.obstacle = {false, true, true, true};
  const NodeRow alone = s.pair_row(g);
  EXPECT_LT((alone.apply(v) - pv.row(0).transpose()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ContactSurface, OnlyRowsOfNodeShapeTakeTheNodeForm) {
  const TriMesh grid = make_grid(0.1, 0.08, 2, 2);
  const LinearFeDiscretization d(grid, {}, cloth());
  CollisionSurface s(d, 0);
  CollisionSurface::DofRow b = {{3, Eigen::Vector3d(0.5, 0, 0)}, {4, Eigen::Vector3d(0, 0.5, 0)}, {5, Eigen::Vector3d(0, 0, 0.5)},
                                {6, Eigen::Vector3d(-1, 0, 0)},  {7, Eigen::Vector3d(0, -1, 0)},  {8, Eigen::Vector3d(0, 0, -1)}};
  std::vector<std::pair<int, double>> nodes;
  s.to_node_form(b, nodes);
  EXPECT_TRUE(b.empty());
  EXPECT_EQ(nodes, (std::vector<std::pair<int, double>>{{1, 0.5}, {2, -1.0}}));
  // Node 1's z DOF missing (prescribed): stays per DOF.
  CollisionSurface::DofRow partial = {{3, Eigen::Vector3d(0.5, 0, 0)}, {4, Eigen::Vector3d(0, 0.5, 0)}, {6, Eigen::Vector3d(-1, 0, 0)}};
  s.to_node_form(partial, nodes);
  EXPECT_EQ(partial.size(), 3u);
  EXPECT_TRUE(nodes.empty());
  // A coupling between components (a rotated row): per DOF too.
  CollisionSurface::DofRow turned = {{0, Eigen::Vector3d(1, 1, 0)}, {1, Eigen::Vector3d(0, 1, 0)}, {2, Eigen::Vector3d(0, 0, 1)}};
  s.to_node_form(turned, nodes);
  EXPECT_EQ(turned.size(), 3u);
  EXPECT_TRUE(nodes.empty());
}

TEST(ContactSurface, TriangleDistanceByHand) {
  Eigen::MatrixX3d p(6, 3);
  p << 0, 0, 0, 1, 0, 0, 0, 1, 0,  // a: in z = 0
      0.2, 0.2, 0.3, 1.2, 0.2, 0.3, 0.2, 1.2, 0.3;  // b: a's copy shifted, 0.3 above
  EXPECT_NEAR(triangle_distance(p, {0, 1, 2}, {3, 4, 5}), 0.3, 1e-15);
  // In one plane, b = a + (1.5, 1.5, 0): b's corner (1.5, 1.5) is (1.5 + 1.5 − 1) / √2 = √2 from
  // a's hypotenuse x + y = 1, and that is the closest approach.
  p << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1.5, 1.5, 0, 2.5, 1.5, 0, 1.5, 2.5, 0;
  EXPECT_NEAR(triangle_distance(p, {0, 1, 2}, {3, 4, 5}), std::sqrt(2.0), 1e-15);
}

TEST(ContactSurface, StackedSheetsAreNearAtRestAndJoinedWhenTouching) {
  const double thickness = 1e-3, near = 2.0 * thickness, joined = 0.01 * thickness;
  for (double gap : {0.5e-3, 5e-6, 5e-3}) {
    TriMesh top = make_grid(0.02, 0.02, 2, 2);
    top.vertices.col(2).array() += gap;
    const TriMesh both = testing::concatenated(make_grid(0.02, 0.02, 2, 2), top);
    const LinearFeDiscretization d(both, {}, cloth());
    const CollisionSurface s(d, 1);
    std::vector<std::vector<int>> near_at_rest, joined_at_rest;
    const long long count = s.find_near_at_rest(near, joined, d.control_triangles(), near_at_rest, joined_at_rest);
    // Reference: every pair of fine triangles by its exact distance; the sheets' fine triangles
    // are the first and second halves, and no two of different sheets share a control vertex.
    const size_t n = s.triangles().size();
    long long across_near = 0, across_joined = 0;
    for (size_t a = 0; a < n; ++a) {
      ASSERT_TRUE(std::is_sorted(near_at_rest[a].begin(), near_at_rest[a].end()));
      for (size_t b = a + 1; b < n; ++b) {
        const bool listed = std::binary_search(near_at_rest[a].begin(), near_at_rest[a].end(), static_cast<int>(b));
        const double dist = triangle_distance(s.rest_points(), s.triangles()[a], s.triangles()[b]);
        EXPECT_EQ(listed, dist < near) << a << " " << b;
        const bool across = (a < n / 2) != (b < n / 2);
        const bool is_joined = std::binary_search(joined_at_rest[a].begin(), joined_at_rest[a].end(), static_cast<int>(b));
        EXPECT_EQ(is_joined, across && dist < joined) << a << " " << b;
        across_near += across && listed;
        across_joined += is_joined;
      }
    }
    EXPECT_EQ(count, across_joined);
    if (gap == 5e-3) {
      EXPECT_EQ(across_near, 0);
    } else {
      EXPECT_GE(across_near, static_cast<long long>(n / 2));  // each triangle at least over its twin
    }
    EXPECT_EQ(across_joined > 0, gap == 5e-6) << "gap " << gap;
  }
}

}  // namespace
}  // namespace clothsim::contact

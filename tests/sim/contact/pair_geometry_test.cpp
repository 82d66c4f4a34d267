// The geometry of candidate pairs (sim/contact/pair_geometry.hpp), built directly on a few
// triangles and edges, against hand-computed values: each kind's corners and cloth points in
// their documented order; a point over a triangle's interior and two crossing edges give the
// distance, normal and coefficients worked out on paper; a pair's distance change bound under
// given point moves; the box gap; a pair that passed through gets a negative distance while one
// that turned round an edge does not; and a translating and a turning obstacle's step maps.
//
// Lengths [m], times [s].
#include "sim/contact/pair_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace clothsim::contact {
namespace {


Eigen::Vector3d v3(double x, double y, double z) { return {x, y, z}; }

// Cloth: points 0 … 5, triangles {0, 1, 2} and {3, 4, 5}, edges {0, 1} and {3, 4}. Obstacle: one
// triangle {0, 1, 2} of three vertices (its edges from build_edges), one obstacle.
struct Scene {
  std::vector<Triangle> triangles{{0, 1, 2}, {3, 4, 5}};
  std::vector<std::array<int, 2>> edges{{0, 1}, {3, 4}};
  ObstacleSet obs;
  Eigen::MatrixX3d p = Eigen::MatrixX3d(6, 3), o = Eigen::MatrixX3d(3, 3);
  Scene() {
    obs.triangles = {{0, 1, 2}};
    build_edges(obs.triangles, obs.edges, obs.triangle_edges);
    obs.obstacle_of_vertex = {0, 0, 0};
    obs.edge_flat.assign(obs.edges.size(), 0);
    obs.vertex_flat.assign(3, 0);
    obs.owned_points = {{0, 1, 2}};
    obs.owned_edges = {{0, 1, 2}};
    // Triangle 0 in z = 0, triangle 1 half a unit above it; obstacle below at z = −1.
    p << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.2, 0.5, 1.2, 0.2, 0.5, 0.2, 1.2, 0.5;
    o << 0, 0, -1, 2, 0, -1, 0, 2, -1;
  }
};

TEST(PairGeometry, CornersAndClothPointsFollowEachKindsOrder) {
  Scene s;
  const PairPrimitives pairs(s.triangles, s.edges, s.obs);
  auto row = [&](const Eigen::MatrixX3d& m, int i) -> Eigen::Vector3d { return m.row(i).transpose(); };
  const Corners pt = pairs.corners({Kind::cloth_point_cloth_triangle, 3, 0}, s.p, s.o);
  EXPECT_EQ(pt[0], row(s.p, 3));
  EXPECT_EQ(pt[3], row(s.p, 2));
  const Corners ee = pairs.corners({Kind::cloth_edge_cloth_edge, 0, 1}, s.p, s.o);
  EXPECT_EQ(ee[1], row(s.p, 1));
  EXPECT_EQ(ee[2], row(s.p, 3));
  const Corners po = pairs.corners({Kind::cloth_point_obstacle_triangle, 4, 0}, s.p, s.o);
  EXPECT_EQ(po[0], row(s.p, 4));
  EXPECT_EQ(po[2], row(s.o, 1));
  const Corners op = pairs.corners({Kind::obstacle_point_cloth_triangle, 2, 1}, s.p, s.o);
  EXPECT_EQ(op[0], row(s.o, 2));
  EXPECT_EQ(op[1], row(s.p, 3));
  EXPECT_EQ(pairs.cloth_points({Kind::cloth_point_cloth_triangle, 3, 0}), (std::array<int, 4>{3, 0, 1, 2}));
  EXPECT_EQ(pairs.cloth_points({Kind::obstacle_point_cloth_triangle, 2, 1}), (std::array<int, 4>{3, 4, 5, -1}));
  EXPECT_EQ(pairs.cloth_points({Kind::cloth_point_obstacle_triangle, 4, 0}), (std::array<int, 4>{4, -1, -1, -1}));
  EXPECT_EQ(pairs.cloth_points({Kind::cloth_edge_cloth_edge, 0, 1}), (std::array<int, 4>{0, 1, 3, 4}));
  EXPECT_TRUE(is_point_triangle(Kind::obstacle_point_cloth_triangle));
  EXPECT_FALSE(is_point_triangle(Kind::cloth_edge_obstacle_edge));
}

TEST(PairGeometry, PointOverATrianglesInteriorByHand) {
  Scene s;
  const PairPrimitives pairs(s.triangles, s.edges, s.obs);
  // Point 3 at (0.2, 0.2, 0.5) over triangle 0: closest point (0.2, 0.2, 0), barycentric
  // (0.6, 0.2, 0.2), distance 0.5, normal from the triangle to the point +z.
  const Candidate c{Kind::cloth_point_cloth_triangle, 3, 0};
  const PairGeometry g = pairs.geometry(c, pairs.corners(c, s.p, s.o));
  EXPECT_NEAR(g.distance, 0.5, 1e-15);
  EXPECT_LT((g.normal - v3(0, 0, 1)).norm(), 1e-15);
  EXPECT_NEAR(g.coef[0], 1.0, 0);
  EXPECT_NEAR(g.coef[1], -0.6, 1e-15);
  EXPECT_NEAR(g.coef[2], -0.2, 1e-15);
  EXPECT_NEAR(g.coef[3], -0.2, 1e-15);
  EXPECT_EQ(g.point, (std::array<int, 4>{3, 0, 1, 2}));
  EXPECT_EQ(pairs.obstacle_of(g), -1);
  // The cloth point 1 at (1, 0, 0) against the obstacle triangle 1 below: distance 1, normal +z,
  // and the pair belongs to obstacle 0.
  const Candidate co{Kind::cloth_point_obstacle_triangle, 1, 0};
  const PairGeometry go = pairs.geometry(co, pairs.corners(co, s.p, s.o));
  EXPECT_NEAR(go.distance, 1.0, 1e-15);
  EXPECT_LT((go.normal - v3(0, 0, 1)).norm(), 1e-15);
  EXPECT_EQ(go.obstacle, (std::array<bool, 4>{false, true, true, true}));
  EXPECT_EQ(pairs.obstacle_of(go), 0);
}

TEST(PairGeometry, CrossingEdgesByHand) {
  Scene s;
  // Edge 0 from (0, 0, 0) to (1, 0, 0); edge 1 moved to cross over it at x = 0.25, 2 above, from
  // y = −1 to y = 1: closest points at s = 0.25 and t = 0.5, distance 2, normal from edge 1 to
  // edge 0 along −z.
  s.p.row(3) << 0.25, -1, 2;
  s.p.row(4) << 0.25, 1, 2;
  const PairPrimitives pairs(s.triangles, s.edges, s.obs);
  const Candidate c{Kind::cloth_edge_cloth_edge, 0, 1};
  const PairGeometry g = pairs.geometry(c, pairs.corners(c, s.p, s.o));
  EXPECT_NEAR(g.distance, 2.0, 1e-15);
  EXPECT_LT((g.normal - v3(0, 0, -1)).norm(), 1e-15);
  EXPECT_NEAR(g.coef[0], 0.75, 1e-15);
  EXPECT_NEAR(g.coef[1], 0.25, 1e-15);
  EXPECT_NEAR(g.coef[2], -0.5, 1e-15);
  EXPECT_NEAR(g.coef[3], -0.5, 1e-15);
}

TEST(PairGeometry, DistanceChangeBoundUnderPointMoves) {
  Scene s;
  const PairPrimitives pairs(s.triangles, s.edges, s.obs);
  Eigen::VectorXd move(6);
  move << 0.1, 0.4, 0.2, 0.3, 0.05, 0.6;
  // Point 3 with triangle 0: 0.3 + max(0.1, 0.4, 0.2).
  EXPECT_DOUBLE_EQ(pairs.motion({Kind::cloth_point_cloth_triangle, 3, 0}, move, 9.0), 0.7);
  // Edge {0, 1} with edge {3, 4}: max(0.1, 0.4) + max(0.3, 0.05).
  EXPECT_DOUBLE_EQ(pairs.motion({Kind::cloth_edge_cloth_edge, 0, 1}, move, 9.0), 0.7);
  // Obstacle vertex with triangle 1: max(0.3, 0.05, 0.6) + the obstacle's 0.25.
  EXPECT_DOUBLE_EQ(pairs.motion({Kind::obstacle_point_cloth_triangle, 0, 1}, move, 0.25), 0.85);
}

TEST(PairGeometry, BoxGapIsTheLargestSeparationAlongAnAxis) {
  // A point 0.5 above the triangle's box and 0.2 beyond it along x: the gap is 0.5.
  const Corners pt{v3(1.2, 0.5, 0.5), v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0)};
  EXPECT_DOUBLE_EQ(box_gap(pt, true), 0.5);
  // Two edges whose boxes overlap: 0.
  const Corners ee{v3(0, 0, 0), v3(1, 1, 0), v3(0, 1, 0), v3(1, 0, 0)};
  EXPECT_EQ(box_gap(ee, false), 0.0);
  // Two parallel edges 0.3 apart along y (read as edges: the second pair of corners).
  const Corners apart{v3(0, 0, 0), v3(1, 0, 0), v3(0, 0.3, 0), v3(1, 0.3, 0)};
  EXPECT_DOUBLE_EQ(box_gap(apart, false), 0.3);
}

TEST(PairGeometry, APairThatPassedThroughIsSignedByItsStartSide) {
  Scene s;
  const PairPrimitives pairs(s.triangles, s.edges, s.obs);
  const Candidate c{Kind::cloth_point_cloth_triangle, 3, 0};
  const PairGeometry start = pairs.geometry(c, pairs.corners(c, s.p, s.o));  // 0.5 above
  // The point ends 0.1 below the triangle's interior: it went through.
  Eigen::MatrixX3d below = s.p;
  below(3, 2) = -0.1;
  PairGeometry end = pairs.geometry(c, pairs.corners(c, below, s.o));
  EXPECT_NEAR(end.distance, 0.1, 1e-15);
  sign_by_start(start, end, true);
  EXPECT_NEAR(end.distance, -0.1, 1e-15);
  EXPECT_LT((end.normal - start.normal).norm(), 1e-15);
  // Ending below the plane but beyond the hypotenuse (closest point on the edge): it may have
  // turned round the edge, so the distance stays unsigned.
  Eigen::MatrixX3d round = s.p;
  round.row(3) << 0.8, 0.8, -0.1;
  PairGeometry around = pairs.geometry(c, pairs.corners(c, round, s.o));
  const double unsigned_distance = around.distance;
  sign_by_start(start, around, true);
  EXPECT_EQ(around.distance, unsigned_distance);
  EXPECT_GT(around.distance, 0.0);
}

TEST(PairGeometry, StepMapOfATranslatingAndATurningObstacle) {
  Obstacle o;
  o.shape = Obstacle::Shape::sphere;
  Motion slide;
  slide.type = Motion::Type::translate;
  slide.displacement = v3(1.0, 0, 0);
  slide.start = 0.0;
  slide.end = 1.0;
  o.motion = {slide};
  // Over [0.2, 0.3] it moves 0.1 along x.
  const RigidMap m = obstacle_step_map(o, 0.2, 0.1);
  EXPECT_LT((m.r - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_LT((m.c - v3(0.1, 0, 0)).norm(), 1e-14);
  // A quarter turn about z through (1, 0, 0) over [0, 1]: over [0, 1] the map takes (2, 0, 0) to
  // (1, 1, 0) and (1, 0, 5) to itself.
  Motion turn;
  turn.type = Motion::Type::rotate;
  turn.axis = v3(0, 0, 1);
  turn.center = v3(1, 0, 0);
  turn.angle_deg = 90.0;
  turn.start = 0.0;
  turn.end = 1.0;
  o.motion = {turn};
  const RigidMap q = obstacle_step_map(o, 0.0, 1.0);
  EXPECT_LT((q(v3(2, 0, 0)) - v3(1, 1, 0)).norm(), 1e-12);
  EXPECT_LT((q(v3(1, 0, 5)) - v3(1, 0, 5)).norm(), 1e-12);
  // At rest: the identity.
  o.motion.clear();
  const RigidMap still = obstacle_step_map(o, 0.3, 0.01);
  EXPECT_LT((still.r - Eigen::Matrix3d::Identity()).norm() + still.c.norm(), 1e-15);
}

}  // namespace
}  // namespace clothsim::contact

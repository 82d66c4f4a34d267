// The geometry of the contact stage's candidate pairs (sim/contact/pair_types.hpp): a pair's four
// corners at given positions of the collision surface's points and the obstacles' vertices, its
// closest points, normal and distance there, which cloth points it has, how far its distance can
// change when its points move, and the quick bounds and sign rules the stage uses on them. Also
// the rigid map that moves an obstacle over a step.
//
// The primitives (the surface's fine triangles and edges, the obstacles' combined mesh) are fixed
// for a run and referenced; the positions are arguments.
#pragma once

#include "sim/contact/impact_zones.hpp"
#include "sim/contact/obstacle.hpp"
#include "sim/contact/obstacle_set.hpp"
#include "sim/contact/pair_types.hpp"
#include "sim/mesh/mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace clothsim::contact {

using Corners = std::array<Eigen::Vector3d, 4>;

// Whether a pair of this kind is a point with a triangle (else two edges).
inline bool is_point_triangle(Kind k) { return k != Kind::cloth_edge_cloth_edge && k != Kind::cloth_edge_obstacle_edge; }

// The largest gap along an axis between the boxes of a pair's two primitives (the point x[0] and
// the triangle x[1..3], or the edges x[0..1] and x[2..3]); 0 when they overlap: a lower bound of
// their distance [m].
double box_gap(const Corners& x, bool point_triangle);

// Signs a pair's distance at the end of a move by the side it started on: when the closest points
// are inside both primitives (a point over a triangle's interior, two edges at interior points) at
// the start and at the end and the normal turned against the start's, the pair has passed
// through: `end` gets a negative distance and the start side's normal. (Where a closest point is
// on a primitive's boundary the normal can turn round an edge without a crossing; there the
// distance stays unsigned.)
void sign_by_start(const PairGeometry& start, PairGeometry& end, bool point_triangle);

// The rigid map that takes obstacle o from its place at time t to its place at t + h [s].
RigidMap obstacle_step_map(const Obstacle& o, double t, double h);

class PairPrimitives {
 public:
  // The collision surface's fine triangles and edges, and the obstacles (referenced: they must
  // outlive this).
  PairPrimitives(const std::vector<Triangle>& cloth_triangles, const std::vector<std::array<int, 2>>& cloth_edges,
                 const ObstacleSet& obstacles)
      : triangles_(cloth_triangles), edges_(cloth_edges), obs_(obstacles) {}

  // The pair's four points for surface points p and obstacle vertices o (rows) [m]: the point
  // then the triangle's corners, or the first edge's ends then the second's (o is only read for
  // pairs with an obstacle).
  Corners corners(const Candidate& c, const Eigen::MatrixX3d& p, const Eigen::MatrixX3d& o) const;
  // The pair's points, coefficients, normal and distance for its four corners x.
  PairGeometry geometry(const Candidate& c, const Corners& x) const;
  // The cloth points of a pair (up to four, in corner order but for obstacle point–cloth
  // triangle, whose three cloth points come first; −1 for none).
  std::array<int, 4> cloth_points(const Candidate& c) const;
  // The obstacle of the pair's first obstacle point, or −1.
  int obstacle_of(const PairGeometry& g) const;
  // A point–obstacle-triangle pair that adds nothing (ObstacleSet::redundant_on_flat_face).
  bool redundant_on_flat_face(const Candidate& c, const PairGeometry& g, const Corners& x) const;
  // How much a pair's distance can change when each of its cloth points p moves by at most
  // move(p) and each obstacle vertex by at most `obstacle` [m] (the distance between two
  // primitives changes by at most the largest move of a point of each).
  double motion(const Candidate& c, const Eigen::VectorXd& move, double obstacle) const;

 private:
  const std::vector<Triangle>& triangles_;
  const std::vector<std::array<int, 2>>& edges_;
  const ObstacleSet& obs_;
};

}  // namespace clothsim::contact

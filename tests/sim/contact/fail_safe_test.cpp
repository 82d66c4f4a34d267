// The contact stage's response after the solve (sim/contact/fail_safe.hpp), built directly,
// against hand-computed expectations: the implicit response stops one node's approach to a
// plane with the impulse m Δv, bounds its slide by Coulomb's μ λ, and meets a separating target;
// kept multipliers start the next step's constraint of the same key only; the impact zones merge
// the nodes of pairs that share a node, move a free zone with its momentum (a rigid spin stays a
// spin, a head-on pair stops), a zone on an obstacle with the obstacle and one with a prescribed
// node with that node; and through ContactStage::filter two triangles meeting head-on within a
// step end it apart, not crossed, with the collision reported and momentum kept.
//
// Lengths [m], times [s], masses [kg].
#include "sim/contact/fail_safe.hpp"

#include "sim/contact/collision_surface.hpp"
#include "sim/flat_fe/flat_fe.hpp"
#include "sim/shell/material_presets.hpp"
#include "sim/mesh/mesh.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace clothsim::contact {
namespace {

// The cotton preset (the material does not matter here: the surface is the mesh's geometry).
ShellMaterial cloth() { return *material_preset("cotton"); }

// One triangle of 1 cm in z = 0 (three nodes) and, with `second`, a copy 3 mm above it.
TriMesh triangles(bool second) {
  TriMesh m;
  m.vertices.resize(second ? 6 : 3, 3);
  m.vertices.row(0) << 0, 0, 0;
  m.vertices.row(1) << 0.01, 0, 0;
  m.vertices.row(2) << 0, 0.01, 0;
  m.triangles = {{0, 1, 2}};
  if (second) {
    m.vertices.row(3) << 0.001, 0.001, 0.003;
    m.vertices.row(4) << 0.011, 0.001, 0.003;
    m.vertices.row(5) << 0.001, 0.011, 0.003;
    m.triangles.push_back({3, 4, 5});
  }
  return m;
}

// A system A = m I (lumped masses, no stiffness) with its exact inverse.
struct MassSystem {
  Eigen::SparseMatrix<double> a;
  double m;
  MassSystem(int dofs, double mass) : m(mass) {
    a.resize(dofs, dofs);
    a.setIdentity();
    a *= mass;
  }
  ResponseSystem system() const {
    return ResponseSystem{a, [mass = m](const Eigen::VectorXd& r, Eigen::VectorXd& z) { z = r / mass; }};
  }
};

// A constraint on node `node`'s velocity (its three DOFs) along +z against a still plane.
Found on_node(int node, double target, double mu) {
  Found f;
  for (int c = 0; c < 3; ++c) f.constraint.b.emplace_back(3 * node + c, Eigen::Vector3d::Unit(c));
  f.constraint.normal = Eigen::Vector3d::UnitZ();
  f.constraint.target = target;
  f.constraint.mu = mu;
  f.key = {0, 255, 0, node};
  return f;
}

TEST(ContactFailSafe, ResponseStopsAnApproachWithTheImpulseMassTimesVelocity) {
  const LinearFeDiscretization d(triangles(false), {}, cloth());
  CollisionSurface surface(d, 0);
  const MassSystem a(9, 2.0);
  const std::vector<char> free(9, 1);
  const Eigen::VectorXd diagonal = Eigen::VectorXd::Constant(9, 2.0);
  ContactParameters params;
  ImplicitResponse response(params);
  Eigen::VectorXd base = Eigen::VectorXd::Zero(9);
  base.segment<3>(0) << 2.0, 0.0, -1.0;  // node 0 slides along x and approaches the plane
  base.segment<3>(3) << 0.3, 0.0, -0.5;  // node 1 too, but not constrained
  const double tolerance = 1e-6;

  // No friction: v_z → 0, λ = m Δv_z = 2, the rest unchanged.
  std::vector<Found> found{on_node(0, 0.0, 0.0)};
  Eigen::VectorXd v = base;
  ContactReport report;
  response.solve(found, base, v, a.system(), diagonal, free, tolerance, surface, report);
  EXPECT_NEAR(v(2), 0.0, 10 * tolerance);
  EXPECT_NEAR(v(0), 2.0, 10 * tolerance);
  EXPECT_NEAR(found[0].constraint.lambda, 2.0, 1e-4);
  EXPECT_EQ((v.tail(6) - base.tail(6)).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(report.impulses, 1);
  EXPECT_GT(report.response_iterations, 0);

  // Friction μ = 0.5: the slide (2 m/s, far above what the impulse can stop) loses μ λ / m =
  // 0.5 m/s.
  found = {on_node(0, 0.0, 0.5)};
  v = base;
  response.solve(found, base, v, a.system(), diagonal, free, tolerance, surface, report);
  EXPECT_NEAR(v(2), 0.0, 10 * tolerance);
  // (The disc's radius follows λ for the first `friction_updates` updates only: the bound is μ λ
  // to the accuracy λ had then, here 0.1 %.)
  EXPECT_NEAR(v(0), 1.5, 1e-3);
  EXPECT_NEAR(v(1), 0.0, 10 * tolerance);
  EXPECT_NEAR(found[0].constraint.friction.norm(), 1.0, 2e-3);

  // A separating target of 0.25 m/s: v_z = 0.25, λ = 2 × 1.25.
  found = {on_node(0, 0.25, 0.0)};
  v = base;
  response.solve(found, base, v, a.system(), diagonal, free, tolerance, surface, report);
  EXPECT_NEAR(v(2), 0.25, 10 * tolerance);
  EXPECT_NEAR(found[0].constraint.lambda, 2.5, 1e-4);

  // Already separating faster than the target: no impulse, v unchanged.
  base(2) = 1.0;
  found = {on_node(0, 0.0, 0.0)};
  v = base;
  ContactReport quiet;
  response.solve(found, base, v, a.system(), diagonal, free, tolerance, surface, quiet);
  EXPECT_EQ(found[0].constraint.lambda, 0.0);
  EXPECT_EQ(quiet.impulses, 0);
  EXPECT_LT((v - base).cwiseAbs().maxCoeff(), 10 * tolerance);
}

TEST(ContactFailSafe, KeptMultipliersStartOnlyTheSameKey) {
  KeptMultipliers kept;
  std::vector<Found> last{on_node(0, 0, 0), on_node(1, 0, 0), on_node(2, 0, 0)};
  last[0].constraint.lambda = 3.0;
  last[0].constraint.friction = Eigen::Vector3d(0.1, 0, 0);
  last[2].constraint.lambda = 0.0;  // no impulse: not kept
  kept.keep(last);
  std::vector<Found> now{on_node(2, 0, 0), on_node(0, 0, 0), on_node(1, 0, 0)};
  now[2].key.source = 1;  // the same pair found by CCD is another constraint
  kept.warm_start(now);
  EXPECT_EQ(now[1].constraint.lambda, 3.0);
  EXPECT_EQ(now[1].constraint.friction, Eigen::Vector3d(0.1, 0, 0));
  EXPECT_EQ(now[0].constraint.lambda, 0.0);
  EXPECT_EQ(now[2].constraint.lambda, 0.0);
}

TEST(ContactFailSafe, PairsSharingANodeMergeIntoOneZone) {
  Zones zones(6);
  std::vector<int> zone_obstacle(6, -2);
  Found a, b, c;
  for (int dof : {0, 1, 2, 3, 4, 5}) a.constraint.b.emplace_back(dof, Eigen::Vector3d::Zero());     // nodes 0, 1
  for (int dof : {3, 4, 5, 6, 7, 8}) b.constraint.b.emplace_back(dof, Eigen::Vector3d::Zero());     // nodes 1, 2
  for (int dof : {15, 16, 17}) c.constraint.b.emplace_back(dof, Eigen::Vector3d::Zero());           // node 5
  c.constraint.obstacle = 3;
  merge_zones({a, b, c}, zones, zone_obstacle);
  EXPECT_EQ(zones.find(0), zones.find(2));
  EXPECT_NE(zones.find(0), zones.find(5));
  EXPECT_NE(zones.find(3), zones.find(0));
  EXPECT_EQ(zone_obstacle, (std::vector<int>{-1, -1, -1, -2, -2, 3}));
}

TEST(ContactFailSafe, AFreeZoneMovesWithItsMomentum) {
  // Two nodes of mass 1 at (0, 0, 0) and (1, 0, 0).
  Eigen::VectorXd x(6), mass(2);
  x << 0, 0, 0, 1, 0, 0;
  mass << 1.0, 1.0;
  const std::vector<char> free(6, 1);
  std::vector<int> zone_obstacle{-1, -1};
  Zones zones(2);
  zones.unite(0, 1);
  ContactReport report;
  // Head-on: no momentum, no angular momentum: both stop.
  Eigen::VectorXd v(6);
  v << 1, 0, 0, -1, 0, 0;
  move_impact_zones(zones, zone_obstacle, x, 0.0, 0.01, free, mass, {}, v, report);
  EXPECT_LT(v.cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(report.impact_zones, 1);
  // A spin about z through the centre (and a drift along z): a rigid motion, kept.
  v << 0, 1, 0.5, 0, -1, 0.5;
  const Eigen::VectorXd spin = v;
  move_impact_zones(zones, zone_obstacle, x, 0.0, 0.01, free, mass, {}, v, report);
  EXPECT_LT((v - spin).cwiseAbs().maxCoeff(), 1e-12);
  // Uneven: momentum (2, 0, 0) + (0, 0, 0) over mass 2 → 1 m/s each; no angular momentum.
  v << 2, 0, 0, 0, 0, 0;
  move_impact_zones(zones, zone_obstacle, x, 0.0, 0.01, free, mass, {}, v, report);
  EXPECT_LT((v - (Eigen::VectorXd(6) << 1, 0, 0, 1, 0, 0).finished()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(ContactFailSafe, ZonesOnAnObstacleOrAPrescribedNodeFollowIt) {
  Eigen::VectorXd x(6), mass(2);
  x << 0, 0, 0, 1, 0, 0;
  mass << 1.0, 1.0;
  Zones zones(2);
  zones.unite(0, 1);
  ContactReport report;
  const double h = 0.1;
  // On an obstacle sliding 1 m along y over [0, 1]: 1 m/s along y for both.
  Obstacle o;
  o.shape = Obstacle::Shape::sphere;
  Motion slide;
  slide.type = Motion::Type::translate;
  slide.displacement = Eigen::Vector3d(0, 1, 0);
  slide.end = 1.0;
  o.motion = {slide};
  std::vector<int> on_obstacle{0, -1};
  Eigen::VectorXd v(6);
  v << 5, 0, 0, -5, 0, 3;
  move_impact_zones(zones, on_obstacle, x, 0.2, h, std::vector<char>(6, 1), mass, {o}, v, report);
  EXPECT_LT((v - (Eigen::VectorXd(6) << 0, 1, 0, 0, 1, 0).finished()).cwiseAbs().maxCoeff(), 1e-12);
  // Node 0 prescribed (moving at 2 m/s along z): node 1 follows its translation; node 0's
  // velocity is not touched.
  std::vector<char> free(6, 1);
  free[0] = free[1] = free[2] = 0;
  std::vector<int> cloth_zone{-1, -1};
  v << 0, 0, 2, 7, 7, 7;
  move_impact_zones(zones, cloth_zone, x, 0.0, h, free, mass, {}, v, report);
  EXPECT_LT((v - (Eigen::VectorXd(6) << 0, 0, 2, 0, 0, 2).finished()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(ContactFailSafe, TwoTrianglesMeetingHeadOnEndTheStepApart) {
  const LinearFeDiscretization d(triangles(true), {}, cloth());
  const double m = 1e-3, h = 0.01;
  const Eigen::VectorXd mass = Eigen::VectorXd::Constant(6, m);
  const std::vector<char> free(18, 1);
  CollisionSettings settings;
  settings.self = true;
  settings.thickness = 1e-3;
  settings.friction = 0.0;
  ContactParameters params;
  params.surface_level = 0;
  ContactStage stage(d, mass, free, settings, {}, params);
  const MassSystem a(18, m);
  // 3 mm apart (beyond the near distance at rest), closing at 2 m/s: 2 cm over the step, far
  // through each other.
  const Eigen::VectorXd x = d.rest();
  Eigen::VectorXd v(18);
  for (int i = 0; i < 6; ++i) v.segment<3>(3 * i) << 0.0, 0.0, i < 3 ? 1.0 : -1.0;
  const ContactReport report = stage.filter(x, 0.0, h, v, a.system());
  EXPECT_GT(report.ccd_collisions, 0);
  EXPECT_GT(report.impulses, 0);
  EXPECT_EQ(report.unresolved, 0);
  // The end positions: the triangles at least half the CCD's minimum separation (0.1 mm) apart,
  // and the top triangle's corner that was over the bottom one's interior still on the side it
  // started on (above the bottom triangle's plane, normal +z at the start); momentum kept (the
  // impulses are equal and opposite).
  const Eigen::VectorXd end = x + h * v;
  Eigen::MatrixX3d points(6, 3);
  for (int i = 0; i < 6; ++i) points.row(i) = end.segment<3>(3 * i).transpose();
  const double gap = triangle_distance(points, {0, 1, 2}, {3, 4, 5});
  EXPECT_GT(gap, 0.5 * params.min_separation_ratio * settings.thickness);
  const Eigen::Vector3d q0 = points.row(0).transpose(), q1 = points.row(1).transpose(), q2 = points.row(2).transpose();
  const Eigen::Vector3d normal = (q1 - q0).cross(q2 - q0).normalized();
  EXPECT_GT(normal.z(), 0.0);
  EXPECT_GT(normal.dot(points.row(3).transpose() - q0), 0.0);
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
  for (int i = 0; i < 6; ++i) momentum += m * v.segment<3>(3 * i);
  EXPECT_LT(momentum.norm(), 1e-9 * m);
  std::printf("head-on: %d collisions, %lld impulses, distance at the end %.3g mm\n", report.ccd_collisions, report.impulses,
              1e3 * gap);
}

}  // namespace
}  // namespace clothsim::contact

// The contact potential inside the step (sim/contact/barrier_potential.hpp), built directly on
// the flat ("linear_fe") discretisation of one or two 1 cm triangles at collision level 0 (each
// surface point is a node), against independent expectations: the energy is the cubic barrier
// b(d) = k (d̂ − d)³ / (3 d̂) with k h² = 4 × the node's mass, summed by hand over the pairs in
// the layer (a cloth triangle over a large obstacle triangle; two cloth triangles, one over the
// other, with a point–triangle and two crossing edge–edge pairs); its gradient matches central
// differences of the energy, and over the obstacle (where the distance is linear in the
// positions) its Hessian blocks match central differences of the gradient; nothing acts farther
// than the thickness; the step bound stops a triangle falling through another before the
// separation (α ≤ 0.2 for a 0.5 mm gap closed by 2 mm, positions at 0.9 α uncrossed) and lets a
// move away go whole; the candidates are made again only when a point leaves the serve radius
// (half the thickness) of the motion they were made for; and of the broad phase's pairs over a fan
// of long wedges exactly those closer than the boxes' growth are kept.
//
// Lengths [m], times [s], masses [kg]; the thickness d̂ is 1 mm.
#include "sim/contact/barrier_potential.hpp"

#include "tests/support/test_meshes.hpp"
#include "sim/flat_fe/flat_fe.hpp"
#include "sim/shell/material_presets.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

namespace clothsim::contact {
namespace {

constexpr double kThickness = 1e-3;
constexpr double kRatio = 4.0;  // BarrierSettings::barrier_ratio
constexpr double kStep = 2e-3;

// One triangle of 1 cm (legs along x and y) at height z, offset by (dx, dy).
TriMesh triangle(double dx, double dy, double z) {
  TriMesh m;
  m.vertices.resize(3, 3);
  m.vertices.row(0) << dx, dy, z;
  m.vertices.row(1) << dx + 0.01, dy, z;
  m.vertices.row(2) << dx, dy + 0.01, z;
  m.triangles = {{0, 1, 2}};
  return m;
}

// A large obstacle triangle in z = 0, facing +z, its edges and corners 0.3 m or more from the cloth.
Obstacle floor_triangle() {
  Obstacle o;
  o.name = "floor";
  o.shape = Obstacle::Shape::mesh;
  o.friction = 0.0;
  o.mesh.vertices.resize(3, 3);
  o.mesh.vertices << -1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 0.0, 1.0, 0.0;
  o.mesh.triangles = {{0, 1, 2}};
  return o;
}

// The parts the potential refers to, over `mesh` (at rest as given) and `obstacles` (at rest),
// and the step's positions for node positions x.
struct Scene {
  LinearFeDiscretization d;
  CollisionSurface surf;
  std::vector<Obstacle> obstacles;
  ObstacleSet obs;
  PairPrimitives pairs;
  std::optional<CandidateSearch> search;
  std::optional<BarrierPotential> potential;
  StepPositions step;
  Eigen::VectorXd diagonal;

  Scene(const TriMesh& mesh, std::vector<Obstacle> obstacle_list, bool self, const Eigen::VectorXd& node_mass)
      : d(mesh, {}, *material_preset("cotton")),
        surf(d, 0),
        obstacles(std::move(obstacle_list)),
        obs(obstacles),
        pairs(surf.triangles(), surf.edges(), obs) {
    std::vector<std::vector<int>> near_at_rest, joined_at_rest;
    if (self)
      surf.find_near_at_rest(2.0 * kThickness, 0.01 * kThickness, d.control_triangles(), near_at_rest, joined_at_rest);
    CandidateSettings cs;
    cs.self = self;
    cs.thickness = kThickness;
    cs.flat_region_angle = 0.0;
    search.emplace(SearchSurface{surf.triangles(), surf.op().levels, surf.edges(), surf.triangle_edges(), surf.owned_points(),
                                 surf.owned_edges(), d.control_triangles(), d.num_nodes()},
                   std::move(near_at_rest), std::move(joined_at_rest), obs, cs);
    BarrierSettings bs;
    bs.thickness = kThickness;
    bs.friction = 0.0;
    bs.barrier_ratio = kRatio;
    bs.obstacles_static = true;
    surf.make_point_rows();
    potential.emplace(surf, pairs, obs, obstacles, *search, bs);
    diagonal.resize(3 * d.num_nodes());
    for (int k = 0; k < d.num_nodes(); ++k) diagonal.segment<3>(3 * k).setConstant(node_mass(k));
    step.o0.resize(static_cast<Eigen::Index>(obs.obstacle_of_vertex.size()), 3);
    for (size_t k = 0; k < obstacles.size(); ++k)
      if (obstacles[k].shape != Obstacle::Shape::plane)
        step.o0.middleRows(obs.vertex_offset[k], obstacles[k].mesh.num_vertices()) = mesh_at(obstacles[k], 0.0);
    step.o1 = step.o0;
  }

  void begin(const Eigen::VectorXd& x, const Eigen::VectorXd& v, double t = 0.0) {
    step.p0 = surf.points(x);
    potential->begin_step(step, x, v, t, kStep, diagonal);
  }
  PotentialLinearisation linearise(const Eigen::VectorXd& v) {
    PotentialLinearisation out;
    potential->linearise(step, v, out);
    return out;
  }
};

// The barrier of a pair at distance d with the stiffness of a point of mass m (by hand).
double barrier_energy(double d, double m) {
  const double k = kRatio * m / (kStep * kStep);
  return d < kThickness ? k * std::pow(kThickness - d, 3) / (3.0 * kThickness) : 0.0;
}

Eigen::VectorXd random_direction(Eigen::Index n, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd dir(n);
  for (Eigen::Index i = 0; i < n; ++i) dir(i) = normal(rng);
  return dir / dir.norm();
}

// A cloth triangle over the obstacle triangle, its corners 0.3, 0.4 and 0.5 mm above it.
struct OverObstacle : Scene {
  Eigen::VectorXd x;
  static Eigen::VectorXd masses() { return Eigen::Vector3d(1e-4, 2e-4, 3e-4); }
  explicit OverObstacle(double lift = 0.0) : Scene(triangle(0.0, 0.0, 0.0), {floor_triangle()}, false, masses()) {
    x = d.rest();
    x(2) += 0.3e-3 + lift;
    x(5) += 0.4e-3 + lift;
    x(8) += 0.5e-3 + lift;
  }
};

TEST(BarrierPotential, OverAnObstacleTriangleTheEnergyIsEachCornersBarrier) {
  OverObstacle s;
  ASSERT_LT((s.surf.points(s.x) - s.x.reshaped(3, 3).transpose()).norm(), 1e-15) << "point k is node k at level 0";
  std::mt19937 rng(3);
  const Eigen::VectorXd v = 0.02 * random_direction(9, rng);  // moves of up to ~40 µm
  s.begin(s.x, v);
  const PotentialLinearisation lin = s.linearise(v);
  const Eigen::VectorXd end = s.x + kStep * v;
  double expected = 0.0;
  for (int k = 0; k < 3; ++k) expected += barrier_energy(end(3 * k + 2), OverObstacle::masses()(k));
  EXPECT_EQ(lin.active, 3);
  EXPECT_NEAR(lin.energy, expected, 1e-12 * expected);
  // The force −∇ₓE on each corner is straight up, b'(d) by hand.
  for (int k = 0; k < 3; ++k) {
    const double m = OverObstacle::masses()(k), d = end(3 * k + 2);
    const double force = kRatio * m / (kStep * kStep) * std::pow(kThickness - d, 2) / kThickness;
    EXPECT_NEAR(-lin.energy_gradient(3 * k + 2), force, 1e-9 * force) << "corner " << k;
    EXPECT_NEAR(lin.energy_gradient.segment<2>(3 * k).norm(), 0.0, 1e-12 * force) << "corner " << k;
  }
}

TEST(BarrierPotential, OverAnObstacleGradientAndHessianMatchFiniteDifferences) {
  OverObstacle s;
  std::mt19937 rng(5);
  const Eigen::VectorXd v0 = 0.02 * random_direction(9, rng);
  s.begin(s.x, v0);
  const PotentialLinearisation lin = s.linearise(v0);
  ASSERT_EQ(lin.active, 3);
  const double eps = 1e-6;  // [m/s]: 2 nm of end position
  for (int trial = 0; trial < 4; ++trial) {
    const Eigen::VectorXd dir = random_direction(9, rng);
    const PotentialLinearisation plus = s.linearise(v0 + eps * dir), minus = s.linearise(v0 - eps * dir);
    // dE(x + h v)/dv · dir = h ∇ₓE · dir.
    const double slope = kStep * lin.energy_gradient.dot(dir);
    EXPECT_NEAR((plus.energy - minus.energy) / (2 * eps), slope, 1e-6 * std::abs(slope)) << "trial " << trial;
    // d(∇ₓE)/dv · dir = h Σ Bᵀ H B dir (exact here: each distance is linear in its point).
    Eigen::VectorXd applied = Eigen::VectorXd::Zero(9);
    for (const PotentialLinearisation::Block& b : lin.blocks) lin.scatter(b, b.hessian * lin.apply(b, dir), applied);
    const Eigen::VectorXd fd = (plus.energy_gradient - minus.energy_gradient) / (2 * eps);
    EXPECT_LE((fd - kStep * applied).norm(), 1e-6 * (kStep * applied).norm()) << "trial " << trial;
  }
}

// Two triangles 3 mm apart at rest (so not near each other at rest), the upper one offset by
// (1, 1) mm; x lowers it to `gap` above the lower one.
struct TwoTriangles : Scene {
  static constexpr double kMass = 1e-4;
  Eigen::VectorXd x;
  explicit TwoTriangles(double gap)
      : Scene(testing::concatenated(triangle(0.0, 0.0, 0.0), triangle(0.001, 0.001, 0.003)), {}, true,
              Eigen::VectorXd::Constant(6, kMass)) {
    x = d.rest();
    for (int k = 3; k < 6; ++k) x(3 * k + 2) = gap;
  }
  // Velocities that move the upper triangle by u over the step.
  static Eigen::VectorXd upper_moves(const Eigen::Vector3d& u) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(18);
    for (int k = 3; k < 6; ++k) v.segment<3>(3 * k) = u / kStep;
    return v;
  }
};

TEST(BarrierPotential, TwoTrianglesHaveAPointPairAndTwoCrossingEdgePairsInTheLayer) {
  // 0.5 mm apart: the upper triangle's corner 3 is over the lower triangle, and its two legs
  // cross the lower one's long edge; every other pair is more than 1 mm apart (by hand: 1.12 mm
  // and more).
  TwoTriangles s(0.5e-3);
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(18);
  s.begin(s.x, v);
  const PotentialLinearisation lin = s.linearise(v);
  EXPECT_EQ(lin.active, 3);
  EXPECT_NEAR(lin.energy, 3.0 * barrier_energy(0.5e-3, TwoTriangles::kMass), 1e-12 * lin.energy);
  // The forces push the triangles apart: up on the upper one, down on the lower one, and sum to 0.
  double up = 0.0, down = 0.0;
  for (int k = 0; k < 3; ++k) down -= lin.energy_gradient(3 * k + 2);
  for (int k = 3; k < 6; ++k) up -= lin.energy_gradient(3 * k + 2);
  EXPECT_GT(up, 0.0);
  EXPECT_NEAR(up + down, 0.0, 1e-12 * up);
}

TEST(BarrierPotential, TwoTrianglesGradientMatchesFiniteDifferencesOfTheEnergy) {
  TwoTriangles s(0.5e-3);
  std::mt19937 rng(7);
  const Eigen::VectorXd v0 = 0.02 * random_direction(18, rng);
  s.begin(s.x, v0);
  const PotentialLinearisation lin = s.linearise(v0);
  ASSERT_EQ(lin.active, 3);
  const double eps = 1e-6;
  int checked = 0;
  for (int trial = 0; trial < 4; ++trial) {
    const Eigen::VectorXd dir = random_direction(18, rng);
    const PotentialLinearisation plus = s.linearise(v0 + eps * dir), minus = s.linearise(v0 - eps * dir);
    if (plus.active != lin.active || minus.active != lin.active) continue;
    ++checked;
    const double slope = kStep * lin.energy_gradient.dot(dir);
    EXPECT_NEAR((plus.energy - minus.energy) / (2 * eps), slope, 1e-5 * std::abs(slope)) << "trial " << trial;
  }
  EXPECT_GE(checked, 3);
}

TEST(BarrierPotential, NothingActsFartherThanTheThickness) {
  TwoTriangles apart(3e-3);  // as at rest
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(18);
  apart.begin(apart.x, v);
  const PotentialLinearisation a = apart.linearise(v);
  EXPECT_EQ(a.active, 0);
  EXPECT_TRUE(a.blocks.empty());
  EXPECT_EQ(a.energy, 0.0);
  EXPECT_EQ(a.energy_gradient.norm(), 0.0);

  OverObstacle high(1.5e-3);  // corners 1.8 to 2 mm above the obstacle
  high.begin(high.x, Eigen::VectorXd::Zero(9));
  const PotentialLinearisation b = high.linearise(Eigen::VectorXd::Zero(9));
  EXPECT_EQ(b.active, 0);
  EXPECT_TRUE(b.blocks.empty());
  EXPECT_EQ(b.energy, 0.0);
  EXPECT_EQ(b.dissipation, 0.0);
}

TEST(BarrierPotential, StepBoundStopsATriangleFallingThroughAnother) {
  TwoTriangles s(0.5e-3);
  const Eigen::VectorXd still = Eigen::VectorXd::Zero(18);
  s.begin(s.x, still);
  // Down by 2 mm: the pairs at 0.5 mm reach the separation (0.1 mm, a tenth of the thickness) at
  // a fifth of the move, and cross at a quarter.
  const Eigen::VectorXd fall = TwoTriangles::upper_moves(Eigen::Vector3d(0.0, 0.0, -2e-3));
  const double alpha = s.potential->step_bound(s.step, still, fall);
  EXPECT_LE(alpha, 0.2 + 1e-12);
  EXPECT_GT(alpha, 0.1);
  const Eigen::MatrixX3d p = s.surf.points(s.x + kStep * 0.9 * alpha * fall);
  EXPECT_GT(triangle_distance(p, s.surf.triangles()[0], s.surf.triangles()[1]), 0.0);
  for (int k = 3; k < 6; ++k) EXPECT_GT(p(k, 2), 0.0) << "point " << k << " stays above";
  // Up by 2 mm, or sideways along the lower triangle's plane: nothing to cut.
  EXPECT_EQ(s.potential->step_bound(s.step, still, TwoTriangles::upper_moves(Eigen::Vector3d(0.0, 0.0, 2e-3))), 1.0);
  EXPECT_EQ(s.potential->step_bound(s.step, still, TwoTriangles::upper_moves(Eigen::Vector3d(2e-3, 0.0, 0.0))), 1.0);
}

TEST(BarrierPotential, CandidatesAreMadeAgainOnlyWhenAPointLeavesTheServeRadius) {
  TwoTriangles s(0.5e-3);
  ASSERT_EQ(s.potential->serve_radius(), 0.5 * kThickness);
  const Eigen::VectorXd still = Eigen::VectorXd::Zero(18);
  s.begin(s.x, still);
  EXPECT_EQ(s.potential->candidate_builds(), 1);
  s.linearise(TwoTriangles::upper_moves(Eigen::Vector3d(0.3e-3, 0.0, 0.0)));  // 0.3 mm from where they were made for
  EXPECT_EQ(s.potential->candidate_builds(), 1);
  s.linearise(TwoTriangles::upper_moves(Eigen::Vector3d(0.8e-3, 0.0, 0.0)));  // 0.8 mm: beyond half the thickness
  EXPECT_EQ(s.potential->candidate_builds(), 2);
  // The next step from the same start: on the path they were made for, so they are kept.
  s.begin(s.x, still, kStep);
  EXPECT_EQ(s.potential->candidate_builds(), 2);
  // A start 0.7 mm to the side of that path: made again.
  Eigen::VectorXd moved = s.x;
  for (int k = 3; k < 6; ++k) moved(3 * k + 1) += 0.7e-3;
  s.begin(moved, still, 2 * kStep);
  EXPECT_EQ(s.potential->candidate_builds(), 3);
}

// A 10 cm fan of 48 long wedges in z = 0 (as the top of a meshed cylinder) under a 2 cm lattice
// of 7 × 7 points 0.6 mm above it: the wedges' boxes overlap over much of the lattice.
struct OverFan : Scene {
  Eigen::VectorXd x;
  static Obstacle fan() {
    Obstacle o;
    o.name = "fan";
    o.shape = Obstacle::Shape::mesh;
    o.mesh = testing::make_fan_disc(48, 1);
    o.mesh.vertices *= 0.05;
    return o;
  }
  static TriMesh lattice() {
    TriMesh m = testing::make_lattice(7, 0.02);
    m.vertices.col(0).array() -= 0.012;
    m.vertices.col(1).array() -= 0.008;
    m.vertices.col(2).setConstant(0.6e-3);
    return m;
  }
  OverFan() : Scene(lattice(), {fan()}, false, Eigen::VectorXd::Constant(49, 1e-5)) { x = d.rest(); }
};

TEST(BarrierPotential, CandidatesFartherThanTheirGrowthAreDroppedAndNoneWithinIt) {
  OverFan s;
  const Eigen::VectorXd still = Eigen::VectorXd::Zero(s.x.size());
  s.begin(s.x, still);
  ASSERT_EQ(s.potential->candidate_builds(), 1);
  // The broad phase's pairs for the same (still) motion with the same growth, and their exact
  // distances at the start.
  const double grow = kThickness + 2.0 * s.potential->serve_radius();
  ContactCounters scratch;
  const std::vector<Candidate> all = s.search->find(s.step.p0, s.step.p0, s.step.o0, s.step.o1, false, grow, scratch);
  std::vector<Candidate> kept = s.potential->candidates();
  std::sort(kept.begin(), kept.end());
  int within = 0, beyond = 0;
  for (const Candidate& c : all) {
    const double distance = s.pairs.geometry(c, s.pairs.corners(c, s.step.p0, s.step.o0)).distance;
    const bool is_kept = std::binary_search(kept.begin(), kept.end(), c);
    if (distance < grow) {
      ++within;
      EXPECT_TRUE(is_kept) << "a pair " << distance << " m apart was dropped";
    } else {
      ++beyond;
      EXPECT_FALSE(is_kept) << "a pair " << distance << " m apart was kept";
    }
  }
  EXPECT_EQ(static_cast<size_t>(within), kept.size());
  EXPECT_GT(beyond, within) << "the fan's boxes give more far pairs than near ones";
  EXPECT_GT(within, 49) << "every point has its wedge";
  // The barrier is unchanged by the dropped pairs: each point pressed by its closest wedge.
  const PotentialLinearisation lin = s.linearise(still);
  EXPECT_EQ(lin.active, 49);
}

}  // namespace
}  // namespace clothsim::contact

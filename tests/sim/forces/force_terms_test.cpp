// Every force term against finite differences (tests/support/fd_check.hpp) at rest, at seeded
// random states and at hard states (strong compression, near-folded, large rotation), plus the
// invariants each must keep: no force or energy at rest, none under rigid motion, forces that sum
// to zero where nothing external acts, and the totals of the loads.
#include "sim/loop_shell/loop_shell.hpp"
#include "sim/forces/corotated_shell.hpp"
#include "sim/forces/damping.hpp"
#include "sim/forces/external_loads.hpp"
#include "sim/forces/follower_couples.hpp"
#include "sim/forces/gravity.hpp"
#include "sim/forces/point_loads.hpp"
#include "sim/forces/surface_load.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/scene/scene.hpp"
#include "tests/support/fd_check.hpp"
#include "tests/support/term_states.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace clothsim {
namespace {

using testing::check_force_against_energy;
using testing::check_matrix_against_force;
using testing::FdReport;
using testing::force_at;
using testing::matrix_at;
using testing::rigidly_moved;
using testing::rotation;
using testing::State;
using testing::update_at;

constexpr double kSize = 0.1;   // plate side [m]
constexpr double kEps = 1e-6;   // finite-difference step [m]
// Forces below this are round-off of a state at rest [N] (1e-12 of E·t·side = 500 N).
constexpr double kForceFloor = 5e-10;

// Cotton-like shell, a little stiffer in bending so both parts of K matter.
ShellMaterial cloth() {
  ShellMaterial m;
  m.stretch_modulus = 5000.0;
  m.bending_rigidity = 1e-4;
  m.poisson_ratio = 0.25;
  m.areal_density = 0.12;
  return m;
}

// The structures the terms are checked on: a free plate (every element an identity patch), a plate
// clamped along one edge (tied components: folded elements), and a short sleeve whose top rim is
// held in x and z only (partly fixed vertices: folded elements of the other kind).
struct Structure {
  std::string name;
  std::unique_ptr<LoopShellDiscretization> d;
};

std::vector<Structure> structures() {
  std::vector<Structure> out;
  const TriMesh plate = make_grid(kSize, kSize, 4, 4);
  out.push_back({"free plate", std::make_unique<LoopShellDiscretization>(plate, std::vector<BoundaryCondition>{}, cloth(),
                                                                         Quadrature::one_point)});
  BoundaryCondition clamp;
  clamp.vertices = select_box(plate.vertices, Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(-0.049, 1, 1));
  clamp.clamped = true;
  out.push_back({"clamped plate", std::make_unique<LoopShellDiscretization>(plate, std::vector<BoundaryCondition>{clamp},
                                                                            cloth(), Quadrature::three_point)});
  const TriMesh sleeve = make_cylinder(0.03, 0.06, 8, 4);
  BoundaryCondition bottom, top;
  bottom.vertices = select_box(sleeve.vertices, Eigen::Vector3d(-1, -1e-4, -1), Eigen::Vector3d(1, 1e-4, 1));
  top.vertices = select_box(sleeve.vertices, Eigen::Vector3d(-1, 0.06 - 1e-4, -1), Eigen::Vector3d(1, 1, 1));
  top.fix = {true, false, true};
  out.push_back({"sleeve", std::make_unique<LoopShellDiscretization>(sleeve, std::vector<BoundaryCondition>{bottom, top},
                                                                     cloth(), Quadrature::one_point)});
  return out;
}

// The states of the checks (tests/support/term_states.hpp): three random ones, and the part with
// x > 0 turned 170° about the y axis (a crease along x = 0).
std::vector<State> states(const Discretization& d) {
  return testing::states(d, {.random_states = 3, .fold_degrees = 170.0, .fold_from = 0.0, .fold_name = "near-folded"});
}

// The corotated shell: with the rotations frozen at the state, the force is exactly −∂E/∂x and
// the assembled matrix (through the real gather, folds included) exactly −∂f/∂x.
TEST(CorotatedShellTerm, ForceAndMatrixMatchFiniteDifferencesWithFrozenRotations) {
  for (const Structure& s : structures())
    for (const State& state : states(*s.d)) {
      CorotatedShell shell(s.d->model(), /*corotational=*/true, /*tension_stiffening=*/false);
      update_at(shell, *s.d, state.x);  // rotations extracted at the state
      shell.freeze_rotations(true);
      FdReport energy = check_force_against_energy(shell, *s.d, state.x, kEps);
      energy.floor = kForceFloor;
      EXPECT_LT(energy.relative(), 1e-6) << s.name << ", " << state.name << ": force vs energy: " << energy.describe();
      FdReport matrix = check_matrix_against_force(shell, *s.d, state.x, kEps);
      EXPECT_LT(matrix.relative(), 1e-6) << s.name << ", " << state.name << ": matrix vs force: " << matrix.describe();
    }
}

// The tension-stiffening part of the matrix (with it minus without it, both assembled through the
// real path) is the exact Jacobian of the tension force with the tensile membrane forces frozen.
TEST(CorotatedShellTerm, TensionStiffeningMatchesTheJacobianOfTheTensionForce) {
  int states_with_tension = 0;
  for (const Structure& s : structures())
    for (const State& state : states(*s.d)) {
      CorotatedShell with(s.d->model(), true, true), without(s.d->model(), true, false);
      const Eigen::MatrixXd k = matrix_at(without, *s.d, state.x, {1.0, 0.0});
      const Eigen::MatrixXd g = matrix_at(with, *s.d, state.x, {1.0, 0.0}) - k;
      const FdReport r = check_matrix_against_force(g, *s.d, state.x, kEps, [&](const Eigen::VectorXd& y) {
        Eigen::VectorXd u = y - s.d->rest();
        s.d->make_consistent(u);
        return with.elements().tension_force(u);
      });
      if (g.cwiseAbs().maxCoeff() < 1e-12 * k.cwiseAbs().maxCoeff()) {  // no tension (at rest: round-off)
        EXPECT_LT(r.scale, 1e-12 * k.cwiseAbs().maxCoeff()) << s.name << ", " << state.name;
        continue;
      }
      ++states_with_tension;
      EXPECT_LT(r.relative(), 1e-6) << s.name << ", " << state.name << ": " << r.describe();
      // G is symmetric positive semi-definite (compression adds nothing).
      EXPECT_LT((g - g.transpose()).cwiseAbs().maxCoeff(), 1e-12 * g.cwiseAbs().maxCoeff()) << s.name << ", " << state.name;
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(g).eigenvalues().minCoeff(), -1e-9 * g.cwiseAbs().maxCoeff())
          << s.name << ", " << state.name;
    }
  EXPECT_GE(states_with_tension, 12);  // the random, folded and rotated states all carry tension
}

// Invariants with the rotations extracted at every state: no energy or force at rest or after a
// rigid motion; the forces of a free structure sum to zero at any state.
TEST(CorotatedShellTerm, RigidMotionsStoreNoEnergyAndForcesBalance) {
  const std::vector<Structure> all = structures();
  const Discretization& plate = *all[0].d;
  CorotatedShell shell(all[0].d->model(), true, true);
  const double stiffness_scale = cloth().stretch_modulus * kSize;  // [N] per unit strain
  for (const Eigen::VectorXd& x : {plate.rest(), rigidly_moved(plate, rotation(2.5, Eigen::Vector3d(0.3, -1, 0.7)),
                                                               Eigen::Vector3d(1, 2, 3))}) {
    const Eigen::VectorXd f = force_at(shell, plate, x);
    EXPECT_LT(std::abs(shell.energy()), 1e-12 * stiffness_scale * kSize);
    EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-10 * stiffness_scale);
  }
  for (const State& state : states(plate)) {
    const Eigen::VectorXd f = force_at(shell, plate, state.x);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int v = 0; v < plate.num_nodes(); ++v) sum += f.segment<3>(3 * v);
    EXPECT_LT(sum.norm(), 1e-10 * std::max(f.cwiseAbs().maxCoeff(), 1e-300)) << state.name;
    if (state.name != "rest") {
      EXPECT_GT(shell.energy(), 0.0) << state.name;
    }
  }
}

// State-independent loads: f = F, E = −F·u, no matrix; and their totals.
TEST(LoadTerms, ConstantLoadsMatchFiniteDifferencesAndTheirTotals) {
  // Six-point quadrature: the one-point rule integrates the border patches of this coarse plate
  // 0.6 % high (their parametrisation is not affine), the six-point rule to 1.5e-4.
  const LoopShellDiscretization plate(make_grid(kSize, kSize, 4, 4), {}, cloth(), Quadrature::six_point);
  const Eigen::Vector3d g(0, 0, -9.81), q(1.0, -2.0, 3.0);
  const double rho = cloth().areal_density;
  // Consistent loads integrate over the element's surface, the limit surface of the control mesh,
  // which at free borders covers a little less than the control mesh (1.8 % here). Its area,
  // independently: the triangles of the limit surface refined five times (converged to ~4e-6).
  const SurfaceOperator fine = plate.display(5);
  const Eigen::MatrixX3d p = fine.positions(plate.control_net(plate.rest()));
  double area = 0.0;
  for (const Triangle& t : fine.triangles)
    area += 0.5 * (p.row(t[1]) - p.row(t[0])).cross(p.row(t[2]) - p.row(t[0])).norm();
  EXPECT_LT(area, kSize * kSize);
  EXPECT_GT(area, 0.95 * kSize * kSize);
  const double lumped_area = kSize * kSize;  // the lumped mass is a partition of the control mesh
  std::vector<std::unique_ptr<ConstantForce>> terms;
  terms.push_back(make_gravity(plate, rho, g, GravityModel::lumped));
  terms.push_back(make_gravity(plate, rho, g, GravityModel::consistent));
  terms.push_back(make_surface_load(plate, q));
  terms.push_back(make_pressure(plate, 2.0));
  terms.push_back(make_point_loads(plate, {{12, Eigen::Vector3d(0.5, 0, -1)}, {3, Eigen::Vector3d(0, 1, 0)}}));
  const std::vector<Eigen::Vector3d> totals = {rho * lumped_area * g, rho * area * g, area * q,
                                               Eigen::Vector3d(0, 0, 2.0 * area), Eigen::Vector3d(0.5, 1, -1)};
  const std::vector<double> tolerance = {1e-12, 3e-4, 3e-4, 3e-4, 1e-12};  // six-point rule: 1.5e-4
  for (size_t i = 0; i < terms.size(); ++i) {
    ForceTerm& term = *terms[i];
    for (const State& state : states(plate)) {
      FdReport energy = check_force_against_energy(term, plate, state.x, kEps);
      energy.floor = kForceFloor;
      EXPECT_LT(energy.relative(), 1e-6) << term.name() << ", " << state.name << ": " << energy.describe();
      const FdReport matrix = check_matrix_against_force(term, plate, state.x, kEps);
      EXPECT_EQ(matrix.max_error, 0.0) << term.name() << ", " << state.name;
    }
    EXPECT_FALSE(term.has_matrix()) << term.name();
    const Eigen::VectorXd f = force_at(term, plate, plate.rest());
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int v = 0; v < plate.num_nodes(); ++v) sum += f.segment<3>(3 * v);
    EXPECT_LT((sum - totals[i]).norm(), tolerance[i] * totals[i].norm()) << term.name() << ": total " << sum.transpose();
  }
}

// Follower couples: no potential and no matrix; the forces sum to zero, are perpendicular to the
// moment, and at rest (offsets symmetric about the moment's axis, as at a strip's end) their
// moment about the group's centroid is exactly M.
TEST(LoadTerms, FollowerCouplesCarryTheirMoment) {
  const std::vector<Structure> all = structures();
  const Discretization& plate = *all[0].d;
  MomentLoad couple;
  couple.vertices = select_box(plate.mesh().vertices, Eigen::Vector3d(0.02, -1, -1), Eigen::Vector3d(1, 1, 1));
  couple.moment = Eigen::Vector3d(0, -0.3, 0);
  FollowerCouples term({couple});
  EXPECT_FALSE(term.has_energy());
  EXPECT_FALSE(term.has_matrix());
  const Eigen::VectorXd turned = rigidly_moved(plate, rotation(0.8, Eigen::Vector3d(1, 1, 0)), Eigen::Vector3d(0.1, 0, 0));
  for (const Eigen::VectorXd& x : {plate.rest(), turned}) {
    const Eigen::VectorXd f = force_at(term, plate, x);
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero(), sum = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
    for (int v : couple.vertices) centroid += x.segment<3>(3 * v) / static_cast<double>(couple.vertices.size());
    for (int v : couple.vertices) {
      sum += f.segment<3>(3 * v);
      moment += (x.segment<3>(3 * v) - centroid).cross(f.segment<3>(3 * v));
      EXPECT_LT(std::abs(f.segment<3>(3 * v).dot(couple.moment)), 1e-12);
    }
    EXPECT_LT(sum.norm(), 1e-12);
    EXPECT_GT(f.norm(), 1.0);
    if (x == plate.rest()) {
      EXPECT_LT((moment - couple.moment).norm(), 1e-12);
    }
  }
  // A group on one line parallel to the moment cannot carry it: a clear error naming the couple.
  MomentLoad line;
  line.vertices = {0, 5, 10};  // the column x = −0.05 (grid rows of 5)
  line.moment = Eigen::Vector3d(0, 1, 0);
  FollowerCouples bad({line});
  try {
    update_at(bad, plate, plate.rest());
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("moment 0"), std::string::npos) << e.what();
  }
}

// Damping terms: Kelvin–Voigt adds c·K of the term it damps with the damping weight (and K with
// the stiffness weight), mass damping c·M on the diagonal; neither adds a force of its own.
TEST(DampingTerms, MatricesAreTheirDefinitions) {
  const std::vector<Structure> all = structures();
  for (const Structure& s : all) {
    const Eigen::VectorXd x = testing::perturbed_rest(*s.d, 2e-3, 5);
    const double c = 0.01;
    KelvinVoigtDamping damped(s.d->elastic_term(true, true), c);
    CorotatedShell plain(s.d->model(), true, true);
    const Eigen::MatrixXd k = matrix_at(plain, *s.d, x, {1.0, 0.0});
    EXPECT_LT((matrix_at(damped, *s.d, x, {0.0, 1.0}) - c * k).cwiseAbs().maxCoeff(), 1e-12 * k.cwiseAbs().maxCoeff()) << s.name;
    EXPECT_LT((matrix_at(damped, *s.d, x, {1.0, 0.0}) - k).cwiseAbs().maxCoeff(), 1e-12 * k.cwiseAbs().maxCoeff()) << s.name;
    EXPECT_EQ(force_at(damped, *s.d, x), force_at(plain, *s.d, x)) << s.name;
    EXPECT_EQ(damped.energy(), plain.energy()) << s.name;

    const Eigen::VectorXd mass = s.d->lumped_mass(cloth().areal_density);
    MassDamping drag(mass, 3.0, s.d->matrix_pattern());
    const Eigen::MatrixXd d = matrix_at(drag, *s.d, x, {0.0, 2.0});
    Eigen::VectorXd expected(3 * mass.size());
    for (Eigen::Index v = 0; v < mass.size(); ++v) expected.segment<3>(3 * v).setConstant(6.0 * mass(v));
    EXPECT_LT((d.diagonal() - expected).cwiseAbs().maxCoeff(), 1e-15 * expected.maxCoeff()) << s.name;
    EXPECT_EQ((d - Eigen::MatrixXd(d.diagonal().asDiagonal())).cwiseAbs().maxCoeff(), 0.0) << s.name;
    EXPECT_EQ(force_at(drag, *s.d, x).cwiseAbs().maxCoeff(), 0.0) << s.name;
    // Total mass: areal density × area (the lumped mass is a partition of the area).
    if (s.name != "sleeve") {
      EXPECT_NEAR(mass.sum(), cloth().areal_density * kSize * kSize, 1e-15);
    }
  }
}

// The external loads are ramped: at half the ramp time, half the force; full force after it.
TEST(LoadTerms, ExternalLoadsRampLinearly) {
  const std::vector<Structure> all = structures();
  const Discretization& plate = *all[0].d;
  std::vector<std::unique_ptr<ForceTerm>> constant, varying;
  constant.push_back(make_gravity(plate, 0.1, Eigen::Vector3d(0, 0, -9.81), GravityModel::lumped));
  const Eigen::VectorXd full = force_at(*constant.back(), plate, plate.rest());
  ExternalLoads loads(std::move(constant), std::move(varying), /*ramp_time=*/2.0, 3 * plate.num_nodes());
  EXPECT_LT((force_at(loads, plate, plate.rest(), 1.0) - 0.5 * full).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(force_at(loads, plate, plate.rest(), 3.0), full);
  EXPECT_FALSE(loads.has_energy());  // time-dependent
}

}  // namespace
}  // namespace clothsim

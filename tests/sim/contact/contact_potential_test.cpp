// The contact potential inside the step (ContactStage::begin_step / linearise) built directly:
// its energy gradient ∇ₓE and friction gradient ∇ᵥΨ against central differences of E(x + h v)
// and Ψ(v) over random velocity directions, and its Hessian blocks Σ Bᵀ H B against central
// differences of the gradients where they are exact (cloth points over a ground plane and over
// the flat top of a box: the distance is then linear in the positions). States: a sheet lying
// inside the contact layer, moving at random velocities (some points pressed deeper, some lifted
// out of the layer). Also: a sheet far from everything has no potential at all.
#include "sim/contact/contact_stage.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/setup/setup.hpp"
#include "sim/shell/material_presets.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

namespace clothsim {
namespace {

struct PotentialFixture {
  Problem problem;
  std::shared_ptr<Discretization> d;
  Eigen::VectorXd mass;
  std::vector<char> free;
  std::unique_ptr<ContactStage> stage;
  Eigen::VectorXd x;
  double h = 2e-3;

  // A 0.1 m square of 6 × 6 cells at height `height` above the ground plane z = 0, over a box
  // whose top face, the plane z = −0.0002, reaches 0.15 m beyond the sheet on every side (the
  // box's face and the plane both act; no box edge or corner is near the cloth, so every distance
  // is linear in the positions and the Gauss–Newton Hessian is the exact one).
  explicit PotentialFixture(double height) {
    problem.mesh = make_grid(0.1, 0.1, 6, 6);
    problem.material = *material_preset("cotton");
    problem.collision_level = 1;
    problem.collision.thickness = 1e-3;
    problem.collision.friction = 0.4;
    Obstacle ground;
    ground.name = "ground";
    ground.shape = Obstacle::Shape::plane;
    ground.point = Eigen::Vector3d::Zero();
    ground.normal = Eigen::Vector3d::UnitZ();
    ground.friction = 0.5;
    Obstacle box;
    box.name = "box";
    box.shape = Obstacle::Shape::box;
    box.center = Eigen::Vector3d(0.0, 0.0, -0.0502);
    box.size = Eigen::Vector3d(0.4, 0.4, 0.1);
    box.friction = 0.3;
    box.mesh = tessellate(box);
    problem.obstacles = {ground, box};
    d = make_discretization(problem);
    mass = d->lumped_mass(problem.material.areal_density);
    free.assign(static_cast<size_t>(3 * d->num_nodes()), 1);
    ContactParameters parameters;
    parameters.surface_level = problem.collision_level;
    stage = std::make_unique<ContactStage>(*d, mass, free, problem.collision, problem.obstacles, parameters);
    stage->enable_potential();
    x = d->rest();
    for (int k = 0; k < d->num_nodes(); ++k) x(3 * k + 2) += height;
  }

  Eigen::VectorXd diagonal() const {  // a stand-in for the step's matrix diagonal: the masses
    Eigen::VectorXd out(3 * d->num_nodes());
    for (int k = 0; k < d->num_nodes(); ++k) out.segment<3>(3 * k).setConstant(mass(k));
    return out;
  }
};

TEST(ContactPotential, GradientsAndHessianMatchFiniteDifferences) {
  PotentialFixture f(0.45e-3);  // inside the 1 mm layer of the ground and of the box top
  const int n3 = 3 * f.d->num_nodes();
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd v0(n3);
  for (int i = 0; i < n3; ++i) v0(i) = 0.05 * normal(rng);  // up to ~0.1 mm per 2 ms step
  f.stage->begin_step(f.x, v0, 0.0, f.h, f.diagonal());
  PotentialLinearisation lin, plus, minus;
  f.stage->linearise(v0, lin);
  ASSERT_GT(lin.active, 20) << "the sheet lies in the contact layer";
  ASSERT_GT(lin.dissipation, 0.0) << "friction acts on the pressed pairs";
  int checked = 0;
  for (int trial = 0; trial < 4; ++trial) {
    Eigen::VectorXd dir(n3);
    for (int i = 0; i < n3; ++i) dir(i) = normal(rng);
    dir /= dir.norm();
    const double eps = 1e-6;  // [m/s]: 2 nm of end position
    f.stage->linearise(v0 + eps * dir, plus);
    f.stage->linearise(v0 - eps * dir, minus);
    if (plus.active != lin.active || minus.active != lin.active) continue;  // a pair crossed the layer's edge
    ++checked;
    // E(x + h v): dE/dv · dir = h ∇ₓE · dir.
    const double fd_energy = (plus.energy - minus.energy) / (2 * eps);
    const double energy_slope = f.h * lin.energy_gradient.dot(dir);
    EXPECT_NEAR(fd_energy, energy_slope, 1e-5 * std::abs(energy_slope) + 1e-15) << "trial " << trial;
    const double fd_dissipation = (plus.dissipation - minus.dissipation) / (2 * eps);
    const double dissipation_slope = lin.dissipation_gradient.dot(dir);
    EXPECT_NEAR(fd_dissipation, dissipation_slope, 1e-5 * std::abs(dissipation_slope) + 1e-15) << "trial " << trial;
    // Hessians: d(∇ₓE)/dv · dir = h ∇²ₓE dir and d(∇ᵥΨ)/dv · dir = ∇²ᵥΨ dir, with ∇² = Σ Bᵀ H B.
    Eigen::VectorXd stiffness = Eigen::VectorXd::Zero(n3), damping = Eigen::VectorXd::Zero(n3);
    for (const PotentialLinearisation::Block& b : lin.blocks)
      lin.scatter(b, b.hessian * lin.apply(b, dir), b.dissipative ? damping : stiffness);
    const Eigen::VectorXd fd_stiffness = (plus.energy_gradient - minus.energy_gradient) / (2 * eps);
    const Eigen::VectorXd fd_damping = (plus.dissipation_gradient - minus.dissipation_gradient) / (2 * eps);
    EXPECT_LE((fd_stiffness - f.h * stiffness).norm(), 1e-5 * (f.h * stiffness).norm()) << "trial " << trial;

    EXPECT_LE((fd_damping - damping).norm(), 1e-4 * damping.norm()) << "trial " << trial;
  }
  EXPECT_GE(checked, 2) << "too few directions kept the active set";
  // The barrier pushes the sheet up: its force −∇ₓE has a positive total z component.
  double lift = 0.0;
  for (int k = 0; k < f.d->num_nodes(); ++k) lift -= lin.energy_gradient(3 * k + 2);
  EXPECT_GT(lift, 0.0);
}

TEST(ContactPotential, NothingWhereNothingIsNear) {
  PotentialFixture f(0.05);  // 5 cm above the ground
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(3 * f.d->num_nodes());
  f.stage->begin_step(f.x, v, 0.0, f.h, f.diagonal());
  PotentialLinearisation lin;
  f.stage->linearise(v, lin);
  EXPECT_EQ(lin.active, 0);
  EXPECT_TRUE(lin.blocks.empty());
  EXPECT_EQ(lin.energy, 0.0);
  EXPECT_EQ(lin.dissipation, 0.0);
}

}  // namespace
}  // namespace clothsim

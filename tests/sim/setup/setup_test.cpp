// sim/setup: the registry of discretisation methods and the one builder of a problem's external
// loads that the static and the dynamic analysis share.
#include "sim/setup/setup.hpp"

#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace clothsim {
namespace {

Problem small_plate() {
  Problem p;
  p.mesh = prepare_mesh("loop_kl", make_grid(0.1, 0.1, 4, 4), {});
  p.material.stretch_modulus = 5000.0;
  p.material.bending_rigidity = 1e-4;
  p.material.poisson_ratio = 0.25;
  p.material.areal_density = 0.12;
  return p;
}

TEST(Setup, MakesTheNamedDiscretisationAndRejectsUnknownOnes) {
  const std::vector<std::string> methods = discretization_methods();
  ASSERT_NE(std::find(methods.begin(), methods.end(), "loop_kl"), methods.end());
  Problem p = small_plate();
  const std::shared_ptr<Discretization> d = make_discretization(p);
  EXPECT_EQ(d->method(), "loop_kl");
  EXPECT_EQ(d->num_nodes(), p.mesh.num_vertices());

  p.method = "mass_springs_of_the_future";
  try {
    make_discretization(p);
    FAIL() << "an unknown method was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("\"mass_springs_of_the_future\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("loop_kl"), std::string::npos) << e.what();  // lists the known ones
  }
  EXPECT_THROW(prepare_mesh("nope", p.mesh, {}), std::invalid_argument);
}

// The loads of a problem sum to their totals in both gravity models (lumped: exactly m g; the
// point load exactly), are ramped, and are absent when the problem has none.
TEST(Setup, ExternalLoadsOfAProblemSumToTheirTotals) {
  Problem p = small_plate();
  const std::shared_ptr<Discretization> d = make_discretization(p);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(3 * d->num_nodes());
  EXPECT_TRUE(make_external_loads(*d, p, GravityModel::lumped, 0.0)->empty());

  p.gravity = Eigen::Vector3d(0, 0, -9.81);
  p.point_loads = {{12, Eigen::Vector3d(0.5, 0, -1)}};
  const double mass = d->lumped_mass(p.material.areal_density).sum();
  EXPECT_NEAR(mass, 0.12 * 0.01, 1e-15);
  for (const GravityModel model : {GravityModel::lumped, GravityModel::consistent}) {
    const std::unique_ptr<ExternalLoads> loads = make_external_loads(*d, p, model, /*ramp_time=*/0.5);
    ASSERT_FALSE(loads->empty());
    loads->update(d->rest(), zero, 0.25);  // half way up the ramp
    EXPECT_DOUBLE_EQ(loads->ramp(), 0.5);
    Eigen::VectorXd f = zero;
    loads->add_force(f);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int v = 0; v < d->num_nodes(); ++v) sum += f.segment<3>(3 * v);
    const Eigen::Vector3d total = 0.5 * (mass * p.gravity + p.point_loads[0].force);
    // Lumped gravity is a partition of the control mesh's area; the consistent load integrates
    // over the limit surface, 1.8 % smaller at this coarse plate's free borders.
    const double tolerance = model == GravityModel::lumped ? 1e-14 : 0.02 * total.norm();
    EXPECT_NEAR(sum.x(), total.x(), tolerance);
    EXPECT_NEAR(sum.z(), total.z(), tolerance);
  }
}

}  // namespace
}  // namespace clothsim

// A force term added by a test, without touching the integrator: a zero-length spring that ties
// one node to a fixed point (E = ½ k |x_n − p|², f = −k (x_n − p), K = k I on the node's block).
// It passes the same finite-difference checks as the built-in terms, and a free plate hung from it
// under gravity settles where the spring carries the plate's weight.
#include "sim/loop_shell/loop_shell.hpp"
#include "sim/dynamics/simulator.hpp"
#include "sim/forces/damping.hpp"
#include "sim/mesh/generators.hpp"
#include "tests/support/fd_check.hpp"

#include <gtest/gtest.h>

namespace clothsim {
namespace {

class AnchorSpring final : public ForceTerm {
 public:
  // `k` [N/m], `anchor` [m]; `pattern`: the system matrix pattern (for the node's diagonal block).
  AnchorSpring(int node, const Eigen::Vector3d& anchor, double k, const Eigen::SparseMatrix<double>& pattern)
      : node_(node), anchor_(anchor), k_(k), diagonal_(diagonal_offsets(pattern)) {}
  std::string name() const override { return "anchor spring"; }
  void update(const Eigen::VectorXd& x, const Eigen::VectorXd&, double) override { stretch_ = x.segment<3>(3 * node_) - anchor_; }
  bool has_energy() const override { return true; }
  double energy() const override { return 0.5 * k_ * stretch_.squaredNorm(); }
  void add_force(Eigen::VectorXd& f) const override { f.segment<3>(3 * node_) -= k_ * stretch_; }
  bool has_matrix() const override { return true; }
  void add_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const override {
    for (int c = 0; c < 3; ++c) a.valuePtr()[diagonal_[static_cast<size_t>(3 * node_ + c)]] += w.stiffness * k_;
  }
  Eigen::Vector3d force() const { return -k_ * stretch_; }

 private:
  int node_;
  Eigen::Vector3d anchor_;
  double k_;
  std::vector<Eigen::Index> diagonal_;
  Eigen::Vector3d stretch_ = Eigen::Vector3d::Zero();
};

Problem hanging_plate() {
  Problem p;
  p.mesh = make_grid(0.1, 0.1, 4, 4);
  p.material.stretch_modulus = 5000.0;
  p.material.bending_rigidity = 0.1;  // a stiff plate: it hangs nearly flat
  p.material.poisson_ratio = 0.25;
  p.material.areal_density = 0.12;
  p.gravity = Eigen::Vector3d(0, 0, -9.81);
  p.damping.mass = 20.0;  // [1/s]: settles within a second
  p.time.dt = 0.01;
  p.time.end = 3.0;
  return p;
}

TEST(AddedTerm, AnchorSpringPassesTheFiniteDifferenceChecks) {
  const Problem p = hanging_plate();
  const LoopShellDiscretization d(p.mesh, {}, p.material, p.quadrature);
  AnchorSpring spring(12, Eigen::Vector3d(0.01, -0.02, 0.03), 7.0, d.matrix_pattern());
  for (unsigned seed : {1u, 2u}) {
    const Eigen::VectorXd x = testing::perturbed_rest(d, 0.01, seed);
    const testing::FdReport energy = testing::check_force_against_energy(spring, d, x, 1e-6);
    EXPECT_LT(energy.relative(), 1e-6) << energy.describe();
    const testing::FdReport matrix = testing::check_matrix_against_force(spring, d, x, 1e-6);
    EXPECT_LT(matrix.relative(), 1e-6) << matrix.describe();
  }
}

TEST(AddedTerm, PlateHungFromASpringSettlesWhereTheSpringCarriesItsWeight) {
  const Problem p = hanging_plate();
  Simulator sim(p);
  const int centre = 12;  // (0, 0, 0) of the 5 × 5 grid
  const double k = 10.0;  // [N/m]
  auto spring = std::make_unique<AnchorSpring>(centre, Eigen::Vector3d::Zero(), k, sim.discretization().matrix_pattern());
  const AnchorSpring* anchor = spring.get();
  sim.add_term(std::move(spring));
  EXPECT_THROW(sim.add_term(nullptr), std::invalid_argument);
  for (int s = 0; s < sim.num_steps(); ++s) sim.step();
  const double weight = sim.vertex_mass().sum() * 9.81;  // [N]
  // At rest the spring's pull balances the weight: a stretch of weight / k below the anchor.
  EXPECT_NEAR(anchor->force().z(), weight, 1e-4 * weight);
  EXPECT_NEAR(sim.state().positions()(centre, 2), -weight / k, 1e-4 * weight / k);
  EXPECT_LT(sim.kinetic_energy(), 1e-12);
  // The integrator counts the spring's energy with the cloth's own.
  EXPECT_GT(sim.elastic_energy(), 0.5 * k * (weight / k) * (weight / k) * 0.999);
}

}  // namespace
}  // namespace clothsim

// The smoothed-aggregation preconditioner (MultilevelPreconditioner) on the implicit-Euler matrix
// of a cotton sleeve at rest, A = M + h² K (h = 0.01 s, the timing scene's step; both rims held):
// it converges, it is deterministic, its iteration count does not grow with refinement, and a
// refresh equals a set-up on the same matrix.
#include "sim/mesh/generators.hpp"
#include "sim/mesh/mesh.hpp"
#include "sim/shell/material_presets.hpp"
#include "sim/shell/shell_model.hpp"
#include "sim/solver/multilevel_preconditioner.hpp"
#include "sim/solver/pcg.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace clothsim {
namespace {

struct ShellSystem {
  Eigen::SparseMatrix<double> a;
  std::vector<char> free;
  Eigen::VectorXd positions, b;
};

// The sleeve of scenes/sleeve_compress_2542.json (R = 5 cm, L = 20 cm, cotton) with `segments` ×
// `rings` vertices: A = M + h² K at rest, b a smooth load (M times a swirl of velocities).
ShellSystem sleeve_system(int segments, int rings) {
  const TriMesh mesh = make_cylinder(0.05, 0.2, segments, rings);
  BoundaryCondition rims;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (mesh.vertices(v, 1) < 1e-9 || mesh.vertices(v, 1) > 0.2 - 1e-9) rims.vertices.push_back(v);
  const ShellMaterial cotton = *material_preset("cotton");
  const ShellModel model(mesh, cotton, {rims}, Quadrature::one_point);
  const double h = 0.01;
  ShellSystem s;
  s.a = h * h * model.stiffness();
  const Eigen::VectorXd mass = lumped_vertex_mass(mesh, cotton.areal_density);
  const int n = mesh.num_vertices();
  s.free.assign(3 * static_cast<std::size_t>(n), 0);
  s.positions.resize(3 * n);
  s.b.resize(3 * n);
  for (int v = 0; v < n; ++v)
    for (int c = 0; c < 3; ++c) {
      const int i = 3 * v + c;
      s.a.coeffRef(i, i) += mass(v);
      s.free[static_cast<std::size_t>(i)] = model.dofs().is_free(v, c);
      s.positions(i) = mesh.vertices(v, c);
      const Eigen::Vector3d x = mesh.vertices.row(v);
      const Eigen::Vector3d swirl(std::sin(40 * x(1)) - x(2), 0.3 * std::cos(25 * x(0)), x(0) * std::cos(30 * x(1)));
      s.b(i) = mass(v) * swirl(c);
    }
  s.a.makeCompressed();
  return s;
}

int pcg_iterations(const ShellSystem& s, const Preconditioner& p, double tolerance = 1e-8) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(s.a.rows());
  const PcgResult r = solve_pcg(s.a, s.b, s.free, x, tolerance, 2000, p);
  EXPECT_TRUE(r.converged);
  // The true residual, not PCG's recurrence.
  const Eigen::VectorXd mask = free_mask(s.free);
  EXPECT_LT((s.a * x - s.b).cwiseProduct(mask).norm(), 1.1 * tolerance * s.b.cwiseProduct(mask).norm());
  return r.iterations;
}

Preconditioner as_function(const MultilevelPreconditioner& m) {
  return [&m](const Eigen::VectorXd& r, Eigen::VectorXd& z) { m.apply(r, z); };
}

TEST(MultilevelPreconditioner, ConvergesOnASleeveSystemFasterThanBlockJacobi) {
  const ShellSystem s = sleeve_system(32, 21);
  MultilevelPreconditioner m;
  EXPECT_FALSE(m.ready());
  ASSERT_TRUE(m.setup(s.a, s.free, s.positions));
  ASSERT_TRUE(m.ready());
  EXPECT_GE(m.levels(), 2);
  EXPECT_LT(m.level_sizes().back(), m.level_sizes().front() / 4);
  EXPECT_GT(m.operator_complexity(), 1.0);
  EXPECT_LT(m.operator_complexity(), 2.0);
  const int multilevel = pcg_iterations(s, as_function(m));
  const int jacobi = pcg_iterations(s, block_jacobi(s.a, s.free));
  EXPECT_LT(multilevel, 40);
  EXPECT_LT(3 * multilevel, jacobi);
  // Zero at the held rows, whatever r holds there.
  Eigen::VectorXd z;
  m.apply(Eigen::VectorXd::Ones(s.a.rows()), z);
  for (std::size_t i = 0; i < s.free.size(); ++i) {
    if (!s.free[i]) {
      EXPECT_EQ(z(static_cast<Eigen::Index>(i)), 0.0);
    }
  }
}

// Same inputs, same bytes: two set-ups, and one thread against all of them.
TEST(MultilevelPreconditioner, IsDeterministicForAnyNumberOfThreads) {
  const ShellSystem s = sleeve_system(48, 31);
  auto run = [&] {
    MultilevelPreconditioner m;
    EXPECT_TRUE(m.setup(s.a, s.free, s.positions));
    Eigen::VectorXd z;
    m.apply(s.b, z);
    return z;
  };
  const Eigen::VectorXd first = run(), second = run();
  Eigen::VectorXd single;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    single = run();
  }
  ASSERT_EQ(first.size(), s.a.rows());
  EXPECT_EQ(std::memcmp(first.data(), second.data(), sizeof(double) * static_cast<std::size_t>(first.size())), 0);
  EXPECT_EQ(std::memcmp(first.data(), single.data(), sizeof(double) * static_cast<std::size_t>(first.size())), 0);
  EXPECT_GT(first.norm(), 0.0);
}

// The sleeve at 16 × 11, 32 × 21 and 64 × 41 vertices (each one Loop refinement of the one
// before, 16 times the unknowns from first to last): the iteration count stays flat. Measured:
// see the test's output; block Jacobi, for contrast, grows with the mesh.
TEST(MultilevelPreconditioner, IterationsDoNotGrowWithRefinement) {
  std::vector<int> iterations, jacobi;
  MultilevelSettings settings;
  settings.coarse_size = 150;  // so that every size has at least two levels
  for (const auto& [segments, rings] : {std::pair{16, 11}, std::pair{32, 21}, std::pair{64, 41}, std::pair{128, 81}}) {
    const ShellSystem s = sleeve_system(segments, rings);
    MultilevelPreconditioner m(settings);
    ASSERT_TRUE(m.setup(s.a, s.free, s.positions));
    iterations.push_back(pcg_iterations(s, as_function(m)));
    jacobi.push_back(pcg_iterations(s, block_jacobi(s.a, s.free)));
    std::printf("sleeve %d x %d: %d unknowns, %d levels, multilevel %d iterations, block Jacobi %d\n", segments, rings,
                static_cast<int>(m.level_sizes().front()), m.levels(), iterations.back(), jacobi.back());
  }
  EXPECT_LE(iterations[3], iterations[0] + 6);
  EXPECT_LE(iterations[3], iterations[1] + 4);
  EXPECT_GT(jacobi[3], 2 * jacobi[0]);
}

// A refresh with the set-up's own matrix changes nothing; with a different matrix it follows it
// (the prolongators kept, the level matrices recomputed) and still converges.
TEST(MultilevelPreconditioner, RefreshKeepsTheHierarchy) {
  const ShellSystem s = sleeve_system(32, 21);
  MultilevelPreconditioner m;
  ASSERT_TRUE(m.setup(s.a, s.free, s.positions));
  Eigen::VectorXd before, after;
  m.apply(s.b, before);
  ASSERT_TRUE(m.refresh(s.a, /*galerkin=*/true));
  m.apply(s.b, after);
  EXPECT_EQ(std::memcmp(before.data(), after.data(), sizeof(double) * static_cast<std::size_t>(before.size())), 0);

  ShellSystem stiffer = s;  // twice the stiffness on top of the same mass
  stiffer.a = 2.0 * s.a;
  const std::vector<long> sizes = m.level_sizes();
  ASSERT_TRUE(m.refresh(stiffer.a, /*galerkin=*/true));
  EXPECT_EQ(m.level_sizes(), sizes);
  EXPECT_LT(pcg_iterations(stiffer, as_function(m)), 40);
  ASSERT_TRUE(m.refresh(stiffer.a, /*galerkin=*/false));  // level 0 only
  EXPECT_LT(pcg_iterations(stiffer, as_function(m)), 40);
}

TEST(MultilevelPreconditioner, SettingsFromText) {
  const MultilevelSettings s = parse_multilevel_settings("threshold=0.05 smoothing_steps=3 cycle=2");
  EXPECT_EQ(s.threshold, 0.05);
  EXPECT_EQ(s.smoothing_steps, 3);
  EXPECT_EQ(s.cycle, 2);
  EXPECT_EQ(s.near_null_space, MultilevelSettings{}.near_null_space);
  EXPECT_THROW(parse_multilevel_settings("threshod=0.05"), std::invalid_argument);
  EXPECT_THROW(parse_multilevel_settings("threshold=abc"), std::invalid_argument);
  EXPECT_THROW(parse_multilevel_settings("threshold"), std::invalid_argument);
}

}  // namespace
}  // namespace clothsim

// The ghost layer, Loop refinement on load, and consistent loads of the shell model.
#include "sim/mesh/generators.hpp"
#include "sim/shell/shell_model.hpp"
#include "sim/loop_shell/loop_shell.hpp"
#include "sim/static/static_solve.hpp"
#include "sim/subdivision/loop.hpp"
#include "tests/support/test_meshes.hpp"

#include <gtest/gtest.h>

#include <random>

namespace clothsim {
namespace {

ShellMaterial cloth() {
  ShellMaterial m;
  m.stretch_modulus = 1000;
  m.bending_rigidity = 1e-3;
  m.poisson_ratio = 0.3;
  m.areal_density = 0.2;
  return m;
}

TEST(GhostLayer, OneGhostPerBorderEdgeAndClosedRings) {
  const TriMesh grid = make_grid(1.0, 0.5, 6, 3);
  const ExtendedMesh ext = build_ghost_layer(grid);
  EXPECT_EQ(ext.ghosts.size(), static_cast<size_t>(2 * (6 + 3)));
  const Topology real(grid.num_vertices(), grid.triangles);
  for (int v = 0; v < grid.num_vertices(); ++v) {
    EXPECT_FALSE(ext.topology.is_boundary(v)) << "vertex " << v;
    if (real.is_boundary(v))
      EXPECT_EQ(ext.topology.valence(v), real.num_incident_triangles(v) + 3) << "vertex " << v;
    else
      EXPECT_EQ(ext.topology.valence(v), real.valence(v));
  }
  for (size_t k = 0; k < ext.ghosts.size(); ++k) {
    const GhostVertex& g = ext.ghosts[k];
    const Eigen::RowVector3d expect = grid.vertices.row(g.a) + grid.vertices.row(g.b) - grid.vertices.row(g.c);
    EXPECT_LT((ext.rest.row(ext.num_real + static_cast<Eigen::Index>(k)) - expect).norm(), 1e-15);
    EXPECT_EQ(real.opposite(g.a, g.b), g.c);
  }
  // Straight borders of a regular grid are regular after the ghost layer; only corners are not.
  int irregular = 0;
  for (int v = 0; v < grid.num_vertices(); ++v) irregular += ext.topology.valence(v) != 6;
  EXPECT_EQ(irregular, 4);
}

TEST(GhostLayer, ValenceAboveTwelveIsRejectedNamingTheVertex) {
  const TriMesh disc = testing::make_fan_disc(13, 3);
  try {
    build_ghost_layer(disc);
    FAIL() << "valence 13 accepted";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 0 has valence 13"), std::string::npos) << e.what();
  }
}

TEST(LoopSubdivision, RefinedMeshHasTheSameLimitPoints) {
  // Limit masks are the fixed point of the subdivision masks: the limit point of an old interior
  // vertex is the same before and after one refinement.
  TriMesh disc = testing::make_fan_disc(5, 4);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> noise(-0.05, 0.05);
  for (int v = 0; v < disc.num_vertices(); ++v) disc.vertices(v, 2) = 0.3 * disc.vertices(v, 0) * disc.vertices(v, 1) + noise(rng);
  const TriMesh fine = loop_subdivide(disc);
  EXPECT_EQ(fine.num_triangles(), 4 * disc.num_triangles());
  const Topology coarse_top(disc.num_vertices(), disc.triangles), fine_top(fine.num_vertices(), fine.triangles);
  auto limit = [](const Topology& top, const Eigen::MatrixX3d& x, int v) {
    const int n = top.valence(v);
    const double w = limit_neighbour_weight(n);
    Eigen::RowVector3d p = (1 - n * w) * x.row(v);
    for (int r : top.ring(v)) p += w * x.row(r);
    return p;
  };
  int checked = 0;
  for (int v = 0; v < disc.num_vertices(); ++v) {
    if (coarse_top.is_boundary(v)) continue;
    bool ring_interior = true;
    for (int r : coarse_top.ring(v)) ring_interior = ring_interior && !coarse_top.is_boundary(r);
    if (!ring_interior) continue;
    EXPECT_LT((limit(coarse_top, disc.vertices, v) - limit(fine_top, fine.vertices, v)).norm(), 1e-14) << "vertex " << v;
    ++checked;
  }
  EXPECT_GT(checked, 10);
}

TEST(PrepareControlMesh, RefinesOnceWhenATriangleHasTwoIrregularVertices) {
  std::vector<std::string> log;
  const TriMesh coarse = make_grid(1.0, 1.0, 1, 1);  // every vertex is a corner
  const TriMesh prepared = LoopShellDiscretization::prepare_mesh(coarse, [&](const std::string& line) { log.push_back(line); });
  EXPECT_EQ(prepared.num_triangles(), 8);
  ASSERT_EQ(log.size(), 1u);
  EXPECT_NE(log[0].find("refined once by Loop subdivision"), std::string::npos) << log[0];
  // Crease rules keep a flat square flat and its corners in place.
  EXPECT_LT(prepared.vertices.col(2).cwiseAbs().maxCoeff(), 1e-15);
  for (int v = 0; v < 4; ++v) EXPECT_LT((prepared.vertices.row(v) - coarse.vertices.row(v)).norm(), 1e-15);
  // A regular grid is left alone.
  log.clear();
  const TriMesh grid = make_grid(1.0, 1.0, 8, 8);
  EXPECT_EQ(LoopShellDiscretization::prepare_mesh(grid, [&](const std::string& line) { log.push_back(line); }).num_vertices(),
            grid.num_vertices());
  EXPECT_TRUE(log.empty());
}

TEST(Loads, AreaLoadIntegratesToTotalForceOnFreeMeshes) {
  for (Quadrature rule : {Quadrature::one_point, Quadrature::three_point, Quadrature::six_point}) {
    const ShellModel plate(make_grid(2.0, 0.5, 8, 4), cloth(), {}, rule);
    const Eigen::Vector3d q(0.3, -0.2, -9.81 * 0.2);
    const Eigen::VectorXd f = plate.area_load(q);
    const Eigen::Vector3d total = f.reshaped(3, f.size() / 3).rowwise().sum();
    // Partition of unity, and ghost weights (1 + 1 − 1) that conserve force: the total is q
    // times the quadrature of the limit surface's area.
    double area = 0.0;
    for (const ShellElement& el : plate.elements()) {
      Eigen::MatrixX3d x(static_cast<Eigen::Index>(el.patch.size()), 3);
      for (size_t i = 0; i < el.patch.size(); ++i) x.row(static_cast<Eigen::Index>(i)) = plate.extended().rest.row(el.patch[i]);
      for (size_t k = 0; k < el.basis.size(); ++k) area += el.weights[k] * surface_point(el.basis[k], x).j;
    }
    EXPECT_LT((total - q * area).norm(), 1e-12 * q.norm()) << to_string(rule);
    // The limit surface of a flat grid differs from the control polygon only at the four
    // (irregular) corners.
    EXPECT_NEAR(area, 1.0, 0.02) << to_string(rule);
  }
}

TEST(Loads, PointLoadIsSpreadWithLimitWeightsAndSumsToTheForce) {
  const ShellModel plate(make_grid(1.0, 1.0, 6, 6), cloth(), {}, Quadrature::one_point);
  const Eigen::Vector3d force(1.0, -2.0, 3.0);
  for (int v : {0, 3, 24}) {  // corner, border, interior
    const Eigen::VectorXd f = plate.point_load(v, force);
    const Eigen::Vector3d total = f.reshaped(3, f.size() / 3).rowwise().sum();
    EXPECT_LT((total - force).norm(), 1e-14) << "vertex " << v;
  }
  // Interior regular vertex: 1/2 on itself, 1/12 on each neighbour.
  const Eigen::VectorXd f = plate.point_load(24, force);
  EXPECT_NEAR(f(3 * 24 + 2), 0.5 * force(2), 1e-15);
  for (int r : plate.extended().topology.ring(24)) EXPECT_NEAR(f(3 * r + 2), force(2) / 12, 1e-15);
}

TEST(Loads, FixedComponentsKeepTheirLoadUntilRestricted) {
  BoundaryCondition bc;
  bc.vertices = {0, 1, 2};
  bc.fix = {false, false, true};
  const ShellModel plate(make_grid(1.0, 1.0, 4, 4), cloth(), {bc}, Quadrature::one_point);
  Eigen::VectorXd f = plate.area_load(Eigen::Vector3d(1, 1, 1));
  // The load on a fixed component is the support's reaction share: present, then removed.
  for (int v : bc.vertices) EXPECT_GT(f(3 * v + 2), 0.0);
  plate.restrict_to_free(f);
  for (int v : bc.vertices) {
    EXPECT_EQ(f(3 * v + 2), 0.0);
    EXPECT_GT(f(3 * v + 0), 0.0);
  }
}

}  // namespace
}  // namespace clothsim

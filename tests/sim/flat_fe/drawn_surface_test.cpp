// What the pictures show ("render.surface", Discretization::drawn_display) and the membrane strain
// query (Discretization::max_membrane_strain):
//  - a flat method's Loop limit surface equals what loop_kl draws for the same mesh and node
//    positions (two code paths: the flat discretisation's ghost layer composed into its operator,
//    and the Loop shell's control net);
//  - on a planar grid the drawn limit points stay in the plane, and at an interior valence-6
//    vertex the limit point is the closed-form mask ½ p + (1/12) Σ neighbours;
//  - the default draws the method's own surface (linear_fe: the midpoint-refined flat triangles);
//  - the scene key's values and its error;
//  - principal Green strain of a 1 % stretch ((1.01² − 1)/2 = 0.01005), of a rigid rotation (0),
//    and the Loop shell's value against the corotational elements' strains.
#include "sim/corotation/corotational_elements.hpp"
#include "sim/flat_fe/flat_fe.hpp"
#include "sim/flat_fe/mass_spring.hpp"
#include "sim/loop_shell/loop_shell.hpp"
#include "sim/mesh/generators.hpp"

#include "tests/support/scene_files.hpp"
#include "tests/support/test_meshes.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace clothsim {
namespace {

ShellMaterial cloth() {
  ShellMaterial m;
  m.stretch_modulus = 5000.0;
  m.bending_rigidity = 1e-4;
  m.poisson_ratio = 0.25;
  m.areal_density = 0.12;
  return m;
}

// Rest positions moved by a smooth bend plus random noise of `noise` [m] per component.
Eigen::VectorXd deformed(const Eigen::VectorXd& rest, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-noise, noise);
  Eigen::VectorXd x = rest;
  for (Eigen::Index i = 0; i < x.size(); i += 3) {
    x(i + 2) += 0.3 * x(i) * x(i) - 0.2 * x(i) * x(i + 1);
    for (int k = 0; k < 3; ++k) x(i + k) += u(rng);
  }
  return x;
}

double max_abs(const Eigen::MatrixXd& m) { return m.size() ? m.cwiseAbs().maxCoeff() : 0.0; }

// (a) The flat methods' Loop limit surface is loop_kl's drawn surface for the same mesh and node
// positions (free borders): positions, normals and triangles, at refinement levels 0 to 2, on a
// grid, a fan disc with a valence-5 centre and an open cylinder (two border loops).
TEST(DrawnSurface, FlatMethodsLoopLimitSurfaceIsLoopKlsDrawnSurface) {
  const std::vector<std::pair<std::string, TriMesh>> meshes = {
      {"grid 6 x 5", make_grid(0.3, 0.25, 6, 5)},
      {"fan disc, valence-5 centre", testing::make_fan_disc(5, 3)},
      {"open cylinder", make_cylinder(0.1, 0.3, 12, 5)}};
  for (const auto& [name, mesh] : meshes) {
    ASSERT_EQ(LoopShellDiscretization::prepare_mesh(mesh, {}).num_vertices(), mesh.num_vertices())
        << name << ": loop_kl would refine it";
    const LinearFeDiscretization flat(mesh, {}, cloth());
    const MassSpringDiscretization springs(mesh, {}, cloth());
    const LoopShellDiscretization loop(mesh, {}, cloth(), Quadrature::one_point);
    const Eigen::VectorXd x = deformed(flat.rest(), 0.01, 11);
    for (int levels : {0, 1, 2}) {
      const SurfaceOperator mine = flat.drawn_display(levels, DrawnSurface::loop_limit);
      const SurfaceOperator theirs = loop.drawn_display(levels, DrawnSurface::method);
      ASSERT_EQ(mine.position.cols(), flat.num_nodes());  // an operator over the flat control net
      EXPECT_EQ(mine.triangles, theirs.triangles) << name;
      EXPECT_EQ(mine.levels, levels);
      Eigen::MatrixX3d p, n, q, m;
      mine.evaluate(flat.control_net(x), p, n);
      theirs.evaluate(loop.control_net(x), q, m);
      ASSERT_EQ(p.rows(), q.rows());
      const double dp = max_abs(p - q), dn = max_abs(n - m);
      std::printf("%s, levels %d: %d points; |flat loop_limit - loop_kl| positions %.1e m, normals %.1e\n",
                  name.c_str(), levels, mine.num_points(), dp, dn);
      EXPECT_LT(dp, 1e-12) << name << " levels " << levels;
      EXPECT_LT(dn, 1e-12) << name << " levels " << levels;
      // mass_spring shares the construction; loop_kl's loop_limit is its own surface.
      EXPECT_LT(max_abs(springs.drawn_display(levels, DrawnSurface::loop_limit).positions(springs.control_net(x)) - q), 1e-12);
      EXPECT_LT(max_abs(loop.drawn_display(levels, DrawnSurface::loop_limit).positions(loop.control_net(x)) - q), 1e-15);
    }
  }
}

// (b) A planar grid, tilted into a general plane: every drawn limit point lies in the plane with
// the plane's normal; with out-of-plane noise on the nodes, an interior valence-6 vertex's drawn
// point is ½ p + (1/12) Σ of its six edge neighbours (the closed-form Loop limit mask).
TEST(DrawnSurface, LoopLimitOfAPlanarGridStaysInItsPlaneAndUsesTheValenceSixMask) {
  const int nx = 6, ny = 6;
  TriMesh grid = make_grid(0.3, 0.3, nx, ny);
  const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()) *
                                Eigen::AngleAxisd(-0.7, Eigen::Vector3d(1, 1, 0).normalized()))
                                   .toRotationMatrix();
  const Eigen::Vector3d offset(0.1, -0.2, 0.3);
  for (Eigen::Index v = 0; v < grid.vertices.rows(); ++v)
    grid.vertices.row(v) = (tilt * grid.vertices.row(v).transpose() + offset).transpose();
  const Eigen::Vector3d normal = tilt.col(2);
  const LinearFeDiscretization flat(grid, {}, cloth());
  for (int levels : {0, 1, 2, 3}) {
    const SurfaceOperator op = flat.drawn_display(levels, DrawnSurface::loop_limit);
    Eigen::MatrixX3d p, n;
    op.evaluate(flat.control_net(flat.rest()), p, n);
    double off_plane = 0.0, normal_error = 0.0;
    for (Eigen::Index i = 0; i < p.rows(); ++i) {
      off_plane = std::max(off_plane, std::abs((p.row(i).transpose() - offset).dot(normal)));
      normal_error = std::max(normal_error, (n.row(i).transpose() - normal).norm());
    }
    std::printf("planar grid, levels %d: %d points, largest distance from the plane %.1e m, normal error %.1e\n", levels,
                op.num_points(), off_plane, normal_error);
    EXPECT_LT(off_plane, 1e-15);
    EXPECT_LT(normal_error, 1e-13);
  }
  // Noise along the normal; vertex (i, j) = (3, 2) is interior with valence 6.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  Eigen::VectorXd x = flat.rest();
  for (int v = 0; v < flat.num_nodes(); ++v) x.segment<3>(3 * v) += u(rng) * normal;
  const int centre = 2 * (nx + 1) + 3;
  std::set<int> ring;
  for (const Triangle& t : grid.triangles)
    for (int k = 0; k < 3; ++k)
      if (t[k] == centre) {
        ring.insert(t[(k + 1) % 3]);
        ring.insert(t[(k + 2) % 3]);
      }
  ASSERT_EQ(ring.size(), 6u);
  Eigen::Vector3d expected = 0.5 * x.segment<3>(3 * centre);
  for (int v : ring) expected += x.segment<3>(3 * v) / 12.0;
  // The drawn point at the vertex: corner 0 of the first fine triangle of a mesh triangle whose
  // corner 0 is the vertex (its descendants keep corner 0 there).
  size_t first = grid.triangles.size();
  for (size_t t = 0; t < grid.triangles.size() && first == grid.triangles.size(); ++t)
    if (grid.triangles[t][0] == centre) first = t;
  ASSERT_LT(first, grid.triangles.size());
  for (int levels : {0, 1, 2}) {
    const SurfaceOperator op = flat.drawn_display(levels, DrawnSurface::loop_limit);
    const Eigen::MatrixX3d p = op.positions(flat.control_net(x));
    const int point = op.triangles[first << (2 * levels)][0];
    const double error = (p.row(point).transpose() - expected).norm();
    std::printf("valence-6 vertex, levels %d: |drawn point - (p/2 + sum/12)| = %.1e m\n", levels, error);
    EXPECT_LT(error, 1e-15);
  }
}

// (d) The default (render.surface "method") draws each method's own surface: for linear_fe the flat
// triangles, midpoint-refined (level 1 checked against the triangles' corners and edge midpoints);
// for loop_kl its limit surface. "flat" draws loop_kl's control mesh flat.
TEST(DrawnSurface, DefaultIsTheMethodsOwnSurface) {
  EXPECT_EQ(RenderSettings{}.surface, DrawnSurface::method);
  const TriMesh grid = make_grid(0.2, 0.2, 4, 3);
  const LinearFeDiscretization flat(grid, {}, cloth());
  const LoopShellDiscretization loop(grid, {}, cloth(), Quadrature::one_point);
  const Eigen::VectorXd x = deformed(flat.rest(), 0.01, 5);
  const SurfaceOperator one = flat.drawn_display(1, RenderSettings{}.surface);
  const Eigen::MatrixX3d p = one.positions(flat.control_net(x));
  double worst = 0.0;
  for (size_t t = 0; t < grid.triangles.size(); ++t) {
    const Triangle& c = grid.triangles[t];
    auto at = [&](int v) { return Eigen::Vector3d(x.segment<3>(3 * v)); };
    const Eigen::Vector3d ab = 0.5 * (at(c[0]) + at(c[1])), bc = 0.5 * (at(c[1]) + at(c[2])), ca = 0.5 * (at(c[2]) + at(c[0]));
    const Eigen::Vector3d expected[4][3] = {{at(c[0]), ab, ca}, {at(c[1]), bc, ab}, {at(c[2]), ca, bc}, {ab, bc, ca}};
    for (size_t k = 0; k < 4; ++k)
      for (size_t i = 0; i < 3; ++i)
        worst = std::max(worst, (p.row(one.triangles[4 * t + k][i]).transpose() - expected[k][i]).norm());
  }
  std::printf("linear_fe default, level 1: largest distance from the flat triangles' midpoint refinement %.1e m\n", worst);
  EXPECT_LT(worst, 1e-15);
  for (int levels : {0, 2}) {
    EXPECT_EQ(max_abs(flat.drawn_display(levels, DrawnSurface::method).positions(flat.control_net(x)) -
                      flat.drawn_display(levels, DrawnSurface::flat).positions(flat.control_net(x))),
              0.0);
    const Eigen::MatrixX3d limit = loop.display(levels).positions(loop.control_net(x));
    EXPECT_EQ(max_abs(loop.drawn_display(levels, DrawnSurface::method).positions(loop.control_net(x)) - limit), 0.0);
    // loop_kl drawn flat: its control mesh's (the nodes') flat triangles.
    const SurfaceOperator loop_flat = loop.drawn_display(levels, DrawnSurface::flat);
    EXPECT_EQ(loop_flat.position.cols(), loop.control_net(x).rows());
    EXPECT_LT(max_abs(loop_flat.positions(loop.control_net(x)) - flat.display(levels).positions(flat.control_net(x))), 1e-15);
    EXPECT_EQ(loop_flat.triangles, flat.display(levels).triangles);
    // A curved control net: the limit surface is not the flat one.
    EXPECT_GT(max_abs(limit - loop_flat.positions(loop.control_net(x))), 1e-4);
  }
  EXPECT_EQ(resolve_drawn_surface("linear_fe", DrawnSurface::method), DrawnSurface::flat);
  EXPECT_EQ(resolve_drawn_surface("mass_spring", DrawnSurface::method), DrawnSurface::flat);
  EXPECT_EQ(resolve_drawn_surface("loop_kl", DrawnSurface::method), DrawnSurface::loop_limit);
  EXPECT_EQ(drawn_surface_description("linear_fe", DrawnSurface::method, 2), "flat mesh refined 2x");
  EXPECT_EQ(drawn_surface_description("linear_fe", DrawnSurface::loop_limit, 3), "Loop limit surface refined 3x");
  EXPECT_EQ(drawn_surface_description("loop_kl", DrawnSurface::method, 0), "Loop limit surface refined 0x");
  EXPECT_EQ(drawn_surface_description("loop_kl", DrawnSurface::flat, 1), "flat mesh refined 1x");
}

// (c) The scene key: its values, and the error for anything else, naming the key and the values.
class RenderSurfaceKey : public testing::SceneFileTest {};

TEST_F(RenderSurfaceKey, ReadsTheValuesAndRejectsOthers) {
  const std::string head = R"({"method": "linear_fe", "mesh": {"primitive": "grid", "size": [1, 1], "divisions": [2, 2]}, )";
  EXPECT_EQ(load(head + R"("render": {}})").render.surface, DrawnSurface::method);
  EXPECT_EQ(load(head + R"("render": {"surface": "method"}})").render.surface, DrawnSurface::method);
  EXPECT_EQ(load(head + R"("render": {"surface": "loop_limit"}})").render.surface, DrawnSurface::loop_limit);
  EXPECT_EQ(load(head + R"("render": {"surface": "flat"}})").render.surface, DrawnSurface::flat);
  const std::string bad = error(head + R"("render": {"surface": "smooth"}})");
  std::printf("%s\n", bad.c_str());
  EXPECT_EQ(bad, expected(R"(render.surface: unknown surface "smooth" (allowed: "method", "loop_limit", "flat"))"));
  EXPECT_EQ(error(head + R"("render": {"surface": 1}})"),
            expected(R"(render.surface: expected a string (got 1; allowed: "method", "loop_limit", "flat"))"));
}

// Membrane strain of the flat triangles: a uniform 1 % stretch along x gives the principal Green
// strain ((1.01)² − 1)/2 = 0.01005 exactly, a rigid rotation (with a translation) 0; mass_spring
// reports the same (the query belongs to the flat triangles). On a lattice of equilateral
// triangles too, with the stretch along a direction that is no edge.
TEST(MembraneStrain, FlatTrianglesGiveTheGreenStrainOfAStretchAndZeroForARotation) {
  const double expected = (1.01 * 1.01 - 1.0) / 2.0;
  for (const TriMesh& mesh : {make_grid(0.3, 0.2, 6, 4), testing::make_lattice(5, 0.2)}) {
    const LinearFeDiscretization flat(mesh, {}, cloth());
    const MassSpringDiscretization springs(mesh, {}, cloth());
    const Eigen::Vector3d dir = Eigen::Vector3d(1.0, 0.3, 0.0).normalized();
    for (const Eigen::Vector3d& d : {Eigen::Vector3d(Eigen::Vector3d::UnitX()), dir}) {
      Eigen::VectorXd u(flat.rest().size());
      for (int v = 0; v < flat.num_nodes(); ++v) u.segment<3>(3 * v) = 0.01 * d * d.dot(flat.rest().segment<3>(3 * v));
      const double strain = flat.max_membrane_strain(u);
      std::printf("stretch 1 %% along (%.3f, %.3f): max principal Green strain %.17g (expected %.17g)\n", d(0), d(1),
                  strain, expected);
      EXPECT_NEAR(strain, expected, 1e-15);
      EXPECT_NEAR(springs.max_membrane_strain(u), expected, 1e-15);
    }
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, -0.5, 1).normalized())).toRotationMatrix();
    Eigen::VectorXd u(flat.rest().size());
    for (int v = 0; v < flat.num_nodes(); ++v) {
      const Eigen::Vector3d p = flat.rest().segment<3>(3 * v);
      u.segment<3>(3 * v) = r * p + Eigen::Vector3d(0.3, -1, 2) - p;
    }
    const double rigid = flat.max_membrane_strain(u);
    std::printf("rigid rotation: max principal Green strain %.1e\n", rigid);
    EXPECT_LT(rigid, 1e-14);
    EXPECT_LT(flat.max_membrane_strain(Eigen::VectorXd::Zero(flat.rest().size())), 1e-15);
    // Stretch and shear by hand on one triangle: F = [[1.02, 0.01], [0, 0.99]] in the plane gives
    // E = ½(FᵀF − I) = [[0.0202, 0.0051], [0.0051, -0.0099]]·… (eigenvalues below).
    Eigen::Matrix2d f;
    f << 1.02, 0.01, 0.0, 0.99;
    const Eigen::Matrix2d e = 0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity());
    const double mean = 0.5 * (e(0, 0) + e(1, 1)), radius = std::hypot(0.5 * (e(0, 0) - e(1, 1)), e(0, 1));
    const double by_hand = std::max(std::abs(mean + radius), std::abs(mean - radius));
    for (int v = 0; v < flat.num_nodes(); ++v) {
      const Eigen::Vector3d p = flat.rest().segment<3>(3 * v);
      u.segment<3>(3 * v) << f(0, 0) * p(0) + f(0, 1) * p(1) - p(0), f(1, 0) * p(0) + f(1, 1) * p(1) - p(1), 0.0;
    }
    EXPECT_NEAR(flat.max_membrane_strain(u), by_hand, 1e-15);
  }
}

// The Loop shell's strain: the corotational elements' principal strains (the value the
// simulator reported before the query moved to the discretisation) on a random deformation of a
// grid and of a fan disc; and a 1 % stretch of the grid (free borders: the ghosts follow affinely).
TEST(MembraneStrain, LoopShellAgreesWithTheCorotationalElements) {
  for (const TriMesh& mesh : {make_grid(0.3, 0.2, 6, 4), testing::make_fan_disc(5, 3)}) {
    const LoopShellDiscretization loop(mesh, {}, cloth(), Quadrature::three_point);
    const CorotationalElements elements(loop.model(), true);
    const Eigen::VectorXd u = deformed(loop.rest(), 0.005, 21) - loop.rest();
    const double before = elements.membrane_principal_strains(u).cwiseAbs().maxCoeff();
    const double now = loop.max_membrane_strain(u);
    std::printf("loop_kl random deformation: corotational elements %.17g, discretisation %.17g\n", before, now);
    EXPECT_GT(before, 1e-3);
    EXPECT_NEAR(now, before, 1e-13 * before);
  }
  const LoopShellDiscretization loop(make_grid(0.3, 0.2, 6, 4), {}, cloth(), Quadrature::one_point);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(loop.rest().size());
  for (int v = 0; v < loop.num_nodes(); ++v) u(3 * v) = 0.01 * loop.rest()(3 * v);
  EXPECT_NEAR(loop.max_membrane_strain(u), (1.01 * 1.01 - 1.0) / 2.0, 1e-14);
}

}  // namespace
}  // namespace clothsim

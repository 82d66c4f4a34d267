// The linear_fe discretisation (sim/flat_fe/flat_fe.hpp) through the Discretization interface:
// mesh preparation, DOF status and the boundary conditions it refuses, the rigid motions the
// constraints leave free (the same answers as loop_kl), lumped mass and consistent loads, and the
// surface operators — node points, samples, the display refinement (loop_kl's triangle and point
// numbering, flat positions and facet normals), point forces and the point Jacobian.
#include "sim/flat_fe/flat_fe.hpp"
#include "sim/loop_shell/loop_shell.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/setup/setup.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
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

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

Eigen::VectorXd deformed(const Discretization& d, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  Eigen::VectorXd x = d.rest();
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) += u(rng);
  return x;
}

TEST(LinearFeDiscretization, PrepareMeshKeepsTheMeshAndChecksIt) {
  const TriMesh grid = make_grid(0.1, 0.1, 3, 2);
  std::vector<std::string> log;
  const TriMesh prepared = prepare_mesh("linear_fe", grid, [&](const std::string& line) { log.push_back(line); });
  EXPECT_EQ(prepared.vertices, grid.vertices);
  EXPECT_EQ(prepared.triangles, grid.triangles);
  ASSERT_EQ(log.size(), 1u);
  EXPECT_TRUE(contains(log[0], "no refinement")) << log[0];
  std::printf("%s\n", log[0].c_str());
  TriMesh flipped = grid;
  std::swap(flipped.triangles[3][1], flipped.triangles[3][2]);  // inconsistent orientation
  EXPECT_THROW(prepare_mesh("linear_fe", flipped, {}), MeshError);
  TriMesh degenerate = grid;
  degenerate.triangles[0][2] = degenerate.triangles[0][1];
  EXPECT_THROW(prepare_mesh("linear_fe", degenerate, {}), MeshError);
}

TEST(LinearFeDiscretization, BoundaryConditionsFixComponentsAndRefuseClampedAndSymmetryBorders) {
  const TriMesh grid = make_grid(0.1, 0.1, 3, 3);
  BoundaryCondition held;
  held.vertices = {0, 1, 2, 3};
  held.fix = {false, true, true};
  const LinearFeDiscretization d(grid, {held}, cloth());
  int fixed = 0;
  for (int dof = 0; dof < 3 * d.num_nodes(); ++dof) {
    EXPECT_NE(d.status(dof), DofStatus::dependent);
    fixed += d.status(dof) == DofStatus::fixed;
  }
  EXPECT_EQ(fixed, 8);
  EXPECT_EQ(d.status(3 * 2 + 0), DofStatus::free);
  EXPECT_EQ(d.status(3 * 2 + 1), DofStatus::fixed);
  Eigen::VectorXd u = Eigen::VectorXd::Random(3 * d.num_nodes());
  const Eigen::VectorXd before = u;
  d.make_consistent(u);
  EXPECT_EQ(u, before);  // nothing is derived

  for (const char* kind : {"clamped", "symmetry"}) {
    BoundaryCondition border = held;
    border.clamped = std::string(kind) == "clamped";
    border.symmetric = !border.clamped;
    try {
      LinearFeDiscretization bad(grid, {held, border}, cloth());
      FAIL() << kind << " was accepted";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      std::printf("%s\n", what.c_str());
      EXPECT_TRUE(contains(what, "boundary condition 1")) << what;
      EXPECT_TRUE(contains(what, std::string("\"") + kind + "\"")) << what;
      EXPECT_TRUE(contains(what, "linear_fe")) << what;
    }
  }
  BoundaryCondition outside;
  outside.vertices = {99};
  EXPECT_THROW(LinearFeDiscretization(grid, {outside}, cloth()), std::runtime_error);
}

// The rigid motions the fixed components leave free: as many as the Loop shell finds for the same
// (hinged) conditions, described in the same words.
TEST(LinearFeDiscretization, UnrestrainedRigidMotionsMatchTheLoopShell) {
  const TriMesh grid = make_grid(0.2, 0.1, 4, 2);
  auto line = [&](double x) {
    std::vector<int> out;
    for (int v = 0; v < grid.num_vertices(); ++v)
      if (std::abs(grid.vertices(v, 0) - x) < 1e-9) out.push_back(v);
    return out;
  };
  BoundaryCondition left_z, right_z, left_all, corner_xy;
  left_z.vertices = line(-0.1);
  left_z.fix = {false, false, true};
  right_z.vertices = line(0.1);
  right_z.fix = {false, false, true};
  left_all.vertices = line(-0.1);
  corner_xy.vertices = {grid.num_vertices() - 1};
  corner_xy.fix = {true, true, false};
  const std::vector<std::vector<BoundaryCondition>> cases = {
      {}, {left_z}, {left_z, right_z}, {left_all}, {left_z, right_z, corner_xy}, {left_all, right_z}};
  const std::vector<size_t> expected_counts = {6, 4, 3, 1, 1, 0};
  for (size_t i = 0; i < cases.size(); ++i) {
    const LinearFeDiscretization flat(grid, cases[i], cloth());
    const LoopShellDiscretization loop(grid, cases[i], cloth(), Quadrature::one_point);
    const std::vector<std::string> a = flat.unrestrained_rigid_motions(), b = loop.unrestrained_rigid_motions();
    std::string list;
    for (const std::string& m : a) list += (list.empty() ? "" : "; ") + m;
    std::printf("case %zu: %zu free rigid motion(s): %s\n", i, a.size(), list.c_str());
    EXPECT_EQ(a.size(), expected_counts[i]) << "case " << i << ": " << list;
    // The same null space: its size, and its one mode where it has one (a larger null space may
    // come out in another basis).
    EXPECT_EQ(a.size(), b.size()) << "case " << i;
    if (a.size() == 1) {
      EXPECT_EQ(a, b) << "case " << i;
    }
  }
}

// Lumped mass: a third of each incident triangle's area; consistent loads: the same partition for
// a constant traction, and the facet normal for a pressure.
TEST(LinearFeDiscretization, LumpedMassAndTractionLoads) {
  TriMesh sleeve = make_cylinder(0.05, 0.1, 12, 5);
  const LinearFeDiscretization d(sleeve, {}, cloth());
  double area = 0.0;
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  for (const Triangle& t : sleeve.triangles) {
    const Eigen::Vector3d n = (sleeve.vertices.row(t[1]) - sleeve.vertices.row(t[0]))
                                  .cross(sleeve.vertices.row(t[2]) - sleeve.vertices.row(t[0]))
                                  .transpose();
    area += 0.5 * n.norm();
    normal_sum += 0.5 * n;
  }
  const Eigen::VectorXd mass = d.lumped_mass(0.12);
  EXPECT_NEAR(mass.sum(), 0.12 * area, 1e-15);
  EXPECT_GT(mass.minCoeff(), 0.0);
  const Eigen::Vector3d q(1.0, -2.0, 3.0);
  const Eigen::VectorXd f = d.traction_load([&](const Eigen::Vector3d&) { return q; });
  for (int v = 0; v < d.num_nodes(); ++v)
    EXPECT_LT((f.segment<3>(3 * v) - mass(v) / 0.12 * q).norm(), 1e-14) << "node " << v;
  // Pressure along the normal: each triangle contributes p·n·A/3 to its nodes; the sum is p Σ A n.
  Eigen::VectorXd pressure = d.traction_load([](const Eigen::Vector3d& n) -> Eigen::Vector3d { return 2.0 * n; });
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (int v = 0; v < d.num_nodes(); ++v) total += pressure.segment<3>(3 * v);
  EXPECT_LT((total - 2.0 * normal_sum).norm(), 1e-14);
  // Outward normals on the sleeve: the rim nodes are pushed away from the axis.
  const Eigen::Vector3d p0 = pressure.segment<3>(0), x0 = sleeve.vertices.row(0).transpose();
  EXPECT_GT(p0.dot(Eigen::Vector3d(x0.x(), 0, x0.z())), 0.0);
}

// Node points are the nodes; samples interpolate barycentrically; point forces are Jᵀ F; the
// points are affine in x with the Jacobian J.
TEST(LinearFeDiscretization, NodePointsSamplesPointForcesAndJacobian) {
  const LinearFeDiscretization d(make_grid(0.1, 0.1, 3, 3), {}, cloth());
  const Eigen::VectorXd x = deformed(d, 3);
  const SurfaceOperator nodes = d.node_points({5, 0, 15});
  const Eigen::MatrixX3d p = d.surface_positions(nodes, x);
  EXPECT_EQ(p.row(0), x.segment<3>(15).transpose());
  EXPECT_EQ(p.row(2), x.segment<3>(45).transpose());
  EXPECT_THROW(d.node_points({16}), std::out_of_range);

  const std::vector<SurfaceSample> where = {{4, 0.2, 0.3}, {0, 0.0, 0.0}, {17, 1.0, 0.0}, {9, 0.0, 1.0}};
  const SurfaceOperator samples = d.samples(where);
  const Eigen::MatrixX3d s = d.surface_positions(samples, x);
  for (size_t i = 0; i < where.size(); ++i) {
    const Triangle& t = d.mesh().triangles[static_cast<size_t>(where[i].triangle)];
    const Eigen::Vector3d expected = (1 - where[i].v - where[i].w) * x.segment<3>(3 * t[0]) + where[i].v * x.segment<3>(3 * t[1]) +
                                     where[i].w * x.segment<3>(3 * t[2]);
    EXPECT_LT((s.row(static_cast<Eigen::Index>(i)).transpose() - expected).norm(), 1e-15) << "sample " << i;
  }
  EXPECT_THROW(d.samples({{18, 0.1, 0.1}}), std::invalid_argument);

  const Eigen::SparseMatrix<double, Eigen::RowMajor> j = d.point_jacobian(samples);
  ASSERT_EQ(j.rows(), 3 * static_cast<Eigen::Index>(where.size()));
  ASSERT_EQ(j.cols(), 3 * d.num_nodes());
  const Eigen::VectorXd dx = deformed(d, 8) - d.rest();
  Eigen::VectorXd moved(3 * static_cast<Eigen::Index>(where.size()));
  RowMatrixX3d diff = d.surface_positions(samples, x + dx) - d.surface_positions(samples, x);
  for (Eigen::Index i = 0; i < diff.rows(); ++i) moved.segment<3>(3 * i) = diff.row(i).transpose();
  EXPECT_LT((moved - j * dx).cwiseAbs().maxCoeff(), 1e-15);

  Eigen::MatrixX3d forces = Eigen::MatrixX3d::Random(static_cast<Eigen::Index>(where.size()), 3);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * d.num_nodes());
  d.add_point_forces(samples, forces, f);
  Eigen::VectorXd flat_forces(3 * forces.rows());
  for (Eigen::Index i = 0; i < forces.rows(); ++i) flat_forces.segment<3>(3 * i) = forces.row(i).transpose();
  EXPECT_LT((f - j.transpose() * flat_forces).cwiseAbs().maxCoeff(), 1e-15);
  // Work: F · (J δx) = (Jᵀ F) · δx.
  EXPECT_NEAR(flat_forces.dot(j * dx), f.dot(dx), 1e-15);
}

// The display refinement uses loop_kl's conventions exactly: the same fine triangles over the same
// point numbering (so surface triangle i has fine triangles [i·4^L, (i+1)·4^L) and the children of
// t are 4t … 4t + 3), one point per position; the points lie on the flat triangles (midpoint
// subdivision) and interior points show their facet's normal.
TEST(LinearFeDiscretization, DisplayFollowsTheLoopShellConventionsOnTheFlatSurface) {
  const TriMesh grid = make_grid(0.1, 0.1, 4, 4);
  const LinearFeDiscretization flat(grid, {}, cloth());
  const LoopShellDiscretization loop(grid, {}, cloth(), Quadrature::one_point);
  const Eigen::VectorXd x = deformed(flat, 5);
  const Eigen::MatrixX3d net = flat.control_net(x);
  for (int levels : {0, 1, 2, 3}) {
    const SurfaceOperator a = flat.display(levels), b = loop.display(levels);
    EXPECT_EQ(a.levels, levels);
    EXPECT_EQ(a.triangles, b.triangles) << "levels " << levels;
    EXPECT_EQ(a.num_points(), b.num_points()) << "levels " << levels;
    ASSERT_EQ(a.triangles.size(), grid.triangles.size() << (2 * levels));
    Eigen::MatrixX3d p, n;
    a.evaluate(net, p, n);
    // One point per position.
    std::vector<std::array<double, 3>> keys;
    for (Eigen::Index i = 0; i < p.rows(); ++i) keys.push_back({p(i, 0), p(i, 1), p(i, 2)});
    std::sort(keys.begin(), keys.end());
    EXPECT_EQ(std::adjacent_find(keys.begin(), keys.end()), keys.end()) << "levels " << levels;
    const size_t per = size_t{1} << (2 * levels);
    double worst_plane = 0.0, worst_normal = 0.0, area_error = 0.0;
    for (size_t coarse = 0; coarse < grid.triangles.size(); ++coarse) {
      const Triangle& t = grid.triangles[coarse];
      const Eigen::Vector3d c0 = x.segment<3>(3 * t[0]), c1 = x.segment<3>(3 * t[1]), c2 = x.segment<3>(3 * t[2]);
      const Eigen::Vector3d facet = (c1 - c0).cross(c2 - c0);
      double fine_area = 0.0;
      for (size_t k = coarse * per; k < (coarse + 1) * per; ++k) {
        const Triangle& ft = a.triangles[k];
        const Eigen::Vector3d q0 = p.row(ft[0]), q1 = p.row(ft[1]), q2 = p.row(ft[2]);
        fine_area += 0.5 * (q1 - q0).cross(q2 - q0).dot(facet.normalized());
        for (const Eigen::Vector3d& q : {q0, q1, q2}) {
          // Barycentric coordinates in the coarse triangle: in [0, 1] and reproducing q.
          Eigen::Matrix<double, 3, 2> e;
          e << c1 - c0, c2 - c0;
          const Eigen::Vector2d vw = (e.transpose() * e).ldlt().solve(e.transpose() * (q - c0));
          worst_plane = std::max(worst_plane, (c0 + e * vw - q).norm());
          EXPECT_GE(std::min({vw(0), vw(1), 1 - vw(0) - vw(1)}), -1e-12);
        }
        // Points strictly inside the coarse triangle have its normal.
        for (int v : ft) {
          bool shared = false;
          for (size_t other = 0; other < grid.triangles.size() && !shared; ++other)
            if (other != coarse)
              for (size_t m = other * per; m < (other + 1) * per && !shared; ++m)
                for (int w : a.triangles[m]) shared = shared || w == v;
          if (!shared) worst_normal = std::max(worst_normal, (n.row(v).transpose() - facet.normalized()).norm());
        }
      }
      area_error = std::max(area_error, std::abs(fine_area - 0.5 * facet.norm()) / (0.5 * facet.norm()));
    }
    std::printf("display levels %d: %d points, %zu triangles; off-plane %.1e m, normal error %.1e, area error %.1e\n", levels,
                a.num_points(), a.triangles.size(), worst_plane, worst_normal, area_error);
    EXPECT_LT(worst_plane, 1e-15);
    EXPECT_LT(worst_normal, 1e-14);
    EXPECT_LT(area_error, 1e-12);  // the children tile their parent, none flipped
  }
  // Level 1 by hand: the children of triangle t = (a, b, c) are (a, ab, ca), (b, bc, ab),
  // (c, ca, bc), (ab, bc, ca) with the edge midpoints.
  const SurfaceOperator one = flat.display(1);
  Eigen::MatrixX3d p, n;
  one.evaluate(net, p, n);
  for (size_t t = 0; t < grid.triangles.size(); ++t) {
    const Triangle& c = grid.triangles[t];
    auto at = [&](int v) { return Eigen::Vector3d(x.segment<3>(3 * v)); };
    const Eigen::Vector3d mid_ab = 0.5 * (at(c[0]) + at(c[1])), mid_bc = 0.5 * (at(c[1]) + at(c[2])),
                          mid_ca = 0.5 * (at(c[2]) + at(c[0]));
    const Eigen::Vector3d expected[4][3] = {{at(c[0]), mid_ab, mid_ca}, {at(c[1]), mid_bc, mid_ab}, {at(c[2]), mid_ca, mid_bc},
                                            {mid_ab, mid_bc, mid_ca}};
    for (size_t k = 0; k < 4; ++k)
      for (size_t i = 0; i < 3; ++i)
        EXPECT_LT((p.row(one.triangles[4 * t + k][i]).transpose() - expected[k][i]).norm(), 1e-15) << t << " " << k << " " << i;
  }
  EXPECT_THROW(flat.display(-1), std::invalid_argument);
}

}  // namespace
}  // namespace clothsim

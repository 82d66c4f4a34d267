// The limit fit (sim/shell/fit_limit.hpp): the fitted control mesh's limit points, taken through
// the shell's own code path (ShellModel::limit_points on the ghost-layer rest net), are the input
// vertices on closed and open meshes; a fitted icosphere's limit surface stays on its sphere
// within the tessellation's sag while the unfitted one shrinks inside; a flat mesh stays flat
// (a regular grid is its own fit away from its four corners); fitting a control mesh's limit
// points gives it back; a closed mesh the shell refines on load keeps its fitted limit points
// through that refinement; meshes the fit cannot take are rejected naming the problem.
#include "sim/shell/fit_limit.hpp"

#include "sim/loop_shell/loop_shell.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/topology.hpp"
#include "sim/shell/ghost_layer.hpp"
#include "sim/shell/shell_model.hpp"
#include "sim/subdivision/limit_refinement.hpp"
#include "sim/subdivision/loop.hpp"
#include "sim/subdivision/patch.hpp"
#include "tests/support/test_meshes.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace clothsim {
namespace {

// The icosahedron (12 vertices of valence 5), radius 1, counter-clockwise seen from outside.
TriMesh icosahedron() {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriMesh m;
  m.vertices.resize(12, 3);
  m.vertices << -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, 0, 0, -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, t, 0, -1, t, 0, 1,
      -t, 0, -1, -t, 0, 1;
  m.vertices.rowwise().normalize();
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},   {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  return m;
}

// The icosahedron split `levels` times 1-to-4 at edge midpoints, every vertex pushed onto the
// sphere of the given radius [m] (the 12 original vertices keep valence 5, all others have 6).
TriMesh icosphere(int levels, double radius) {
  TriMesh m = icosahedron();
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> mid;
    std::vector<Eigen::RowVector3d> pts;
    for (int v = 0; v < m.num_vertices(); ++v) pts.push_back(m.vertices.row(v));
    auto midpoint = [&](int a, int b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto [it, inserted] = mid.emplace(key, static_cast<int>(pts.size()));
      if (inserted) pts.push_back((0.5 * (pts[static_cast<size_t>(a)] + pts[static_cast<size_t>(b)])).normalized());
      return it->second;
    };
    std::vector<Triangle> tris;
    for (const Triangle& t : m.triangles) {
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      tris.push_back({t[0], ab, ca});
      tris.push_back({t[1], bc, ab});
      tris.push_back({t[2], ca, bc});
      tris.push_back({ab, bc, ca});
    }
    m.triangles = std::move(tris);
    m.vertices.resize(static_cast<Eigen::Index>(pts.size()), 3);
    for (size_t i = 0; i < pts.size(); ++i) m.vertices.row(static_cast<Eigen::Index>(i)) = pts[i];
  }
  m.vertices *= radius;
  return m;
}

double diagonal(const TriMesh& m) {
  return (m.vertices.colwise().maxCoeff() - m.vertices.colwise().minCoeff()).norm();
}

// Limit points of the real vertices through the shell's own path: the ghost-layer rest net of
// the control mesh and ShellModel::limit_points.
Eigen::MatrixX3d shell_limit_points(const TriMesh& control) {
  const ShellModel model(control, ShellMaterial{}, {}, Quadrature::one_point);
  return model.limit_points(model.extended().rest);
}

double max_limit_error(const TriMesh& control, const TriMesh& target) {
  return (shell_limit_points(control) - target.vertices).rowwise().norm().maxCoeff();
}

// Largest and smallest distance from the origin of the limit surface of `control`, sampled by the
// project's limit refinement (`levels` Loop steps, then the limit masks).
std::pair<double, double> limit_radius_range(const TriMesh& control, int levels) {
  const ExtendedMesh ext = build_ghost_layer(control);
  const LimitRefinement r = build_limit_refinement(ext.rest, ext.triangles, ext.num_real_triangles, levels);
  Eigen::MatrixX3d p, n;
  evaluate_limit(r, ext.rest, p, n);
  const Eigen::VectorXd radius = p.rowwise().norm();
  return {radius.minCoeff(), radius.maxCoeff()};
}

// The same at the centre of every triangle, by direct evaluation of the element basis.
std::pair<double, double> centre_radius_range(const TriMesh& control) {
  const ExtendedMesh ext = build_ghost_layer(control);
  double lo = INFINITY, hi = 0;
  for (int t = 0; t < ext.num_real_triangles; ++t) {
    const PatchEvaluation e = evaluate_patch(ext.topology, ext.triangles[static_cast<size_t>(t)], 1.0 / 3, 1.0 / 3);
    Eigen::RowVector3d p = Eigen::RowVector3d::Zero();
    for (size_t k = 0; k < e.vertices.size(); ++k)
      p += e.basis(kValue, static_cast<Eigen::Index>(k)) * ext.rest.row(e.vertices[k]);
    lo = std::min(lo, p.norm());
    hi = std::max(hi, p.norm());
  }
  return {lo, hi};
}

TEST(FitLimit, LimitPointsOfAFittedClosedMeshAreItsVertices) {
  // A lumpy icosphere: 162 vertices (12 of valence 5) moved radially by up to ±10 %.
  TriMesh sphere = icosphere(2, 0.4);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> bump(0.9, 1.1);
  for (int v = 0; v < sphere.num_vertices(); ++v) sphere.vertices.row(v) *= bump(rng);
  const LimitFit fit = fit_limit(sphere);
  const double d = diagonal(sphere);
  EXPECT_LE(fit.residual, 1e-12);
  EXPECT_GE(fit.iterations, 1);
  EXPECT_EQ(fit.control.triangles, sphere.triangles);
  EXPECT_LT(max_limit_error(fit.control, sphere), 1e-9 * d);
  // The unfitted mesh's limit points are far from its vertices (the fit did something).
  EXPECT_GT(max_limit_error(sphere, sphere), 1e-3 * d);
}

TEST(FitLimit, LimitPointsOfAFittedOpenMeshAreItsVerticesAtBordersToo) {
  // A grid bent into a cylinder panel (corners of valence 4 and 5 with the ghost layer) with a
  // little noise, the same panel small and far from the origin, and a wavy disc with a valence-5
  // centre; the panel carries texture coordinates and warp directions that must come through.
  TriMesh panel = make_cylinder_panel(0.5, 0.8, 100.0, 12, 9);
  TriMesh disc = testing::make_fan_disc(5, 4);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> noise(-0.01, 0.01);
  for (int v = 0; v < disc.num_vertices(); ++v)
    disc.vertices(v, 2) = 0.2 * std::sin(3 * disc.vertices(v, 0)) * std::cos(2 * disc.vertices(v, 1)) + noise(rng);
  for (int v = 0; v < panel.num_vertices(); ++v)
    panel.vertices.row(v) += Eigen::RowVector3d(noise(rng), noise(rng), noise(rng));
  TriMesh far_panel = panel;
  far_panel.vertices = (far_panel.vertices * 1e-3).rowwise() + Eigen::RowVector3d(1e3, -2e3, 5e2);
  for (int t = 0; t < panel.num_triangles(); ++t) {
    panel.warp.emplace_back(1.0, 0.0, 0.0);
    panel.uv.push_back({Eigen::Vector2d(t, 0), Eigen::Vector2d(t, 1), Eigen::Vector2d(t + 1, 0)});
  }
  for (const TriMesh* mesh : {&panel, &disc, &far_panel}) {
    const LimitFit fit = fit_limit(*mesh);
    const double d = diagonal(*mesh);
    EXPECT_LE(fit.residual, 1e-12);
    const Eigen::MatrixX3d limit = shell_limit_points(fit.control);
    const Topology real(mesh->num_vertices(), mesh->triangles);
    double border = 0, interior = 0;
    for (int v = 0; v < mesh->num_vertices(); ++v) {
      double& worst = real.is_boundary(v) ? border : interior;
      worst = std::max(worst, (limit.row(v) - mesh->vertices.row(v)).norm() / d);
    }
    EXPECT_LT(border, 1e-9) << mesh->num_vertices() << " vertices";
    EXPECT_LT(interior, 1e-9) << mesh->num_vertices() << " vertices";
    EXPECT_GT(max_limit_error(*mesh, *mesh), 1e-4 * d);  // unfitted: visibly off
  }
  const LimitFit fit = fit_limit(panel);
  EXPECT_EQ(fit.control.warp, panel.warp);
  EXPECT_EQ(fit.control.uv, panel.uv);
}

TEST(FitLimit, FittedIcosphereLimitSurfaceStaysOnTheSphereWithinTheTessellationSag) {
  const double r = 0.3;
  const TriMesh sphere = icosphere(3, r);  // 642 vertices, 1280 triangles
  // The tessellation's own error: the chord sag of its widest edge, r (1 − cos(θ/2)).
  double theta = 0;
  for (const Triangle& t : sphere.triangles)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d a = sphere.vertices.row(t[k]), b = sphere.vertices.row(t[(k + 1) % 3]);
      theta = std::max(theta, std::acos(std::clamp(a.dot(b) / (r * r), -1.0, 1.0)));
    }
  const double sag = r * (1 - std::cos(theta / 2));
  const LimitFit fit = fit_limit(sphere);
  const auto [fit_lo, fit_hi] = limit_radius_range(fit.control, 3);
  const auto [raw_lo, raw_hi] = limit_radius_range(sphere, 3);
  const auto [fit_c_lo, fit_c_hi] = centre_radius_range(fit.control);
  const double fit_error = std::max(r - fit_lo, fit_hi - r), raw_error = std::max(r - raw_lo, raw_hi - r);
  std::printf("sphere r = %g m, %d vertices: edge angle %.4f rad, sag %.3e m; limit |‖p‖ − r| max: fitted %.3e m "
              "(radius %.6f..%.6f, triangle centres %.6f..%.6f), unfitted %.3e m (radius %.6f..%.6f)\n",
              r, sphere.num_vertices(), theta, sag, fit_error, fit_lo, fit_hi, fit_c_lo, fit_c_hi, raw_error, raw_lo,
              raw_hi);
  EXPECT_LE(fit_error, sag);
  EXPECT_LE(std::max(r - fit_c_lo, fit_c_hi - r), sag);
  // Unfitted: the whole limit surface lies inside the sphere, off by more than the sag.
  EXPECT_LT(raw_hi, r - sag);
  EXPECT_GT(raw_error, 5 * fit_error);
}

TEST(FitLimit, FlatMeshStaysFlatAndARegularGridIsItsOwnFitAwayFromItsCorners) {
  // A regular grid's extended net is an affine lattice everywhere except around its four corners,
  // where the ghost layer's one-ring is lopsided and the limit point is off the vertex; so the fit
  // moves the corners (in the plane) and the correction dies out geometrically away from them.
  const int nx = 16, ny = 12;
  const double h = 0.1;
  const TriMesh grid = make_grid(nx * h, ny * h, nx, ny);
  const LimitFit fit = fit_limit(grid);
  EXPECT_LT(fit.control.vertices.col(2).cwiseAbs().maxCoeff(), 1e-12);
  double corner_shift = INFINITY, far_shift = 0;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const int v = j * (nx + 1) + i;
      const double shift = (fit.control.vertices.row(v) - grid.vertices.row(v)).norm();
      // Edge steps to the nearest corner (the diagonals run from (i, j) to (i + 1, j + 1)).
      const int rings = std::min({std::max(i, j), std::max(nx - i, ny - j), nx - i + j, i + ny - j});
      if (rings == 0) corner_shift = std::min(corner_shift, shift);
      if (rings >= 6) far_shift = std::max(far_shift, shift);
    }
  std::printf("regular grid (h = %g m): smallest corner shift %.3e m, "
              "largest shift 6 or more rings from a corner %.3e m\n",
              h, corner_shift, far_shift);
  EXPECT_GT(corner_shift, 0.1 * h);
  EXPECT_LT(far_shift, 1e-2 * corner_shift);
  // An irregular flat mesh (jittered grid) stays in its plane too.
  const TriMesh jittered = testing::jittered_grid();
  EXPECT_LT(fit_limit(jittered).control.vertices.col(2).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(FitLimit, FittingTheLimitPointsOfAControlMeshGivesThatControlMeshBack) {
  // Round trip: X = limit points of P (the shell's path), then fit_limit(X) = P; and the fit
  // commutes with a rigid motion.
  TriMesh control = make_cylinder_panel(0.5, 0.8, 100.0, 12, 9);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(-0.02, 0.02);
  for (int v = 0; v < control.num_vertices(); ++v)
    control.vertices.row(v) += Eigen::RowVector3d(noise(rng), noise(rng), noise(rng));
  TriMesh limit = control;
  limit.vertices = shell_limit_points(control);
  const LimitFit fit = fit_limit(limit);
  const double d = diagonal(control);
  EXPECT_LT((fit.control.vertices - control.vertices).rowwise().norm().maxCoeff(), 1e-12 * d);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::RowVector3d shift(3, -1, 2);
  TriMesh moved = limit;
  moved.vertices = (limit.vertices * rotation.transpose()).rowwise() + shift;
  const LimitFit moved_fit = fit_limit(moved);
  const Eigen::MatrixX3d expect = (fit.control.vertices * rotation.transpose()).rowwise() + shift;
  EXPECT_LT((moved_fit.control.vertices - expect).rowwise().norm().maxCoeff(), 1e-12 * d);
}

TEST(FitLimit, ClosedMeshTheShellRefinesOnLoadKeepsItsFittedLimitPoints) {
  // A lumpy icosahedron: every triangle has three irregular vertices, so the shell refines it once
  // on load (prepare_mesh). Loop refinement keeps a closed mesh's limit surface, so the limit
  // points of the original vertices (which keep their ids) are still the targets, read through
  // the discretisation's node points on the control net it builds.
  TriMesh ico = icosahedron();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> bump(0.8, 1.2);
  for (int v = 0; v < ico.num_vertices(); ++v) ico.vertices.row(v) *= 0.25 * bump(rng);
  const LimitFit fit = fit_limit(ico);
  EXPECT_LE(fit.residual, 1e-12);
  std::string said;
  const TriMesh prepared =
      LoopShellDiscretization::prepare_mesh(fit.control, [&](const std::string& line) { said += line; });
  EXPECT_NE(said.find("refined once"), std::string::npos) << said;
  ASSERT_EQ(prepared.num_vertices(), 42);
  const LoopShellDiscretization shell(prepared, {}, ShellMaterial{}, Quadrature::one_point);
  std::vector<int> originals(12);
  for (int v = 0; v < 12; ++v) originals[static_cast<size_t>(v)] = v;
  const Eigen::MatrixX3d limit = shell.node_points(originals).position * shell.control_net(shell.rest());
  EXPECT_LT((limit - ico.vertices).rowwise().norm().maxCoeff(), 1e-9 * diagonal(ico));
}

TEST(FitLimit, RejectsMeshesItCannotFitNamingTheProblem) {
  auto message = [](const TriMesh& m) {
    try {
      fit_limit(m);
    } catch (const MeshError& e) {
      return std::string(e.what());
    }
    return std::string("no MeshError");
  };
  // An open pentagon fan: every vertex is irregular (the centre has valence 5, the rim vertices 2
  // triangles + 3 for the ghost layer), so the shell would refine it with its crease rule at the
  // border, which would move the fitted limit points.
  const TriMesh fan = testing::make_fan_disc(5, 1);
  const std::string irregular = message(fan);
  EXPECT_NE(irregular.find("triangle 0 (0, 1, 2) has more than one irregular vertex (valences 5, 5, 5"),
            std::string::npos)
      << irregular;
  EXPECT_NE(irregular.find("and so do 4 other triangle(s)"), std::string::npos) << irregular;
  EXPECT_NE(irregular.find("refine the mesh first"), std::string::npos) << irregular;
  // Once refined it fits.
  EXPECT_NO_THROW(fit_limit(loop_subdivide(fan)));
  // Three triangles on one edge.
  TriMesh fin;
  fin.vertices.resize(5, 3);
  fin.vertices << 0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, -1, 0, 0.5, 0, 1;
  fin.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const std::string fin_message = message(fin);
  EXPECT_NE(fin_message.find("non-manifold edge (0, 1)"), std::string::npos) << fin_message;
  // A position that is not a number.
  TriMesh nan = make_grid(1.0, 1.0, 3, 3);
  nan.vertices(5, 1) = NAN;
  const std::string nan_message = message(nan);
  EXPECT_NE(nan_message.find("vertex 5 has a non-finite position"), std::string::npos) << nan_message;
}

}  // namespace
}  // namespace clothsim

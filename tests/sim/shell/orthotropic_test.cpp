// The orthotropic (woven) Kirchhoff–Love material (docs/materials.md): the curvilinear transform
// against the law written in the orthonormal (warp, weft) frame, the isotropic limit against
// today's matrices, the corotated term's force and matrix against finite differences, a patch
// test on an irregular mesh, invariance under rotating mesh and grain together, strips along
// warp, weft and 45° against the orthotropic membrane and beam formulas, and a simply supported
// orthotropic plate against its Navier double series.
#include "sim/forces/corotated_shell.hpp"
#include "sim/loop_shell/loop_shell.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/scene/scene.hpp"
#include "sim/shell/element.hpp"
#include "sim/shell/shell_model.hpp"
#include "sim/static/static_solve.hpp"
#include "sim/study/plates.hpp"
#include "tests/support/fd_check.hpp"
#include "tests/support/strips.hpp"
#include "tests/support/term_states.hpp"
#include "tests/support/test_meshes.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace clothsim {
namespace {

// The woven example: stiff along the yarns, soft in shear.
Orthotropy woven() { return testing::woven_example(); }

ShellMaterial woven_material() {
  ShellMaterial m;
  set_orthotropy(m, woven());
  m.areal_density = 0.12;
  return m;
}

// Every triangle's warp along `dir`.
using testing::set_warp;

// A random point of a curved surface: tangents of any length and angle.
SurfacePoint random_point(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SurfacePoint s;
  s.a1 = Eigen::Vector3d(u(rng), u(rng), u(rng));
  s.a2 = Eigen::Vector3d(u(rng), u(rng), u(rng));
  const Eigen::Vector3d n = s.a1.cross(s.a2);
  s.j = n.norm();
  s.a3 = n / s.j;
  return s;
}

TEST(OrthotropicLaw, PlaneStressMatrixIsTheInverseOfTheCompliance) {
  // Independent: the compliance written from the engineering constants.
  const double ew = 5000, ef = 3000, g = 60, nu = 0.25;
  Eigen::Matrix3d compliance;
  compliance << 1 / ew, -nu / ew, 0, -nu / ew, 1 / ef, 0, 0, 0, 1 / g;
  EXPECT_LT((plane_stress_matrix(ew, ef, g, nu) * compliance - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  // ν_fw = ν_wf E_f/E_w: the weft contraction under warp stress is ν_wf, the warp contraction
  // under weft stress ν_fw.
  const Eigen::Matrix3d s = plane_stress_matrix(ew, ef, g, nu).inverse();
  EXPECT_NEAR(-s(1, 0) / s(0, 0), nu, 1e-14);
  EXPECT_NEAR(-s(0, 1) / s(1, 1), nu * ef / ew, 1e-14);
}

TEST(OrthotropicLaw, DefaultTwistIsTheIsotropicValueOfTheGeometricMean) {
  EXPECT_NEAR(default_twist(2e-5, 2e-5, 0.3), 2e-5 / 2.6, 1e-20);
  // B̄ = √(B_w B_f) = 2e-5, ν̄ = ν √(B_f/B_w) = 0.3 · 2 = 0.6... with B_w = 1e-5, B_f = 4e-5.
  EXPECT_NEAR(default_twist(1e-5, 4e-5, 0.3), 2e-5 / (2 * 1.6), 1e-20);
}

TEST(OrthotropicLaw, ValidationNamesTheIndefiniteLaw) {
  Orthotropy o = woven();
  EXPECT_EQ(validate(o), "");
  o.poisson = 1.3;  // ν² = 1.69 ≥ E_w/E_f = 1.67
  EXPECT_NE(validate(o).find("membrane law indefinite"), std::string::npos) << validate(o);
  o = woven();
  o.warp_bending = 0.5e-5;
  o.poisson = 0.8;  // ν² = 0.64 < 5/3 but ≥ B_w/B_f = 0.56
  EXPECT_NE(validate(o).find("bending law indefinite"), std::string::npos) << validate(o);
  o = woven();
  o.shear_stretch = 0;
  EXPECT_NE(validate(o).find("shear"), std::string::npos);
}

// H from curvilinear_matrix gives the energy density of the law: for a Cartesian strain e (2 × 2
// in the (g₁, g₂) frame) the covariant components are ε_αβ = (A_α·g_i) e_ij (A_β·g_j), and
// ½ εᵀ H ε (Voigt, engineering shear) must equal ½ eᵀ Q e.
TEST(OrthotropicLaw, CurvilinearMatrixCarriesTheEnergyOfTheFrameLaw) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Matrix3d q = plane_stress_matrix(5000, 3000, 60, 0.25);
  for (int trial = 0; trial < 50; ++trial) {
    const SurfacePoint s = random_point(rng);
    const Eigen::Vector3d warp(u(rng), u(rng), u(rng));
    const Eigen::Matrix3d h = curvilinear_matrix(s, warp, q);
    const Eigen::Vector3d g1 = (warp - warp.dot(s.a3) * s.a3).normalized(), g2 = s.a3.cross(g1);
    Eigen::Matrix2d e;
    e << u(rng), u(rng), 0, u(rng);
    e(1, 0) = e(0, 1);
    Eigen::Matrix2d basis;  // basis(α, i) = A_α · g_i
    basis << s.a1.dot(g1), s.a1.dot(g2), s.a2.dot(g1), s.a2.dot(g2);
    const Eigen::Matrix2d cov = basis * e * basis.transpose();
    const Eigen::Vector3d eps(cov(0, 0), cov(1, 1), 2 * cov(0, 1)), frame(e(0, 0), e(1, 1), 2 * e(0, 1));
    const double expected = 0.5 * frame.dot(q * frame);
    EXPECT_NEAR(0.5 * eps.dot(h * eps), expected, 1e-12 * std::abs(expected) + 1e-12) << "trial " << trial;
    EXPECT_LT((h - h.transpose()).norm(), 1e-12 * h.norm());
  }
}

TEST(OrthotropicLaw, IsotropicLimitReproducesTheIsotropicMatrices) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  ShellMaterial iso;
  iso.stretch_modulus = 5000;
  iso.bending_rigidity = 1.3e-5;
  iso.poisson_ratio = 0.3;
  ShellMaterial ortho = iso;
  ortho.orthotropy = isotropic_orthotropy(iso);  // (the representative fields stay those of iso)
  for (int trial = 0; trial < 50; ++trial) {
    const SurfacePoint s = random_point(rng);
    const Eigen::Vector3d warp(u(rng), u(rng), u(rng));
    Eigen::Matrix3d hm, hb;
    material_matrices(s, ortho, warp, hm, hb);
    const Eigen::Matrix3d h = material_matrix(s, iso.poisson_ratio);
    const Eigen::Matrix3d m = iso.membrane_stiffness() * h, b = iso.bending_stiffness() * h;
    EXPECT_LT((hm - m).norm(), 1e-13 * m.norm()) << "trial " << trial;
    EXPECT_LT((hb - b).norm(), 1e-13 * b.norm()) << "trial " << trial;
  }
  // The element matrices of a curved mesh, any grain.
  TriMesh mesh = make_cylinder(0.05, 0.1, 10, 5);
  set_warp(mesh, Eigen::Vector3d(0.3, 1.0, -0.2));
  const ShellModel a(mesh, iso, {}, Quadrature::three_point), b(mesh, ortho, {}, Quadrature::three_point);
  for (int e = 0; e < static_cast<int>(a.elements().size()); e += 7) {
    const Eigen::MatrixXd ka = a.patch_stiffness(e), kb = b.patch_stiffness(e);
    EXPECT_LT((ka - kb).norm(), 1e-12 * ka.norm()) << "element " << e;
  }
}

TEST(OrthotropicLaw, AMeshWithoutGrainOrAGrainAlongTheNormalIsRefused) {
  TriMesh mesh = make_grid(0.1, 0.1, 4, 4);
  EXPECT_THROW(ShellModel(mesh, woven_material(), {}, Quadrature::one_point), std::invalid_argument);
  set_warp(mesh, Eigen::Vector3d::UnitZ());
  try {
    ShellModel(mesh, woven_material(), {}, Quadrature::one_point);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("triangle 0"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// The corotated term with an orthotropic material: force = −∂E/∂x and matrix = −∂f/∂x with the
// rotations frozen, on a free plate with the grain at 30°, a clamped plate and a sleeve whose warp
// runs along the axis (all folded paths as in force_terms_test.cpp).

TEST(OrthotropicCorotatedShell, ForceAndMatrixMatchFiniteDifferencesWithFrozenRotations) {
  const double size = 0.1, eps = 1e-6;
  TriMesh plate = make_grid(size, size, 4, 4);
  set_warp(plate, Eigen::Vector3d(std::cos(0.5), std::sin(0.5), 0));
  ShellMaterial m = woven_material();
  m.orthotropy->warp_bending = 1e-4;  // bending matters as much as in force_terms_test
  m.orthotropy->weft_bending = 0.6e-4;
  m.orthotropy->twist = 0.3e-4;
  std::vector<std::pair<std::string, std::unique_ptr<LoopShellDiscretization>>> cases;
  cases.emplace_back("free plate", std::make_unique<LoopShellDiscretization>(plate, std::vector<BoundaryCondition>{}, m,
                                                                              Quadrature::one_point));
  BoundaryCondition clamp;
  clamp.vertices = select_box(plate.vertices, Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(-0.049, 1, 1));
  clamp.clamped = true;
  cases.emplace_back("clamped plate", std::make_unique<LoopShellDiscretization>(
                                          plate, std::vector<BoundaryCondition>{clamp}, m, Quadrature::three_point));
  TriMesh sleeve = make_cylinder(0.03, 0.06, 8, 4);
  set_warp(sleeve, Eigen::Vector3d::UnitY());
  BoundaryCondition bottom;
  bottom.vertices = select_box(sleeve.vertices, Eigen::Vector3d(-1, -1e-4, -1), Eigen::Vector3d(1, 1e-4, 1));
  cases.emplace_back("sleeve", std::make_unique<LoopShellDiscretization>(sleeve, std::vector<BoundaryCondition>{bottom}, m,
                                                                         Quadrature::one_point));
  int checked = 0, with_tension = 0;
  for (const auto& [name, d] : cases)
    for (const testing::State& state :
         testing::states(*d, {.random_states = 2, .fold_degrees = 170.0, .fold_from = 0.0, .fold_name = "near-folded"})) {
      CorotatedShell shell(d->model(), true, false);
      testing::update_at(shell, *d, state.x);
      shell.freeze_rotations(true);
      testing::FdReport energy = testing::check_force_against_energy(shell, *d, state.x, eps);
      energy.floor = 5e-10;
      EXPECT_LT(energy.relative(), 1e-6) << name << ", " << state.name << ": force vs energy: " << energy.describe();
      const testing::FdReport matrix = testing::check_matrix_against_force(shell, *d, state.x, eps);
      EXPECT_LT(matrix.relative(), 1e-6) << name << ", " << state.name << ": matrix vs force: " << matrix.describe();
      ++checked;
      // The tension stiffening (with it minus without it) is the Jacobian of the tension force
      // with the tensile membrane forces of the orthotropic law frozen.
      CorotatedShell with(d->model(), true, true), without(d->model(), true, false);
      const Eigen::MatrixXd k = testing::matrix_at(without, *d, state.x, {1.0, 0.0});
      const Eigen::MatrixXd g = testing::matrix_at(with, *d, state.x, {1.0, 0.0}) - k;
      if (g.cwiseAbs().maxCoeff() < 1e-12 * k.cwiseAbs().maxCoeff()) continue;  // no tension
      ++with_tension;
      // (Through a plain pointer: clang does not let a lambda capture a structured binding.)
      const LoopShellDiscretization* disc = d.get();
      const testing::FdReport t = testing::check_matrix_against_force(g, *d, state.x, eps, [&](const Eigen::VectorXd& y) {
        Eigen::VectorXd u = y - disc->rest();
        disc->make_consistent(u);
        return with.elements().tension_force(u);
      });
      EXPECT_LT(t.relative(), 1e-6) << name << ", " << state.name << ": tension stiffening: " << t.describe();
    }
  EXPECT_GE(checked, 9);
  EXPECT_GE(with_tension, 6);
}

// ---------------------------------------------------------------------------------------------
// Patch test: on an irregular (jittered) flat mesh with the grain at 20°, an affine in-plane
// displacement u = F x (every control value, ghosts included, on the affine field) is a state of
// constant strain: the internal force vanishes at every vertex not on the border, and the energy
// is ½ eᵀ Q e times the area (e the strain in the warp frame).
// A 0.12 m square of 12 × 12 cells whose interior vertices are moved in the plane by up to 20 % of
// a cell (seeded).
TriMesh jittered_square() {
  TriMesh m = make_grid(0.12, 0.12, 12, 12);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-0.002, 0.002);
  for (int v = 0; v < m.num_vertices(); ++v)
    if (std::abs(m.vertices(v, 0)) < 0.06 - 1e-9 && std::abs(m.vertices(v, 1)) < 0.06 - 1e-9) {
      m.vertices(v, 0) += u(rng);
      m.vertices(v, 1) += u(rng);
    }
  return m;
}

TEST(OrthotropicPatchTest, ConstantStrainIsInEquilibriumAndStoresTheLawsEnergy) {
  TriMesh mesh = jittered_square();
  const double angle = 20.0 * M_PI / 180.0;
  const Eigen::Vector3d g1(std::cos(angle), std::sin(angle), 0), g2(-std::sin(angle), std::cos(angle), 0);
  set_warp(mesh, g1);
  const ShellMaterial m = woven_material();
  for (Quadrature rule : {Quadrature::one_point, Quadrature::three_point}) {
    const ShellModel model(mesh, m, {}, rule);
    const Eigen::MatrixXd k(model.stiffness());
    Eigen::Matrix3d f = Eigen::Matrix3d::Zero();
    f(0, 0) = 1e-3;
    f(1, 1) = -4e-4;
    f(0, 1) = 7e-4;
    f(1, 0) = 1e-4;
    Eigen::VectorXd u(3 * mesh.num_vertices());
    for (int v = 0; v < mesh.num_vertices(); ++v) u.segment<3>(3 * v) = f * mesh.vertices.row(v).transpose();
    const Eigen::VectorXd force = k * u;
    double interior = 0.0, scale = 0.0;
    int inner = 0;
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      scale = std::max(scale, force.segment<3>(3 * v).norm());
      // Vertices whose basis functions (their two-ring) reach no border element: 3 cells in.
      const double x = mesh.vertices(v, 0), y = mesh.vertices(v, 1);
      if (std::abs(x) > 0.06 - 0.03 + 0.0025 || std::abs(y) > 0.06 - 0.03 + 0.0025) continue;
      ++inner;
      interior = std::max(interior, force.segment<3>(3 * v).norm());
    }
    EXPECT_GT(scale, 0.0);
    EXPECT_GE(inner, 25);
    EXPECT_LT(interior, 1e-10 * scale) << to_string(rule) << " (largest interior force " << interior << " N)";
    // Strain in the warp frame (small strain: the symmetric part of F).
    const Eigen::Matrix2d e_xy = 0.5 * (f.topLeftCorner<2, 2>() + f.topLeftCorner<2, 2>().transpose());
    Eigen::Matrix2d rot;
    rot << g1.head<2>(), g2.head<2>();  // columns g₁, g₂
    const Eigen::Matrix2d e = rot.transpose() * e_xy * rot;
    const Eigen::Vector3d voigt(e(0, 0), e(1, 1), 2 * e(0, 1));
    const double density = 0.5 * voigt.dot(plane_stress_matrix(5000, 3000, 60, 0.25) * voigt);
    const Eigen::VectorXd load = model.area_load(Eigen::Vector3d::UnitZ());
    double area = 0;
    for (Eigen::Index i = 2; i < load.size(); i += 3) area += load(i);
    const double energy = 0.5 * u.dot(k * u);
    EXPECT_NEAR(energy, density * area, 1e-9 * energy) << to_string(rule);
  }
}

// ---------------------------------------------------------------------------------------------
// Rotating the mesh and its grain together by Q rotates the stiffness: K' = Q K Qᵀ blockwise, and
// equal energies for rotated displacements. The grain alone turned by 90° changes it.
TEST(OrthotropicInvariance, RotatingMeshAndGrainTogetherRotatesStiffnessAndForces) {
  TriMesh mesh = make_cylinder(0.04, 0.08, 8, 5);
  const Eigen::Vector3d warp = Eigen::Vector3d(0.4, 1.0, 0.3).normalized();
  set_warp(mesh, warp);
  const ShellMaterial m = woven_material();
  const Eigen::Matrix3d q = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  TriMesh turned = mesh;
  turned.vertices = mesh.vertices * q.transpose();
  set_warp(turned, q * warp);
  const Eigen::MatrixXd k(ShellModel(mesh, m, {}, Quadrature::three_point).stiffness());
  const Eigen::MatrixXd kt(ShellModel(turned, m, {}, Quadrature::three_point).stiffness());
  const int n = mesh.num_vertices();
  Eigen::MatrixXd big = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int v = 0; v < n; ++v) big.block<3, 3>(3 * v, 3 * v) = q;
  EXPECT_LT((kt - big * k * big.transpose()).norm(), 1e-10 * k.norm());
  std::mt19937 rng(2);
  std::normal_distribution<double> g;
  Eigen::VectorXd u(3 * n);
  for (Eigen::Index i = 0; i < u.size(); ++i) u(i) = 1e-3 * g(rng);
  const Eigen::VectorXd ut = big * u;
  EXPECT_NEAR(ut.dot(kt * ut), u.dot(k * u), 1e-10 * u.dot(k * u));
  EXPECT_LT((kt * ut - big * (k * u)).norm(), 1e-10 * (k * u).norm());
  // The control: the grain turned about the normal changes the stiffness.
  TriMesh across = mesh;
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    const auto& tri = mesh.triangles[static_cast<size_t>(t)];
    const Eigen::Vector3d n3 = (mesh.vertices.row(tri[1]) - mesh.vertices.row(tri[0]))
                                   .cross(mesh.vertices.row(tri[2]) - mesh.vertices.row(tri[0]))
                                   .transpose()
                                   .normalized();
    across.warp[static_cast<size_t>(t)] = n3.cross(warp);
  }
  const Eigen::MatrixXd ka(ShellModel(across, m, {}, Quadrature::three_point).stiffness());
  EXPECT_GT((ka - k).norm(), 1e-2 * k.norm());
}

// ---------------------------------------------------------------------------------------------
// Strips under a small static load, the grain at 0°, 90° and 45° to the strip.

ShellMaterial strip_material(double poisson) {
  Orthotropy o = woven();
  o.poisson = poisson;
  ShellMaterial m;
  set_orthotropy(m, o);
  return m;
}

// Compliance along a direction at `angle` to the warp (classical laminate rotation):
// 1/E_θ = c⁴/E_w + s⁴/E_f + (1/G − 2ν_wf/E_w) s²c².
double directional_compliance(double ew, double ef, double g, double nu, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return std::pow(c, 4) / ew + std::pow(s, 4) / ef + (1.0 / g - 2.0 * nu / ew) * s * s * c * c;
}

// The strip of tests/support/strips.hpp with the Loop element (the default method).
double strip_strain(double angle, double force, double length, double width) {
  return testing::pulled_strip_strain("", strip_material(0.25), angle, force, length, width);
}

TEST(OrthotropicStrips, ElongationAlongWarpWeftAndBiasMatchesTheMembraneFormula) {
  const double length = 0.2, width = 0.04, force = 0.02;  // n = 0.5 N/m: strains ≤ 0.3 %
  for (double deg : {0.0, 90.0, 45.0, 30.0}) {
    const double angle = deg * M_PI / 180.0;
    const double expected = force / width * directional_compliance(5000, 3000, 60, 0.25, angle);
    const double strain = strip_strain(angle, force, length, width);
    std::printf("strip at %g deg to the warp: strain %.6e, formula %.6e, error %.3f%%\n", deg, strain, expected,
                100 * (strain / expected - 1));
    EXPECT_NEAR(strain / expected, 1.0, 0.03) << deg << " deg";
  }
}

// A strip [−L/2, L/2] × [−W/2, W/2] (nx × ny cells) of law `o` with its warp along `warp`,
// clamped at x = −L/2, with the force P (along −z) spread evenly over the tip's vertices.
Problem cantilever_problem(const Orthotropy& o, const Eigen::Vector3d& warp, double force, double length, double width,
                           int nx, int ny) {
  Problem p;
  p.mesh = make_grid(length, width, nx, ny);
  set_warp(p.mesh, warp);
  set_orthotropy(p.material, o);
  BoundaryCondition clamp;
  clamp.vertices = select_vertices(p.mesh, [&](const auto& x) { return x(0) < -length / 2 + 1e-9; });
  clamp.clamped = true;
  p.boundary = {clamp};
  const std::vector<int> tip = select_vertices(p.mesh, [&](const auto& x) { return x(0) > length / 2 - 1e-9; });
  for (size_t i = 0; i < tip.size(); ++i) {
    const double share = (i == 0 || i + 1 == tip.size()) ? 0.5 : 1.0;
    p.point_loads.push_back({tip[i], Eigen::Vector3d(0, 0, -share * force / static_cast<double>(tip.size() - 1))});
  }
  return p;
}

// Cantilever strip (ν = 0: plate bending along the strip is beam bending), 40 × 4 cells, tip force
// P: tip deflection P L³ / (3 B b) with B the rigidity along the strip.
double cantilever_tip(double angle, const Orthotropy& o, double force, double length, double width) {
  const Problem p = cantilever_problem(o, Eigen::Vector3d(std::cos(angle), std::sin(angle), 0), force, length, width, 40, 4);
  const StaticResult r = solve_static(p);
  return -r.limit_displacement(nearest_vertex(p.mesh, Eigen::Vector3d(length / 2, 0, 0)), 2);
}

TEST(OrthotropicStrips, CantileverDeflectionUsesTheRigidityAlongTheStrip) {
  const double length = 0.2, width = 0.02, force = 1e-6;
  Orthotropy o = woven();
  o.poisson = 0.0;
  for (double deg : {0.0, 90.0}) {
    const double rigidity = deg == 0.0 ? o.warp_bending : o.weft_bending;
    const double expected = force * std::pow(length, 3) / (3.0 * rigidity * width);
    const double tip = cantilever_tip(deg * M_PI / 180.0, o, force, length, width);
    std::printf("cantilever at %g deg to the warp: tip %.6e, formula %.6e, error %.3f%%\n", deg, tip, expected,
                100 * (tip / expected - 1));
    EXPECT_NEAR(tip / expected, 1.0, 0.03) << deg << " deg";
  }
}

// At 45° to the grain the strip also twists (the law couples bending and twist there); far from
// the clamp, which holds the twist, the beam formula holds with the directional rigidity of
// docs/materials.md §1, 1/B₄₅ = ¼ (1/B_w + 1/B_f + 1/D_t − 2ν/B_w). The curvature is measured on
// the centre line between 40 % and 80 % of the length (w'' = M / (B₄₅ b), M = P (L − x)) from
// second differences of the limit displacement.
TEST(OrthotropicStrips, CantileverAt45DegreesBendsWithTheBiasRigidity) {
  const double length = 0.2, width = 0.02, force = 1e-6;
  Orthotropy o = woven();
  o.poisson = 0.0;
  const double bias = 1.0 / (0.25 * (1 / o.warp_bending + 1 / o.weft_bending + 1 / o.twist));
  const Problem p = cantilever_problem(o, Eigen::Vector3d(1, 1, 0).normalized(), force, length, width, 80, 8);
  const StaticResult r = solve_static(p);
  auto w = [&](double x) { return r.limit_displacement(nearest_vertex(p.mesh, Eigen::Vector3d(x, 0, 0)), 2); };
  const double h = length / 80;
  double worst = 0.0;
  for (double f : {0.4, 0.6, 0.8}) {
    const double x = -length / 2 + f * length;
    const double curvature = -(w(x + 4 * h) - 2 * w(x) + w(x - 4 * h)) / (16 * h * h);
    const double expected = force * (length / 2 - x) / (bias * width);
    std::printf("cantilever at 45 deg, x = %.2f L: curvature %.6e, beam %.6e, error %.3f%%\n", f, curvature, expected,
                100 * (curvature / expected - 1));
    worst = std::max(worst, std::abs(curvature / expected - 1));
  }
  EXPECT_LT(worst, 0.03);
}

// ---------------------------------------------------------------------------------------------
// Simply supported rectangular orthotropic plate under a uniform load q (docs/materials.md, Navier
// series): w(x, y) = Σ_{m,n odd} 16 q sin(mπx/a) sin(nπy/b) /
//   (π⁶ m n [D₁₁ (m/a)⁴ + 2 (D₁₂ + 2 D₆₆)(m/a)²(n/b)² + D₂₂ (n/b)⁴]), x, y from a corner.
double navier_centre(double a, double b, double q, double d11, double d22, double d12, double d66) {
  double w = 0.0;
  for (int m = 1; m < 400; m += 2)
    for (int n = 1; n < 400; n += 2) {
      const double ma = m / a, nb = n / b;
      const double denom = d11 * std::pow(ma, 4) + 2 * (d12 + 2 * d66) * ma * ma * nb * nb + d22 * std::pow(nb, 4);
      w += 16 * q / (std::pow(M_PI, 6) * m * n * denom) * std::sin(m * M_PI / 2) * std::sin(n * M_PI / 2);
    }
  return w;
}

TEST(OrthotropicPlate, SimplySupportedUnderUniformLoadMatchesTheNavierSeries) {
  // The series itself against the isotropic square plate's tabulated coefficient 0.00406235.
  EXPECT_NEAR(navier_centre(1, 1, 1, 1, 1, 0.3, 0.35), 0.00406235, 1e-8);
  Orthotropy o;
  o.warp_stretch = 1e5;
  o.weft_stretch = 0.6e5;
  o.shear_stretch = 2e4;
  o.poisson = 0.2;
  o.warp_bending = 1.0;
  o.weft_bending = 0.4;
  o.twist = 0.15;
  const double nu_fw = o.poisson * o.weft_bending / o.warp_bending, den = 1 - o.poisson * nu_fw;
  const double d11 = o.warp_bending / den, d22 = o.weft_bending / den, d12 = o.poisson * d22;
  for (double deg : {0.0, 90.0}) {
    Problem p = square_plate(32, false, Quadrature::one_point);
    set_orthotropy(p.material, o);
    const double angle = deg * M_PI / 180.0;
    set_warp(p.mesh, Eigen::Vector3d(std::cos(angle), std::sin(angle), 0));
    p.surface_load = Eigen::Vector3d(0, 0, -1.0);
    const StaticResult r = solve_static(p);
    const double w = -r.limit_displacement(nearest_vertex(p.mesh, Eigen::Vector3d::Zero()), 2);
    // On the unit square the series is symmetric in D₁₁ ↔ D₂₂: the same centre deflection.
    const double expected = navier_centre(1, 1, 1, d11, d22, d12, o.twist);
    std::printf("orthotropic plate, warp at %g deg: centre %.6e, Navier %.6e, error %.3f%%\n", deg, w, expected,
                100 * (w / expected - 1));
    EXPECT_NEAR(w / expected, 1.0, 0.015) << deg << " deg";
  }
  // A rectangular plate 1 m × 0.5 m tells warp from weft.
  for (double deg : {0.0, 90.0}) {
    Problem p;
    p.mesh = make_grid(1.0, 0.5, 32, 16);
    set_orthotropy(p.material, o);
    const double angle = deg * M_PI / 180.0;
    set_warp(p.mesh, Eigen::Vector3d(std::cos(angle), std::sin(angle), 0));
    BoundaryCondition bc;
    bc.vertices = select_vertices(p.mesh, [](const auto& x) { return std::abs(x(0)) > 0.5 - 1e-9 || std::abs(x(1)) > 0.25 - 1e-9; });
    p.boundary = {bc};
    p.surface_load = Eigen::Vector3d(0, 0, -1.0);
    const StaticResult r = solve_static(p);
    const double w = -r.limit_displacement(nearest_vertex(p.mesh, Eigen::Vector3d::Zero()), 2);
    const double expected = deg == 0.0 ? navier_centre(1, 0.5, 1, d11, d22, d12, o.twist)
                                       : navier_centre(1, 0.5, 1, d22, d11, d12, o.twist);
    std::printf("orthotropic 1 x 0.5 plate, warp at %g deg: centre %.6e, Navier %.6e, error %.3f%%\n", deg, w, expected,
                100 * (w / expected - 1));
    EXPECT_NEAR(w / expected, 1.0, 0.015) << deg << " deg";
  }
}

}  // namespace
}  // namespace clothsim

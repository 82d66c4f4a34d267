// The linear_fe elastic term (sim/flat_fe/flat_fe_term.hpp) against finite differences and exact
// solutions: force vs energy, matrix vs force (the frozen-rotation membrane, the exact hinge
// Hessian), the Gauss–Newton hinge matrix, rigid-motion invariance, the plane-stress energy of a
// uniform stretch and the patch test, the hinge calibration on cylinders as the mesh is refined,
// the dihedral angle itself, and the matrix pattern.
#include "sim/flat_fe/flat_fe.hpp"
#include "sim/flat_fe/flat_fe_term.hpp"
#include "sim/mesh/generators.hpp"
#include "tests/support/fd_check.hpp"
#include "tests/support/flat_terms.hpp"
#include "tests/support/term_states.hpp"
#include "tests/support/test_meshes.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace clothsim {
namespace {

using testing::bent_into_cylinder;
using testing::check_matrix_against_force;
using testing::energy_at;
using testing::FdReport;
using testing::force_at;
using testing::jittered_grid;
using testing::matrix_at;
using testing::mesh_area;
using testing::rigidly_moved;
using testing::rotation;
using testing::sheet_material;
using testing::State;
using testing::states;
using testing::update_at;

constexpr double kEps = 1e-6;  // finite-difference step [m]

using Structure = testing::Structure<LinearFeDiscretization>;

// The jittered grid (flat at rest) and a short sleeve (curved at rest: every hinge has θ̄ ≠ 0),
// each in three materials so that the membrane and the hinges are each checked where they dominate.
std::vector<Structure> structures() { return testing::grid_and_sleeve<LinearFeDiscretization>("membrane only"); }

LinearFeElastic& as_fe(std::unique_ptr<ForceTerm>& term) { return dynamic_cast<LinearFeElastic&>(*term); }

// f = −∂E/∂x with the rotations re-extracted at every perturbed state (the polar rotation makes
// −R K d the exact gradient), for the corotated and the linear element. At rest, where the force is
// zero, errors are measured against the largest force of the first random state.
TEST(LinearFeTerm, ForceIsTheGradientOfTheEnergy) {
  double worst = 0.0;
  for (const Structure& s : structures())
    for (bool corotational : {true, false}) {
      std::unique_ptr<ForceTerm> term = s.d->elastic_term(corotational, true);
      worst = std::max(worst, testing::expect_force_is_the_gradient(*term, *s.d, states(*s.d), kEps,
                                                                    s.name + (corotational ? ", corotated" : ", linear")));
    }
  std::printf("linear_fe force vs energy: worst relative error %.2e over %zu structures x 2 x 6 states\n", worst,
              structures().size());
}

// K = −∂f/∂x exactly with the membrane rotations frozen and the exact hinge Hessian switched on.
TEST(LinearFeTerm, MatrixIsTheJacobianOfTheForceWithFrozenRotationsAndTheExactHingeHessian) {
  double worst = 0.0;
  for (const Structure& s : structures())
    for (const State& state : states(*s.d)) {
      std::unique_ptr<ForceTerm> term = s.d->elastic_term(true, true);
      update_at(*term, *s.d, state.x);  // rotations extracted at the state
      as_fe(term).freeze_rotations(true);
      as_fe(term).set_exact_bending_hessian(true);
      const FdReport r = check_matrix_against_force(*term, *s.d, state.x, kEps);
      worst = std::max(worst, r.relative());
      EXPECT_LT(r.relative(), 1e-6) << s.name << ", " << state.name << ": " << r.describe();
    }
  std::printf("linear_fe matrix vs force (frozen R, exact hinge Hessian): worst relative error %.2e\n", worst);
}

// The solver's matrix: symmetric, positive semidefinite (Gauss–Newton hinges, R K Rᵀ), and
// different from the exact Jacobian where hinges are bent away from rest — the switch matters.
TEST(LinearFeTerm, GaussNewtonMatrixIsSymmetricPositiveSemidefinite) {
  for (const Structure& s : structures()) {
    if (s.name.find("bending only") == std::string::npos) continue;
    for (const State& state : states(*s.d)) {
      std::unique_ptr<ForceTerm> term = s.d->elastic_term(true, true);
      const Eigen::MatrixXd k = matrix_at(*term, *s.d, state.x, {1.0, 0.0});
      const double scale = k.cwiseAbs().maxCoeff();
      ASSERT_GT(scale, 0.0);
      EXPECT_LT((k - k.transpose()).cwiseAbs().maxCoeff(), 1e-14 * scale) << s.name << ", " << state.name;
      const double lowest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(k).eigenvalues().minCoeff();
      EXPECT_GT(lowest, -1e-10 * scale) << s.name << ", " << state.name;
      as_fe(term).set_exact_bending_hessian(true);
      const Eigen::MatrixXd exact = matrix_at(*term, *s.d, state.x, {1.0, 0.0});
      const double difference = (exact - k).cwiseAbs().maxCoeff() / scale;
      if (state.name == "rest") {
        EXPECT_LT(difference, 1e-12) << s.name;  // θ = θ̄: the two agree
      } else {
        EXPECT_GT(difference, 1e-3) << s.name << ", " << state.name;
      }
    }
  }
}

// Rigid motions store no energy and make no force (corotated element); the linear element is not
// invariant under rotation (the reason for the corotation), so the check can fail.
TEST(LinearFeTerm, RigidMotionsStoreNoEnergyAndMakeNoForce) {
  for (const Structure& s : structures()) {
    if (s.name.find("cloth") == std::string::npos) continue;
    const Discretization& d = *s.d;
    std::unique_ptr<ForceTerm> corotated = d.elastic_term(true, true), linear = d.elastic_term(false, true);
    const Eigen::Vector3d shift(1.0, 2.0, -3.0);
    const Eigen::VectorXd moved[] = {rigidly_moved(d, Eigen::Matrix3d::Identity(), shift),
                                     rigidly_moved(d, rotation(2.5, Eigen::Vector3d(0.3, -1, 0.7)), shift)};
    for (const Eigen::VectorXd& x : moved) {
      const Eigen::VectorXd f = force_at(*corotated, d, x);
      std::printf("%s, rigid motion: energy %.2e J, largest force %.2e N\n", s.name.c_str(), corotated->energy(),
                  f.cwiseAbs().maxCoeff());
      EXPECT_LT(std::abs(corotated->energy()), 1e-18) << s.name;
      EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-10) << s.name;
    }
    const Eigen::VectorXd f = force_at(*linear, d, moved[0]);
    EXPECT_LT(std::abs(linear->energy()), 1e-18) << s.name;  // translation: fine for the linear element too
    EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-10) << s.name;
    const double turned = energy_at(*linear, d, rigidly_moved(d, rotation(0.5, Eigen::Vector3d(0, 1, 0)), shift));
    EXPECT_GT(turned, 1e-3) << s.name << ": the linear element should store energy under a rotation of 0.5 rad";
  }
}

// A uniform in-plane strain of the jittered grid: the energy is the plane-stress energy density
//     W = ½ E t/(1 − ν²) (ε_xx² + 2ν ε_xx ε_yy + ε_yy² + (1 − ν)/2 γ²)
// times the area (ShellMaterial::membrane_stiffness() = E t/(1 − ν²)), exactly; no interior node
// feels a force (the patch test), and the border x = +a/2 carries the resultant −σ_xx·b.
TEST(LinearFeTerm, UniformStrainGivesThePlaneStressEnergyAndPassesThePatchTest) {
  const ShellMaterial m = sheet_material(5000.0, 1e-4);
  const LinearFeDiscretization d(jittered_grid(), {}, m);
  const double area = 0.1 * 0.08, km = m.membrane_stiffness(), nu = m.poisson_ratio;
  struct Case {
    const char* name;
    double exx, eyy, gamma;
    bool corotational;
  };
  const Case cases[] = {{"stretch, corotated", 0.01, -0.004, 0.0, true},
                        {"stretch, linear", 0.01, -0.004, 0.0, false},
                        {"shear, linear", 0.0, 0.0, 0.006, false},
                        {"stretch and shear, linear", 0.003, 0.002, -0.004, false}};
  for (const Case& c : cases) {
    Eigen::VectorXd x = d.rest();
    for (int v = 0; v < d.num_nodes(); ++v) {
      const double px = d.rest()(3 * v), py = d.rest()(3 * v + 1);
      x(3 * v) += c.exx * px + c.gamma * py;
      x(3 * v + 1) += c.eyy * py;
    }
    std::unique_ptr<ForceTerm> term = d.elastic_term(c.corotational, false);
    const Eigen::VectorXd f = force_at(*term, d, x);
    const double expected =
        0.5 * km * (c.exx * c.exx + 2 * nu * c.exx * c.eyy + c.eyy * c.eyy + 0.5 * (1 - nu) * c.gamma * c.gamma) * area;
    const double relative = std::abs(term->energy() - expected) / expected;
    std::printf("uniform strain (%s): energy %.10e J, expected %.10e J, relative error %.1e\n", c.name, term->energy(),
                expected, relative);
    EXPECT_LT(relative, 1e-10) << c.name;
    EXPECT_LT(as_fe(term).bending_energy(), 1e-30) << c.name;
    double interior = 0.0, border_x = 0.0;
    for (int v = 0; v < d.num_nodes(); ++v) {
      const double px = d.rest()(3 * v), py = d.rest()(3 * v + 1);
      const bool on_border = std::abs(std::abs(px) - 0.05) < 1e-9 || std::abs(std::abs(py) - 0.04) < 1e-9;
      if (!on_border) interior = std::max(interior, f.segment<3>(3 * v).norm());
      if (std::abs(px - 0.05) < 1e-9) border_x += f(3 * v);
    }
    const double sigma_xx = km * (c.exx + nu * c.eyy);  // [N/m]
    EXPECT_LT(interior, 1e-10 * f.cwiseAbs().maxCoeff()) << c.name;
    if (!c.corotational || c.gamma == 0.0) {
      EXPECT_NEAR(border_x, -sigma_xx * 0.08, 1e-10 * std::max(1.0, std::abs(sigma_xx))) << c.name;
    }
  }
}

// The hinge energy of a flat mesh bent isometrically into a cylinder of curvature κ, as the mesh is
// refined, against B κ²/2 × area times the factor docs/linear_fe.md derives for the mesh and the
// bending direction φ (the curvature direction, from the x axis): 1 on the equilateral lattice in
// every direction; 1 + sin 2φ + sin² 2φ on the generator's grid (cells split along (1, 1)): 1
// across x, across y and across the anti-diagonal, 3 across the diagonal. The remaining error is
// the border's (the outermost edges across the bending direction carry no hinge), O(h).
TEST(LinearFeTerm, HingeEnergyOfACylinderConvergesToHalfBKappaSquaredTimesTheArea) {
  const double b = 1e-4, kappa = 5.0;  // [N·m], [1/m]
  struct Case {
    std::string name;
    bool lattice;
    double angle_deg;
  };
  const std::vector<Case> cases = {{"grid, 0 deg", false, 0.0},        {"grid, 90 deg", false, 90.0},
                                   {"grid, -45 deg", false, -45.0},    {"grid, 45 deg", false, 45.0},
                                   {"grid, 20 deg", false, 20.0},      {"lattice, 0 deg", true, 0.0},
                                   {"lattice, 17 deg", true, 17.0},    {"lattice, 30 deg", true, 30.0},
                                   {"lattice, 90 deg", true, 90.0}};
  std::printf("hinge energy of a bent mesh (kappa = %.0f 1/m) / (factor * B kappa^2/2 * area) - 1:\n", kappa);
  for (const Case& c : cases) {
    const double a = c.angle_deg * M_PI / 180.0;
    const double factor = c.lattice ? 1.0 : 1.0 + std::sin(2 * a) + std::sin(2 * a) * std::sin(2 * a);
    std::vector<double> errors;
    std::string row;
    for (int n : {8, 16, 32}) {
      const TriMesh mesh = c.lattice ? testing::make_lattice(n + 1, 0.1) : make_grid(0.1, 0.1, n, n);
      const LinearFeDiscretization d(mesh, {}, sheet_material(5000.0, b));
      const double area = mesh_area(mesh);
      std::unique_ptr<ForceTerm> term = d.elastic_term(true, false);
      update_at(*term, d, bent_into_cylinder(d, a, kappa));
      errors.push_back(as_fe(term).bending_energy() / (factor * 0.5 * b * kappa * kappa * area) - 1.0);
      char cell[64];
      std::snprintf(cell, sizeof(cell), "  n = %2d: %+.5f", n, errors.back());
      row += cell;
    }
    std::printf("  %-16s (factor %.3f)%s\n", c.name.c_str(), factor, row.c_str());
    EXPECT_LT(std::abs(errors[2]), 0.04) << c.name;
    testing::expect_halved_by_each_refinement(errors, c.name);
  }
}

// The hinges' energy for a small quadratic deflection w = ε (a x² + 2c xy + b y²)/2 (constant
// curvatures w_xx = εa, w_yy = εb, w_xy = εc) against the energy densities docs/linear_fe.md
// derives, times the area:
//   grid (cells split along (1, 1)):  W = B/2 [(w_xx + w_xy)² + (w_yy + w_xy)² + 4 w_xy²],
//   equilateral lattice:              W = B/2 [(w_xx + w_yy)² − (8/3)(w_xx w_yy − w_xy²)]
// (an isotropic plate with Poisson ratio −1/3). The difference is the border's, O(h).
TEST(LinearFeTerm, HingeEnergyOfQuadraticDeflectionsMatchesTheDerivedDensities) {
  const double b = 1e-4, eps = 1e-3;
  struct Case {
    const char* name;
    double a, bb, c;
  };
  const Case cases[] = {{"paraboloid", 1, 1, 0}, {"saddle", 1, -1, 0}, {"twist", 0, 0, 1}, {"mixed", 1, 0.4, -0.3}};
  std::printf("hinge energy of w = eps (a x^2 + 2c xy + b y^2)/2 / (W area) - 1:\n");
  for (bool lattice : {false, true})
    for (const Case& c : cases) {
      const double wxx = eps * c.a, wyy = eps * c.bb, wxy = eps * c.c;
      const double density = lattice ? 0.5 * b * ((wxx + wyy) * (wxx + wyy) - 8.0 / 3.0 * (wxx * wyy - wxy * wxy))
                                     : 0.5 * b * ((wxx + wxy) * (wxx + wxy) + (wyy + wxy) * (wyy + wxy) + 4 * wxy * wxy);
      std::vector<double> errors;
      std::string row;
      for (int n : {8, 16, 32}) {
        const TriMesh mesh = lattice ? testing::make_lattice(n + 1, 0.1) : make_grid(0.1, 0.1, n, n);
        const LinearFeDiscretization d(mesh, {}, sheet_material(5000.0, b));
        const double area = mesh_area(mesh);
        Eigen::VectorXd x = d.rest();
        for (int v = 0; v < d.num_nodes(); ++v) {
          const double px = x(3 * v), py = x(3 * v + 1);
          x(3 * v + 2) = 0.5 * (wxx * px * px + 2 * wxy * px * py + wyy * py * py);
        }
        std::unique_ptr<ForceTerm> term = d.elastic_term(true, false);
        update_at(*term, d, x);
        errors.push_back(as_fe(term).bending_energy() / (density * area) - 1.0);
        char cell[64];
        std::snprintf(cell, sizeof(cell), "  n = %2d: %+.5f", n, errors.back());
        row += cell;
      }
      std::printf("  %-8s %-10s%s\n", lattice ? "lattice" : "grid", c.name, row.c_str());
      EXPECT_LT(std::abs(errors[2]), 0.06) << c.name;
      EXPECT_LT(std::abs(errors[2]), 0.6 * std::abs(errors[1]) + 1e-4) << c.name;
      EXPECT_LT(std::abs(errors[1]), 0.6 * std::abs(errors[0]) + 1e-4) << c.name;
    }
}

// The dihedral angle of one hinge: its value and sign convention, and its gradient and Hessian
// against central differences.
TEST(LinearFeDihedral, AngleGradientAndHessian) {
  for (double alpha : {0.3, 2.0, 3.0}) {
    // B turned about the edge (the x axis) by α, lifting its apex towards the normals (+z).
    const HingePositions x = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.4, 1, 0),
                              Eigen::Vector3d(0.7, -std::cos(alpha), std::sin(alpha))};
    EXPECT_NEAR(dihedral_angle(x), -alpha, 1e-14) << alpha;
    HingePositions mirrored = x;
    mirrored[3].z() = -mirrored[3].z();
    EXPECT_NEAR(dihedral_angle(mirrored), alpha, 1e-14) << alpha;
  }
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int trial = 0; trial < 5; ++trial) {
    HingePositions x = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.4, 1, 0), Eigen::Vector3d(0.6, -1, 0)};
    for (Eigen::Vector3d& p : x) p += Eigen::Vector3d(u(rng), u(rng), 3 * u(rng));
    const HingeVector g = dihedral_gradient(x);
    const HingeMatrix h = dihedral_hessian(x);
    double g_error = 0.0, h_error = 0.0;
    for (int j = 0; j < 12; ++j) {
      HingePositions xp = x, xm = x;
      xp[static_cast<size_t>(j / 3)](j % 3) += kEps;
      xm[static_cast<size_t>(j / 3)](j % 3) -= kEps;
      g_error = std::max(g_error, std::abs(g(j) - (dihedral_angle(xp) - dihedral_angle(xm)) / (2 * kEps)));
      h_error = std::max(h_error, ((dihedral_gradient(xp) - dihedral_gradient(xm)) / (2 * kEps) - h.col(j)).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(g_error, 1e-8 * g.cwiseAbs().maxCoeff()) << "trial " << trial;
    EXPECT_LT(h_error, 1e-7 * h.cwiseAbs().maxCoeff()) << "trial " << trial;
    // Invariance: the gradient sums to zero and has no moment.
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) {
      sum += g.segment<3>(3 * k);
      moment += x[static_cast<size_t>(k)].cross(Eigen::Vector3d(g.segment<3>(3 * k)));
    }
    EXPECT_LT(sum.norm() + moment.norm(), 1e-12 * g.norm()) << "trial " << trial;
  }
}

// The pattern holds exactly the 3 × 3 blocks of node pairs that share a triangle or a hinge (and
// the diagonal), in full symmetric storage with sorted rows; a bent state puts non-zero values
// into every hinge's apex–apex block (the coupling only hinges make).
TEST(LinearFeTerm, MatrixPatternHoldsTheTriangleAndHingeCouplings) {
  const LinearFeDiscretization d(jittered_grid(), {}, sheet_material(5000.0, 1e-4));
  const Eigen::SparseMatrix<double>& p = d.matrix_pattern();
  const int n = d.num_nodes();
  ASSERT_EQ(p.rows(), 3 * n);
  ASSERT_TRUE(p.isCompressed());
  std::set<std::pair<int, int>> expected;
  for (int v = 0; v < n; ++v) expected.insert({v, v});
  for (const Triangle& t : d.mesh().triangles)
    for (int a : t)
      for (int b : t) expected.insert({a, b});
  for (const Hinge& h : d.hinges()) {
    expected.insert({h.nodes[2], h.nodes[3]});
    expected.insert({h.nodes[3], h.nodes[2]});
  }
  std::set<std::pair<int, int>> found;
  for (Eigen::Index col = 0; col < p.cols(); ++col) {
    Eigen::Index last = -1;
    for (Eigen::SparseMatrix<double>::InnerIterator it(p, col); it; ++it) {
      EXPECT_GT(it.row(), last) << "column " << col << ": rows not sorted";
      last = it.row();
      EXPECT_EQ(it.value(), 0.0);
      found.insert({static_cast<int>(it.row() / 3), static_cast<int>(col / 3)});
    }
  }
  EXPECT_EQ(found, expected);
  EXPECT_EQ(p.nonZeros(), 9 * static_cast<Eigen::Index>(expected.size()));  // whole blocks
  std::printf("pattern: %d nodes, %zu triangles, %zu hinges, %zu blocks\n", n, d.mesh().triangles.size(), d.hinges().size(),
              expected.size());
  // 5 × 4 cells: interior edges along x (5 per inner row, 3 rows), along y (4 per inner column, 4
  // columns) and every cell's diagonal.
  EXPECT_EQ(d.hinges().size(), static_cast<size_t>(5 * 3 + 4 * 4 + 5 * 4));

  std::unique_ptr<ForceTerm> term = d.elastic_term(true, true);
  const Eigen::VectorXd x = testing::perturbed_rest(d, 2e-3, 4);
  const Eigen::MatrixXd k = matrix_at(*term, d, x, {1.0, 0.0});
  for (const Hinge& h : d.hinges()) {
    const double apex_coupling = k.block<3, 3>(3 * h.nodes[2], 3 * h.nodes[3]).cwiseAbs().maxCoeff();
    EXPECT_GT(apex_coupling, 0.0) << "hinge " << h.nodes[0] << "-" << h.nodes[1];
  }
}

// Kelvin–Voigt damping wraps the term: the same force and energy, the matrix (w_K + c w_D) K; mass
// damping finds every diagonal entry in the pattern.
TEST(LinearFeTerm, DampingWrappersWork) {
  testing::expect_damping_wrappers_work(LinearFeDiscretization(jittered_grid(), {}, sheet_material(5000.0, 1e-4)));
}

}  // namespace
}  // namespace clothsim

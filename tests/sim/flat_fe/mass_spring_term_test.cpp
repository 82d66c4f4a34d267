// The mass_spring elastic term (sim/flat_fe/mass_spring_term.hpp) against finite differences and
// its derivations (docs/mass_spring.md): force vs energy, the exact Hessian vs the force, the
// solver's matrix (symmetric, positive semidefinite, the transverse part dropped only where it is
// negative), rigid motions, the stretch springs' plane-stress law with ν = 1/3 on the equilateral
// lattice and the law they give on the grid primitive, the bending springs' in-plane stiffness,
// their energy on cylinders (the calibration, the direction factor, the quartic growth), the
// reference curvature, the matrix pattern and the damping wrappers.
#include "sim/flat_fe/mass_spring.hpp"
#include "sim/flat_fe/mass_spring_term.hpp"
#include "sim/mesh/generators.hpp"
#include "tests/support/fd_check.hpp"
#include "tests/support/flat_terms.hpp"
#include "tests/support/term_states.hpp"
#include "tests/support/test_meshes.hpp"

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace clothsim {
namespace {

using testing::bent_into_cylinder;
using testing::check_matrix_against_force;
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

using Structure = testing::Structure<MassSpringDiscretization>;

// The jittered grid (flat at rest) and a short sleeve (curved at rest), each in three materials so
// that each kind of spring is checked where it dominates the force. The reference curvature is the
// material's (its inverse bending length).
std::vector<Structure> structures() { return testing::grid_and_sleeve<MassSpringDiscretization>("stretch only"); }

MassSpringElastic& as_springs(std::unique_ptr<ForceTerm>& term) { return dynamic_cast<MassSpringElastic&>(*term); }

// Σ ½ k (nᵀ(u_i − u_j))² over springs, n the rest direction: the springs' energy linearised about
// the rest state for displacements u [J] (what ½ uᵀ K u gives with the rest matrix).
double linearised_energy(const std::vector<Spring>& springs, const Eigen::VectorXd& rest, const Eigen::VectorXd& u) {
  double e = 0.0;
  for (const Spring& s : springs) {
    const Eigen::Vector3d n = (rest.segment<3>(3 * s.i) - rest.segment<3>(3 * s.j)).normalized();
    const double stretch = n.dot(u.segment<3>(3 * s.i) - u.segment<3>(3 * s.j));
    e += 0.5 * s.stiffness * stretch * stretch;
  }
  return e;
}

// Displacements of the uniform in-plane strain (ε_xx, ε_yy, γ_xy engineering) about the origin.
Eigen::VectorXd uniform_strain(const Discretization& d, double exx, double eyy, double gamma) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(d.rest().size());
  for (int v = 0; v < d.num_nodes(); ++v) {
    const double px = d.rest()(3 * v), py = d.rest()(3 * v + 1);
    u(3 * v) = exx * px + 0.5 * gamma * py;
    u(3 * v + 1) = 0.5 * gamma * px + eyy * py;
  }
  return u;
}

// The plane-stress energy density W = ½ E t/(1 − ν²) (ε_xx² + 2ν ε_xx ε_yy + ε_yy² + (1 − ν)/2 γ²) [J/m²].
double plane_stress_density(double stretch_modulus, double nu, double exx, double eyy, double gamma) {
  return 0.5 * stretch_modulus / (1 - nu * nu) * (exx * exx + 2 * nu * exx * eyy + eyy * eyy + 0.5 * (1 - nu) * gamma * gamma);
}

// f = −∂E/∂x for every structure and state. At rest, where the force is zero, errors are measured
// against the largest force of the first random state.
TEST(MassSpringTerm, ForceIsTheGradientOfTheEnergy) {
  double worst = 0.0;
  for (const Structure& s : structures()) {
    std::unique_ptr<ForceTerm> term = s.d->elastic_term(true, true);
    worst = std::max(worst, testing::expect_force_is_the_gradient(*term, *s.d, states(*s.d), kEps, s.name));
  }
  std::printf("mass_spring force vs energy: worst relative error %.2e over %zu structures x 6 states\n", worst,
              structures().size());
}

// K = −∂f/∂x with the exact spring Hessian switched on.
TEST(MassSpringTerm, ExactHessianIsTheJacobianOfTheForce) {
  double worst = 0.0;
  for (const Structure& s : structures())
    for (const State& state : states(*s.d)) {
      std::unique_ptr<ForceTerm> term = s.d->elastic_term(true, true);
      as_springs(term).set_exact_hessian(true);
      const FdReport r = check_matrix_against_force(*term, *s.d, state.x, kEps);
      worst = std::max(worst, r.relative());
      EXPECT_LT(r.relative(), 1e-6) << s.name << ", " << state.name << ": " << r.describe();
    }
  std::printf("mass_spring exact Hessian vs force: worst relative error %.2e\n", worst);
}

// The solver's matrix: symmetric and positive semidefinite at every state; equal to the exact
// Hessian at rest and wherever every spring is stretched (a uniform expansion, rotated); different
// where springs are compressed (their negative transverse part is dropped). Without tension
// stiffening it differs from the exact one when stretched too, and stays semidefinite.
TEST(MassSpringTerm, SolverMatrixIsSymmetricPositiveSemidefiniteAndExactWhereNoSpringIsCompressed) {
  for (const Structure& s : structures()) {
    if (s.name.find("cloth") == std::string::npos) continue;
    std::vector<State> all = states(*s.d);
    all.push_back({"expanded 10 %, turned",
                   rigidly_moved(*s.d, 1.1 * rotation(0.7, Eigen::Vector3d(1, -1, 2)), Eigen::Vector3d(0.1, 0, 0))});
    for (bool stiffening : {true, false})
      for (const State& state : all) {
        std::unique_ptr<ForceTerm> term = s.d->elastic_term(true, stiffening);
        const Eigen::MatrixXd k = matrix_at(*term, *s.d, state.x, {1.0, 0.0});
        const double scale = k.cwiseAbs().maxCoeff();
        ASSERT_GT(scale, 0.0);
        EXPECT_LT((k - k.transpose()).cwiseAbs().maxCoeff(), 1e-14 * scale) << s.name << ", " << state.name;
        const double lowest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(k).eigenvalues().minCoeff();
        EXPECT_GT(lowest, -1e-10 * scale) << s.name << ", " << state.name;
        as_springs(term).set_exact_hessian(true);
        const Eigen::MatrixXd exact = matrix_at(*term, *s.d, state.x, {1.0, 0.0});
        const double difference = (exact - k).cwiseAbs().maxCoeff() / scale;
        const double exact_lowest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(exact).eigenvalues().minCoeff();
        std::printf("%-14s %-22s tension stiffening %-3s: lowest eigenvalue %+.3e (exact Hessian %+.3e) x largest entry, "
                    "|exact - solver| %.2e\n",
                    s.name.c_str(), state.name.c_str(), stiffening ? "on" : "off", lowest / scale, exact_lowest / scale,
                    difference);
        if (state.name == "rest" || (stiffening && state.name.rfind("expanded", 0) == 0)) {
          EXPECT_LT(difference, 1e-12) << s.name << ", " << state.name;
        } else {
          EXPECT_GT(difference, 1e-4) << s.name << ", " << state.name;
        }
        if (state.name == "compressed 30 %") {
          EXPECT_LT(exact_lowest, -1e-6 * scale) << s.name << ": the exact Hessian should be indefinite here";
        }
      }
  }
}

// Rigid motions store no energy and make no force; `corotational` changes nothing (springs need no
// rotation to be invariant).
TEST(MassSpringTerm, RigidMotionsStoreNoEnergyAndMakeNoForce) {
  for (const Structure& s : structures()) {
    if (s.name.find("cloth") == std::string::npos) continue;
    const Discretization& d = *s.d;
    std::unique_ptr<ForceTerm> corotated = d.elastic_term(true, true), linear = d.elastic_term(false, true);
    const Eigen::Vector3d shift(1.0, 2.0, -3.0);
    const Eigen::VectorXd moved[] = {rigidly_moved(d, Eigen::Matrix3d::Identity(), shift),
                                     rigidly_moved(d, rotation(2.5, Eigen::Vector3d(0.3, -1, 0.7)), shift)};
    for (const Eigen::VectorXd& x : moved) {
      const Eigen::VectorXd f = force_at(*corotated, d, x), g = force_at(*linear, d, x);
      std::printf("%s, rigid motion: energy %.2e J, largest force %.2e N\n", s.name.c_str(), corotated->energy(),
                  f.cwiseAbs().maxCoeff());
      EXPECT_LT(std::abs(corotated->energy()), 1e-18) << s.name;
      EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-10) << s.name;
      EXPECT_EQ(f, g) << s.name;
    }
    const Eigen::VectorXd x = testing::perturbed_rest(d, 2e-3, 3);
    EXPECT_EQ(force_at(*corotated, d, x), force_at(*linear, d, x)) << s.name;
    EXPECT_EQ(matrix_at(*corotated, d, x, {1.0, 0.0}), matrix_at(*linear, d, x, {1.0, 0.0})) << s.name;
  }
}

// The stretch springs on the equilateral lattice under uniform strains: linearised, they store
// exactly the plane-stress energy with the stretch modulus E·t and Poisson ratio 1/3 — whatever the
// material's ν (0.3 here) — times the area, border included (each triangle's share of k_e carries
// its own area). The term's stretch energy at strains of 1e-4 agrees to O(strain) (the springs'
// geometric nonlinearity). A material with ν = 1/3 is therefore matched exactly, the material's own
// ν = 0.3 is not (printed).
TEST(MassSpringTerm, StretchSpringsOnTheEquilateralLatticeArePlaneStressWithPoissonRatioOneThird) {
  const ShellMaterial m = sheet_material(5000.0, 1e-5);
  const MassSpringDiscretization d(testing::make_lattice(9, 0.1), {}, m);
  const double area = mesh_area(d.mesh());
  struct Case {
    const char* name;
    double exx, eyy, gamma;
  };
  const Case cases[] = {{"uniaxial x", 1, 0, 0},      {"uniaxial y", 0, 1, 0},         {"equibiaxial", 1, 1, 0},
                        {"shear", 0, 0, 1},           {"pure shear 45 deg", 1, -1, 0}, {"mixed", 1, -0.4, 0.7}};
  for (const Case& c : cases) {
    const double scale = 1e-4;
    const Eigen::VectorXd u = uniform_strain(d, scale * c.exx, scale * c.eyy, scale * c.gamma);
    const double linear = linearised_energy(d.stretch_springs(), d.rest(), u);
    const double third = plane_stress_density(m.stretch_modulus, 1.0 / 3.0, scale * c.exx, scale * c.eyy, scale * c.gamma) * area;
    const double own = plane_stress_density(m.stretch_modulus, m.poisson_ratio, scale * c.exx, scale * c.eyy, scale * c.gamma) * area;
    std::unique_ptr<ForceTerm> term = d.elastic_term(true, true);
    update_at(*term, d, d.rest() + u);
    const double stretch = as_springs(term).stretch_energy();
    std::printf("lattice, %-17s: linearised %.10e J, plane stress (E t, nu = 1/3) %.10e J (%+.1e), the term %+.1e; "
                "against nu = %.2f: %+.3f\n",
                c.name, linear, third, linear / third - 1.0, stretch / third - 1.0, m.poisson_ratio, linear / own - 1.0);
    EXPECT_NEAR(linear / third, 1.0, 1e-12) << c.name;
    EXPECT_NEAR(stretch / third, 1.0, 3e-4) << c.name;
  }
}

// The stretch springs on the grid primitive (square cells split along (1, 1), right triangles):
// the legs get k = E·t, the diagonals E·t/2 (E·t/2 and E·t/4 on the border), so a uniform strain
// stores per unit area, exactly (docs/mass_spring.md),
//     W = ½ E t [ε_xx² + ε_yy² + ((ε_xx + ε_yy)/2 + ε_xy)²],   ε_xy = γ/2:
// anisotropic (shears of opposite sign differ; stretch couples to shear). Printed against the
// isotropic law with ν = 1/3.
TEST(MassSpringTerm, StretchSpringsOnTheGridGiveTheDerivedAnisotropicLaw) {
  const ShellMaterial m = sheet_material(5000.0, 1e-5);
  const MassSpringDiscretization d(make_grid(0.1, 0.08, 10, 8), {}, m);
  const double area = 0.1 * 0.08;
  struct Case {
    const char* name;
    double exx, eyy, gamma;
  };
  const Case cases[] = {{"uniaxial x", 1, 0, 0},       {"uniaxial y", 0, 1, 0},         {"equibiaxial", 1, 1, 0},
                        {"shear +", 0, 0, 1},          {"shear -", 0, 0, -1},           {"pure shear 45 deg", 1, -1, 0},
                        {"x, contracting", 1, -0.2, 0}, {"x, sheared back", 1, 0, -1}};
  for (const Case& c : cases) {
    const double scale = 1e-4, exx = scale * c.exx, eyy = scale * c.eyy, gamma = scale * c.gamma;
    const Eigen::VectorXd u = uniform_strain(d, exx, eyy, gamma);
    const double linear = linearised_energy(d.stretch_springs(), d.rest(), u);
    const double diagonal = 0.5 * (exx + eyy) + 0.5 * gamma;
    const double derived = 0.5 * m.stretch_modulus * (exx * exx + eyy * eyy + diagonal * diagonal) * area;
    const double isotropic = plane_stress_density(m.stretch_modulus, 1.0 / 3.0, exx, eyy, gamma) * area;
    std::printf("grid, %-17s: linearised %.10e J, derived %.10e J (%+.1e); / isotropic (E t, nu = 1/3) = %.4f\n", c.name,
                linear, derived, linear / derived - 1.0, linear / isotropic);
    EXPECT_NEAR(linear / derived, 1.0, 1e-12) << c.name;
  }
  // The springs' stiffness: legs E·t (E·t/2 on the border), diagonals E·t/2.
  std::set<long> found;
  for (const Spring& s : d.stretch_springs()) {
    const Eigen::Vector3d e = d.rest().segment<3>(3 * s.i) - d.rest().segment<3>(3 * s.j);
    const bool diagonal = std::abs(e.x()) > 1e-12 && std::abs(e.y()) > 1e-12;
    const Eigen::Vector3d mid = 0.5 * (d.rest().segment<3>(3 * s.i) + d.rest().segment<3>(3 * s.j));
    const bool border = !diagonal && (std::abs(std::abs(mid.x()) - 0.05) < 1e-9 || std::abs(std::abs(mid.y()) - 0.04) < 1e-9);
    const double expected = m.stretch_modulus * (diagonal ? 0.5 : border ? 0.5 : 1.0);
    EXPECT_NEAR(s.stiffness, expected, 1e-9 * expected) << s.i << "-" << s.j;
    found.insert(std::lround(s.stiffness));
  }
  EXPECT_EQ(found, (std::set<long>{2500, 5000}));
}

// The bending springs also resist in-plane strain. On the equilateral lattice (side h) they add
// 2√3 k_b = 73728/945 · B/(κ_ref² h⁴) ≈ 78.0 B/(κ_ref² h⁴) to the stretch modulus (same isotropic
// form as the edge springs); the interior edges only carry them, so the measured addition
// approaches that as the lattice is refined (the border's missing springs, O(h)).
TEST(MassSpringTerm, BendingSpringsAddInPlaneStiffnessGrowingAsTheMeshIsRefined) {
  const ShellMaterial m = sheet_material(5000.0, 1e-5);
  const double kappa = MassSpringDiscretization::bending_length_curvature(m);
  std::printf("bending springs' in-plane stiffness (cloth: E t = %.0f N/m, B = %.0e N m, kappa_ref = %.2f 1/m):\n",
              m.stretch_modulus, m.bending_rigidity, kappa);
  std::vector<double> errors;
  for (int n : {8, 16, 32}) {
    const double h = 0.1 / n;
    const MassSpringDiscretization d(testing::make_lattice(n + 1, 0.1), {}, m);
    const double added = 73728.0 / 945.0 * m.bending_rigidity / (kappa * kappa * h * h * h * h);  // [N/m]
    const Eigen::VectorXd u = uniform_strain(d, 1e-4, -0.3e-4, 0.5e-4);
    const double measured = linearised_energy(d.bending_springs(), d.rest(), u);
    const double expected = plane_stress_density(added, 1.0 / 3.0, 1e-4, -0.3e-4, 0.5e-4) * mesh_area(d.mesh());
    errors.push_back(measured / expected - 1.0);
    std::printf("  h = %.5f m: adds %.4e N/m = %.2e E t; measured / derived - 1 = %+.4f\n", h, added,
                added / m.stretch_modulus, errors.back());
  }
  EXPECT_LT(errors[0], 0.0);  // the border's missing springs
  EXPECT_LT(std::abs(errors[2]), 0.06);
  EXPECT_LT(std::abs(errors[1]), 0.55 * std::abs(errors[0]));
  EXPECT_LT(std::abs(errors[2]), 0.55 * std::abs(errors[1]));
}

// The reference curvature: the inverse bending length (ρ_A g / B)^(1/3) unless given; a material
// without mass cannot set it.
TEST(MassSpringTerm, ReferenceCurvatureIsTheInverseBendingLength) {
  ShellMaterial m = sheet_material(5000.0, 1e-5);
  m.areal_density = 0.1;
  const double expected = std::cbrt(0.1 * 9.80665 / 1e-5);
  const MassSpringDiscretization d(make_grid(0.1, 0.1, 2, 2), {}, m);
  std::printf("reference curvature of E t = 5000 N/m, B = 1e-5 N m, rho_A = 0.1 kg/m^2: %.4f 1/m (bending length %.4f m)\n",
              d.reference_curvature(), 1.0 / d.reference_curvature());
  EXPECT_NEAR(d.reference_curvature(), expected, 1e-12 * expected);
  EXPECT_NEAR(d.reference_curvature(), 46.11, 0.01);
  EXPECT_EQ(MassSpringDiscretization(make_grid(0.1, 0.1, 2, 2), {}, m, 7.0).reference_curvature(), 7.0);
  m.areal_density = 0.0;
  EXPECT_THROW(MassSpringDiscretization(make_grid(0.1, 0.1, 2, 2), {}, m), std::runtime_error);
  EXPECT_NO_THROW(MassSpringDiscretization(make_grid(0.1, 0.1, 2, 2), {}, m, 7.0));
}

// The bending springs' energy of a flat mesh bent isometrically into a cylinder of curvature
// κ = κ_ref, against B κ²/2 × area times the direction factor docs/mass_spring.md derives: each
// spring at angle ψ to the curvature direction stores B κ²/2 · (Ā_e/3) · (128/35) cos⁸ψ, so
//   equilateral lattice (springs at 30°, 90°, 150°):  1 − (8/35) cos 6φ   (0.771 … 1.229),
//   grid (springs along (1, 2), (2, 1), (−1, 1)):    (128/105) Σ cos⁸(φ − α_s),
// φ the curvature direction. The remaining error is the border's (the border edges carry no
// bending spring), O(h).
TEST(MassSpringTerm, BendingSpringEnergyOfACylinderAtTheReferenceCurvature) {
  const double b = 1e-4, kappa = 5.0;  // [N·m], [1/m]
  struct Case {
    std::string name;
    bool lattice;
    double angle_deg;
  };
  const std::vector<Case> cases = {{"grid, 0 deg", false, 0.0},     {"grid, 90 deg", false, 90.0},
                                   {"grid, 45 deg", false, 45.0},   {"grid, -45 deg", false, -45.0},
                                   {"lattice, 0 deg", true, 0.0},   {"lattice, 17 deg", true, 17.0},
                                   {"lattice, 30 deg", true, 30.0}, {"lattice, 90 deg", true, 90.0}};
  std::printf("bending-spring energy of a cylinder (kappa = kappa_ref = %.0f 1/m) / (factor * B kappa^2/2 * area) - 1:\n",
              kappa);
  for (const Case& c : cases) {
    const double a = c.angle_deg * M_PI / 180.0;
    double factor = 0.0;
    if (c.lattice) {
      factor = 1.0 - 8.0 / 35.0 * std::cos(6 * a);
    } else {
      for (const Eigen::Vector2d& s : {Eigen::Vector2d(1, 2), Eigen::Vector2d(2, 1), Eigen::Vector2d(-1, 1)})
        factor += 128.0 / 105.0 * std::pow(s.normalized().dot(Eigen::Vector2d(std::cos(a), std::sin(a))), 8);
    }
    std::vector<double> errors;
    std::string row;
    double stretch_ratio = 0.0;
    for (int n : {8, 16, 32}) {
      const TriMesh mesh = c.lattice ? testing::make_lattice(n + 1, 0.1) : make_grid(0.1, 0.1, n, n);
      const MassSpringDiscretization d(mesh, {}, sheet_material(5000.0, b), kappa);
      std::unique_ptr<ForceTerm> term = d.elastic_term(true, true);
      update_at(*term, d, bent_into_cylinder(d, a, kappa));
      const double reference = 0.5 * b * kappa * kappa * mesh_area(mesh);
      errors.push_back(as_springs(term).bending_energy() / (factor * reference) - 1.0);
      stretch_ratio = as_springs(term).stretch_energy() / reference;
      char cell[64];
      std::snprintf(cell, sizeof(cell), "  n = %2d: %+.5f", n, errors.back());
      row += cell;
    }
    std::printf("  %-16s (factor %.4f)%s; stretch springs at n = 32: %.3f x B kappa^2/2 area\n", c.name.c_str(), factor,
                row.c_str(), stretch_ratio);
    EXPECT_LT(std::abs(errors[2]), 0.04) << c.name;
    testing::expect_halved_by_each_refinement(errors, c.name);
  }
}

// The bending springs' energy grows as κ⁴ (their length changes as κ²): at κ_ref/2 and 2κ_ref it is
// 1/4 and 4 times B κ²/2 (times the direction factor). Measured exponent d ln E / d ln κ between
// neighbouring curvatures of the lattice bent across x.
TEST(MassSpringTerm, BendingSpringEnergyIsQuarticInTheCurvature) {
  const double b = 1e-4, kappa_ref = 5.0;
  const TriMesh mesh = testing::make_lattice(33, 0.1);
  const MassSpringDiscretization d(mesh, {}, sheet_material(5000.0, b), kappa_ref);
  const double area = mesh_area(mesh), factor = 27.0 / 35.0;  // φ = 0
  std::unique_ptr<ForceTerm> term = d.elastic_term(true, true);
  std::vector<double> kappas = {0.25 * kappa_ref, 0.5 * kappa_ref, kappa_ref, 2 * kappa_ref, 4 * kappa_ref}, energies;
  for (double kappa : kappas) {
    Eigen::VectorXd x = d.rest();
    for (int v = 0; v < d.num_nodes(); ++v) {
      const double s = d.rest()(3 * v);
      x(3 * v) = std::sin(kappa * s) / kappa;
      x(3 * v + 2) = (1.0 - std::cos(kappa * s)) / kappa;
    }
    update_at(*term, d, x);
    energies.push_back(as_springs(term).bending_energy());
    const double ratio = energies.back() / (factor * 0.5 * b * kappa * kappa * area);
    std::printf("kappa = %5.2f 1/m = %.2f kappa_ref: bending-spring energy %.4e J = %.4f x factor B kappa^2/2 area "
                "(expected (kappa/kappa_ref)^2 = %.4f, less the border's)\n",
                kappa, kappa / kappa_ref, energies.back(), ratio, std::pow(kappa / kappa_ref, 2));
    EXPECT_NEAR(ratio / std::pow(kappa / kappa_ref, 2), 1.0, 0.04) << kappa;
  }
  for (size_t k = 1; k < kappas.size(); ++k) {
    const double exponent = std::log(energies[k] / energies[k - 1]) / std::log(kappas[k] / kappas[k - 1]);
    std::printf("exponent between kappa = %.2f and %.2f 1/m: %.5f\n", kappas[k - 1], kappas[k], exponent);
    EXPECT_NEAR(exponent, 4.0, 0.01) << kappas[k];
  }
}

// The stretch springs in the same isometric cylinder: the flat triangles' chords shorten by
// κ² ℓ³ cos⁴ψ / 24, so the edge springs store, per unit area of the equilateral lattice (side h, the
// edges at 0°, 60°, 120°, bent across φ),
//     E t κ⁴ h⁴ / 1152 · (3/128) (35 + 8 cos 6φ),
// exactly up to O((κh)²) (each triangle's share of k_e carries its own area, so the border adds
// nothing). Against B κ²/2 this grows as (κh)⁴ E t/B: small on the fine meshes above, large for cloth
// at its reference curvature on centimetre meshes (printed) — the flat triangles' membrane locking,
// which the bending springs add to.
TEST(MassSpringTerm, StretchSpringsResistIsometricBendingAsTheDerivedChordLaw) {
  const ShellMaterial m = sheet_material(5000.0, 1e-5);
  const double kappa = MassSpringDiscretization::bending_length_curvature(m);
  std::printf("isometric cylinder of the lattice at kappa_ref = %.2f 1/m (E t = %.0f N/m, B = %.0e N m):\n", kappa,
              m.stretch_modulus, m.bending_rigidity);
  for (double angle_deg : {0.0, 90.0}) {
    const double a = angle_deg * M_PI / 180.0;
    for (int n : {8, 16, 32}) {
      const double h = 0.1 / n;
      const TriMesh mesh = testing::make_lattice(n + 1, 0.1);
      const MassSpringDiscretization d(mesh, {}, m);
      std::unique_ptr<ForceTerm> term = d.elastic_term(true, true);
      update_at(*term, d, bent_into_cylinder(d, a, kappa));
      const double area = mesh_area(mesh);
      const double derived =
          m.stretch_modulus * std::pow(kappa * kappa * h * h, 2) / 1152.0 * 3.0 / 128.0 * (35.0 + 8.0 * std::cos(6 * a)) * area;
      const double bending = 0.5 * m.bending_rigidity * kappa * kappa * area;
      const double ratio = as_springs(term).stretch_energy() / derived;
      std::printf("  %2.0f deg, h = %.5f m (kappa h = %.3f): stretch springs %.4e J = %.4f x derived, %.3g x B kappa^2/2 "
                  "area; bending springs %.3f x B kappa^2/2 area\n",
                  angle_deg, h, kappa * h, as_springs(term).stretch_energy(), ratio,
                  as_springs(term).stretch_energy() / bending, as_springs(term).bending_energy() / bending);
      EXPECT_NEAR(ratio, 1.0, 0.25 * kappa * kappa * h * h) << angle_deg << " deg, n = " << n;
    }
  }
}

// The pattern holds every spring's pair of nodes, and nothing the springs leave empty: the stretch
// springs cover the triangles' pairs, the bending springs the hinges' apex pairs. One stretch
// spring per edge, one bending spring per hinge, each naming its group's slots correctly.
TEST(MassSpringTerm, MatrixPatternCoversEverySpring) {
  const MassSpringDiscretization d(jittered_grid(), {}, sheet_material(5000.0, 1e-4));
  const Eigen::SparseMatrix<double>& p = d.matrix_pattern();
  std::set<std::pair<int, int>> in_pattern;
  for (Eigen::Index col = 0; col < p.cols(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(p, col); it; ++it)
      if (it.row() / 3 != col / 3) in_pattern.insert({static_cast<int>(it.row() / 3), static_cast<int>(col / 3)});
  std::set<std::pair<int, int>> springs;
  for (const std::vector<Spring>* list : {&d.stretch_springs(), &d.bending_springs()})
    for (const Spring& s : *list) {
      EXPECT_EQ(d.blocks().group_node(s.group, s.a), s.i);
      EXPECT_EQ(d.blocks().group_node(s.group, s.b), s.j);
      EXPECT_NE(s.i, s.j);
      springs.insert({s.i, s.j});
      springs.insert({s.j, s.i});
    }
  EXPECT_EQ(springs, in_pattern);
  // 5 × 4 cells: V = 30, T = 40, so V + T − 1 = 69 edges, 18 on the border and 51 interior (the
  // hinges: 5 × 3 along x, 4 × 4 along y, 20 diagonals).
  EXPECT_EQ(d.stretch_springs().size(), 69u);
  EXPECT_EQ(d.bending_springs().size(), d.hinges().size());
  EXPECT_EQ(d.bending_springs().size(), 51u);
  std::printf("pattern: %d nodes, %zu stretch springs, %zu bending springs, %zu off-diagonal blocks\n", d.num_nodes(),
              d.stretch_springs().size(), d.bending_springs().size(), in_pattern.size());

  // At a deformed state every spring's block is non-zero, and the matrix is zero outside them.
  std::unique_ptr<ForceTerm> term = d.elastic_term(true, true);
  const Eigen::MatrixXd k = matrix_at(*term, d, testing::perturbed_rest(d, 2e-3, 4), {1.0, 0.0});
  for (const auto& [i, j] : springs) {
    const double coupling = k.block<3, 3>(3 * i, 3 * j).cwiseAbs().maxCoeff();
    EXPECT_GT(coupling, 0.0) << i << "-" << j;
  }
}

// Kelvin–Voigt damping wraps the term: the same force and energy, the matrix (w_K + c w_D) K; mass
// damping finds every diagonal entry in the pattern.
TEST(MassSpringTerm, DampingWrappersWork) {
  const MassSpringDiscretization d(jittered_grid(), {}, sheet_material(5000.0, 1e-4));
  testing::expect_damping_wrappers_work(d);
  std::unique_ptr<ForceTerm> term = d.elastic_term(true, true);
  EXPECT_GT(matrix_at(*term, d, testing::perturbed_rest(d, 2e-3, 9), {1.0, 0.0}).cwiseAbs().maxCoeff(), 0.0);
}

// Two nodes of a spring at the same place: the direction is undefined and the update says which.
TEST(MassSpringTerm, CoincidentNodesAreReported) {
  const MassSpringDiscretization d(make_grid(0.1, 0.1, 2, 2), {}, sheet_material(5000.0, 1e-4));
  std::unique_ptr<ForceTerm> term = d.elastic_term(true, true);
  Eigen::VectorXd x = d.rest();
  const Spring& s = d.stretch_springs().front();
  x.segment<3>(3 * s.j) = x.segment<3>(3 * s.i);
  try {
    update_at(*term, d, x);
    FAIL() << "a spring of zero length was accepted";
  } catch (const std::runtime_error& e) {
    std::printf("%s\n", e.what());
    EXPECT_NE(std::string(e.what()).find("coincide"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(update_at(*term, d, d.rest()));
}

}  // namespace
}  // namespace clothsim

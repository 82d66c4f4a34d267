// The seeded geometric imperfection (sim/mesh/imperfection.hpp) and its scene key: the largest
// displacement is the amplitude, along the vertex normals; a seed gives the same shape every
// time and another seed another shape; the field is one of position (two meshes of a square
// agree where their vertices coincide) and smooth on the mesh; bad values are errors naming the
// key; the boundary is selected on the unperturbed mesh.
#include "sim/mesh/imperfection.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/scene/scene.hpp"

#include "tests/support/scene_files.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace clothsim {
namespace {

Imperfection imperfection(double amplitude, std::uint64_t seed) {
  Imperfection i;
  i.amplitude = amplitude;
  i.seed = seed;
  return i;
}

TEST(Imperfection, LargestNormalDisplacementIsTheAmplitude) {
  const TriMesh flat = make_grid(1.0, 1.0, 40, 40);  // in z = 0: the normals are +z
  TriMesh m = flat;
  apply_imperfection(m, imperfection(2e-4, 7));
  const Eigen::MatrixX3d d = m.vertices - flat.vertices;
  std::printf("largest |dz| %.6e m, largest in-plane move %.3e m\n", d.col(2).cwiseAbs().maxCoeff(),
              d.leftCols(2).cwiseAbs().maxCoeff());
  EXPECT_NEAR(d.col(2).cwiseAbs().maxCoeff(), 2e-4, 1e-18);
  EXPECT_EQ(d.leftCols(2).cwiseAbs().maxCoeff(), 0.0);
  // Both signs occur: it is a waviness, not a shift.
  EXPECT_LT(d.col(2).minCoeff(), -0.2e-4);
  EXPECT_GT(d.col(2).maxCoeff(), 0.2e-4);
}

TEST(Imperfection, SeedSetsTheShape) {
  const TriMesh flat = make_grid(0.5, 0.3, 20, 12);
  TriMesh a = flat, b = flat, c = flat;
  apply_imperfection(a, imperfection(1e-3, 1));
  apply_imperfection(b, imperfection(1e-3, 1));
  apply_imperfection(c, imperfection(1e-3, 2));
  EXPECT_EQ((a.vertices - b.vertices).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT((a.vertices - c.vertices).cwiseAbs().maxCoeff(), 2e-4);
  // Amplitude 0 leaves the mesh as it is.
  TriMesh d = flat;
  apply_imperfection(d, imperfection(0.0, 1));
  EXPECT_EQ((d.vertices - flat.vertices).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Imperfection, FieldIsAFunctionOfPositionAndSmooth) {
  // The same square at 10 × 10 and 40 × 40 cells: every coarse vertex is a fine one.
  TriMesh coarse = make_grid(1.0, 1.0, 10, 10), fine = make_grid(1.0, 1.0, 40, 40);
  const Eigen::MatrixX3d coarse_rest = coarse.vertices, fine_rest = fine.vertices;
  apply_imperfection(coarse, imperfection(1e-3, 3));
  apply_imperfection(fine, imperfection(1e-3, 3));
  Eigen::VectorXd dc(121), df(121);
  for (int i = 0; i <= 10; ++i)
    for (int j = 0; j <= 10; ++j) {
      const int c = j * 11 + i, f = (4 * j) * 41 + 4 * i;
      ASSERT_NEAR((coarse_rest.row(c) - fine_rest.row(f)).norm(), 0.0, 1e-12);
      dc(c) = coarse.vertices(c, 2) - coarse_rest(c, 2);
      df(c) = fine.vertices(f, 2) - fine_rest(f, 2);
    }
  // One field, scaled on each mesh so that its largest value on that mesh's vertices is the
  // amplitude: the two agree up to one factor.
  const double scale = dc.dot(df) / dc.dot(dc);
  const double largest_mismatch = (df - scale * dc).cwiseAbs().maxCoeff();
  // Neighbouring vertices of the fine grid (2.5 cm apart; shortest default wavelength 8.8 cm).
  double largest_step = 0.0;
  for (int j = 0; j <= 40; ++j)
    for (int i = 0; i < 40; ++i) largest_step = std::max(largest_step, std::abs(fine.vertices(j * 41 + i + 1, 2) - fine.vertices(j * 41 + i, 2)));
  std::printf("coarse vs fine at shared points: scale %.4f, mismatch %.3e m; largest step between neighbours: %.3e m "
              "(amplitude 1e-3 m)\n", scale, largest_mismatch, largest_step);
  EXPECT_LT(largest_mismatch, 1e-15);
  EXPECT_GT(scale, 0.8);
  EXPECT_LT(scale, 1.0);  // the fine mesh comes closer to the field's peak
  EXPECT_LT(largest_step, 0.6e-3);
}

TEST(Imperfection, BadValuesAreErrors) {
  TriMesh m = make_grid(1.0, 1.0, 2, 2);
  Imperfection bad = imperfection(-1e-3, 1);
  EXPECT_THROW(apply_imperfection(m, bad), std::invalid_argument);
  bad = imperfection(std::nan(""), 1);
  EXPECT_THROW(apply_imperfection(m, bad), std::invalid_argument);
  bad = imperfection(1e-3, 1);
  bad.wavelength_min = 0.2;
  bad.wavelength_max = 0.1;
  EXPECT_THROW(apply_imperfection(m, bad), std::invalid_argument);
  bad.wavelength_max = 0.0;
  EXPECT_THROW(apply_imperfection(m, bad), std::invalid_argument);
}

class ImperfectionKey : public testing::SceneFileTest {};

const char* const kPlate = R"({"mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [8, 8]},
  "boundary": [{"select": {"box": [[-1, -1, -1e-9], [1, -0.0999, 1e-9]]}, "fix": ["x", "y", "z"]}])";

TEST_F(ImperfectionKey, PerturbsTheRestShapeAfterTheSelections) {
  const Scene plain = load(std::string(kPlate) + "}");
  const Scene s = load(std::string(kPlate) + R"(, "imperfection": {"amplitude": 0.0002, "seed": 5, "wavelength": [0.02, 0.1]}})");
  const Eigen::MatrixX3d d = s.problem.mesh.vertices - plain.problem.mesh.vertices;
  EXPECT_NEAR(d.col(2).cwiseAbs().maxCoeff(), 2e-4, 1e-18);
  // The thin selection box (|z| <= 1e-9) still found the whole edge of 9 vertices.
  ASSERT_EQ(s.problem.boundary.size(), 1u);
  EXPECT_EQ(s.problem.boundary[0].vertices.size(), 9u);
  // Without "seed": seed 1.
  const Scene s1 = load(std::string(kPlate) + R"(, "imperfection": {"amplitude": 0.0002}})");
  const Scene s1b = load(std::string(kPlate) + R"(, "imperfection": {"amplitude": 0.0002, "seed": 1}})");
  EXPECT_EQ((s1.problem.mesh.vertices - s1b.problem.mesh.vertices).cwiseAbs().maxCoeff(), 0.0);
}

TEST_F(ImperfectionKey, Errors) {
  auto imp = [&](const std::string& j) { return error(std::string(kPlate) + R"(, "imperfection": )" + j + "}"); };
  EXPECT_EQ(imp(R"({"seed": 1})"), expected("imperfection.amplitude: required key is missing"));
  EXPECT_EQ(imp(R"({"amplitude": -0.001})"), expected("imperfection.amplitude: must be >= 0 [m] (got -0.001)"));
  EXPECT_EQ(imp(R"({"amplitude": 0.001, "seed": -1})"), expected("imperfection.seed: must be an integer >= 0 (got -1)"));
  EXPECT_EQ(imp(R"({"amplitude": 0.001, "wavelength": [0.2, 0.1]})"),
            expected("imperfection.wavelength: the shortest wavelength (first) must not exceed the longest (got [0.2,0.1])"));
  EXPECT_EQ(imp(R"({"amplitude": 0.001, "wavelength": [0, 0.1]})"), expected("imperfection.wavelength[0]: must be > 0 [m] (got 0)"));
  EXPECT_EQ(imp(R"({"amplitude": 0.001, "size": 2})"), expected("imperfection.size: unknown key (allowed: amplitude, seed, wavelength)"));
}

}  // namespace
}  // namespace clothsim

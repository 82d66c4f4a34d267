// A flat rest state from the pattern (sim/shell/flat_rest.hpp): every element's patch at rest is
// laid out flat with the pattern's lengths, across seams too, while the mesh's positions (the
// pieces as placed) are where the run starts.
#include "sim/shell/flat_rest.hpp"

#include "sim/corotation/corotational_elements.hpp"
#include "sim/dynamics/simulator.hpp"
#include "sim/pattern/pattern.hpp"
#include "sim/shell/shell_model.hpp"
#include "sim/subdivision/patch.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

namespace clothsim {
namespace {

constexpr double kPi = std::numbers::pi;

ShellMaterial cloth(double bending, double stretch = 5000.0) {
  ShellMaterial m;
  m.stretch_modulus = stretch;
  m.poisson_ratio = 0.25;
  m.bending_rigidity = bending;
  m.areal_density = 0.1;
  return m;
}

PatternSpec one_piece(double width, double height, double edge, std::optional<double> wrap) {
  PatternSpec s;
  s.edge_length = edge;
  PatternPiece p;
  p.name = "panel";
  p.points = {{0, 0}, {width, 0}, {width, height}, {0, height}};
  p.placement.wrap_radius = wrap;
  s.pieces.push_back(p);
  return s;
}

// A tube of radius r and length l sewn from one rectangle (its edges 1 and 3 joined).
PatternSpec tube(double r, double l, double edge) {
  PatternSpec s = one_piece(2 * kPi * r, l, edge, r);
  s.seams.push_back({{"panel", 1, 1}, {"panel", 3, 3}, true});
  return s;
}

double strain_energy(const ShellModel& model) {
  CorotationalElements elements(model, true);
  elements.evaluate(Eigen::VectorXd::Zero(3 * model.num_vertices()));
  return elements.energy();
}

TEST(FlatRest, TubeSewnFromARectangleRestsFlatAndCarriesTheCylindersBendingEnergy) {
  const double r = 0.1, l = 0.3;
  const PatternMesh pm = build_pattern(tube(r, l, 0.01));
  // Bending-dominated (B / (E·t) large): the Loop limit surface of control points on a cylinder
  // lies a little inside it (paper §7), a circumferential strain of order (h/r)² whose membrane
  // energy would otherwise swamp the bending energy measured here.
  const ShellMaterial m = cloth(1e-3, 50.0);
  const ShellModel model(pm.mesh, m, {}, Quadrature::one_point, RestShape::pattern);
  // Every patch at rest is flat (in z = 0) and has no curvature, the seam's patches included.
  for (const ShellElement& el : model.elements()) {
    ASSERT_EQ(el.reference.col(2).cwiseAbs().maxCoeff(), 0.0);
    const SurfacePoint s = surface_point(el.basis[0], el.reference);
    EXPECT_NEAR(s.a11.dot(s.a3), 0.0, 1e-12);
    EXPECT_NEAR(s.a22.dot(s.a3), 0.0, 1e-12);
  }
  // The element's own triangle lies at its pattern coordinates (edge lengths of the pattern).
  for (size_t t = 0; t < pm.mesh.triangles.size(); ++t) {
    const ShellElement& el = model.elements()[t];
    for (int k = 0; k < 3; ++k) {
      const int v = pm.mesh.triangles[t][static_cast<size_t>(k)];
      const auto at = std::find(el.patch.begin(), el.patch.end(), v) - el.patch.begin();
      const Eigen::Vector2d p = el.reference.row(at).head<2>().transpose();
      EXPECT_NEAR((p - pm.mesh.uv[t][static_cast<size_t>(k)]).norm(), 0.0, 1e-12);
    }
  }
  // Placed on the cylinder it is bent from flat by κ = 1/r around and not stretched (wrapping is
  // an isometry): its strain energy is the plate's cylindrical bending energy
  // ½ D κ² · 2π r l with D = B / (1 − ν²).
  const double expected = 0.5 * m.bending_rigidity / (1 - m.poisson_ratio * m.poisson_ratio) / (r * r) * 2 * kPi * r * l;
  EXPECT_NEAR(strain_energy(model) / expected, 1.0, 0.03);
  // With the placed tube as its rest state (today's behaviour) there is nothing to release.
  EXPECT_LT(strain_energy(ShellModel(pm.mesh, m, {}, Quadrature::one_point, RestShape::initial)), 1e-9 * expected);
}

TEST(FlatRest, APlacedFlatPieceIsUnstrained) {
  PatternSpec s = one_piece(0.3, 0.2, 0.02, std::nullopt);
  s.pieces[0].placement.rotate_deg = {30, 40, 50};
  s.pieces[0].placement.translate = {1, 2, 3};
  const PatternMesh pm = build_pattern(s);
  const ShellModel model(pm.mesh, cloth(1e-5), {}, Quadrature::one_point, RestShape::pattern);
  // Energy of a 1e-3 stretch of the whole piece, for scale: ½ K_m ε² A.
  const double scale = 0.5 * 5000.0 * 1e-6 * 0.06;
  EXPECT_LT(strain_energy(model), 1e-20 * scale);
  CorotationalElements elements(model, true);
  elements.evaluate(Eigen::VectorXd::Zero(3 * model.num_vertices()));
  EXPECT_LT(elements.force().cwiseAbs().maxCoeff(), 1e-9);
}

TEST(FlatRest, APieceWrappedOntoACylinderSpringsBackFlat) {
  // A 0.2 m square bent by 2 rad around a cylinder of 0.1 m, released without gravity: with its
  // rest state flat it opens up into a plane; with the placed shape as rest it would stay bent.
  const PatternMesh pm = build_pattern(one_piece(0.2, 0.2, 0.02, 0.1));
  Problem p;
  p.mesh = pm.mesh;
  p.rest = RestShape::pattern;
  p.material = cloth(1e-3);
  p.time.dt = 2e-3;
  p.time.end = 1.0;
  p.damping.mass = 20.0;
  Simulator sim(p);
  const auto bow = [&] {
    // The largest distance of a vertex from the least-squares plane of all of them.
    const Eigen::MatrixX3d x = sim.state().positions();
    const Eigen::RowVector3d c = x.colwise().mean();
    const Eigen::MatrixX3d d = x.rowwise() - c;
    const Eigen::JacobiSVD<Eigen::MatrixX3d> svd(d, Eigen::ComputeFullV);  // (V is 3 x 3)
    return (d * svd.matrixV().col(2)).cwiseAbs().maxCoeff();
  };
  const double start = bow();
  EXPECT_GT(start, 0.02);  // the arc's sag r (1 − cos 1) = 4.6 cm, split either side of the plane
  const double energy_start = sim.elastic_energy();
  for (int k = 0; k < sim.num_steps(); ++k) sim.step();
  EXPECT_LT(bow(), 0.01 * start);
  EXPECT_LT(sim.elastic_energy(), 1e-4 * energy_start);
  // The flat piece keeps its pattern's area (the lumped mass comes from it too).
  EXPECT_NEAR(sim.vertex_mass().sum(), 0.1 * 0.04, 1e-12);
}

TEST(FlatRest, NeedsTextureCoordinates) {
  const PatternMesh pm = build_pattern(one_piece(0.2, 0.2, 0.02, std::nullopt));
  TriMesh bare = pm.mesh;
  bare.uv.clear();
  try {
    ShellModel(bare, cloth(1e-5), {}, Quadrature::one_point, RestShape::pattern);
    FAIL() << "no error";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("texture coordinates"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace clothsim

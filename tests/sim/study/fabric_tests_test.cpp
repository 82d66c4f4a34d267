// The fabric tests' parts (sim/study/drape_measure, sim/study/fabric_tests; docs/fabric_test.md):
// the Cusick measurement on shapes of known area and lobe count, the specimen and apparatus
// meshes, the tensile tests against the orthotropic membrane formula and the cantilever test's
// bending length against (B / (ρ_A g))^(1/3) (the heavy elastica puts the chord at 41.5° at
// L / c = 2.0003, so c = L / 2 is the standard's exact reading).
#include "sim/mesh/obj_io.hpp"
#include "sim/study/drape_measure.hpp"
#include "sim/study/fabric_tests.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace clothsim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A fan of triangles round the origin in the x–z plane over the outline r(θ) (n segments).
void star(double radius, double amplitude, int lobes, int n, Eigen::MatrixX3d& v, std::vector<std::array<int, 3>>& f) {
  v.resize(n + 1, 3);
  v.row(0).setZero();
  for (int i = 0; i < n; ++i) {
    const double t = 2 * kPi * i / n, r = radius * (1 + amplitude * std::cos(lobes * t));
    v.row(i + 1) << r * std::cos(t), 0.3, -r * std::sin(t);
  }
  f.clear();
  for (int i = 0; i < n; ++i) f.push_back({0, i + 1, (i + 1) % n + 1});
}

TEST(DrapeMeasure, FlatSpecimenHasCoefficientOneAndNoNodes) {
  Eigen::MatrixX3d v;
  std::vector<std::array<int, 3>> f;
  star(0.15, 0.0, 0, 2000, v, f);
  const DrapeMeasure m = measure_drape(v, f);
  EXPECT_NEAR(m.shadow_area, kPi * 0.15 * 0.15, 2 * m.area_bound + 1e-4);
  EXPECT_NEAR(m.drape_coefficient, 1.0, 0.01);
  EXPECT_EQ(m.nodes, 0);
}

TEST(DrapeMeasure, LobedShadowAreaAndNodes) {
  // r = R (1 + a cos kθ): area π R² (1 + a²/2) exactly.
  for (const int lobes : {2, 5, 7}) {
    Eigen::MatrixX3d v;
    std::vector<std::array<int, 3>> f;
    const double R = 0.12, a = 0.15;
    star(R, a, lobes, 4000, v, f);
    const DrapeMeasure m = measure_drape(v, f);
    const double area = kPi * R * R * (1 + a * a / 2);
    EXPECT_NEAR(m.shadow_area, area, 2 * m.area_bound) << lobes;
    const double support = kPi * 0.09 * 0.09, specimen = kPi * 0.15 * 0.15;
    EXPECT_NEAR(m.drape_coefficient, (area - support) / (specimen - support), 0.01) << lobes;
    EXPECT_EQ(m.nodes, lobes);
  }
}

TEST(DrapeMeasure, RipplesOnTheOutlineAreNotNodes) {
  // Three lobes of 18 mm with ripples of 0.6 mm (40 around) on the outline: 3 nodes at the
  // default prominence of 5 mm, more with none.
  Eigen::MatrixX3d v(4001, 3);
  std::vector<std::array<int, 3>> f;
  v.row(0).setZero();
  for (int i = 0; i < 4000; ++i) {
    const double t = 2 * kPi * i / 4000, r = 0.12 * (1 + 0.15 * std::cos(3 * t) + 0.005 * std::cos(40 * t));
    v.row(i + 1) << r * std::cos(t), 0.0, -r * std::sin(t);
    f.push_back({0, i + 1, (i + 1) % 4000 + 1});
  }
  EXPECT_EQ(measure_drape(v, f).nodes, 3);
  DrapeMeasureSettings s;
  s.prominence = 0;
  EXPECT_GT(measure_drape(v, f, s).nodes, 3);
}

TEST(DrapeMeasure, TheSupportDiscIsInTheShadow) {
  // A clamped specimen's mesh leaves out its middle: a flat annulus from the support's rim to the
  // specimen's edge casts, with the support under it, the shadow of the whole disc (DC 1).
  const TriMesh ring = read_obj_text(annulus_obj(0.09, 0.15, 12, 0), "annulus.obj");
  const DrapeMeasure m = measure_drape(ring.vertices, ring.triangles);
  EXPECT_NEAR(m.drape_coefficient, 1.0, 0.01);
  EXPECT_EQ(m.nodes, 0);
  // A specimen smaller than the support, off its axis: the support disc still counts whole.
  Eigen::MatrixX3d v;
  std::vector<std::array<int, 3>> f;
  star(0.03, 0.0, 0, 400, v, f);
  DrapeMeasureSettings s;
  s.support_center = Eigen::Vector3d(0.5, 0.0, -0.5);
  const DrapeMeasure apart = measure_drape(v, f, s);
  EXPECT_NEAR(apart.shadow_area, kPi * (0.03 * 0.03 + 0.09 * 0.09), 2 * apart.area_bound);
}

TEST(DrapeMeasure, BadInputIsRefused) {
  Eigen::MatrixX3d v(3, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_THROW(measure_drape(v, {}), std::invalid_argument);
  DrapeMeasureSettings s;
  s.cell = 0;
  EXPECT_THROW(measure_drape(v, {{0, 1, 2}}, s), std::invalid_argument);
  s = {};
  s.cell = 1e-6;  // 10^12 cells
  EXPECT_THROW(measure_drape(v, {{0, 1, 2}}, s), std::invalid_argument);
}

TEST(FabricTest, DiscSpecimenMesh) {
  const int rings = 7;
  const TriMesh disc = read_obj_text(disc_obj(0.15, rings), "disc.obj");
  EXPECT_EQ(disc.num_vertices(), 1 + 3 * rings * (rings + 1));
  EXPECT_EQ(disc.num_triangles(), 6 * rings * rings);
  double area = 0;
  for (const auto& t : disc.triangles) {
    const Eigen::Vector3d a = disc.vertices.row(t[0]), b = disc.vertices.row(t[1]), c = disc.vertices.row(t[2]);
    const Eigen::Vector3d n = (b - a).cross(c - a);
    EXPECT_GT(n.y(), 0);  // normal +y
    area += 0.5 * n.norm();
  }
  // The outer ring is a polygon of 6N corners on the circle: area (6N/2) R² sin(2π/6N).
  EXPECT_NEAR(area, 3 * rings * 0.15 * 0.15 * std::sin(2 * kPi / (6 * rings)), 1e-12);
}

TEST(FabricTest, AnnulusSpecimenMesh) {
  // Rings at inner·q^k, k = −2 … N, of m vertices each: the rim's ring exactly at the support's
  // radius, nearly equilateral triangles, every interior vertex of valence 6, normal +y, and the
  // area between the outer and the innermost polygon.
  const int rings = 10, inside = 2;
  const double inner = 0.09, outer = 0.15;
  const int m = annulus_around(inner, outer, rings);
  const double q = std::pow(outer / inner, 1.0 / rings);
  EXPECT_EQ(m, static_cast<int>(std::lround(std::sqrt(3.0) * kPi / (q - 1))));
  const TriMesh a = read_obj_text(annulus_obj(inner, outer, rings, inside), "annulus.obj");
  ASSERT_EQ(a.num_vertices(), (rings + 1 + inside) * m);
  EXPECT_EQ(a.num_triangles(), 2 * (rings + inside) * m);
  std::vector<int> valence(static_cast<size_t>(a.num_vertices()), 0);
  double area = 0, worst = 1;
  for (const auto& t : a.triangles) {
    const Eigen::Vector3d p = a.vertices.row(t[0]), b = a.vertices.row(t[1]), c = a.vertices.row(t[2]);
    const Eigen::Vector3d n = (b - p).cross(c - p);
    EXPECT_GT(n.y(), 0);
    area += 0.5 * n.norm();
    const double e[3] = {(b - p).norm(), (c - b).norm(), (p - c).norm()};
    worst = std::max(worst, std::max({e[0], e[1], e[2]}) / std::min({e[0], e[1], e[2]}));
    for (const int v : t) ++valence[static_cast<size_t>(v)];
  }
  EXPECT_LT(worst, 1.1);
  int on_rim = 0, inside_rim = 0;
  for (Eigen::Index i = 0; i < a.vertices.rows(); ++i) {
    const double r = std::hypot(a.vertices(i, 0), a.vertices(i, 2));
    if (std::abs(r - inner) < 1e-12) ++on_rim;
    if (r < inner - 1e-12) ++inside_rim;
    // Border vertices (the innermost and the outer ring) have 3 triangles, the rest 6.
    const bool border = r < inner / (q * q) * (1 + 1e-9) || r > outer * (1 - 1e-9);
    if (!border) {
      EXPECT_EQ(valence[static_cast<size_t>(i)], 6) << i;
    }
  }
  EXPECT_EQ(on_rim, m);
  EXPECT_EQ(inside_rim, inside * m);
  const double r_in = inner / (q * q);
  EXPECT_NEAR(area, 0.5 * m * std::sin(2 * kPi / m) * (outer * outer - r_in * r_in), 1e-12);
  EXPECT_THROW(annulus_obj(0.15, 0.09, 4, 0), std::invalid_argument);
}

TEST(FabricTest, ClampedCusickHoldsTheSpecimenUpToTheRim) {
  // The standard's upper disc: every vertex within the support's radius fixed, none beyond it,
  // and the support's top out of the contact's reach of the clamped part.
  const FabricUnderTest f = fabric_under_test("polyester_faille_ortho");
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "clothsim_cusick_clamp_test";
  std::filesystem::create_directories(dir);
  CusickSettings s;
  ASSERT_TRUE(s.clamped);
  std::ofstream(dir / "annulus.obj") << cusick_specimen_obj(s, 8);
  for (const double a : {0.0, 0.003}) {
    s.imperfection = a;
    const Scene scene = load_scene_text(cusick_scene(f, "annulus.obj", s).dump(), dir / "cusick.json", {});
    EXPECT_EQ(scene.problem.mesh.num_vertices(), cusick_vertices(s, 8));
    ASSERT_EQ(scene.problem.boundary.size(), 1u);
    const BoundaryCondition& clamp = scene.problem.boundary[0];
    EXPECT_EQ(clamp.fix, (std::array<bool, 3>{true, true, true}));
    std::vector<bool> held(static_cast<size_t>(scene.problem.mesh.num_vertices()), false);
    for (const int v : clamp.vertices) held[static_cast<size_t>(v)] = true;
    for (Eigen::Index i = 0; i < scene.problem.mesh.vertices.rows(); ++i) {
      const double r = std::hypot(scene.problem.mesh.vertices(i, 0), scene.problem.mesh.vertices(i, 2));
      EXPECT_EQ(held[static_cast<size_t>(i)], r <= s.support_radius * (1 + 1e-9)) << i << " at r = " << r;
    }
    EXPECT_EQ(static_cast<int>(clamp.vertices.size()), (s.clamped_rings + 1) * annulus_around(0.09, 0.15, 8));
    const nlohmann::json support = cusick_scene(f, "annulus.obj", s).at("obstacles").at(1);
    EXPECT_EQ(support.at("name"), "support");
    EXPECT_DOUBLE_EQ(support.at("to").at(1).get<double>(), s.height - 2 * s.thickness);
    // The upper disc lies above every clamped vertex by at least twice the contact thickness.
    const nlohmann::json upper = cusick_scene(f, "annulus.obj", s).at("obstacles").at(2);
    EXPECT_EQ(upper.at("name"), "clamp");
    double highest = -1e9;
    for (const int v : clamp.vertices) highest = std::max(highest, scene.problem.mesh.vertices(v, 1));
    EXPECT_GE(upper.at("from").at(1).get<double>() - highest, 2 * s.thickness - 1e-12) << a;
  }
  std::filesystem::remove_all(dir);
}

TEST(FabricTest, CusickSpecimenStartsClearOfTheSupport) {
  // With and without a seeded imperfection, every control vertex starts at least the contact
  // thickness above the support's top (an imperfection of 2 mm on a 1 mm gap once started the
  // specimen inside the support).
  const FabricUnderTest f = fabric_under_test("polyester_faille_ortho");
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "clothsim_cusick_scene_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "disc.obj") << disc_obj(0.15, 8);
  for (const double a : {0.0, 0.002, 0.005}) {
    CusickSettings s;
    s.clamped = false;  // loose on the support
    s.imperfection = a;
    const Scene scene = load_scene_text(cusick_scene(f, "disc.obj", s).dump(), dir / "cusick.json", {});
    const double top = s.height - s.thickness;  // the support's top
    double lowest = 1e9;
    for (Eigen::Index i = 0; i < scene.problem.mesh.vertices.rows(); ++i)
      if (std::hypot(scene.problem.mesh.vertices(i, 0), scene.problem.mesh.vertices(i, 2)) <= s.support_radius)
        lowest = std::min(lowest, scene.problem.mesh.vertices(i, 1));
    EXPECT_GE(lowest - top, s.thickness - 1e-12) << a;
  }
  std::filesystem::remove_all(dir);
}

TEST(FabricTest, CusickRampLowersTheSpecimenAndThenRunsTheEndTime) {
  // --ramp T: gravity grows over T s (loads.ramp_time), and the drape then has `end` s more.
  const FabricUnderTest f = fabric_under_test("cotton_broadcloth_ortho");
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "clothsim_cusick_ramp_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "disc.obj") << disc_obj(0.15, 4);
  CusickSettings s;
  s.ramp = 2.0;
  s.end = 3.0;
  const Scene ramped = load_scene_text(cusick_scene(f, "disc.obj", s).dump(), dir / "cusick.json", {});
  EXPECT_DOUBLE_EQ(ramped.problem.ramp_time, 2.0);
  EXPECT_DOUBLE_EQ(ramped.problem.time.end, 5.0);
  s.ramp = 0.0;
  const Scene dropped = load_scene_text(cusick_scene(f, "disc.obj", s).dump(), dir / "cusick.json", {});
  EXPECT_DOUBLE_EQ(dropped.problem.ramp_time, 0.0);
  EXPECT_DOUBLE_EQ(dropped.problem.time.end, 3.0);
  std::filesystem::remove_all(dir);
}

TEST(FabricTest, MaterialFromPresetAndMeasurements) {
  const FabricUnderTest f = fabric_under_test("polyester_faille_ortho");
  ASSERT_TRUE(f.law.orthotropic());
  ASSERT_TRUE(f.measured.has_value());
  EXPECT_DOUBLE_EQ(*f.measured->drape_coefficient, 0.283);
  EXPECT_EQ(*f.measured->nodes, 7);
  EXPECT_NEAR(strip_bending_rigidity(f.law, 0), 1.86e-6, 1e-12);  // B along the warp
  EXPECT_NEAR(shear_modulus(f.law), 56.19, 0.01);                  // 1 gf/cm/deg
  EXPECT_FALSE(fabric_under_test("black_denim").measured.has_value());
  EXPECT_THROW(fabric_under_test("no_such_fabric"), std::exception);
}

TEST(FabricTest, TensileModuliAlongWarpWeftAndBias) {
  const FabricUnderTest f = fabric_under_test("cotton_broadcloth_ortho");
  const TensileSettings s;
  double e[3];
  int i = 0;
  for (const double angle : {0.0, 90.0, 45.0}) {
    const TensileResult t = tensile_test(f, angle, s);
    EXPECT_NEAR(t.modulus / t.expected, 1.0, 0.03) << angle;
    e[i++] = t.modulus;
  }
  // The bias modulus is set by the shear: G recovered within 3 %.
  const Orthotropy& o = *f.law.orthotropy;
  EXPECT_NEAR(shear_from_bias(e[2], e[0], e[1], o.poisson) / shear_modulus(f.law), 1.0, 0.03);
}

TEST(FabricTest, ApparatusIsAClosedObstacle) {
  // Read as an obstacle of a scene (closed, consistently oriented, outward).
  const TriMesh m = read_obj_text(cantilever_apparatus_obj(41.5, 0.0005, 0.03), "apparatus.obj");
  EXPECT_EQ(m.num_triangles(), 12);
  double volume = 0;
  for (const auto& t : m.triangles)
    volume += Eigen::Vector3d(m.vertices.row(t[0])).dot(Eigen::Vector3d(m.vertices.row(t[1])).cross(Eigen::Vector3d(m.vertices.row(t[2])))) / 6;
  // Profile area × extrusion: trapezoid (back + run + back) · depth / 2 … as built.
  const double depth = 0.06, back = 0.05, run = depth / std::tan(41.5 * kPi / 180);
  EXPECT_NEAR(volume, (2 * back + run) * depth / 2 * 0.06, 1e-12);
}

TEST(FabricTest, CantileverBendingLengthWarpAndWeft) {
  // A woven law with different rigidities along warp and weft.
  const FabricUnderTest f = fabric_under_test("black_denim_ortho");
  CantileverSettings s;
  for (const double angle : {0.0, 90.0}) {
    const CantileverResult r = cantilever_test(f, angle, s);
    EXPECT_NEAR(r.bending_length / r.expected_length, 1.0, 0.03) << angle;
    EXPECT_LT(r.runs.back().tip_speed, 1e-3);
    EXPECT_LT(std::abs(r.runs.back().chord_deg - 41.5), s.tolerance_deg + 1e-12);
  }
}

}  // namespace
}  // namespace clothsim

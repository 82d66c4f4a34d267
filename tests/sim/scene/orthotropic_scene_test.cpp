// The orthotropic material keys (material.stretch_modulus / bending_rigidity as objects,
// material.grain; scenes/README.md, Material) and the grain directions of grid, cylinder and OBJ
// meshes (docs/materials.md, Grain): values read, defaults, and errors that name the key.
#include "sim/scene/scene.hpp"

#include "sim/mesh/grain.hpp"
#include "sim/mesh/obj_io.hpp"
#include "sim/shell/material_presets.hpp"

#include "tests/support/scene_files.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>

namespace clothsim {
namespace {

class OrthotropicScene : public testing::SceneFileTest {};

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

const char* const kGrid = R"("mesh": {"primitive": "grid", "size": [0.2, 0.1], "divisions": [4, 2]})";
const char* const kWoven =
    R"("stretch_modulus": {"warp": 5000, "weft": 3000, "shear": 60, "poisson": 0.25},
       "bending_rigidity": {"warp": 1.2e-5, "weft": 0.9e-5, "twist": 0.5e-5}, "areal_density": 0.12)";

std::string scene(const std::string& material, const std::string& mesh = kGrid) {
  return "{" + mesh + R"(, "material": {)" + material + "}}";
}

TEST_F(OrthotropicScene, TheIssuesExampleIsReadAsWritten) {
  const Scene s = load(scene(std::string(kWoven) + R"(, "grain": {"warp_deg": 0})"));
  const ShellMaterial& m = s.problem.material;
  ASSERT_TRUE(m.orthotropic());
  EXPECT_EQ(m.orthotropy->warp_stretch, 5000);
  EXPECT_EQ(m.orthotropy->weft_stretch, 3000);
  EXPECT_EQ(m.orthotropy->shear_stretch, 60);
  EXPECT_EQ(m.orthotropy->poisson, 0.25);
  EXPECT_EQ(m.orthotropy->warp_bending, 1.2e-5);
  EXPECT_EQ(m.orthotropy->weft_bending, 0.9e-5);
  EXPECT_EQ(m.orthotropy->twist, 0.5e-5);
  EXPECT_EQ(m.areal_density, 0.12);
  // The representative isotropic values: geometric means.
  EXPECT_NEAR(m.stretch_modulus, std::sqrt(5000.0 * 3000.0), 1e-9);
  EXPECT_NEAR(m.bending_rigidity, std::sqrt(1.2e-5 * 0.9e-5), 1e-18);
  ASSERT_EQ(s.problem.mesh.warp.size(), s.problem.mesh.triangles.size());
  for (const Eigen::Vector3d& w : s.problem.mesh.warp) EXPECT_LT((w - Eigen::Vector3d::UnitX()).norm(), 1e-15);
}

TEST_F(OrthotropicScene, NumbersKeepTheIsotropicMeaning) {
  const Scene s = load(scene(R"("stretch_modulus": 5000, "bending_rigidity": 1e-5, "poisson_ratio": 0.25)"));
  EXPECT_FALSE(s.problem.material.orthotropic());
  EXPECT_TRUE(s.problem.mesh.warp.empty());  // no grain needed, none made
}

TEST_F(OrthotropicScene, DefaultTwistAndMixedForms) {
  // No twist: √(B_w B_f) / (2 (1 + ν √(B_f/B_w))).
  Scene s = load(scene(R"("stretch_modulus": {"warp": 5000, "weft": 3000, "shear": 60, "poisson": 0.25},
                          "bending_rigidity": {"warp": 1.6e-5, "weft": 0.4e-5})"));
  const double mean = 0.8e-5, nu = 0.25 * 0.5;
  EXPECT_NEAR(s.problem.material.orthotropy->twist, mean / (2 * (1 + nu)), 1e-20);
  // A number bending rigidity beside an object stretch modulus: isotropic bending with the
  // membrane's ν (twist B/(2(1 + ν))).
  s = load(scene(R"("stretch_modulus": {"warp": 5000, "weft": 3000, "shear": 60, "poisson": 0.25},
                    "bending_rigidity": 2e-5)"));
  EXPECT_EQ(s.problem.material.orthotropy->warp_bending, 2e-5);
  EXPECT_EQ(s.problem.material.orthotropy->weft_bending, 2e-5);
  EXPECT_NEAR(s.problem.material.orthotropy->twist, 2e-5 / 2.5, 1e-20);
  // A number stretch modulus beside an object bending rigidity: an isotropic membrane with
  // poisson_ratio (shear E/(2(1 + ν))).
  s = load(scene(R"("stretch_modulus": 4000, "poisson_ratio": 0.3, "bending_rigidity": {"warp": 1e-5, "weft": 2e-5})"));
  EXPECT_EQ(s.problem.material.orthotropy->warp_stretch, 4000);
  EXPECT_EQ(s.problem.material.orthotropy->weft_stretch, 4000);
  EXPECT_NEAR(s.problem.material.orthotropy->shear_stretch, 4000 / 2.6, 1e-9);
  EXPECT_EQ(s.problem.material.orthotropy->poisson, 0.3);
}

TEST_F(OrthotropicScene, ErrorsNameTheKey) {
  const std::string with_grain = std::string(kWoven) + R"(, "grain": {"warp_deg": 0})";
  auto err = [&](const std::string& material) { return error(scene(material)); };
  std::string e = err(R"("stretch_modulus": {"warp": 5000, "weft": 0, "shear": 60, "poisson": 0.25})");
  EXPECT_TRUE(contains(e, expected("material.stretch_modulus.weft: must be > 0"))) << e;
  e = err(R"("stretch_modulus": {"warp": 5000, "weft": 3000, "poisson": 0.25})");
  EXPECT_TRUE(contains(e, expected("material.stretch_modulus.shear: required key is missing"))) << e;
  e = err(R"("stretch_modulus": {"warp": 5000, "weft": 3000, "shear": 60, "poisson": 0.25, "bias": 3})");
  EXPECT_TRUE(contains(e, expected("material.stretch_modulus.bias: unknown key"))) << e;
  // ν² ≥ E_w/E_f: 1.3² = 1.69 ≥ 5000/3000.
  e = err(R"("stretch_modulus": {"warp": 5000, "weft": 3000, "shear": 60, "poisson": 1.3})");
  EXPECT_TRUE(contains(e, expected("material.stretch_modulus.poisson: makes the membrane law indefinite"))) << e;
  e = err(R"("stretch_modulus": {"warp": 5000, "weft": 3000, "shear": 60, "poisson": -0.1})");
  EXPECT_TRUE(contains(e, expected("material.stretch_modulus.poisson: must be >= 0"))) << e;
  e = err(R"("bending_rigidity": {"warp": 1e-5})");
  EXPECT_TRUE(contains(e, expected("material.bending_rigidity.weft: required key is missing"))) << e;
  e = err(R"("bending_rigidity": {"warp": 1e-5, "weft": 1e-5, "twist": -1})");
  EXPECT_TRUE(contains(e, expected("material.bending_rigidity.twist: must be > 0"))) << e;
  e = err(R"("bending_rigidity": {"warp": 1e-5, "weft": 1e-5, "bias": 1})");
  EXPECT_TRUE(contains(e, expected("material.bending_rigidity.bias: unknown key"))) << e;
  // The bending law with the membrane's ν: ν² = 0.64 ≥ B_w/B_f = 0.5.
  e = err(R"("stretch_modulus": {"warp": 5000, "weft": 3000, "shear": 60, "poisson": 0.8},
             "bending_rigidity": {"warp": 1e-5, "weft": 2e-5})");
  EXPECT_TRUE(contains(e, expected("material.bending_rigidity: with the membrane's poisson"))) << e;
  e = err(std::string(kWoven) + R"(, "poisson_ratio": 0.3)");
  EXPECT_TRUE(contains(e, expected("material.poisson_ratio: cannot be combined with an orthotropic membrane"))) << e;
  e = err(std::string(kWoven) + R"(, "grain": {"warp": 0})");
  EXPECT_TRUE(contains(e, expected("material.grain.warp: unknown key"))) << e;
  e = err(std::string(kWoven) + R"(, "grain": {"warp_deg": "x"})");
  EXPECT_TRUE(contains(e, expected("material.grain.warp_deg: expected a number"))) << e;
  EXPECT_EQ(err(with_grain), "no error");
}

TEST_F(OrthotropicScene, GridGrainTurnsFromXTowardsY) {
  const Scene s = load(scene(std::string(kWoven) + R"(, "grain": {"warp_deg": 30})"));
  const Eigen::Vector3d expected_dir(std::sqrt(3.0) / 2, 0.5, 0);
  for (const Eigen::Vector3d& w : s.problem.mesh.warp) EXPECT_LT((w - expected_dir).norm(), 1e-15);
  // The grain turns with mesh.rotate (90° about z: +x becomes +y).
  const Scene r = load(scene(std::string(kWoven),
                             R"("mesh": {"primitive": "grid", "size": [0.2, 0.1], "divisions": [4, 2],
                                 "rotate": {"axis": [0, 0, 1], "angle_deg": 90}})"));
  for (const Eigen::Vector3d& w : r.problem.mesh.warp) EXPECT_LT((w - Eigen::Vector3d::UnitY()).norm(), 1e-15);
}

TEST_F(OrthotropicScene, CylinderGrainRunsAlongTheAxisAndTurnsTowardsTheCircumference) {
  const std::string cylinder = R"("mesh": {"primitive": "cylinder", "radius": 0.05, "length": 0.1, "segments": 12, "rings": 4})";
  Scene s = load(scene(kWoven, cylinder));
  ASSERT_EQ(s.problem.mesh.warp.size(), s.problem.mesh.triangles.size());
  for (const Eigen::Vector3d& w : s.problem.mesh.warp) EXPECT_LT((w - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  s = load(scene(std::string(kWoven) + R"(, "grain": {"warp_deg": 90})", cylinder));
  const TriMesh& m = s.problem.mesh;
  for (int t = 0; t < m.num_triangles(); ++t) {
    const auto& tri = m.triangles[static_cast<size_t>(t)];
    const Eigen::Vector3d c = (m.vertices.row(tri[0]) + m.vertices.row(tri[1]) + m.vertices.row(tri[2])).transpose() / 3;
    const Eigen::Vector3d w = m.warp[static_cast<size_t>(t)];
    EXPECT_NEAR(w.norm(), 1.0, 1e-14);
    EXPECT_NEAR(w.y(), 0.0, 1e-14);                           // no axial part
    EXPECT_NEAR(w.dot(Eigen::Vector3d(c.x(), 0, c.z()).normalized()), 0.0, 1e-14);  // tangent to the circle
    // The direction of increasing θ of make_cylinder: (−sin θ, 0, −cos θ) at (cos θ, ·, −sin θ).
    const double theta = std::atan2(-c.z(), c.x());
    EXPECT_GT(w.dot(Eigen::Vector3d(-std::sin(theta), 0, -std::cos(theta))), 0.999);
  }
}

TEST_F(OrthotropicScene, ObjGrainFollowsTheTextureCoordinates) {
  // A unit square whose u runs along −y and v along +x (the texture turned by 90°): the warp (+u)
  // is −y; with warp_deg 90 it is +v = +x.
  write("square.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "vt 1 0\nvt 1 1\nvt 0 1\nvt 0 0\n"
        "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  Scene s = load(scene(kWoven, R"("mesh": {"obj": "square.obj"})"));
  ASSERT_EQ(s.problem.mesh.warp.size(), s.problem.mesh.triangles.size());
  for (const Eigen::Vector3d& w : s.problem.mesh.warp) EXPECT_LT((w - Eigen::Vector3d(0, -1, 0)).norm(), 1e-14);
  s = load(scene(std::string(kWoven) + R"(, "grain": {"warp_deg": 90})", R"("mesh": {"obj": "square.obj"})"));
  for (const Eigen::Vector3d& w : s.problem.mesh.warp) EXPECT_LT((w - Eigen::Vector3d(1, 0, 0)).norm(), 1e-14);
  // Without texture coordinates: the grain key, or an orthotropic material, is an error naming it.
  write("plain.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  std::string e = error(scene(std::string(kWoven) + R"(, "grain": {"warp_deg": 0})", R"("mesh": {"obj": "plain.obj"})"));
  EXPECT_TRUE(contains(e, expected("material.grain: the mesh \"plain.obj\" has no texture coordinates"))) << e;
  e = error(scene(kWoven, R"("mesh": {"obj": "plain.obj"})"));
  EXPECT_TRUE(contains(e, expected("material: an orthotropic material needs the grain direction"))) << e;
  // An isotropic material on it needs none.
  EXPECT_EQ(error(scene(R"("stretch_modulus": 5000)", R"("mesh": {"obj": "plain.obj"})")), "no error");
  // Degenerate uv (all corners at one point) names the triangle.
  write("flat_uv.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 1/1 3/1 4/1\n");
  e = error(scene(kWoven, R"("mesh": {"obj": "flat_uv.obj"})"));
  EXPECT_TRUE(contains(e, "triangle 0 has degenerate texture coordinates")) << e;
}

// The orthotropic presets against the fit done by hand from the published coefficients
// (docs/materials.md, Presets; numbers computed independently of the code).
TEST(OrthotropicPresets, FitsOfTheMeasuredCloths) {
  const std::optional<ShellMaterial> denim = material_preset("black_denim_ortho");
  ASSERT_TRUE(denim && denim->orthotropic());
  const Orthotropy& d = *denim->orthotropy;
  EXPECT_NEAR(d.warp_stretch, 205.249, 1e-3);   // 205.352 − 10.234²/1013.886
  EXPECT_NEAR(d.weft_stretch, 1013.376, 1e-3);  // 1013.886 − 10.234²/205.352
  EXPECT_NEAR(d.poisson, 0.0100939, 1e-6);      // 10.234/1013.886
  EXPECT_NEAR(d.shear_stretch, 26.6936, 1e-4);  // 53.387/2
  EXPECT_NEAR(d.warp_bending, 9.6951576e-05, 1e-15);
  EXPECT_NEAR(d.weft_bending, 6.4196457e-05, 1e-15);
  EXPECT_NEAR(d.twist, 3.469e-05, 0.001e-05);
  EXPECT_EQ(denim->areal_density, 0.324);
  // A negative c12 (navy sparkle sweat: c12 = −19.9, c12² > c11 c22) is clamped: ν = 0.
  const Orthotropy navy = *material_preset("navy_sparkle_sweat_ortho")->orthotropy;
  EXPECT_EQ(navy.poisson, 0.0);
  EXPECT_EQ(navy.warp_stretch, 12.486332);
  EXPECT_EQ(navy.weft_stretch, 3.272434);
  // Kawabata fabrics: G = 1 gf/cm/deg = 56.19 N/m (assumed), B as measured along both directions.
  const Orthotropy cotton = *material_preset("cotton_broadcloth_ortho")->orthotropy;
  EXPECT_NEAR(cotton.shear_stretch, 56.19, 0.01);
  EXPECT_EQ(cotton.warp_bending, 1.157e-5);
  EXPECT_EQ(cotton.weft_bending, 1.157e-5);
  // Every orthotropic preset is a valid law; the isotropic ones stay isotropic.
  int orthotropic = 0;
  for (const std::string& name : material_preset_names()) {
    const ShellMaterial m = *material_preset(name);
    EXPECT_EQ(validate(m), "") << name;
    EXPECT_EQ(m.orthotropic(), name.size() > 6 && name.substr(name.size() - 6) == "_ortho") << name;
    orthotropic += m.orthotropic();
  }
  EXPECT_EQ(orthotropic, 14);
}

TEST_F(OrthotropicScene, OrthotropicPresetsLoadAndTakeNumberOverrides) {
  Scene s = load(scene(R"("preset": "black_denim_ortho", "grain": {"warp_deg": 90})"));
  ASSERT_TRUE(s.problem.material.orthotropic());
  EXPECT_NEAR(s.problem.material.orthotropy->shear_stretch, 26.6936, 1e-4);
  for (const Eigen::Vector3d& w : s.problem.mesh.warp) EXPECT_LT((w - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  // A number bending rigidity replaces the preset's bending (isotropic, default twist).
  s = load(scene(R"("preset": "black_denim_ortho", "bending_rigidity": 1e-5)"));
  EXPECT_EQ(s.problem.material.orthotropy->warp_bending, 1e-5);
  EXPECT_EQ(s.problem.material.orthotropy->shear_stretch, 0.5 * 53.387184);
  const std::string e = error(scene(R"("preset": "black_denim_ortho", "poisson_ratio": 0.2)"));
  EXPECT_TRUE(contains(e, expected("material.poisson_ratio: cannot be combined with an orthotropic membrane"))) << e;
}

TEST_F(OrthotropicScene, RenderTextureGrainLaysTheGrainEvenOnAnIsotropicMaterial) {
  const Scene s = load(scene(R"("stretch_modulus": 5000, "grain": {"warp_deg": 90})", std::string(kGrid) + R"(, "render": {"texture": "grain"})"));
  EXPECT_EQ(s.render.texture, "grain");
  ASSERT_EQ(s.problem.mesh.warp.size(), s.problem.mesh.triangles.size());
  for (const Eigen::Vector3d& w : s.problem.mesh.warp) EXPECT_LT((w - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  write("plain.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  std::string e = error(scene(R"("stretch_modulus": 5000)", R"("mesh": {"obj": "plain.obj"}, "render": {"texture": "grain"})"));
  EXPECT_TRUE(contains(e, expected("render.texture: \"grain\" needs the grain direction"))) << e;
  e = error(scene(R"("stretch_modulus": 5000)", std::string(kGrid) + R"(, "render": {"texture": "woven"})"));
  EXPECT_TRUE(contains(e, expected("render.texture: unknown texture \"woven\""))) << e;
}

TEST(ObjTextureCoordinates, ReadWhenEveryCornerHasThem) {
  const TriMesh m = read_obj_text("v 0 0 0\nv 2 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n", "t.obj");
  ASSERT_EQ(m.uv.size(), 1u);
  EXPECT_EQ(m.uv[0][1], Eigen::Vector2d(1, 0));
  // uv_warp: +u maps to the edge 1→2 direction (+x), +v to +y.
  EXPECT_LT((uv_warp(m, 0.0)[0] - Eigen::Vector3d::UnitX()).norm(), 1e-15);
  EXPECT_LT((uv_warp(m, 90.0)[0] - Eigen::Vector3d::UnitY()).norm(), 1e-15);
  // A face without texture indices: no uv at all.
  EXPECT_TRUE(read_obj_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 2 4 3\n", "t.obj").uv.empty());
}

}  // namespace
}  // namespace clothsim

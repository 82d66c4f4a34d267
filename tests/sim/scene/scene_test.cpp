// Scene loader: defaults, material overrides and presets, vertex selection, nearest-vertex
// lookup, dynamic settings and scripted motions, error messages that name the file and the key
// path, and every shipped scene.
#include "sim/scene/scene.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/shell/material_presets.hpp"

#include "tests/support/scene_files.hpp"

#include <gtest/gtest.h>

#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

const char* const kGrid4 = R"("mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [4, 4]})";

class SceneLoader : public testing::SceneFileTest {};

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST_F(SceneLoader, DefaultsApplied) {
  const Scene s = load(std::string("{") + kGrid4 + "}", "my-scene_1.json");
  EXPECT_EQ(s.name, "my-scene_1");
  EXPECT_EQ(s.description, "");
  EXPECT_EQ(s.analysis, "static");
  EXPECT_EQ(s.file, dir_ / "my-scene_1.json");
  EXPECT_GE(s.problem.mesh.num_vertices(), 25);
  const ShellMaterial m = ShellMaterial::from_solid(1e7, 0.3, 0.001, 1000.0);
  EXPECT_DOUBLE_EQ(s.problem.material.stretch_modulus, m.stretch_modulus);
  EXPECT_DOUBLE_EQ(s.problem.material.bending_rigidity, m.bending_rigidity);
  EXPECT_DOUBLE_EQ(s.problem.material.poisson_ratio, 0.3);
  EXPECT_DOUBLE_EQ(s.problem.material.areal_density, 1.0);
  EXPECT_TRUE(s.problem.boundary.empty());
  EXPECT_EQ(s.problem.gravity, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.problem.surface_load, Eigen::Vector3d::Zero());
  EXPECT_TRUE(s.problem.point_loads.empty());
  EXPECT_TRUE(s.probes.empty());
  EXPECT_EQ(s.problem.quadrature, Quadrature::one_point);
}

TEST_F(SceneLoader, FullSceneIsRead) {
  const Scene s = load(std::string(R"({"name": "full", "description": "text", "analysis": "static", )") + kGrid4 +
                       R"(, "material": {"youngs_modulus": 2e7, "poisson_ratio": 0.25, "thickness": 0.002, "density": 500},
      "boundary": [{"select": {"box": [[-1, -1, -1], [1, -0.49, 1]]}, "fix": ["z", "x"], "rotation": "clamped"}],
      "loads": {"gravity": [0, 0, -9.81], "surface_load": [0, 0, -2], "point_loads": [{"at": [0.5, 0.5, 0.3], "force": [1, 2, 3]}]},
      "probes": [{"name": "c", "at": [0.1, 0.1, 0]}, {"name": "corner", "at": [-0.6, -0.6, 0]}],
      "numerics": {"quadrature": "six_point"}})");
  EXPECT_EQ(s.name, "full");
  EXPECT_EQ(s.description, "text");
  EXPECT_DOUBLE_EQ(s.problem.material.stretch_modulus, 2e7 * 0.002);
  EXPECT_DOUBLE_EQ(s.problem.material.bending_rigidity, 2e7 * 0.002 * 0.002 * 0.002 / 12.0);
  EXPECT_DOUBLE_EQ(s.problem.material.poisson_ratio, 0.25);
  EXPECT_DOUBLE_EQ(s.problem.material.areal_density, 1.0);
  ASSERT_EQ(s.problem.boundary.size(), 1u);
  EXPECT_EQ(s.problem.boundary[0].fix, (std::array<bool, 3>{true, false, true}));
  EXPECT_TRUE(s.problem.boundary[0].clamped);
  EXPECT_EQ(s.problem.gravity, Eigen::Vector3d(0, 0, -9.81));
  EXPECT_EQ(s.problem.surface_load, Eigen::Vector3d(0, 0, -2));
  EXPECT_EQ(s.problem.quadrature, Quadrature::six_point);

  const Eigen::MatrixX3d& v = s.problem.mesh.vertices;
  ASSERT_EQ(s.problem.point_loads.size(), 1u);
  EXPECT_EQ(s.problem.point_loads[0].force, Eigen::Vector3d(1, 2, 3));
  EXPECT_LT((v.row(s.problem.point_loads[0].vertex).transpose() - Eigen::Vector3d(0.5, 0.5, 0)).norm(), 1e-12);
  ASSERT_EQ(s.probes.size(), 2u);
  EXPECT_EQ(s.probes[0].name, "c");
  EXPECT_EQ(s.probes[0].at, Eigen::Vector3d(0.1, 0.1, 0));
  EXPECT_LT(v.row(s.probes[0].vertex).norm(), 1e-12);
  EXPECT_LT((v.row(s.probes[1].vertex).transpose() - Eigen::Vector3d(-0.5, -0.5, 0)).norm(), 1e-12);
}

TEST_F(SceneLoader, MaterialOverridesReplaceDerivedValues) {
  const Scene s = load(std::string("{") + kGrid4 + R"(, "material": {"youngs_modulus": 2e7, "thickness": 0.002,
      "density": 500, "stretch_modulus": 123, "bending_rigidity": 0.5, "areal_density": 0.07}})");
  EXPECT_DOUBLE_EQ(s.problem.material.stretch_modulus, 123.0);
  EXPECT_DOUBLE_EQ(s.problem.material.bending_rigidity, 0.5);
  EXPECT_DOUBLE_EQ(s.problem.material.areal_density, 0.07);

  // One override leaves the other derived values in place.
  const Scene t = load(std::string("{") + kGrid4 + R"(, "material": {"youngs_modulus": 2e7, "thickness": 0.002,
      "bending_rigidity": 0.5}})");
  EXPECT_DOUBLE_EQ(t.problem.material.stretch_modulus, 2e7 * 0.002);
  EXPECT_DOUBLE_EQ(t.problem.material.bending_rigidity, 0.5);
  EXPECT_DOUBLE_EQ(t.problem.material.areal_density, 1000 * 0.002);
}

TEST_F(SceneLoader, MaterialRangeErrors) {
  auto material = [&](const std::string& m) { return error(std::string("{") + kGrid4 + R"(, "material": )" + m + "}"); };
  EXPECT_EQ(material(R"({"thickness": -0.01})"), expected("material.thickness: must be > 0 [m] (got -0.01)"));
  EXPECT_EQ(material(R"({"youngs_modulus": 0})"), expected("material.youngs_modulus: must be > 0 [Pa] (got 0)"));
  EXPECT_TRUE(contains(material(R"({"poisson_ratio": 0.5})"), expected("material.poisson_ratio: must be >= 0 and < 0.5")));
  EXPECT_TRUE(contains(material(R"({"density": -1})"), expected("material.density: must be >= 0")));
  EXPECT_TRUE(contains(material(R"({"stretch_modulus": 0})"), expected("material.stretch_modulus: must be > 0 [N/m]")));
  EXPECT_TRUE(contains(material(R"({"areal_density": -0.1})"), expected("material.areal_density: must be >= 0")));
}

TEST_F(SceneLoader, SelectBoxIsClosedAndPicksGridEdge) {
  const TriMesh grid = make_grid(1.0, 1.0, 4, 4);
  // Bottom edge (j = 0) of the 5 × 5 vertex grid: indices 0..4.
  EXPECT_EQ(select_box(grid.vertices, {-0.51, -0.51, -1}, {0.51, -0.49, 1}), (std::vector<int>{0, 1, 2, 3, 4}));
  // Left edge (i = 0): indices 0, 5, 10, 15, 20.
  EXPECT_EQ(select_box(grid.vertices, {-0.51, -0.51, -1}, {-0.49, 0.51, 1}), (std::vector<int>{0, 5, 10, 15, 20}));
  // Closed: a degenerate box exactly at a vertex selects it.
  Eigen::MatrixX3d v(3, 3);
  v << 0, 0, 0, 1, 0, 0, 2, 0, 0;
  EXPECT_EQ(select_box(v, {1, 0, 0}, {1, 0, 0}), (std::vector<int>{1}));
  EXPECT_EQ(select_box(v, {0, 0, 0}, {1, 0, 0}), (std::vector<int>{0, 1}));
  EXPECT_TRUE(select_box(v, {0.2, 0, 0}, {0.8, 0, 0}).empty());
}

TEST_F(SceneLoader, BoundaryBoxSelectsOnPreparedMesh) {
  const Scene s = load(std::string("{") + kGrid4 +
                       R"(, "boundary": [{"select": {"box": [[-0.51, -0.51, -1], [0.51, -0.49, 1]]}}]})");
  ASSERT_EQ(s.problem.boundary.size(), 1u);
  const BoundaryCondition& bc = s.problem.boundary[0];
  EXPECT_EQ(bc.fix, (std::array<bool, 3>{true, true, true}));
  EXPECT_FALSE(bc.clamped);
  EXPECT_EQ(bc.vertices, select_box(s.problem.mesh.vertices, {-0.51, -0.51, -1}, {0.51, -0.49, 1}));
  EXPECT_GE(bc.vertices.size(), 5u);
  for (int v : bc.vertices) EXPECT_NEAR(s.problem.mesh.vertices(v, 1), -0.5, 1e-12);
}

TEST_F(SceneLoader, BoundaryBallIsClosedAndSelectsOnPreparedMesh) {
  // The 5 × 5 grid's vertex (i, j) sits at (i/4 − 1/2, j/4 − 1/2, 0), index 5 j + i: the ball of
  // radius 1/4 about the centre holds the centre and, closed, its four neighbours at distance 1/4
  // (the diagonal ones lie at 0.354).
  const TriMesh grid = make_grid(1.0, 1.0, 4, 4);
  EXPECT_EQ(select_ball(grid.vertices, {0, 0, 0}, 0.25), (std::vector<int>{7, 11, 12, 13, 17}));
  EXPECT_EQ(select_ball(grid.vertices, {0, 0, 0}, 0.2499), (std::vector<int>{12}));
  EXPECT_EQ(select_ball(grid.vertices, {-0.5, -0.5, 0.1}, 0.11), (std::vector<int>{0}));
  const Scene s = load(std::string("{") + kGrid4 +
                       R"(, "boundary": [{"select": {"ball": {"center": [0, 0, 0], "radius": 0.3}}, "fix": ["y"]}]})");
  ASSERT_EQ(s.problem.boundary.size(), 1u);
  EXPECT_EQ(s.problem.boundary[0].vertices, (std::vector<int>{7, 11, 12, 13, 17}));
  EXPECT_EQ(s.problem.boundary[0].fix, (std::array<bool, 3>{false, true, false}));
}

TEST_F(SceneLoader, BoundaryBallErrors) {
  auto bc = [&](const std::string& item) { return error(std::string("{") + kGrid4 + R"(, "boundary": [)" + item + "]}"); };
  EXPECT_EQ(bc(R"({"select": {"ball": {"center": [0, 0, 0], "radius": 0}}})"),
            expected("boundary[0].select.ball.radius: must be > 0 [m] (got 0)"));
  EXPECT_TRUE(contains(bc(R"({"select": {"ball": {"center": [3, 0, 0], "radius": 0.5}}})"),
                       expected("boundary[0].select.ball: selects no vertex of the mesh")));
  EXPECT_TRUE(contains(bc(R"({"select": {"ball": {"radius": 0.5}}})"),
                       expected("boundary[0].select.ball.center: required key is missing")));
  EXPECT_TRUE(contains(bc(R"({"select": {"ball": {"center": [0, 0, 0], "radius": 0.5, "r": 1}}})"),
                       expected("boundary[0].select.ball.r: unknown key (allowed: center, radius)")));
  EXPECT_TRUE(contains(bc(R"({"select": {"ball": {"center": [0, 0, 0], "radius": 0.5}, "box": [[-1, -1, -1], [1, 1, 1]]}})"),
                       expected("boundary[0].select: give one of \"box\", \"ball\", \"piece_edge\" and \"piece\"")));
}

TEST_F(SceneLoader, NearestVertexTiesGoToLowestIndex) {
  Eigen::MatrixX3d v(4, 3);
  v << 1, 0, 0, 0, 0, 0, -1, 0, 0, 0, 1, 0;
  EXPECT_EQ(nearest_vertex(v, {0.9, 0.1, 0}), 0);
  EXPECT_EQ(nearest_vertex(v, {0.1, 0.2, 0}), 1);
  EXPECT_EQ(nearest_vertex(v, {0.5, 0, 0}), 0);   // rows 0 and 1 tie
  EXPECT_EQ(nearest_vertex(v, {-0.5, 0, 0}), 1);  // rows 1 and 2 tie
  EXPECT_EQ(nearest_vertex(v, {0, 0, 5}), 1);
  EXPECT_EQ(nearest_vertex(Eigen::MatrixX3d(0, 3), {0, 0, 0}), -1);
}

TEST_F(SceneLoader, UnknownKeysAtAnyLevel) {
  EXPECT_EQ(error(std::string("{") + kGrid4 + R"(, "loads": {"gravty": [0, 0, -9.81]}})"),
            expected("loads.gravty: unknown key (allowed: gravity, surface_load, pressure, point_loads, moments, ramp_time); "
                     "did you mean \"gravity\"?"));
  EXPECT_TRUE(contains(error(std::string("{") + kGrid4 + R"(, "colour": "red"})"),
                       expected("colour: unknown key (allowed: name, description, analysis, method, mesh")));
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4], "radius": 1}})"),
                       expected("mesh.radius: unknown key (allowed: primitive, size, divisions, rotate, translate, max_vertices, fit_limit)")));
  EXPECT_TRUE(contains(error(std::string("{") + kGrid4 +
                             R"(, "boundary": [{"select": {"box": [[0, 0, 0], [1, 1, 1]], "sphere": 1}}]})"),
                       expected("boundary[0].select.sphere: unknown key (allowed: box, ball, piece_edge, piece)")));
  EXPECT_TRUE(contains(error(std::string("{") + kGrid4 + R"(, "probes": [{"name": "a", "at": [0, 0, 0], "x": 1}]})"),
                       expected("probes[0].x: unknown key (allowed: name, at)")));
  EXPECT_TRUE(contains(error(std::string("{") + kGrid4 + R"(, "numerics": {"solver": "cg"}})"),
                       expected("numerics.solver: unknown key (allowed: quadrature)")));
}

TEST_F(SceneLoader, WrongTypesNameTheKeyPath) {
  auto with = [&](const std::string& rest) { return error(std::string("{") + kGrid4 + ", " + rest + "}"); };
  EXPECT_TRUE(contains(with(R"("material": {"thickness": "thin"})"), expected("material.thickness: expected a number")));
  EXPECT_TRUE(contains(with(R"("material": {"thickness": true})"), expected("material.thickness: expected a number")));
  EXPECT_TRUE(contains(with(R"("loads": {"gravity": "down"})"), expected("loads.gravity: expected an array of 3 numbers")));
  EXPECT_TRUE(contains(with(R"("loads": {"surface_load": [0, 0]})"),
                       expected("loads.surface_load: expected an array of 3 numbers")));
  EXPECT_TRUE(contains(with(R"("loads": {"point_loads": [{"at": [0, 0, "a"], "force": [0, 0, 1]}]})"),
                       expected("loads.point_loads[0].at: expected an array of 3 numbers")));
  EXPECT_TRUE(contains(with(R"("loads": {"point_loads": [{"at": [0, 0, 0]}]})"),
                       expected("loads.point_loads[0].force: required key is missing")));
  EXPECT_TRUE(contains(with(R"("probes": {"name": "a"})"), expected("probes: expected an array")));
  EXPECT_TRUE(contains(with(R"("probes": [{"at": [0, 0, 0]}])"), expected("probes[0].name: required key is missing")));
  EXPECT_TRUE(contains(with(R"("probes": [{"name": "", "at": [0, 0, 0]}])"), expected("probes[0].name: must not be empty")));
  EXPECT_TRUE(contains(with(R"("probes": [{"name": "a", "at": [0, 0, 0]}, {"name": "a", "at": [1, 0, 0]}])"),
                       expected("probes[1].name: duplicate probe name \"a\"")));
  EXPECT_TRUE(contains(with(R"("description": 3)"), expected("description: expected a string")));
  EXPECT_TRUE(contains(with(R"("numerics": {"quadrature": "two_point"})"),
                       expected("numerics.quadrature: unknown value \"two_point\" (allowed: \"one_point\", "
                                "\"three_point\", \"six_point\")")));
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 2.5]}})"),
                       expected("mesh.divisions[1]: expected an integer")));
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "grid", "size": [1, 0], "divisions": [4, 4]}})"),
                       expected("mesh.size[1]: must be > 0 [m] (got 0)")));
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [0, 4]}})"),
                       expected("mesh.divisions[0]: must be an integer >= 1 (got 0)")));
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "grid", "divisions": [4, 4]}})"),
                       expected("mesh.size: required key is missing")));
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "cylinder", "radius": 1, "length": 1, "segments": 2, "rings": 3}})"),
                       expected("mesh.segments: must be an integer >= 3 (got 2)")));
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "sphere"}})"),
                       expected("mesh.primitive: unknown primitive \"sphere\" (allowed: \"grid\", \"cylinder\")")));
  EXPECT_TRUE(contains(error(R"({"name": "x"})"), expected("mesh: required key is missing")));
  EXPECT_TRUE(contains(error("[1, 2]"), expected("expected a JSON object at the top level")));
}

TEST_F(SceneLoader, BoundaryErrors) {
  auto bc = [&](const std::string& item) { return error(std::string("{") + kGrid4 + R"(, "boundary": [)" + item + "]}"); };
  EXPECT_EQ(bc(R"({"select": {"box": [[-1, -1, -1], [1, 1, 1]]}, "fix": ["x", "w"]})"),
            expected("boundary[0].fix[1]: unknown component \"w\" (allowed: \"x\", \"y\", \"z\")"));
  EXPECT_TRUE(contains(bc(R"({"select": {"box": [[-1, -1, -1], [1, 1, 1]]}, "fix": ["x", "x"]})"),
                       expected("boundary[0].fix[1]: duplicate component \"x\"")));
  EXPECT_TRUE(contains(bc(R"({"select": {"box": [[-1, -1, -1], [1, 1, 1]]}, "rotation": "fixed"})"),
                       expected("boundary[0].rotation: unknown value \"fixed\" (allowed: \"free\", \"clamped\", \"symmetry\")")));
  EXPECT_TRUE(contains(bc(R"({"fix": ["x"]})"), expected("boundary[0].select: required key is missing")));
  EXPECT_TRUE(contains(bc(R"({"select": {"box": [[2, 2, 2], [3, 3, 3]]}})"),
                       expected("boundary[0].select.box: selects no vertex")));
  EXPECT_TRUE(contains(bc(R"({"select": {"box": [[1, -1, -1], [-1, 1, 1]]}})"),
                       expected("boundary[0].select.box: min must be <= max")));
  EXPECT_TRUE(contains(bc(R"({"select": {"box": [[0, 0, 0]]}})"),
                       expected("boundary[0].select.box: expected an array of 2 points")));
  EXPECT_TRUE(contains(bc(R"({"select": {"box": [[-1, -1, -1], [1, 1]]}})"),
                       expected("boundary[0].select.box[1]: expected an array of 3 numbers")));
}

TEST_F(SceneLoader, AnalysisValues) {
  EXPECT_EQ(error(std::string(R"({"analysis": "modal", )") + kGrid4 + "}"),
            expected("analysis: unknown value \"modal\" (allowed: \"static\", \"dynamic\")"));
  EXPECT_TRUE(contains(error(std::string(R"({"analysis": 1, )") + kGrid4 + "}"), expected("analysis: expected a string")));
  EXPECT_EQ(load(std::string(R"({"analysis": "dynamic", )") + kGrid4 + "}").analysis, "dynamic");
  EXPECT_EQ(load(std::string(R"({"analysis": "static", )") + kGrid4 + "}").analysis, "static");
}

TEST_F(SceneLoader, NamesMustBeSafeFolderNames) {
  EXPECT_TRUE(contains(error(std::string(R"({"name": ".hidden", )") + kGrid4 + "}"), expected("name: must be a safe folder name")));
  EXPECT_TRUE(contains(error(std::string(R"({"name": "a/b", )") + kGrid4 + "}"), expected("name: must be a safe folder name")));
  EXPECT_TRUE(contains(error(std::string(R"({"name": "", )") + kGrid4 + "}"), expected("name: must be a safe folder name")));
  const std::string stem_error = error(std::string("{") + kGrid4 + "}", "my scene.json");
  EXPECT_TRUE(contains(stem_error, "name: not given, and the file name \"my scene\" is not a safe folder name")) << stem_error;
  EXPECT_EQ(load(std::string(R"({"name": "v1.2_final-A", )") + kGrid4 + "}").name, "v1.2_final-A");
}

TEST_F(SceneLoader, MalformedAndDuplicateJson) {
  const std::string malformed = error("{\"mesh\": {\"obj\": \"a.obj\"},\n \"name\" \"x\"}");
  EXPECT_TRUE(contains(malformed, expected("malformed JSON: "))) << malformed;
  EXPECT_TRUE(contains(malformed, "line 2")) << malformed;
  EXPECT_TRUE(contains(error(""), expected("malformed JSON: ")));
  EXPECT_TRUE(contains(error(std::string("{") + kGrid4 + R"(, "material": {"thickness": 0.01, "thickness": 0.02}})"),
                       expected("material.thickness: duplicate key")));
  EXPECT_TRUE(contains(error(std::string("{") + kGrid4 +
                             R"(, "probes": [{"name": "a", "at": [0, 0, 0]}, {"name": "b", "name": "c"}]})"),
                       expected("probes[1].name: duplicate key")));
}

TEST_F(SceneLoader, MissingSceneFile) {
  try {
    load_scene(dir_ / "nope.json", nullptr);
    FAIL() << "no error";
  } catch (const SceneError& e) {
    EXPECT_TRUE(contains(e.what(), (dir_ / "nope.json").string() + ": cannot open the scene file")) << e.what();
  }
}

TEST_F(SceneLoader, ObjMeshRelativeToSceneFolder) {
  write("sub/meshes/square.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  const Scene s = load(R"({"mesh": {"obj": "meshes/square.obj"}, "probes": [{"name": "p", "at": [0.9, 0.1, 0]}]})",
                       "sub/scene.json");
  EXPECT_GE(s.problem.mesh.num_vertices(), 4);
  ASSERT_EQ(s.probes.size(), 1u);
  EXPECT_LT((s.problem.mesh.vertices.row(s.probes[0].vertex).transpose() - Eigen::Vector3d(1, 0, 0)).norm(), 1e-12);
}

TEST_F(SceneLoader, BrokenOrMissingObjNamesMeshObj) {
  const std::string missing = error(R"({"mesh": {"obj": "missing.obj"}})");
  EXPECT_TRUE(contains(missing, expected("mesh.obj: "))) << missing;
  EXPECT_TRUE(contains(missing, "missing.obj")) << missing;
  // Three triangles sharing the edge 1-2.
  write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
  const std::string bad = error(R"({"mesh": {"obj": "bad.obj"}})");
  EXPECT_TRUE(contains(bad, expected("mesh.obj: "))) << bad;
  EXPECT_TRUE(contains(bad, "bad.obj")) << bad;
  EXPECT_TRUE(contains(error(R"({"mesh": {"obj": "bad.obj", "primitive": "grid"}})"), expected("mesh: give one of \"obj\", \"primitive\" and \"pattern\"")));
}

TEST_F(SceneLoader, ShippedScenesLoad) {
  const fs::path scenes = fs::path(CLOTHSIM_SOURCE_DIR) / "scenes";
  for (const std::string name : {"plate_ss", "plate_clamped"}) {
    const Scene s = load_scene(scenes / (name + ".json"), nullptr);
    EXPECT_EQ(s.name, name);
    EXPECT_FALSE(s.description.empty());
    ASSERT_EQ(s.problem.boundary.size(), 4u);
    for (const BoundaryCondition& bc : s.problem.boundary) {
      EXPECT_GE(bc.vertices.size(), 33u);
      EXPECT_EQ(bc.clamped, name == "plate_clamped");
    }
    EXPECT_EQ(s.problem.surface_load, Eigen::Vector3d(0, 0, -1));
    ASSERT_EQ(s.probes.size(), 1u);
    EXPECT_EQ(s.probes[0].name, "center");
    EXPECT_LT(s.problem.mesh.vertices.row(s.probes[0].vertex).norm(), 1e-12);
  }
  const Scene c = load_scene(scenes / "cantilever.json", nullptr);
  EXPECT_EQ(c.name, "cantilever");
  ASSERT_EQ(c.problem.boundary.size(), 1u);
  EXPECT_TRUE(c.problem.boundary[0].clamped);
  for (int v : c.problem.boundary[0].vertices) EXPECT_NEAR(c.problem.mesh.vertices(v, 0), -0.5, 1e-12);
  ASSERT_EQ(c.problem.point_loads.size(), 2u);
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (const PointLoad& p : c.problem.point_loads) {
    total += p.force;
    EXPECT_NEAR(c.problem.mesh.vertices(p.vertex, 0), 0.5, 1e-12);
    EXPECT_NEAR(std::abs(c.problem.mesh.vertices(p.vertex, 1)), 0.05, 1e-12);
  }
  EXPECT_NE(c.problem.point_loads[0].vertex, c.problem.point_loads[1].vertex);
  EXPECT_NEAR(total.z(), -0.001, 1e-15);
  ASSERT_EQ(c.probes.size(), 1u);
  EXPECT_LT((c.problem.mesh.vertices.row(c.probes[0].vertex).transpose() - Eigen::Vector3d(0.5, 0, 0)).norm(), 1e-12);
}

// ---- Material presets -----------------------------------------------------------------------

TEST_F(SceneLoader, MaterialPresetTable) {
  const std::vector<std::string> names = material_preset_names();
  for (const std::string name :
       {"cotton", "metal", "cotton_broadcloth", "wool_tropical", "polyester_tropical", "polyester_faille",
        "gray_interlock", "black_denim", "royal_target", "ivory_rib_knit", "camel_ponte_roma", "navy_sparkle_sweat",
        "pink_ribbon_brown", "tango_red_jet_set", "white_dots_on_black", "white_swim_solid"})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  for (const std::string& name : names) {
    const std::optional<ShellMaterial> m = material_preset(name);
    ASSERT_TRUE(m.has_value()) << name;
    EXPECT_EQ(validate(*m), "") << name;
    EXPECT_GT(m->areal_density, 0.0) << name;
  }
  EXPECT_FALSE(material_preset("silk").has_value());
  EXPECT_FALSE(material_preset("Cotton").has_value());

  const ShellMaterial cotton = *material_preset("cotton");
  EXPECT_DOUBLE_EQ(cotton.stretch_modulus, 5000.0);
  EXPECT_DOUBLE_EQ(cotton.poisson_ratio, 0.25);
  EXPECT_DOUBLE_EQ(cotton.bending_rigidity, 1.157e-5);
  EXPECT_DOUBLE_EQ(cotton.areal_density, 0.1238);
  const ShellMaterial metal = *material_preset("metal");
  EXPECT_DOUBLE_EQ(metal.stretch_modulus, 1e5);
  EXPECT_DOUBLE_EQ(metal.poisson_ratio, 0.05);
  EXPECT_NEAR(metal.bending_rigidity, 8.333e-3, 1e-6);
  EXPECT_DOUBLE_EQ(metal.areal_density, 0.5);
  const ShellMaterial wool = *material_preset("wool_tropical");
  EXPECT_DOUBLE_EQ(wool.stretch_modulus, 5000.0);
  EXPECT_DOUBLE_EQ(wool.bending_rigidity, 6.57e-6);
  EXPECT_DOUBLE_EQ(wool.areal_density, 0.1629);
  const ShellMaterial denim = *material_preset("black_denim");
  EXPECT_DOUBLE_EQ(denim.stretch_modulus, std::sqrt(205.4 * 1013.9));
  EXPECT_DOUBLE_EQ(denim.poisson_ratio, 0.25);
  EXPECT_DOUBLE_EQ(denim.bending_rigidity, 6.42e-5);
  EXPECT_DOUBLE_EQ(denim.areal_density, 0.324);
}

TEST_F(SceneLoader, MaterialPresetWithOverrides) {
  const Scene s = load(std::string("{") + kGrid4 + R"(, "material": {"preset": "cotton"}})");
  EXPECT_DOUBLE_EQ(s.problem.material.stretch_modulus, 5000.0);
  EXPECT_DOUBLE_EQ(s.problem.material.bending_rigidity, 1.157e-5);
  EXPECT_DOUBLE_EQ(s.problem.material.poisson_ratio, 0.25);
  EXPECT_DOUBLE_EQ(s.problem.material.areal_density, 0.1238);

  const Scene t = load(std::string("{") + kGrid4 + R"(, "material": {"preset": "cotton", "bending_rigidity": 1e-3,
      "stretch_modulus": 50000, "poisson_ratio": 0.1, "areal_density": 0.2}})");
  EXPECT_DOUBLE_EQ(t.problem.material.stretch_modulus, 50000.0);
  EXPECT_DOUBLE_EQ(t.problem.material.bending_rigidity, 1e-3);
  EXPECT_DOUBLE_EQ(t.problem.material.poisson_ratio, 0.1);
  EXPECT_DOUBLE_EQ(t.problem.material.areal_density, 0.2);

  // Key order does not matter: an override written before the preset still wins.
  const Scene u = load(std::string("{") + kGrid4 + R"(, "material": {"bending_rigidity": 2e-3, "preset": "metal"}})");
  EXPECT_DOUBLE_EQ(u.problem.material.bending_rigidity, 2e-3);
  EXPECT_DOUBLE_EQ(u.problem.material.stretch_modulus, 1e5);
}

TEST_F(SceneLoader, MaterialPresetErrors) {
  auto material = [&](const std::string& m) { return error(std::string("{") + kGrid4 + R"(, "material": )" + m + "}"); };
  const std::string unknown = material(R"({"preset": "silk"})");
  EXPECT_TRUE(contains(unknown, expected("material.preset: unknown preset \"silk\" (allowed: \"cotton\", \"metal\", ")))
      << unknown;
  for (const std::string& name : material_preset_names()) EXPECT_TRUE(contains(unknown, "\"" + name + "\"")) << name;
  EXPECT_TRUE(contains(material(R"({"preset": 3})"), expected("material.preset: expected a string")));
  EXPECT_TRUE(contains(material(R"({"preset": "cotton", "thickness": 0.001})"),
                       expected("material.thickness: cannot be combined with \"preset\"")));
  EXPECT_TRUE(contains(material(R"({"preset": "cotton", "youngs_modulus": 1e6})"),
                       expected("material.youngs_modulus: cannot be combined with \"preset\"")));
  EXPECT_TRUE(contains(material(R"({"preset": "cotton", "density": 100})"),
                       expected("material.density: cannot be combined with \"preset\"")));
  EXPECT_TRUE(contains(material(R"({"preset": "cotton", "bending_rigidity": -1})"),
                       expected("material.bending_rigidity: must be > 0 [N·m]")));
  EXPECT_TRUE(contains(material(R"({"preset": "cotton", "poisson_ratio": 0.7})"),
                       expected("material.poisson_ratio: must be >= 0 and < 0.5")));
  EXPECT_TRUE(contains(material(R"({"preset": "cotton", "colour": "red"})"),
                       expected("material.colour: unknown key (allowed: preset, youngs_modulus")));
}

// ---- Dynamic scenes -------------------------------------------------------------------------

const char* const kDynamicFull = R"({
  "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [4, 4]},
  "material": {"preset": "cotton"},
  "time": {"dt": 0.002, "end": 2.0, "output_fps": 25},
  "damping": {"stiffness": 0.001, "mass": 0.5},
  "solver": {"type": "cholmod", "tolerance": 1e-6, "max_iterations": 50, "newton_iterations": 3},
  "corotational": false,
  "initial": {"velocity": [1, 2, 3], "angular_velocity": [0, 0, 4], "center": [0.1, 0.2, 0.3]},
  "boundary": [{"select": {"box": [[-1, -0.001, -1], [1, 0.001, 1]]}, "fix": ["x", "y", "z"],
                "motion": [{"type": "rotate", "axis": [0, 1, 0], "center": [0, 0, 0], "angle_deg": 180, "start": 0.0, "end": 1.0},
                           {"type": "translate", "displacement": [0, 0.05, 0], "start": 1.0, "end": 2.0},
                           {"type": "hold", "start": 2.0, "end": 3.0}]},
               {"select": {"box": [[-1, 0.49, -1], [1, 0.51, 1]]}, "fix": ["z"]}],
  "loads": {"gravity": [0, 0, -9.81], "pressure": 2, "point_loads": [{"at": [0.5, 0.5, 0], "force": [0, 0, -1]}]},
  "probes": [{"name": "p", "at": [0, 0, 0]}],
  "numerics": {"quadrature": "three_point"},
  "output": {"obj": true}
})";

TEST_F(SceneLoader, DynamicKeysParsed) {
  const Scene s = load(kDynamicFull);
  EXPECT_EQ(s.analysis, "dynamic");
  const Problem& d = s.problem;
  EXPECT_DOUBLE_EQ(d.time.dt, 0.002);
  EXPECT_DOUBLE_EQ(d.time.end, 2.0);
  EXPECT_DOUBLE_EQ(d.time.output_fps, 25.0);
  EXPECT_DOUBLE_EQ(d.damping.stiffness, 0.001);
  EXPECT_DOUBLE_EQ(d.damping.mass, 0.5);
  EXPECT_EQ(d.solver.type, LinearSolverType::cholmod);
  EXPECT_DOUBLE_EQ(d.solver.tolerance, 1e-6);
  EXPECT_EQ(d.solver.max_iterations, 50);
  EXPECT_EQ(d.solver.newton_iterations, 3);
  EXPECT_FALSE(d.corotational);
  EXPECT_EQ(d.initial.velocity, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(d.initial.angular_velocity, Eigen::Vector3d(0, 0, 4));
  EXPECT_EQ(d.initial.center, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_TRUE(s.write_obj_frames);

  // The shared part is the same as the static problem's.
  EXPECT_EQ(d.mesh.vertices, s.problem.mesh.vertices);
  EXPECT_EQ(d.mesh.num_triangles(), s.problem.mesh.num_triangles());
  EXPECT_DOUBLE_EQ(d.material.stretch_modulus, 5000.0);
  EXPECT_DOUBLE_EQ(d.material.areal_density, 0.1238);
  EXPECT_EQ(d.gravity, Eigen::Vector3d(0, 0, -9.81));
  EXPECT_DOUBLE_EQ(d.pressure, 2.0);
  ASSERT_EQ(d.point_loads.size(), 1u);
  EXPECT_EQ(d.point_loads[0].vertex, s.problem.point_loads[0].vertex);
  EXPECT_EQ(d.quadrature, Quadrature::three_point);

  ASSERT_EQ(d.boundary.size(), 2u);
  EXPECT_EQ(d.boundary[0].vertices, s.problem.boundary[0].vertices);
  EXPECT_EQ(d.boundary[0].vertices.size(), 5u);
  EXPECT_EQ(d.boundary[1].fix, (std::array<bool, 3>{false, false, true}));
  EXPECT_TRUE(d.boundary[1].motion.empty());
  const std::vector<Motion>& m = d.boundary[0].motion;
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0].type, Motion::Type::rotate);
  EXPECT_EQ(m[0].axis, Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(m[0].center, Eigen::Vector3d::Zero());
  EXPECT_DOUBLE_EQ(m[0].angle_deg, 180.0);
  EXPECT_DOUBLE_EQ(m[0].start, 0.0);
  EXPECT_DOUBLE_EQ(m[0].end, 1.0);
  EXPECT_EQ(m[1].type, Motion::Type::translate);
  EXPECT_EQ(m[1].displacement, Eigen::Vector3d(0, 0.05, 0));
  EXPECT_DOUBLE_EQ(m[1].start, 1.0);
  EXPECT_DOUBLE_EQ(m[1].end, 2.0);
  EXPECT_EQ(m[2].type, Motion::Type::hold);
  EXPECT_DOUBLE_EQ(m[2].start, 2.0);
  EXPECT_DOUBLE_EQ(m[2].end, 3.0);
}

TEST_F(SceneLoader, DynamicDefaults) {
  const Scene s = load(std::string(R"({"analysis": "dynamic", )") + kGrid4 +
                       R"(, "boundary": [{"select": {"box": [[-1, -0.51, -1], [1, -0.49, 1]]},
      "motion": [{"type": "rotate", "axis": [0, 0, 2], "angle_deg": 30, "start": 0.5, "end": 0.5}]}]})");
  const Problem& d = s.problem;
  EXPECT_DOUBLE_EQ(d.time.dt, 0.001);
  EXPECT_DOUBLE_EQ(d.time.end, 1.0);
  EXPECT_DOUBLE_EQ(d.time.output_fps, 30.0);
  EXPECT_DOUBLE_EQ(d.damping.stiffness, 0.0);
  EXPECT_DOUBLE_EQ(d.damping.mass, 0.0);
  EXPECT_EQ(d.solver.type, LinearSolverType::automatic);
  EXPECT_EQ(d.solver.preconditioner, PreconditionerType::automatic);
  EXPECT_DOUBLE_EQ(d.solver.tolerance, 1e-5);
  EXPECT_EQ(d.solver.max_iterations, 2000);
  EXPECT_EQ(d.solver.newton_iterations, 1);
  EXPECT_TRUE(d.corotational);
  EXPECT_EQ(d.initial.velocity, Eigen::Vector3d::Zero());
  EXPECT_EQ(d.initial.angular_velocity, Eigen::Vector3d::Zero());
  EXPECT_EQ(d.initial.center, Eigen::Vector3d::Zero());
  EXPECT_FALSE(s.write_obj_frames);
  EXPECT_EQ(d.mesh.vertices, s.problem.mesh.vertices);
  ASSERT_EQ(d.boundary.size(), 1u);
  ASSERT_EQ(d.boundary[0].motion.size(), 1u);
  const Motion& m = d.boundary[0].motion[0];
  EXPECT_EQ(m.type, Motion::Type::rotate);
  EXPECT_EQ(m.center, Eigen::Vector3d::Zero());  // center defaults to the origin
  EXPECT_EQ(m.axis, Eigen::Vector3d(0, 0, 2));
  EXPECT_DOUBLE_EQ(m.start, 0.5);                // a jump (start == end) is allowed
  EXPECT_DOUBLE_EQ(m.end, 0.5);

  // "output": {} and "obj": false leave frames off; the default material has mass.
  EXPECT_FALSE(load(std::string(R"({"analysis": "dynamic", "output": {}, )") + kGrid4 + "}").write_obj_frames);
  EXPECT_FALSE(load(std::string(R"({"analysis": "dynamic", "output": {"obj": false}, )") + kGrid4 + "}").write_obj_frames);
  EXPECT_GT(load(std::string(R"({"analysis": "dynamic", )") + kGrid4 + "}").problem.material.areal_density, 0.0);

  // A static scene writes no OBJ frames.
  const Scene t = load(std::string("{") + kGrid4 + "}");
  EXPECT_FALSE(t.write_obj_frames);
}

TEST_F(SceneLoader, DynamicKeysRejectedInStaticScene) {
  const std::string needs = ": needs \"analysis\": \"dynamic\" (this scene is static)";
  for (const std::string item : {R"("time": {"dt": 0.01})", R"("damping": {})", R"("solver": {"type": "pcg"})",
                                 R"("corotational": true)", R"("initial": {})", R"("output": {"obj": true})"}) {
    const std::string key = item.substr(1, item.find('"', 1) - 1);
    EXPECT_EQ(error(std::string("{") + kGrid4 + ", " + item + "}"), expected(key + needs)) << item;
    EXPECT_EQ(error(std::string(R"({"analysis": "static", )") + kGrid4 + ", " + item + "}"), expected(key + needs))
        << item;
  }
  EXPECT_EQ(error(std::string("{") + kGrid4 + R"(, "boundary": [{"select": {"box": [[-1, -1, -1], [1, 1, 1]]},
      "motion": [{"type": "hold", "start": 0, "end": 1}]}]})"),
            expected("boundary[0].motion" + needs));
  // Unknown keys are still unknown, not "dynamic only".
  EXPECT_TRUE(contains(error(std::string("{") + kGrid4 + R"(, "timestep": 0.01})"),
                       expected("timestep: unknown key (allowed: name, description, analysis, method, mesh, material, "
                                "boundary, loads, probes, numerics, time, damping, solver, corotational, initial, output, "
                                "render, collision, obstacles, imperfection, rest, settle, $schema)")));
}

TEST_F(SceneLoader, DynamicSettingErrors) {
  auto with = [&](const std::string& rest) {
    return error(std::string(R"({"analysis": "dynamic", )") + kGrid4 + ", " + rest + "}");
  };
  EXPECT_EQ(with(R"("time": {"dt": 0})"), expected("time.dt: must be > 0 [s] (got 0)"));
  EXPECT_EQ(with(R"("time": {"end": -1})"), expected("time.end: must be > 0 [s] (got -1)"));
  EXPECT_EQ(with(R"("time": {"dt": 0.1, "end": 0.05})"), expected("time.end: must be >= time.dt = 0.1 [s] (got 0.05)"));
  EXPECT_EQ(with(R"("time": {"dt": 2})"), expected("time.end: must be >= time.dt = 2.0 [s] (got 1.0)"));
  EXPECT_EQ(with(R"("time": {"output_fps": 0})"), expected("time.output_fps: must be > 0 [1/s] (got 0)"));
  EXPECT_TRUE(contains(with(R"("time": {"dt": "1ms"})"), expected("time.dt: expected a number")));
  EXPECT_TRUE(contains(with(R"("time": {"step": 0.01})"), expected("time.step: unknown key (allowed: dt, end, output_fps)")));
  EXPECT_EQ(with(R"("damping": {"stiffness": -0.1})"), expected("damping.stiffness: must be >= 0 [s] (got -0.1)"));
  EXPECT_EQ(with(R"("damping": {"mass": -1})"), expected("damping.mass: must be >= 0 [1/s] (got -1)"));
  EXPECT_TRUE(contains(with(R"("damping": {"alpha": 1})"), expected("damping.alpha: unknown key (allowed: stiffness, mass)")));
  EXPECT_EQ(with(R"("solver": {"type": "gmres"})"),
            expected("solver.type: unknown solver type \"gmres\" (allowed: \"auto\", \"pcg\", \"cholmod\")"));
  EXPECT_EQ(with(R"("solver": {"tolerance": 1})"), expected("solver.tolerance: must be > 0 and < 1 (got 1)"));
  EXPECT_EQ(with(R"("solver": {"tolerance": 0})"), expected("solver.tolerance: must be > 0 and < 1 (got 0)"));
  EXPECT_EQ(with(R"("solver": {"max_iterations": 0})"), expected("solver.max_iterations: must be an integer >= 1 (got 0)"));
  EXPECT_EQ(with(R"("solver": {"newton_iterations": 0})"),
            expected("solver.newton_iterations: must be an integer >= 1 (got 0)"));
  EXPECT_TRUE(contains(with(R"("solver": {"max_iterations": 10.5})"), expected("solver.max_iterations: expected an integer")));
  EXPECT_TRUE(contains(with(R"("solver": {"preconditioner": "jacobi"})"),
                       expected("solver.preconditioner: unknown preconditioner \"jacobi\" (allowed: \"auto\", \"block_jacobi\", \"cholesky\")")));
  EXPECT_TRUE(contains(with(R"("solver": {"precondition": "cholesky"})"),
                       expected("solver.precondition: unknown key (allowed: type, tolerance, max_iterations, "
                                "newton_iterations, rotation_tolerance_deg, preconditioner, refresh_iterations, "
                                "tension_stiffening, warm_start)")));
  EXPECT_EQ(with(R"("solver": {"rotation_tolerance_deg": 0})"),
            expected("solver.rotation_tolerance_deg: must be > 0 and <= 180 [deg] (got 0)"));
  EXPECT_EQ(with(R"("solver": {"rotation_tolerance_deg": 181})"),
            expected("solver.rotation_tolerance_deg: must be > 0 and <= 180 [deg] (got 181)"));
  EXPECT_TRUE(contains(with(R"("solver": {"warm_start": "zero"})"),
                       expected("solver.warm_start: unknown warm start \"zero\" (allowed: \"extrapolated\", \"last_velocity\")")));
  EXPECT_EQ(with(R"("corotational": "yes")"), expected("corotational: expected true or false (got \"yes\")"));
  EXPECT_EQ(with(R"("corotational": 1)"), expected("corotational: expected true or false (got 1)"));
  EXPECT_TRUE(contains(with(R"("initial": {"velocity": [0, 0]})"), expected("initial.velocity: expected an array of 3 numbers")));
  EXPECT_TRUE(contains(with(R"("initial": {"angular_velocity": "spin"})"),
                       expected("initial.angular_velocity: expected an array of 3 numbers")));
  EXPECT_TRUE(contains(with(R"("initial": {"omega": [0, 0, 1]})"),
                       expected("initial.omega: unknown key (allowed: velocity, angular_velocity, center)")));
  EXPECT_EQ(with(R"("output": {"obj": "yes"})"), expected("output.obj: expected true or false (got \"yes\")"));
  EXPECT_TRUE(contains(with(R"("output": {"vtk": true})"), expected("output.vtk: unknown key (allowed: obj, obj_level")));
  EXPECT_TRUE(contains(with(R"("output": true)"), expected("output: expected an object")));
  EXPECT_TRUE(contains(with(R"("material": {"density": 0})"),
                       expected("material: a dynamic analysis needs a positive areal density (mass) [kg/m²] (got 0.0)")));
  EXPECT_TRUE(contains(with(R"("material": {"preset": "cotton", "areal_density": 0})"),
                       expected("material: a dynamic analysis needs a positive areal density")));
}

TEST_F(SceneLoader, RenderFraming) {
  EXPECT_EQ(load(std::string("{") + kGrid4 + "}").render.framing, Framing::motion);
  EXPECT_EQ(load(std::string("{") + kGrid4 + R"(, "render": {"framing": "sequence"}})").render.framing,
            Framing::sequence);
  EXPECT_EQ(load(std::string("{") + kGrid4 + R"(, "render": {"framing": "motion"}})").render.framing, Framing::motion);
  EXPECT_EQ(error(std::string("{") + kGrid4 + R"(, "render": {"framing": "whole"}})"),
            expected("render.framing: unknown framing \"whole\" (allowed: \"motion\", \"sequence\")"));
  EXPECT_TRUE(contains(error(std::string("{") + kGrid4 + R"(, "render": {"framing": 1}})"),
                       expected("render.framing: expected a string")));
}

// render.ground is on by default where gravity is, and lies normal to render.up (opposite to
// gravity); render.shadow is on by default.
TEST_F(SceneLoader, RenderGroundAndShadowDefaults) {
  const std::string dynamic = std::string(R"({"analysis": "dynamic", "time": {"dt": 0.01, "end": 0.02}, )") + kGrid4;
  const Scene without_gravity = load(dynamic + "}");
  EXPECT_FALSE(without_gravity.render.ground);
  EXPECT_TRUE(without_gravity.render.shadow);
  const Scene z_up = load(dynamic + R"(, "loads": {"gravity": [0, 0, -9.81]}})");
  EXPECT_TRUE(z_up.render.ground);
  EXPECT_EQ(z_up.render.world_up, Eigen::Vector3d(0, 0, 1));  // the ground is the x-y plane
  EXPECT_FALSE(load(dynamic + R"(, "loads": {"gravity": [0, 0, -9.81]}, "render": {"ground": false}})").render.ground);
  EXPECT_TRUE(load(dynamic + R"(, "render": {"ground": true}})").render.ground);
  EXPECT_FALSE(load(dynamic + R"(, "render": {"shadow": false}})").render.shadow);
  EXPECT_EQ(error(dynamic + R"(, "render": {"shadow": 1}})"), expected("render.shadow: expected true or false (got 1)"));
  // A static scene without gravity: no ground.
  EXPECT_FALSE(load(std::string("{") + kGrid4 + "}").render.ground);
}

TEST_F(SceneLoader, MotionErrors) {
  auto motion = [&](const std::string& list, const std::string& fix = R"(["x", "y", "z"])") {
    return error(std::string(R"({"analysis": "dynamic", )") + kGrid4 +
                 R"(, "boundary": [{"select": {"box": [[-1, -1, -1], [1, 1, 1]]}, "fix": )" + fix +
                 R"(, "motion": )" + list + "}]}");
  };
  const std::string m0 = "boundary[0].motion[0]";
  EXPECT_TRUE(contains(motion(R"({"type": "hold"})"), expected("boundary[0].motion: expected an array")));
  EXPECT_TRUE(contains(motion("[3]"), expected(m0 + ": expected an object (got 3)")));
  EXPECT_EQ(motion(R"([{"start": 0, "end": 1}])"), expected(m0 + ".type: required key is missing"));
  EXPECT_EQ(motion(R"([{"type": "spin", "start": 0, "end": 1}])"),
            expected(m0 + ".type: unknown motion type \"spin\" (allowed: \"rotate\", \"translate\", \"hold\")"));
  EXPECT_EQ(motion(R"([{"type": "hold", "start": 0}])"), expected(m0 + ".end: required key is missing"));
  EXPECT_EQ(motion(R"([{"type": "hold", "end": 1}])"), expected(m0 + ".start: required key is missing"));
  EXPECT_EQ(motion(R"([{"type": "hold", "start": -0.5, "end": 1}])"), expected(m0 + ".start: must be >= 0 [s] (got -0.5)"));
  EXPECT_EQ(motion(R"([{"type": "hold", "start": 2, "end": 1}])"), expected(m0 + ".end: must be >= start = 2.0 [s] (got 1.0)"));
  EXPECT_EQ(motion(R"([{"type": "rotate", "angle_deg": 90, "start": 0, "end": 1}])"),
            expected(m0 + ".axis: required key is missing"));
  EXPECT_EQ(motion(R"([{"type": "rotate", "axis": [0, 0, 0], "angle_deg": 90, "start": 0, "end": 1}])"),
            expected(m0 + ".axis: must be a non-zero vector (got [0.0, 0.0, 0.0])"));
  EXPECT_EQ(motion(R"([{"type": "rotate", "axis": [0, 1, 0], "start": 0, "end": 1}])"),
            expected(m0 + ".angle_deg: required key is missing"));
  EXPECT_TRUE(contains(motion(R"([{"type": "rotate", "axis": [0, 1, 0], "center": [0, 0], "angle_deg": 9, "start": 0, "end": 1}])"),
                       expected(m0 + ".center: expected an array of 3 numbers")));
  EXPECT_EQ(motion(R"([{"type": "translate", "start": 0, "end": 1}])"), expected(m0 + ".displacement: required key is missing"));
  EXPECT_EQ(motion(R"([{"type": "translate", "displacement": [0, 1, 0], "axis": [0, 1, 0], "start": 0, "end": 1}])"),
            expected(m0 + ".axis: unknown key (allowed: type, displacement, start, end)"));
  EXPECT_EQ(motion(R"([{"type": "hold", "angle_deg": 3, "start": 0, "end": 1}])"),
            expected(m0 + ".angle_deg: unknown key (allowed: type, start, end)"));
  EXPECT_EQ(motion(R"([{"type": "rotate", "axis": [0, 1, 0], "angle_deg": 9, "start": 0, "end": 1, "speed": 2}])"),
            expected(m0 + ".speed: unknown key (allowed: type, axis, center, angle_deg, start, end)"));
  EXPECT_EQ(motion(R"([{"type": "hold", "start": 0, "end": 1}, {"type": "hold", "start": 1}])"),
            expected("boundary[0].motion[1].end: required key is missing"));
  EXPECT_TRUE(contains(motion(R"([{"type": "hold", "start": 0, "end": 1}])", "[]"),
                       expected("boundary[0].motion: has no effect")));
  // A translation beyond a thousand times the mesh's size (the 4 x 4 grid: 1 m square, diagonal
  // sqrt 2 m) is a unit or exponent slip; it once grew to gigabytes before the solver failed.
  EXPECT_EQ(motion(R"([{"type": "translate", "displacement": [0, -1e9, 0], "start": 0, "end": 1}])"),
            expected(m0 + ".displacement: moves the boundary by 1000000000.0 m, more than 1000.0 times the mesh's size "
                          "(1.4142135623730951 m, its bounding-box diagonal); is the unit metres?"));
  EXPECT_TRUE(contains(motion(R"([{"type": "translate", "displacement": [1e308, 1e308, 0], "start": 0, "end": 1}])"),
                       expected(m0 + ".displacement: moves the boundary by")));
  EXPECT_EQ(motion(R"([{"type": "translate", "displacement": [0, 1000, 0], "start": 0, "end": 1}])"), "no error");
  // An empty chain is allowed (the components stay at rest) and so is a partial fix.
  EXPECT_EQ(motion("[]"), "no error");
  EXPECT_EQ(motion(R"([{"type": "translate", "displacement": [0, 1, 0], "start": 0, "end": 1}])", R"(["y"])"), "no error");
}

// ---- Shipped scenes -------------------------------------------------------------------------

TEST_F(SceneLoader, EveryShippedSceneLoads) {
  const fs::path scenes = fs::path(CLOTHSIM_SOURCE_DIR) / "scenes";
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(scenes))
    if (entry.path().extension() == ".json" && entry.path().stem().extension() != ".schema")  // not scene.schema.json
      names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  for (const std::string name :
       {"cantilever", "cylinder_pressure", "fig8_thick", "fig8_thick_stiff", "fig8_thin", "metal_compress",
        "pinched_cylinder", "plate_clamped", "plate_ss", "scordelis_lo", "sleeve_compress", "sleeve_compress_2542",
        "sleeve_gravity", "sleeve_twist"})
    EXPECT_TRUE(std::binary_search(names.begin(), names.end(), name)) << "missing scenes/" << name << ".json";
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    Scene s;
    try {
      s = load_scene(scenes / (name + ".json"), nullptr);
    } catch (const SceneError& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    EXPECT_EQ(s.name, name);
    EXPECT_FALSE(s.description.empty());
    EXPECT_FALSE(s.probes.empty());
  }
}

TEST_F(SceneLoader, ShippedSleeveScenes) {
  const fs::path scenes = fs::path(CLOTHSIM_SOURCE_DIR) / "scenes";
  const double length = 0.2;
  struct Expect {
    std::string name;
    int vertices;
    int triangles;
    double dt;
    double end;
    std::string motion;  // "", "rotate" or "translate" on the top rim
  };
  for (const Expect& e : std::vector<Expect>{{"sleeve_gravity", 494, 936, 0.001, 1.0, ""},
                                             {"sleeve_twist", 494, 936, 0.001, 1.5, "rotate"},
                                             {"sleeve_compress", 494, 936, 0.001, 1.5, "translate"},
                                             {"sleeve_compress_2542", 2542, 4960, 0.01, 1.0, "translate"},
                                             {"metal_compress", 2542, 4960, 0.005, 1.5, "translate"},
                                             {"fig8_thin", 780, 1500, 0.001, 1.5, "rotate"},
                                             {"fig8_thick", 780, 1500, 0.001, 1.5, "rotate"},
                                             {"fig8_thick_stiff", 780, 1500, 0.001, 1.5, "rotate"}}) {
    SCOPED_TRACE(e.name);
    const Scene s = load_scene(scenes / (e.name + ".json"), nullptr);
    const Problem& d = s.problem;
    EXPECT_EQ(s.analysis, "dynamic");
    EXPECT_TRUE(s.write_obj_frames);
    EXPECT_EQ(d.mesh.num_vertices(), e.vertices);
    EXPECT_EQ(d.mesh.num_triangles(), e.triangles);
    EXPECT_DOUBLE_EQ(d.time.dt, e.dt);
    EXPECT_DOUBLE_EQ(d.time.end, e.end);
    EXPECT_TRUE(d.corotational);
    const int per_ring = e.vertices == 494 ? 26 : (e.vertices == 2542 ? 62 : 30);
    // Every boundary condition holds vertices of one rim.
    for (const BoundaryCondition& bc : d.boundary) {
      ASSERT_FALSE(bc.vertices.empty());
      const double y = d.mesh.vertices(bc.vertices[0], 1);
      EXPECT_TRUE(std::abs(y) < 1e-12 || std::abs(y - length) < 1e-12) << y;
      for (int v : bc.vertices) EXPECT_NEAR(d.mesh.vertices(v, 1), y, 1e-12);
    }
    if (e.motion.empty()) {  // hanging under gravity from the top rim
      for (const BoundaryCondition& bc : d.boundary) EXPECT_NEAR(d.mesh.vertices(bc.vertices[0], 1), length, 1e-12);
      EXPECT_EQ(d.gravity, Eigen::Vector3d(0, -9.81, 0));
      continue;
    }
    // Scripted scenes: the bottom rim held all round, the top rim driven all round.
    for (const BoundaryCondition& bc : d.boundary) {
      EXPECT_EQ(static_cast<int>(bc.vertices.size()), per_ring);
      EXPECT_TRUE(bc.fix[0] && bc.fix[2]);
    }
    EXPECT_EQ(d.boundary[0].fix, (std::array<bool, 3>{true, true, true}));
    EXPECT_EQ(d.gravity, Eigen::Vector3d::Zero());
    ASSERT_EQ(d.boundary.size(), 2u);
    EXPECT_TRUE(d.boundary[0].motion.empty());
    ASSERT_EQ(d.boundary[1].motion.size(), 1u);
    EXPECT_NEAR(d.mesh.vertices(d.boundary[1].vertices[0], 1), length, 1e-12);
    const Motion& m = d.boundary[1].motion[0];
    EXPECT_DOUBLE_EQ(m.start, 0.0);
    EXPECT_DOUBLE_EQ(m.end, 1.0);
    if (e.motion == "rotate") {
      EXPECT_EQ(m.type, Motion::Type::rotate);
      EXPECT_EQ(m.axis, Eigen::Vector3d(0, 1, 0));
      EXPECT_DOUBLE_EQ(m.angle_deg, 90.0);
    } else {
      EXPECT_EQ(m.type, Motion::Type::translate);
      EXPECT_LT((m.displacement - Eigen::Vector3d(0, -0.3 * length, 0)).norm(), 1e-15);
    }
  }

  const ShellMaterial cotton = *material_preset("cotton");
  auto material = [&](const std::string& name) { return load_scene(scenes / (name + ".json"), nullptr).problem.material; };
  EXPECT_DOUBLE_EQ(material("sleeve_gravity").bending_rigidity, cotton.bending_rigidity);
  EXPECT_DOUBLE_EQ(material("metal_compress").stretch_modulus, 1e5);
  const ShellMaterial thin = material("fig8_thin"), thick = material("fig8_thick"), stiff = material("fig8_thick_stiff");
  EXPECT_DOUBLE_EQ(thin.bending_rigidity, cotton.bending_rigidity);
  EXPECT_DOUBLE_EQ(thin.stretch_modulus, cotton.stretch_modulus);
  EXPECT_NEAR(thick.bending_rigidity, 100 * cotton.bending_rigidity, 1e-15);
  EXPECT_DOUBLE_EQ(thick.stretch_modulus, cotton.stretch_modulus);
  EXPECT_NEAR(stiff.bending_rigidity, 100 * cotton.bending_rigidity, 1e-15);
  EXPECT_DOUBLE_EQ(stiff.stretch_modulus, 10 * cotton.stretch_modulus);
  EXPECT_DOUBLE_EQ(thick.areal_density, cotton.areal_density);
}

}  // namespace
}  // namespace clothsim

namespace clothsim {
namespace {

// A scene given as text (a study's variant of a scene file) is read like the file and errors
// name the nominal file.
TEST(SceneText, SameAsFileAndErrorsNameTheNominalFile) {
  const std::string text = std::string("{\"name\": \"t\", ") + kGrid4 + "}";
  const Scene s = load_scene_text(text, "scenes/variant.json", nullptr);
  EXPECT_EQ(s.name, "t");
  EXPECT_EQ(s.problem.mesh.num_vertices(), 25);
  try {
    load_scene_text(std::string("{\"nmae\": 1, ") + kGrid4 + "}", "scenes/variant.json", nullptr);
    FAIL() << "an unknown key was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("scenes/variant.json: nmae"), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_scene_text("{\"mesh\": ", "scenes/variant.json", nullptr), SceneError);
}

// Regression: a probe or point load far from the mesh once got vertex -1 (1e200² overflowed to a
// tie at infinity) and the run read memory before the matrix; now it is an error naming the key.
TEST_F(SceneLoader, FarProbesAndPointLoadsAreErrors) {
  const Eigen::MatrixX3d vertices = (Eigen::MatrixX3d(2, 3) << 0, 0, 0, 1, 0, 0).finished();
  for (const double x : {1e200, -1e200, 1e300}) {  // both vertices are equally far in double: either, never -1
    const int v = nearest_vertex(vertices, Eigen::Vector3d(x, 0, 0));
    EXPECT_TRUE(v == 0 || v == 1) << x << " gave " << v;
  }
  EXPECT_EQ(nearest_vertex(vertices, Eigen::Vector3d(0.9, 1e-3, 0)), 1);
  const std::string held = R"("boundary": [{"select": {"box": [[-1, -1, -1], [1, -0.4, 1]]}, "fix": ["x", "y", "z"]}])";
  const std::string probe = error(std::string("{") + kGrid4 + ", " + held + R"(, "probes": [{"name": "p", "at": [1e200, 0, 0]}]})");
  EXPECT_TRUE(contains(probe, expected("probes[0].at: [1e+200, 0.0, 0.0] is 1e+200 m from the nearest vertex, "
                                       "further than the mesh's size (1.4142135623730951 m")))
      << probe;
  const std::string far_load = error(std::string("{") + kGrid4 + ", " + held +
                                     R"(, "loads": {"point_loads": [{"at": [0, 0, 3], "force": [0, 0, -1]}]}})");
  EXPECT_TRUE(contains(far_load, expected("loads.point_loads[0].at: [0.0, 0.0, 3.0] is 3.0 m from the nearest vertex")))
      << far_load;
  // Within the mesh's size a point still snaps to its nearest vertex (the documented behaviour).
  EXPECT_NO_THROW(load(std::string("{") + kGrid4 + ", " + held + R"(, "probes": [{"name": "p", "at": [0.9, 0, 0.5]}]})"));
}

// Regression: dt = 1e-12 over 1 s overflowed the step count; an output_fps of 1e308 wrote frames
// for ever at t = 0. Both are limits now, checked when the scene is read.
TEST_F(SceneLoader, StepAndFrameCountsHaveLimits) {
  const std::string dynamic = std::string(R"({"analysis": "dynamic", )") + kGrid4;
  EXPECT_TRUE(contains(error(dynamic + R"(, "time": {"dt": 1e-12, "end": 1.0}})"),
                       expected("time: time.end / time.dt = 1.0 / 1e-12 needs 1000000000000 steps, more than the limit of "
                                "100000000")));
  EXPECT_TRUE(contains(error(dynamic + R"(, "time": {"dt": 0.001, "end": 1.0, "output_fps": 1e308}})"),
                       expected("time: time.output_fps = 1e+308 over time.end = 1.0 s makes 1e+308 frames")));
  EXPECT_TRUE(contains(error(dynamic + R"(, "time": {"dt": 0.001, "end": 1.0, "output_fps": 1e308}})"),
                       "more than the limit of 1000000"));
  // At the limits themselves the scene is accepted: 1e8 steps and 1e6 frames.
  EXPECT_NO_THROW(load(dynamic + R"(, "time": {"dt": 1e-8, "end": 1.0, "output_fps": 999999}})"));
}

// Regression: a 5000-character name was accepted and failed only when the output folder was made,
// after solving; now it is refused when the scene is read, and the message does not echo it whole.
TEST_F(SceneLoader, OverlongNamesAreRefusedUpFront) {
  const std::string long_name(5000, 'a');
  const std::string message = error(std::string(R"({"name": ")") + long_name + R"(", )" + kGrid4 + "}");
  EXPECT_TRUE(contains(message, expected("name: must be a safe folder name: at most 200 letters"))) << message;
  EXPECT_TRUE(contains(message, "(5000 characters)")) << message;
  EXPECT_LT(message.size(), 400u);
  EXPECT_NO_THROW(load(std::string(R"({"name": ")") + std::string(200, 'b') + R"(", )" + kGrid4 + "}"));
}

// Regressions: a key with a NUL in it printed an empty message (what() stopped at the NUL), and a
// parse error echoed the whole bad token (84 KB for a long one).
TEST_F(SceneLoader, ErrorMessagesArePrintableAndShort) {
  const std::string nul_key = error(std::string("{") + kGrid4 + R"(, "lo\u0000ads": {}})");
  EXPECT_EQ(std::string(nul_key.c_str()), nul_key);  // no NUL inside
  EXPECT_TRUE(contains(nul_key, "lo\\u0000ads")) << nul_key;
  EXPECT_TRUE(contains(nul_key, "unknown key")) << nul_key;
  const std::string long_token = error(std::string("{") + kGrid4 + R"(, "name": x)" + std::string(84000, 'y') + "}");
  EXPECT_TRUE(contains(long_token, "malformed JSON")) << long_token.substr(0, 300);
  EXPECT_LT(long_token.size(), 400u) << long_token.substr(0, 300);
}

}  // namespace
}  // namespace clothsim

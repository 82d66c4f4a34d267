// Scene loader: defaults, material overrides, vertex selection, nearest-vertex lookup, and error
// messages that name the file and the key path.
#include "sim/scene/scene.hpp"

#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

const char* const kGrid4 = R"("mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [4, 4]})";

class SceneLoader : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "clothsim_scene_test_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    fs::create_directories(path.parent_path());
    std::ofstream(path) << text;
    return path;
  }

  Scene load(const std::string& text, const std::string& name = "scene.json") const {
    return load_scene(write(name, text), nullptr);
  }

  // The SceneError message for `text`, or "no error".
  std::string error(const std::string& text, const std::string& name = "scene.json") const {
    try {
      load(text, name);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "no error";
  }

  // The message expected for a problem at `key`, with the file prefix.
  std::string expected(const std::string& key_and_problem) const {
    return (dir_ / "scene.json").string() + ": " + key_and_problem;
  }

  fs::path dir_;
};

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
            expected("loads.gravty: unknown key (allowed: gravity, surface_load, pressure, point_loads)"));
  EXPECT_TRUE(contains(error(std::string("{") + kGrid4 + R"(, "colour": "red"})"),
                       expected("colour: unknown key (allowed: name, description, analysis, mesh")));
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4], "radius": 1}})"),
                       expected("mesh.radius: unknown key (allowed: primitive, size, divisions)")));
  EXPECT_TRUE(contains(error(std::string("{") + kGrid4 +
                             R"(, "boundary": [{"select": {"box": [[0, 0, 0], [1, 1, 1]], "sphere": 1}}]})"),
                       expected("boundary[0].select.sphere: unknown key (allowed: box)")));
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

TEST_F(SceneLoader, AnalysisDynamicRejected) {
  EXPECT_EQ(error(std::string(R"({"analysis": "dynamic", )") + kGrid4 + "}"),
            expected("analysis: dynamic analysis is not available yet (allowed: \"static\")"));
  EXPECT_TRUE(contains(error(std::string(R"({"analysis": "modal", )") + kGrid4 + "}"),
                       expected("analysis: unknown value \"modal\" (allowed: \"static\")")));
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
  EXPECT_TRUE(contains(error(R"({"mesh": {"obj": "bad.obj", "primitive": "grid"}})"), expected("mesh: give either")));
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

}  // namespace
}  // namespace clothsim

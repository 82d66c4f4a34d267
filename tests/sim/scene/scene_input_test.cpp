// Scene input (issue 16): --set overrides applied by load_scene, "did you mean" suggestions for
// unknown keys and values, the mesh.max_vertices limit (checked before anything is allocated),
// absurd load magnitudes, the warning for cracks (coincident border vertices), meshes at extreme
// scales, and the "$schema" key.
#include "sim/scene/scene.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/mesh/obj_io.hpp"
#include "sim/shell/material_presets.hpp"

#include "tests/support/scene_files.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

const char* const kGrid4 = R"("mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [4, 4]})";

// A small dynamic scene with a boundary condition, a camera and damping.
const std::string kDynamic = std::string(R"({"name": "base", "analysis": "dynamic", )") + kGrid4 + R"(,
  "material": {"preset": "cotton"},
  "boundary": [{"select": {"box": [[-0.51, 0.49, -1], [0.51, 0.51, 1]]}, "fix": ["x", "y", "z"]}],
  "loads": {"gravity": [0, 0, -9.81]},
  "time": {"dt": 0.01, "end": 1.0},
  "render": {"camera": {"eye": [0, 0, 3], "target": [0, 0, 0]}}})";

class SceneInput : public testing::SceneFileTest {
 protected:
  Scene load_with(const std::string& text, const std::vector<std::string>& overrides, const LogFn& log = nullptr) const {
    return load_scene(write("scene.json", text), log, overrides);
  }
  // The SceneError message of loading `text` with `overrides`, or "no error".
  std::string error_with(const std::string& text, const std::vector<std::string>& overrides) const {
    try {
      load_with(text, overrides);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "no error";
  }
  // The log lines of loading `text` (which must load).
  std::string log_of(const std::string& text) const {
    std::string lines;
    load_scene(write("scene.json", text), [&](const std::string& line) { lines += line + "\n"; });
    return lines;
  }
};

// ---- --set overrides -----------------------------------------------------------------------

TEST_F(SceneInput, OverridesReplaceValuesOfAnyType) {
  const Scene base = load_with(kDynamic, {});
  EXPECT_EQ(base.name, "base");
  EXPECT_DOUBLE_EQ(base.problem.time.end, 1.0);
  EXPECT_TRUE(base.overrides.empty());

  const std::vector<std::string> sets = {"time.end=0.5", "name=foo", "material.preset=black_denim",
                                         "render.camera.eye=[1,2,3]", "description=hello world, again"};
  const Scene s = load_with(kDynamic, sets);
  EXPECT_DOUBLE_EQ(s.problem.time.end, 0.5);
  EXPECT_EQ(s.name, "foo");  // the output folder follows
  EXPECT_DOUBLE_EQ(s.problem.material.stretch_modulus, material_preset("black_denim")->stretch_modulus);
  EXPECT_DOUBLE_EQ(s.problem.material.areal_density, material_preset("black_denim")->areal_density);
  EXPECT_EQ(s.render.eye, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.render.target, Eigen::Vector3d(0, 0, 0));  // the rest of the camera is kept
  EXPECT_EQ(s.description, "hello world, again");         // not JSON: the text as a string
  EXPECT_EQ(s.overrides, sets);

  // A JSON string, a JSON object, later overrides win.
  const Scene t = load_with(kDynamic, {R"(description="quoted")", R"(render.camera={"eye": [0, 1, 4], "target": [0, 0.5, 0]})",
                                       "time.end=0.5", "time.end=0.25"});
  EXPECT_EQ(t.description, "quoted");
  EXPECT_EQ(t.render.eye, Eigen::Vector3d(0, 1, 4));
  EXPECT_EQ(t.render.target, Eigen::Vector3d(0, 0.5, 0));
  EXPECT_DOUBLE_EQ(t.problem.time.end, 0.25);
}

TEST_F(SceneInput, OverridesIndexArraysBothWaysAppendAndRemove) {
  EXPECT_FALSE(load_with(kDynamic, {}).problem.boundary[0].clamped);
  EXPECT_TRUE(load_with(kDynamic, {"boundary.0.fix=[\"z\"]", "boundary.0.rotation=free"}).problem.boundary[0].fix[2]);
  const std::string clamped_static = std::string("{") + kGrid4 +
                                     R"(, "boundary": [{"select": {"box": [[-0.51, -0.51, -1], [0.51, -0.49, 1]]}}],
                                        "loads": {"surface_load": [0, 0, -1]}})";
  EXPECT_TRUE(load_with(clamped_static, {"boundary.0.rotation=clamped"}).problem.boundary[0].clamped);
  EXPECT_TRUE(load_with(clamped_static, {"boundary[0].rotation=clamped"}).problem.boundary[0].clamped);
  // An index equal to the length appends; null removes an element or a key.
  const Scene appended =
      load_with(clamped_static, {R"(boundary[1]={"select": {"box": [[-0.51, 0.49, -1], [0.51, 0.51, 1]]}})"});
  ASSERT_EQ(appended.problem.boundary.size(), 2u);
  EXPECT_EQ(appended.problem.boundary[1].vertices.size(), 5u);
  EXPECT_TRUE(load_with(clamped_static, {"boundary.0=null"}).problem.boundary.empty());
  EXPECT_EQ(load_with(kDynamic, {"loads.gravity=null"}).problem.gravity, Eigen::Vector3d::Zero());
  EXPECT_FALSE(load_with(kDynamic, {"render.camera=null"}).render.has_camera);
  // Removing what is not there changes nothing; missing objects on the way are created.
  EXPECT_EQ(load_with(kDynamic, {"initial.velocity=null"}).problem.initial.velocity, Eigen::Vector3d::Zero());
  EXPECT_DOUBLE_EQ(load_with(kDynamic, {"damping.mass=0.25"}).problem.damping.mass, 0.25);
  EXPECT_EQ(load_with(kDynamic, {"mesh.max_vertices=25"}).problem.mesh.num_vertices(), 25);
}

TEST_F(SceneInput, OverriddenValuesAreCheckedLikeTheFileAndNamed) {
  const std::string file = (dir_ / "scene.json").string();
  EXPECT_EQ(error_with(kDynamic, {"time.end=-1"}),
            file + ": time.end: must be > 0 [s] (got -1) (set by --set time.end=-1)");
  EXPECT_EQ(error_with(kDynamic, {"name=true"}), file + ": name: expected a string (got true) (set by --set name=true)");
  EXPECT_EQ(error_with(kDynamic, {"name=../x"}).find(file + ": name: must be a safe folder name"), 0u);
  EXPECT_EQ(error_with(kDynamic, {"time.ennd=1"}),
            file + ": time.ennd: unknown key (allowed: dt, end, output_fps); did you mean \"end\"? (set by --set time.ennd=1)");
  EXPECT_EQ(error_with(kDynamic, {"material.preset=coton"}).find(file + ": material.preset: unknown preset \"coton\""), 0u);
  EXPECT_TRUE(contains(error_with(kDynamic, {"material.preset=coton"}),
                       "; did you mean \"cotton\"? (set by --set material.preset=coton)"));
  // An error around the overridden key names it too (time.end above time.dt's limit of steps) ...
  EXPECT_TRUE(contains(error_with(kDynamic, {"time.dt=1e-12"}), "(set by --set time.dt=1e-12)"));
  // ... a dynamic-only key written into a static scene ...
  EXPECT_EQ(error_with(std::string("{") + kGrid4 + "}", {"time.end=0.5"}),
            file + ": time: needs \"analysis\": \"dynamic\" (this scene is static) (set by --set time.end=0.5)");
  // ... but not an unrelated error.
  const std::string unrelated = error_with(std::string("{") + kGrid4 + R"(, "loads": {"gravty": [0, 0, 1]}})", {"name=x"});
  EXPECT_TRUE(contains(unrelated, "loads.gravty: unknown key")) << unrelated;
  EXPECT_FALSE(contains(unrelated, "--set")) << unrelated;
  // The scene file itself is not changed.
  load_with(kDynamic, {"time.end=0.5"});
  std::ifstream in(dir_ / "scene.json");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, kDynamic);
}

TEST_F(SceneInput, MalformedOverridesNameTheArgument) {
  auto message = [&](const std::string& argument) { return error_with(kDynamic, {argument}); };
  EXPECT_EQ(message("time.end"), "--set time.end: expected KEY=VALUE, e.g. --set time.end=0.5 or --set "
                                 "boundary[0].rotation=clamped");
  EXPECT_EQ(message("=1"), "--set =1: expected KEY=VALUE, e.g. --set time.end=0.5 or --set boundary[0].rotation=clamped");
  EXPECT_EQ(message("time..end=1"), "--set time..end=1: empty key name in \"time..end\" (write a.b.c, a[0].b or a.0.b)");
  EXPECT_EQ(message("boundary[x].fix=[]"), "--set boundary[x].fix=[]: malformed index in \"boundary[x].fix\" (write [0], [1], ...)");
  EXPECT_EQ(message("boundary[0]fix=[]"), "--set boundary[0]fix=[]: expected '.' or '[' after ']' in \"boundary[0]fix\"");
  // A key below a value that is not an object (the reproducer of the issue).
  EXPECT_EQ(message("time.end.x=1"),
            "--set time.end.x=1: time.end is 1.0, not an object or array, so it has no key \"x\"");
  EXPECT_EQ(message("material.preset.name=x"),
            "--set material.preset.name=x: material.preset is \"cotton\", not an object or array, so it has no key \"name\"");
  EXPECT_EQ(message("boundary.3.fix=[]"),
            "--set boundary.3.fix=[]: boundary has 1 element; index 3 is out of range (1 appends one)");
  EXPECT_EQ(message("boundary.rotation=free"),
            "--set boundary.rotation=free: boundary is an array: index it by number (boundary[0].rotation or "
            "boundary.0.rotation), not by \"rotation\"");
  EXPECT_EQ(message("material[0]=1"), "--set material[0]=1: material is an object: \"[0]\" indexes an array; write material.0");
  // A value that starts like JSON must be JSON; repeated keys are refused as in a file.
  EXPECT_EQ(message("render.color=[1, 0").find("--set render.color=[1, 0: the value is not valid JSON: "), 0u);
  EXPECT_EQ(message(R"(render.camera={"eye": [0, 0, 1], "eye": [0, 0, 2]})"),
            R"(--set render.camera={"eye": [0, 0, 1], "eye": [0, 0, 2]}: the value repeats the key "eye")");
  // A long argument is shortened in the message.
  const std::string long_value = "description.x=" + std::string(5000, 'a');
  EXPECT_LT(message(long_value).size(), 300u);
}

// ---- did you mean ----------------------------------------------------------------------------

TEST(SceneSuggestions, EditDistanceAndClosestName) {
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(edit_distance("", "abc"), 3u);
  EXPECT_EQ(edit_distance("ab", "ba"), 1u);  // a swap of neighbours counts once
  EXPECT_EQ(edit_distance("Cotton", "cotton"), 0u);
  EXPECT_EQ(closest_name("gravty", {"gravity", "surface_load", "pressure"}), "gravity");
  EXPECT_EQ(closest_name("dinamic", {"static", "dynamic"}), "dynamic");
  EXPECT_EQ(closest_name("Cotton", material_preset_names()), "cotton");
  EXPECT_EQ(closest_name("blackdenim", material_preset_names()), "black_denim");
  EXPECT_EQ(closest_name("tme", {"time", "name"}), "time");
  EXPECT_EQ(closest_name("cotton", material_preset_names()), "");  // allowed: nothing to suggest
  EXPECT_EQ(closest_name("silk", material_preset_names()), "");    // not close to anything
  EXPECT_EQ(closest_name("w", {"x", "y", "z"}), "");               // one letter is never "close"
  EXPECT_EQ(closest_name("size", {"amplitude", "seed", "wavelength"}), "");
  EXPECT_EQ(closest_name(std::string(100000, 'a'), {"time"}), "");  // long input: skipped by length
}

TEST_F(SceneInput, UnknownKeysAndValuesSuggestTheClosestName) {
  auto with = [&](const std::string& rest) { return error(std::string("{") + kGrid4 + ", " + rest + "}"); };
  EXPECT_TRUE(contains(with(R"("method": "loop_k")"), "did you mean \"loop_kl\"?"));
  EXPECT_TRUE(contains(with(R"("analysis": "dynamc")"), "did you mean \"dynamic\"?"));
  EXPECT_TRUE(contains(with(R"("material": {"preset": "blackdenim"})"), "did you mean \"black_denim\"?"));
  EXPECT_TRUE(contains(with(R"("material": {"thicknes": 0.001})"), "did you mean \"thickness\"?"));
  EXPECT_TRUE(contains(with(R"("numerics": {"quadrature": "one_pont"})"), "did you mean \"one_point\"?"));
  EXPECT_TRUE(contains(with(R"("render": {"framing": "sequnce"})"), "did you mean \"sequence\"?"));
  EXPECT_TRUE(contains(with(R"("render": {"colour": [1, 0, 0]})"), "did you mean \"color\"?"));
  EXPECT_TRUE(contains(with(R"("boundary": [{"select": {"box": [[0, 0, 0], [1, 1, 1]]}, "fix": ["X"]}])"),
                       "did you mean \"x\"?"));
  EXPECT_TRUE(contains(with(R"("probs": [])"), "did you mean \"probes\"?"));
  EXPECT_EQ(with(R"("material": {"preset": "silk"})").find("did you mean"), std::string::npos);
  const std::string solver = error(std::string(R"({"analysis": "dynamic", "material": {"preset": "cotton"}, )") + kGrid4 +
                                   R"(, "solver": {"type": "cholmd"}})");
  EXPECT_TRUE(contains(solver, "solver.type: unknown solver type \"cholmd\" (allowed: \"auto\", \"pcg\", \"cholmod\"); did you mean "
                               "\"cholmod\"?"))
      << solver;
}

// ---- mesh.max_vertices -------------------------------------------------------------------------

TEST_F(SceneInput, HugeGridsAreRefusedBeforeAllocating) {
  // The reproducer: 10000 x 10000 divisions allocated 7-8 GB before std::bad_alloc.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(error(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [10000, 10000]}})"),
            expected("mesh.divisions: a 10000 x 10000 grid has 100020001 vertices, more than mesh.max_vertices = 1000000 "
                     "(raise mesh.max_vertices to allow it)"));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  // Counted in 64 bits: (2e9 + 1)² does not overflow into a small number.
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [2000000000, 2000000000]}})"),
                       "has 4000000004000000001 vertices, more than mesh.max_vertices = 1000000"));
  EXPECT_EQ(error(R"({"mesh": {"primitive": "cylinder", "radius": 1, "length": 1, "segments": 100000, "rings": 100000}})"),
            expected("mesh: a cylinder of 100000 segments x 100000 rings has 10000000000 vertices, more than "
                     "mesh.max_vertices = 1000000 (raise mesh.max_vertices to allow it)"));
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "cylinder", "radius": 1, "length": 1, "angle_deg": 90,
                                          "segments": 1999, "rings": 1000}})"),
                       "mesh: a cylinder panel of 1999 segments x 1000 rings has 2000000 vertices"));
  // The limit is a scene key; at it is allowed, one below it is not.
  EXPECT_EQ(load(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4], "max_vertices": 25}})")
                .problem.mesh.num_vertices(),
            25);
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4], "max_vertices": 24}})"),
                       "mesh.divisions: a 4 x 4 grid has 25 vertices, more than mesh.max_vertices = 24"));
  EXPECT_EQ(error(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4], "max_vertices": 2}})"),
            expected("mesh.max_vertices: must be an integer >= 3 (got 2)"));
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4], "max_vertices": 1e9}})"),
                       "mesh.max_vertices: expected an integer"));
  // The mesh as prepared for the method counts too: a 1 x 1 grid is refined once (4 -> 9 vertices).
  EXPECT_EQ(error(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [1, 1], "max_vertices": 5}})"),
            expected("mesh: prepared for the method (refined once by Loop subdivision) it has 9 vertices, more than "
                     "mesh.max_vertices = 5 (raise mesh.max_vertices to allow it)"));
}

TEST_F(SceneInput, HugeObjFilesAreRefusedBeforeAllocating) {
  // The reproducer: /dev/zero was read until memory ran out.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(error(R"({"mesh": {"obj": "/dev/zero"}})"),
            expected("mesh.obj: /dev/zero: not a regular file (a device, pipe or socket); a mesh must be an OBJ file"));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  EXPECT_TRUE(contains(error(R"({"mesh": {"obj": "."}})"), "mesh.obj: " + (dir_ / ".").string() + ": not a regular file (a directory)"));

  std::string obj;
  for (int v = 0; v < 30; ++v) obj += "v " + std::to_string(v) + " 0 0\n";
  write("big.obj", obj + "f 1 2 3\n");
  EXPECT_EQ(error(R"({"mesh": {"obj": "big.obj", "max_vertices": 20}})"),
            expected("mesh.obj: " + (dir_ / "big.obj").string() +
                     ":21: more than 20 vertices (mesh.max_vertices = 20; raise it to read larger meshes)"));
  // The same limit holds for obstacle meshes.
  const std::string with_obstacle = std::string(R"({"analysis": "dynamic", "material": {"preset": "cotton"},
      "mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4], "max_vertices": 25},
      "obstacles": [{"obj": "big.obj"}]})");
  EXPECT_EQ(error(with_obstacle),
            expected("obstacles[0].obj: " + (dir_ / "big.obj").string() +
                     ":26: more than 25 vertices (mesh.max_vertices = 25, which limits obstacle meshes too; raise it to "
                     "read larger ones)"));
}

// ---- load magnitudes -----------------------------------------------------------------------------

TEST_F(SceneInput, AbsurdLoadsAreErrorsNamingTheKey) {
  // The reproducer: 1e308 N/m² on a plate gave a 4e305 m displacement and no warning.
  const std::string plate = std::string("{") + kGrid4 +
                            R"(, "boundary": [{"select": {"box": [[-0.51, -0.51, -1], [0.51, -0.49, 1]]}}], "loads": )";
  auto loads = [&](const std::string& l) { return error(plate + l + "}"); };
  const std::string pressure = loads(R"({"pressure": 1e308})");
  EXPECT_EQ(pressure.find(expected("loads.pressure: 1e+308 N/m²: even carried by stretching alone")), 0u) << pressure;
  EXPECT_TRUE(contains(pressure, "would strain the sheet by about 1.41e+304")) << pressure;
  EXPECT_TRUE(contains(pressure, "more than 100 (10000 %): refused")) << pressure;
  EXPECT_TRUE(contains(loads(R"({"surface_load": [0, 0, -1e9]})"), expected("loads.surface_load: 1e+09 N/m²")));
  EXPECT_TRUE(contains(loads(R"({"point_loads": [{"at": [0, 0, 0], "force": [0, 0, 1e10]}]})"),
                       expected("loads.point_loads[0].force: |F| = 1e+10 N")));
  EXPECT_TRUE(contains(loads(R"({"moments": [{"select": {"box": [[-1, 0.2, -1], [1, 1, 1]]}, "moment": [1e9, 0, 0]}]})"),
                       expected("loads.moments[0].moment: |M| = 1e+09 N·m")));
  // The largest part is named; the sum counts.
  EXPECT_TRUE(contains(loads(R"({"pressure": 1e5, "surface_load": [0, 0, 7e5]})"), expected("loads.surface_load: ")));
  EXPECT_EQ(loads(R"({"gravity": [0, 0, -1e6]})"),
            expected("loads.gravity: |g| = 1e+06 m/s² is more than 1e4 g (9.81e+04 m/s²); check the value and its unit "
                     "[m/s²]"));
  // Non-finite values cannot be written: a JSON number beyond the doubles is malformed, and --set
  // takes "1e999", "inf" or "nan" for strings.
  EXPECT_TRUE(contains(loads(R"({"pressure": 1e999})"), "malformed JSON: number overflow parsing '1e999'"));
  for (const char* value : {"1e999", "inf", "nan", "-Infinity"})
    EXPECT_TRUE(contains(error_with(plate + "{}}", {std::string("loads.pressure=") + value}),
                         "loads.pressure: expected a number (got \"" + std::string(value) + "\")"))
        << value;
  // Ordinary loads pass without a warning; a load straining the sheet beyond 100 % is a warning.
  EXPECT_FALSE(contains(log_of(plate + R"({"pressure": 1000, "gravity": [0, 0, -9.81]}})"), "warning"));
  const std::string heavy = log_of(plate + R"({"pressure": 20000}})");
  EXPECT_TRUE(contains(heavy, "warning: loads.pressure: 2e+04 N/m²: even carried by stretching alone")) << heavy;
  EXPECT_TRUE(contains(heavy, "more than 1 (100 %)")) << heavy;
}

// ---- cracks --------------------------------------------------------------------------------------

TEST_F(SceneInput, CracksAreWarnedAboutWithTheVertices) {
  // Two 1 x 1 squares side by side (x from 0 to 2), the second with its own copies of the shared
  // edge's vertices (OBJ indices 5 and 8 repeat 2 and 3).
  write("split.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "v 1 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\n"
        "f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\n");
  const std::string log = log_of(R"({"mesh": {"obj": "split.obj"}})");
  EXPECT_TRUE(contains(log, "warning: mesh: 2 pairs of distinct border vertices at the same position (within 1e-06 of the "
                            "mesh's size): vertices 1 and 4 (OBJ indices 2 and 5) at [1.0, 0.0, 0.0]; vertices 2 and 7 "
                            "(OBJ indices 3 and 8) at [1.0, 1.0, 0.0]. The surface is split there"))
      << log;
  write("joined.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nf 1 2 3\nf 1 3 4\nf 2 5 6\nf 2 6 3\n");
  EXPECT_FALSE(contains(log_of(R"({"mesh": {"obj": "joined.obj"}})"), "warning")) << log_of(R"({"mesh": {"obj": "joined.obj"}})");
  EXPECT_FALSE(contains(log_of(std::string("{") + kGrid4 + "}"), "warning"));
}

// ---- scale -----------------------------------------------------------------------------------------

TEST_F(SceneInput, MeshesAtExtremeScalesPassTheMeshChecks) {
  // The reproducer: a valid mesh scaled by 1e-160 or 1e300 was refused as "triangle 0 is degenerate".
  for (const double scale : {1e-160, 1e-150, 1e150, 1e300}) {
    const TriMesh grid = make_grid(scale, scale, 4, 4);
    write_obj((dir_ / "scaled.obj").string(), grid.vertices, grid.triangles);
    const Scene s = load(R"({"mesh": {"obj": "scaled.obj"}})");
    EXPECT_EQ(s.problem.mesh.num_vertices(), 25) << scale;
    EXPECT_TRUE(s.problem.mesh.vertices.allFinite()) << scale;
  }
}

// ---- "$schema" ---------------------------------------------------------------------------------------

TEST_F(SceneInput, SchemaKeyIsAcceptedAndIgnored) {
  EXPECT_EQ(load(std::string(R"({"$schema": "../scenes/scene.schema.json", )") + kGrid4 + "}").problem.mesh.num_vertices(),
            25);
  EXPECT_EQ(error(std::string(R"({"$schema": 3, )") + kGrid4 + "}"), expected("$schema: expected a string (got 3)"));
}

}  // namespace
}  // namespace clothsim

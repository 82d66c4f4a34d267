// The JSON Schema of the scene format (scenes/scene.schema.json) against the scene loader:
// - scripts/check_schema.py validates every shipped scene and the cases of schema_cases.json
//   with python3-jsonschema (valid cases must validate, invalid ones must not);
//   and the scenes the stability study generates;
// - the loader gives the same verdicts on those cases, and names the case's key in its error;
// - every object of the schema has exactly the keys the loader allows at that place (the loader
//   lists them when it meets an unknown key), and every enumeration exactly the loader's values.
#include "sim/scene/scene.hpp"

#include "sim/setup/setup.hpp"
#include "sim/shell/material_presets.hpp"
#include "sim/study/stability.hpp"

#include "tests/support/process.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kSource = CLOTHSIM_SOURCE_DIR;

Json read_json(const fs::path& path) {
  std::ifstream in(path);
  return Json::parse(in);
}

const Json& schema() {
  static const Json s = read_json(kSource / "scenes/scene.schema.json");
  return s;
}

const Json& cases() {
  static const Json c = read_json(kSource / "tests/sim/scene/schema_cases.json");
  return c;
}

// The scene of the case called `name`.
Json case_scene(const std::string& name) {
  for (const Json& c : cases())
    if (c["name"] == name) return c["scene"];
  ADD_FAILURE() << "no case " << name;
  return Json::object();
}

// Loads `scene` as if it were scenes/case.json (relative OBJ paths: scenes/meshes/...); the
// SceneError message, or "" if it loads.
std::string load_error(const Json& scene) {
  try {
    load_scene_text(scene.dump(), kSource / "scenes/case.json", nullptr);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

// The names listed in "... (allowed: a, b, c)" or "(allowed: \"a\", \"b\")" of `message`.
std::set<std::string> allowed_in(const std::string& message) {
  std::set<std::string> out;
  const auto open = message.find("(allowed: ");
  if (open == std::string::npos) return out;
  const auto close = message.find(')', open);
  std::string list = message.substr(open + 10, close - open - 10);
  std::size_t pos = 0;
  while (pos <= list.size()) {
    auto comma = list.find(", ", pos);
    if (comma == std::string::npos) comma = list.size();
    std::string item = list.substr(pos, comma - pos);
    if (item.size() >= 2 && item.front() == '"') item = item.substr(1, item.size() - 2);
    out.insert(item);
    pos = comma + 2;
  }
  return out;
}

std::set<std::string> keys_of(const Json& object) {
  std::set<std::string> out;
  for (auto it = object.begin(); it != object.end(); ++it) out.insert(it.key());
  return out;
}

TEST(SceneSchema, ShippedScenesAndCasesValidateWithPythonJsonschema) {
  ASSERT_EQ(testing::run_shell("/usr/bin/python3 -c 'import jsonschema' 2>/dev/null"), 0)
      << "python3-jsonschema is missing: run scripts/install_deps.sh";
  const fs::path dir = testing::make_temp_dir("clothsim_schema_");
  const std::string command = "/usr/bin/python3 " + testing::shell_quote((kSource / "scripts/check_schema.py").string()) +
                              " " + testing::shell_quote((kSource / "scenes/scene.schema.json").string()) + " --cases " +
                              testing::shell_quote((kSource / "tests/sim/scene/schema_cases.json").string()) + " " +
                              testing::shell_quote((kSource / "scenes").string()) + " > " +
                              testing::shell_quote((dir / "out.txt").string()) + " 2>&1";
  const int code = testing::run_shell(command);
  const std::string out = testing::read_file_bytes(dir / "out.txt");
  fs::remove_all(dir);
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("agree with"), std::string::npos) << out;
}

TEST(SceneSchema, StabilityStudyScenesValidate) {
  // The scenes `clothsim study stability` writes and runs (with and without their remedies).
  const fs::path dir = testing::make_temp_dir("clothsim_schema_");
  int written = 0;
  for (const StabilityCase& c : stability_cases(false)) {
    std::ofstream(dir / (c.name + ".json")) << c.scene_json;
    ++written;
    if (!c.without_remedy_json.empty()) {
      std::ofstream(dir / (c.name + "_without_remedy.json")) << c.without_remedy_json;
      ++written;
    }
  }
  ASSERT_GT(written, 10);
  const std::string command = "/usr/bin/python3 " + testing::shell_quote((kSource / "scripts/check_schema.py").string()) +
                              " " + testing::shell_quote((kSource / "scenes/scene.schema.json").string()) + " " +
                              testing::shell_quote(dir.string()) + " > " + testing::shell_quote((dir / "out.txt").string()) +
                              " 2>&1";
  const int code = testing::run_shell(command);
  const std::string out = testing::read_file_bytes(dir / "out.txt");
  fs::remove_all(dir);
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find(std::to_string(written) + " scene file(s)"), std::string::npos) << out;
}

TEST(SceneSchema, CheckerFailsOnABadScene) {
  // The checker can fail: a scene with a misspelt key and a dynamic-only key in a static scene.
  const fs::path dir = testing::make_temp_dir("clothsim_schema_");
  std::ofstream(dir / "bad.json") << R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4]},
                                         "time": {"end": 1}, "material": {"thicknes": 0.001}})";
  const std::string command = "/usr/bin/python3 " + testing::shell_quote((kSource / "scripts/check_schema.py").string()) +
                              " " + testing::shell_quote((kSource / "scenes/scene.schema.json").string()) + " " +
                              testing::shell_quote((dir / "bad.json").string()) + " > " +
                              testing::shell_quote((dir / "out.txt").string()) + " 2>&1";
  const int code = testing::run_shell(command);
  const std::string out = testing::read_file_bytes(dir / "out.txt");
  fs::remove_all(dir);
  EXPECT_EQ(code, 1) << out;
  EXPECT_NE(out.find("at material: Additional properties are not allowed ('thicknes' was unexpected)"), std::string::npos)
      << out;
  EXPECT_NE(out.find("at time: False schema does not allow"), std::string::npos) << out;
}

TEST(SceneSchema, LoaderGivesTheCasesVerdicts) {
  const std::string file = (kSource / "scenes/case.json").string();
  ASSERT_GT(cases().size(), 50u);
  for (const Json& c : cases()) {
    const std::string name = c["name"];
    const std::string message = load_error(c["scene"]);
    if (c["valid"]) {
      EXPECT_EQ(message, "") << name;
    } else {
      const std::string key = c["key"];
      EXPECT_EQ(message.rfind(file + ": " + key + ": ", 0), 0u) << name << ": " << message;
    }
  }
}

// An object of the schema ($defs/<def>, or the top level for "") and where it sits in a valid
// case's scene.
struct Place {
  std::string def, case_name, pointer, key_path;
};

const std::vector<Place>& places() {
  static const std::vector<Place> p = {
      {"", "every dynamic key", "", ""},
      {"mesh_grid", "every dynamic key", "/mesh", "mesh"},
      {"mesh_obj", "obj mesh, placed", "/mesh", "mesh"},
      {"mesh_cylinder", "cylinder panel of one segment", "/mesh", "mesh"},
      {"mesh_rotate", "every static key", "/mesh/rotate", "mesh.rotate"},
      {"material", "every static key", "/material", "material"},
      {"boundary_condition", "every static key", "/boundary/0", "boundary[0]"},
      {"select", "every static key", "/boundary/0/select", "boundary[0].select"},
      {"loads", "every static key", "/loads", "loads"},
      {"point_load", "every static key", "/loads/point_loads/0", "loads.point_loads[0]"},
      {"moment_load", "every static key", "/loads/moments/0", "loads.moments[0]"},
      {"probe", "every static key", "/probes/0", "probes[0]"},
      {"numerics", "every static key", "/numerics", "numerics"},
      {"render", "every static key", "/render", "render"},
      {"camera", "every static key", "/render/camera", "render.camera"},
      {"stretch_orthotropic", "every orthotropic key", "/material/stretch_modulus", "material.stretch_modulus"},
      {"bending_orthotropic", "every orthotropic key", "/material/bending_rigidity", "material.bending_rigidity"},
      {"grain", "every orthotropic key", "/material/grain", "material.grain"},
      {"imperfection", "every static key", "/imperfection", "imperfection"},
      {"motion_rotate", "every dynamic key", "/boundary/0/motion/0", "boundary[0].motion[0]"},
      {"motion_translate", "every dynamic key", "/boundary/0/motion/1", "boundary[0].motion[1]"},
      {"motion_hold", "every dynamic key", "/boundary/0/motion/2", "boundary[0].motion[2]"},
      {"time", "every dynamic key", "/time", "time"},
      {"damping", "every dynamic key", "/damping", "damping"},
      {"solver", "every dynamic key", "/solver", "solver"},
      {"initial", "every dynamic key", "/initial", "initial"},
      {"output", "every dynamic key", "/output", "output"},
      {"collision", "every dynamic key", "/collision", "collision"},
      {"obstacle_plane", "every dynamic key", "/obstacles/0", "obstacles[0]"},
      {"obstacle_sphere", "every dynamic key", "/obstacles/1", "obstacles[1]"},
      {"obstacle_capsule", "every dynamic key", "/obstacles/2", "obstacles[2]"},
      {"obstacle_box", "every dynamic key", "/obstacles/3", "obstacles[3]"},
      {"obstacle_cylinder", "every dynamic key", "/obstacles/4", "obstacles[4]"},
      {"obstacle_obj", "every dynamic key", "/obstacles/5", "obstacles[5]"},
      {"mesh_pattern", "every pattern key", "/mesh", "mesh"},
      {"pattern_piece", "every pattern key", "/mesh/pattern/pieces/0", "mesh.pattern.pieces[0]"},
      {"pattern_seam", "every pattern key", "/mesh/pattern/seams/0", "mesh.pattern.seams[0]"},
      {"piece_edge", "every pattern key", "/mesh/pattern/seams/0/a", "mesh.pattern.seams[0].a"},
      {"settle", "every pattern key", "/settle", "settle"},
      {"half_space", "obj obstacle part", "/obstacles/0/keep/0", "obstacles[0].keep[0]"},
      {"piece_region", "pattern vertex group", "/boundary/0/select/piece", "boundary[0].select.piece"},
  };
  return p;
}

TEST(SceneSchema, EveryObjectHasTheLoadersKeys) {
  std::set<std::string> covered;
  for (const Place& place : places()) {
    const Json& object = place.def.empty() ? schema() : schema()["$defs"][place.def];
    ASSERT_TRUE(object.contains("properties")) << place.def;
    EXPECT_EQ(object["additionalProperties"], false) << place.def;
    Json scene = case_scene(place.case_name);
    scene[Json::json_pointer(place.pointer)]["zz_unknown"] = 1;
    const std::string message = load_error(scene);
    const std::string key = place.key_path.empty() ? "zz_unknown" : place.key_path + ".zz_unknown";
    EXPECT_NE(message.find(": " + key + ": unknown key (allowed: "), std::string::npos) << place.def << ": " << message;
    EXPECT_EQ(allowed_in(message), keys_of(object["properties"])) << place.def << ": " << message;
    covered.insert(place.def);
  }
  // Every object of the schema is compared (a new one must be added above).
  for (auto it = schema()["$defs"].begin(); it != schema()["$defs"].end(); ++it) {
    if (it->contains("properties")) {
      EXPECT_TRUE(covered.count(it.key())) << "$defs/" << it.key() << " is not compared";
    }
  }
}

// The values a schema property allows: its enum, or the consts of the variants of a oneOf.
std::set<std::string> schema_values(const Json& property) {
  std::set<std::string> out;
  if (property.contains("enum"))
    for (const Json& v : property["enum"]) out.insert(v.get<std::string>());
  return out;
}

std::set<std::string> variant_values(const std::string& def, const std::string& key) {
  std::set<std::string> out;
  for (const Json& variant : schema()["$defs"][def]["oneOf"]) {
    const std::string ref = variant["$ref"];
    const Json& target = schema()["$defs"][ref.substr(ref.rfind('/') + 1)];
    if (target["properties"].contains(key)) out.insert(target["properties"][key]["const"].get<std::string>());
  }
  return out;
}

TEST(SceneSchema, EveryEnumerationHasTheLoadersValues) {
  struct Enumerated {
    std::string case_name, pointer, key_path;
    std::set<std::string> schema;
  };
  const Json& defs = schema()["$defs"];
  const std::vector<Enumerated> enumerated = {
      {"minimal grid", "/analysis", "analysis", schema_values(schema()["properties"]["analysis"])},
      {"minimal grid", "/method", "method", schema_values(schema()["properties"]["method"])},
      {"every static key", "/numerics/quadrature", "numerics.quadrature", schema_values(defs["numerics"]["properties"]["quadrature"])},
      {"every static key", "/boundary/0/rotation", "boundary[0].rotation",
       schema_values(defs["boundary_condition"]["properties"]["rotation"])},
      {"every static key", "/boundary/0/fix/0", "boundary[0].fix[0]",
       schema_values(defs["boundary_condition"]["properties"]["fix"]["items"])},
      {"every static key", "/material/preset", "material.preset", schema_values(defs["material"]["properties"]["preset"])},
      {"every static key", "/render/surface", "render.surface", schema_values(defs["render"]["properties"]["surface"])},
      {"every static key", "/render/framing", "render.framing", schema_values(defs["render"]["properties"]["framing"])},
      {"every dynamic key", "/solver/type", "solver.type", schema_values(defs["solver"]["properties"]["type"])},
      {"every dynamic key", "/solver/preconditioner", "solver.preconditioner",
       schema_values(defs["solver"]["properties"]["preconditioner"])},
      {"every dynamic key", "/solver/warm_start", "solver.warm_start", schema_values(defs["solver"]["properties"]["warm_start"])},
      {"every dynamic key", "/mesh/primitive", "mesh.primitive", variant_values("mesh", "primitive")},
      {"every pattern key", "/rest", "rest", schema_values(schema()["properties"]["rest"])},
      {"every dynamic key", "/boundary/0/motion/0/type", "boundary[0].motion[0].type", variant_values("motion", "type")},
      {"every dynamic key", "/obstacles/1/primitive", "obstacles[1].primitive", variant_values("obstacle", "primitive")},
  };
  for (const Enumerated& e : enumerated) {
    Json scene = case_scene(e.case_name);
    scene[Json::json_pointer(e.pointer)] = "zz_unknown";
    const std::string message = load_error(scene);
    EXPECT_NE(message.find(": " + e.key_path + ": unknown "), std::string::npos) << e.key_path << ": " << message;
    EXPECT_EQ(allowed_in(message), e.schema) << e.key_path << ": " << message;
  }
  // The two lists that live in code elsewhere, directly.
  const std::vector<std::string> presets = material_preset_names(), methods = discretization_methods();
  EXPECT_EQ(schema_values(defs["material"]["properties"]["preset"]), std::set<std::string>(presets.begin(), presets.end()));
  EXPECT_EQ(schema_values(schema()["properties"]["method"]), std::set<std::string>(methods.begin(), methods.end()));
}

TEST(SceneSchema, DefaultsInTheSchemaAreTheLoadersDefaults) {
  // A few defaults that a user reads from an editor's hover: those of the loader.
  const Scene s = load_scene_text(R"({"analysis": "dynamic", "material": {"preset": "cotton"},
      "mesh": {"primitive": "grid", "size": [1, 1], "divisions": [2, 2]}})",
                                  kSource / "scenes/case.json", nullptr);
  const Json& defs = schema()["$defs"];
  EXPECT_EQ(defs["time"]["properties"]["dt"]["default"].get<double>(), s.problem.time.dt);
  EXPECT_EQ(defs["time"]["properties"]["end"]["default"].get<double>(), s.problem.time.end);
  EXPECT_EQ(defs["time"]["properties"]["output_fps"]["default"].get<double>(), s.problem.time.output_fps);
  EXPECT_EQ(defs["solver"]["properties"]["tolerance"]["default"].get<double>(), s.problem.solver.tolerance);
  EXPECT_EQ(defs["solver"]["properties"]["max_iterations"]["default"].get<int>(), s.problem.solver.max_iterations);
  EXPECT_EQ(defs["solver"]["properties"]["refresh_iterations"]["default"].get<int>(), s.problem.solver.refresh_iterations);
  EXPECT_EQ(defs["collision"]["properties"]["thickness"]["default"].get<double>(), s.problem.collision.thickness);
  EXPECT_EQ(defs["collision"]["properties"]["friction"]["default"].get<double>(), s.problem.collision.friction);
  EXPECT_EQ(defs["collision"]["properties"]["tolerance"]["default"].get<double>(), s.problem.collision.tolerance);
  EXPECT_EQ(defs["render"]["properties"]["width"]["default"].get<int>(), s.render.width);
  EXPECT_EQ(defs["render"]["properties"]["height"]["default"].get<int>(), s.render.height);
  EXPECT_EQ(defs["render"]["properties"]["refine"]["default"].get<int>(), s.render.refine);
  EXPECT_EQ(defs["mesh_grid"]["properties"]["max_vertices"]["default"].get<long long>(), kDefaultMaxVertices);
}

}  // namespace
}  // namespace clothsim

// What the libFuzzer targets in fuzz/ do with one input, shared with the regression test
// (tests/fuzz/fuzz_regression_test.cpp), which replays the inputs in fuzz/regressions/ in every
// build. A function returns normally when the input was handled as documented (read, or refused
// with the documented exception); anything else — a crash, a sanitizer report, another exception
// escaping — is a finding.
#pragma once

#include "sim/mesh/obj_io.hpp"
#include "sim/scene/scene.hpp"

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace clothsim::fuzz {

// The OBJ reader on `text`: a mesh whose triangles index its vertices, or a MeshError (any other
// exception escapes).
inline void run_obj_input(std::string_view text) {
  try {
    const TriMesh mesh = read_obj_text(text, "fuzz.obj");
    for (const Triangle& t : mesh.triangles)
      for (const int v : t)
        if (v < 0 || v >= mesh.num_vertices()) std::abort();  // read_obj promised a valid mesh
  } catch (const MeshError&) {
  }
}

// The OBJ files a fuzzed scene may name ("mesh": {"obj": ...}, obstacles' "obj"), all in the
// scene's folder: a valid 4 x 4 vertex grid, a closed tetrahedron, a file read_obj refuses, and a
// name that does not exist.
inline constexpr const char* kSceneObjFiles[] = {"mesh.obj", "obstacle.obj", "broken.obj", "missing.obj"};

// Writes the OBJ files of kSceneObjFiles into `dir` (which must exist).
inline void write_scene_obj_files(const std::filesystem::path& dir) {
  std::string grid;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) grid += "v " + std::to_string(i / 3.0 - 0.5) + " " + std::to_string(j / 3.0 - 0.5) + " 0\n";
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      const int a = 4 * j + i + 1, b = a + 1, c = a + 5, d = a + 4;
      grid += "f " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(c) + "\n";
      grid += "f " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(d) + "\n";
    }
  std::ofstream(dir / kSceneObjFiles[0]) << grid;
  std::ofstream(dir / kSceneObjFiles[1]) << "v 0 0 0\nv 0.2 0 0\nv 0 0.2 0\nv 0 0 0.2\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  std::ofstream(dir / kSceneObjFiles[2]) << "v 0 0 0\nv 1 0 0\nf 1 2 3\n";
}

// Replaces, everywhere in `j`, the string value of a key "obj" that is not one of kSceneObjFiles
// by kSceneObjFiles[0]. Returns whether anything was replaced.
inline bool confine_obj_names(nlohmann::json& j) {
  bool changed = false;
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (it.key() == "obj" && it->is_string()) {
        bool allowed = false;
        for (const char* name : kSceneObjFiles) allowed = allowed || it->get_ref<const std::string&>() == name;
        if (!allowed) {
          *it = kSceneObjFiles[0];
          changed = true;
        }
      }
      changed = confine_obj_names(*it) || changed;
    }
  } else if (j.is_array()) {
    for (nlohmann::json& item : j) changed = confine_obj_names(item) || changed;
  }
  return changed;
}

// The vertex limit a fuzzed scene runs with: a scene that gives no mesh.max_vertices, or a larger
// one, gets this. A scene may raise its limit as far as it likes, and a mesh of that size is then
// what it asked for, not a bug; and under the sanitizers even the default limit (a million
// vertices) takes 19 s and 1.2 GB to load (docs/fuzzing.md), a third of the fuzzer's minute.
// 10 000 vertices load in a fraction of a second.
inline constexpr long long kFuzzMaxVertices = 10'000;

// Gives the object "mesh" of `j`, if there is one, mesh.max_vertices = kFuzzMaxVertices unless it
// has a smaller number there, or a value that is not a number (which the loader refuses).
inline void confine_max_vertices(nlohmann::json& j) {
  if (!j.is_object() || !j.contains("mesh") || !j["mesh"].is_object()) return;
  nlohmann::json& mesh = j["mesh"];
  if (mesh.contains("max_vertices")) {
    const nlohmann::json& given = mesh["max_vertices"];
    if (!given.is_number() || given.get<double>() <= static_cast<double>(kFuzzMaxVertices)) return;
  }
  mesh["max_vertices"] = kFuzzMaxVertices;
}

// Parses `text` as the loader does, or gives a discarded value if it is not JSON or repeats a key
// in an object (the loader refuses both before it reads anything else).
inline nlohmann::json parse_without_duplicates(const std::string& text) {
  std::vector<std::set<std::string>> keys;  // of the objects being parsed
  bool duplicate = false;
  nlohmann::json j = nlohmann::json::parse(
      text,
      [&keys, &duplicate](int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
        using E = nlohmann::json::parse_event_t;
        if (event == E::object_start) keys.emplace_back();
        if (event == E::object_end && !keys.empty()) keys.pop_back();
        if (event == E::key && !keys.empty() && !keys.back().insert(parsed.get<std::string>()).second)
          duplicate = true;
        return true;
      },
      /*allow_exceptions=*/false);
  return duplicate ? nlohmann::json(nlohmann::json::value_t::discarded) : j;
}

// The scene loader on `input` as the file `dir`/scene.json (`dir` holds write_scene_obj_files'
// files): a scene, or a SceneError (any other exception escapes). A text that parses as JSON (and
// repeats no key) is loaded as the loader would see it after two changes: OBJ names other than
// those in `dir` replaced (confine_obj_names, so that a fuzzed scene reads no other file), and
// the vertex limit set to kFuzzMaxVertices (confine_max_vertices). Any other text is loaded as it
// is: the loader refuses it before it reads a file or builds a mesh.
inline void run_scene_input(std::string_view input, const std::filesystem::path& dir) {
  std::string text(input);
  nlohmann::json j = parse_without_duplicates(text);
  if (!j.is_discarded()) {
    confine_obj_names(j);
    confine_max_vertices(j);
    text = j.dump();
  }
  try {
    const Scene scene = load_scene_text(text, dir / "scene.json", [](const std::string&) {});
  } catch (const SceneError&) {
  }
}

}  // namespace clothsim::fuzz

// The fuzz targets' per-input code (fuzz/fuzz_inputs.hpp) in every build: the inputs the fuzzers
// once failed on (fuzz/regressions/) replayed, the hand-written seed scenes load (or fail) as
// meant, and a fuzzed scene cannot make the loader read a file outside its folder or lift the
// vertex limit. Under the sanitize preset a replayed input that still fails is a sanitizer
// report; in any build an exception other than the documented one fails the test.
#include "fuzz/fuzz_inputs.hpp"

#include "sim/contact/obstacle.hpp"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

const fs::path kFuzzDir = fs::path(CLOTHSIM_SOURCE_DIR) / "fuzz";

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The files in `dir` (none if it does not exist), sorted.
std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

class FuzzInputs : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "clothsim_fuzz_test_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    fuzz::write_scene_obj_files(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

TEST_F(FuzzInputs, RegressionInputsAreHandled) {
  int replayed = 0;
  for (const fs::path& file : files_in(kFuzzDir / "regressions" / "obj")) {
    SCOPED_TRACE(file.string());
    EXPECT_NO_THROW(fuzz::run_obj_input(read_file(file)));
    ++replayed;
  }
  for (const fs::path& file : files_in(kFuzzDir / "regressions" / "scene")) {
    SCOPED_TRACE(file.string());
    EXPECT_NO_THROW(fuzz::run_scene_input(read_file(file), dir_));
    ++replayed;
  }
  std::cout << "replayed " << replayed << " fuzz regression inputs\n";
}

TEST_F(FuzzInputs, SceneObjFilesAreWhatTheirNamesSay) {
  EXPECT_EQ(read_obj((dir_ / "mesh.obj").string()).num_vertices(), 16);
  EXPECT_EQ(read_obj((dir_ / "mesh.obj").string()).num_triangles(), 18);
  EXPECT_EQ(read_obj((dir_ / "obstacle.obj").string()).num_triangles(), 4);
  EXPECT_THROW(read_obj((dir_ / "broken.obj").string()), MeshError);
  EXPECT_FALSE(fs::exists(dir_ / "missing.obj"));
}

TEST_F(FuzzInputs, SeedScenesLoadOrFailAsMeant) {
  const fs::path seeds = kFuzzDir / "seeds" / "scene";
  for (const char* name : {"obj_mesh_and_obstacle.json", "cylinder_static.json"}) {
    SCOPED_TRACE(name);
    const Scene scene = load_scene_text(read_file(seeds / name), dir_ / "scene.json", nullptr);
    EXPECT_GT(scene.problem.mesh.num_vertices(), 0);
  }
  for (const auto& [name, file] : {std::pair{"obj_broken.json", "broken.obj"}, std::pair{"obj_missing_obstacle.json", "missing.obj"}}) {
    SCOPED_TRACE(name);
    try {
      load_scene_text(read_file(seeds / name), dir_ / "scene.json", nullptr);
      ADD_FAILURE() << "loaded";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    }
  }
}

TEST(FuzzConfinement, ObjNamesOutsideTheFolderAreReplaced) {
  nlohmann::json j = nlohmann::json::parse(R"({"mesh": {"obj": "/dev/zero"}, "obstacles": [{"obj": "../../x.obj"},
      {"obj": "obstacle.obj"}, {"obj": 3}], "output": {"obj": true}})");
  EXPECT_TRUE(fuzz::confine_obj_names(j));
  EXPECT_EQ(j["mesh"]["obj"], "mesh.obj");
  EXPECT_EQ(j["obstacles"][0]["obj"], "mesh.obj");
  EXPECT_EQ(j["obstacles"][1]["obj"], "obstacle.obj");
  EXPECT_EQ(j["obstacles"][2]["obj"], 3);  // not a name: the loader refuses it
  EXPECT_EQ(j["output"]["obj"], true);
  EXPECT_FALSE(fuzz::confine_obj_names(j));  // nothing left to replace
}

TEST(FuzzConfinement, VertexLimitIsTheFuzzLimitAtMost) {
  nlohmann::json j = nlohmann::json::parse(R"({"mesh": {"primitive": "grid", "max_vertices": 1e12}})");
  fuzz::confine_max_vertices(j);
  EXPECT_EQ(j["mesh"]["max_vertices"], fuzz::kFuzzMaxVertices);
  j["mesh"].erase("max_vertices");
  fuzz::confine_max_vertices(j);
  EXPECT_EQ(j["mesh"]["max_vertices"], fuzz::kFuzzMaxVertices);
  j["mesh"]["max_vertices"] = 500;
  fuzz::confine_max_vertices(j);
  EXPECT_EQ(j["mesh"]["max_vertices"], 500);
  j["mesh"]["max_vertices"] = "many";  // the loader's error to give
  fuzz::confine_max_vertices(j);
  EXPECT_EQ(j["mesh"]["max_vertices"], "many");
  nlohmann::json no_mesh = nlohmann::json::parse(R"({"mesh": 3})");
  fuzz::confine_max_vertices(no_mesh);
  EXPECT_EQ(no_mesh["mesh"], 3);
}

// A grid above the fuzz limit is refused (a SceneError, so run_scene_input returns), and a
// repeated key leaves the text as it is, so the loader's duplicate-key error is reached.
TEST_F(FuzzInputs, LargeMeshesAndRepeatedKeys) {
  const std::string big = R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [999, 999], "max_vertices": 2000000}})";
  EXPECT_NO_THROW(fuzz::run_scene_input(big, dir_));
  nlohmann::json j = nlohmann::json::parse(big);
  fuzz::confine_max_vertices(j);
  try {
    load_scene_text(j.dump(), dir_ / "scene.json", nullptr);
    ADD_FAILURE() << "loaded";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("mesh.max_vertices"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fuzz::parse_without_duplicates(R"({"a": {"b": 1, "b": 2}})").is_discarded());
  EXPECT_TRUE(fuzz::parse_without_duplicates(R"({"a": 1,)").is_discarded());
  EXPECT_FALSE(fuzz::parse_without_duplicates(R"({"a": {"b": 1}, "c": {"b": 2}})").is_discarded());
}

// A scene that names a file outside the folder reads the folder's mesh.obj instead (its 16
// vertices, as the loader's log says), not /dev/zero.
TEST_F(FuzzInputs, FuzzedSceneReadsOnlyItsFolder) {
  const std::string text = R"({"mesh": {"obj": "/dev/zero"}})";
  EXPECT_NO_THROW(fuzz::run_scene_input(text, dir_));
  nlohmann::json j = nlohmann::json::parse(text);
  ASSERT_TRUE(fuzz::confine_obj_names(j));
  std::string log;
  load_scene_text(j.dump(), dir_ / "scene.json", [&log](const std::string& line) { log += line + "\n"; });
  EXPECT_NE(log.find("mesh: " + (dir_ / "mesh.obj").string() + ": 16 vertices, 18 triangles"), std::string::npos) << log;
}

TEST(FuzzObjInput, ReadErrorsAreMeshErrors) {
  EXPECT_NO_THROW(fuzz::run_obj_input("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_NO_THROW(fuzz::run_obj_input("f 1 2 3\n"));
  EXPECT_NO_THROW(fuzz::run_obj_input(std::string("v 0 0 0\0\n", 9)));
  EXPECT_THROW(read_obj_text("v 0 0 0\nv 1 0 0\nf 1 2 3\n", "x.obj"), MeshError);
}

// fuzz_scene's first finding (fuzz/regressions/scene/capsule_length_1e120.json): a capsule
// 8.9e119 m long asked for 2.9e122 rings along its side, converted to int before it was clamped
// to 200 (UBSan: float-cast-overflow; without the sanitizer the count came out as INT_MIN,
// clamped to 1 ring). Any capsule longer than 800 segment lengths (rings are 4 apart) has 200.
TEST(FuzzFindings, VeryLongCapsuleHasTheMostRingsNotOne) {
  Obstacle capsule;
  capsule.shape = Obstacle::Shape::capsule;
  capsule.radius = 0.035;
  capsule.from = Eigen::Vector3d(0, -0.05, 0);
  capsule.to = Eigen::Vector3d(1000, 0.32, 0);
  const int rings_200 = tessellate(capsule).num_triangles();
  capsule.to = Eigen::Vector3d(8.9e119, 0.32, 0);
  EXPECT_EQ(tessellate(capsule).num_triangles(), rings_200);
  capsule.to = Eigen::Vector3d(0.2, -0.05, 0);  // a short one has fewer
  EXPECT_LT(tessellate(capsule).num_triangles(), rings_200);
}

// fuzz_scene's second finding (fuzz/regressions/scene/long_string_cut_inside_a_character.json): a
// scene that is a string longer than 40 bytes is described by its first 40 bytes, and when byte
// 40 fell inside a UTF-8 character, quoting that cut string threw nlohmann's type_error 316
// instead of the SceneError. The same for a file name that is not UTF-8, quoted when it is not a
// safe scene name.
TEST_F(FuzzInputs, MessagesQuoteBytesThatAreNotUtf8) {
  const std::string cut = "\"" + std::string(39, 'a') + "\u0651 and more\"";  // U+0651: bytes 40 and 41
  try {
    load_scene_text(cut, dir_ / "scene.json", nullptr);
    ADD_FAILURE() << "loaded";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("expected a JSON object at the top level"), std::string::npos) << e.what();
  }
  try {
    load_scene_text(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [2, 2]}})", dir_ / "\xff\xfe.json", nullptr);
    ADD_FAILURE() << "loaded";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("is not a safe folder name"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace clothsim

// The clothsim command: runs the built binary on scenes written to a fresh temporary folder and
// checks exit codes, error messages, and that failed runs leave no output behind.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <stdlib.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct RunResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

const char* const kGridPlate = R"({
  "name": "plate",
  "mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [8, 8]},
  "material": {"youngs_modulus": 1e7, "poisson_ratio": 0.3, "thickness": 0.01},
  "boundary": [
    {"select": {"box": [[-0.51, -0.51, -1], [0.51, -0.49, 1]]}},
    {"select": {"box": [[-0.51, 0.49, -1], [0.51, 0.51, 1]]}},
    {"select": {"box": [[-0.51, -0.51, -1], [-0.49, 0.51, 1]]}},
    {"select": {"box": [[0.49, -0.51, -1], [0.51, 0.51, 1]]}}
  ],
  "loads": {"surface_load": [0, 0, -1]},
  "probes": [{"name": "center", "at": [0, 0, 0]}, {"name": "edge", "at": [0.5, 0, 0]}]
})";

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "clothsim_cli_test_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    out_ = dir_ / "out";
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    std::ofstream(path) << text;
    return path;
  }

  // Runs `clothsim <args>` with stdout and stderr captured.
  RunResult run(const std::string& args) const {
    const fs::path out_file = dir_ / "stdout.txt";
    const fs::path err_file = dir_ / "stderr.txt";
    const std::string command = shell_quote(CLOTHSIM_BINARY) + " " + args + " >" + shell_quote(out_file.string()) +
                                " 2>" + shell_quote(err_file.string());
    const int status = std::system(command.c_str());
    RunResult r;
    r.exit_code = (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
    r.out = read_text(out_file);
    r.err = read_text(err_file);
    return r;
  }

  RunResult run_scene(const fs::path& scene) const {
    return run(shell_quote(scene.string()) + " --out " + shell_quote(out_.string()));
  }

  // A failed run: non-zero exit, "clothsim: error: " naming every part in `parts`, no output root.
  void expect_failure(const RunResult& r, const std::vector<std::string>& parts) const {
    EXPECT_NE(r.exit_code, 0);
    EXPECT_TRUE(contains(r.err, "clothsim: error: ")) << r.err;
    for (const std::string& part : parts) EXPECT_TRUE(contains(r.err, part)) << "missing \"" << part << "\" in: " << r.err;
    EXPECT_FALSE(fs::exists(out_)) << "output root was created";
  }

  fs::path dir_;
  fs::path out_;
};

TEST_F(CliTest, HelpExitsZero) {
  const RunResult r = run("--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_TRUE(contains(r.out, "--out")) << r.out;
  EXPECT_TRUE(contains(r.out, "SCENE")) << r.out;
}

TEST_F(CliTest, NoArgumentsFails) {
  const RunResult r = run("");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.err, "clothsim: error: ")) << r.err;
}

TEST_F(CliTest, MissingSceneFileFails) {
  const fs::path scene = dir_ / "does_not_exist.json";
  expect_failure(run_scene(scene), {scene.string()});
}

TEST_F(CliTest, MalformedJsonFails) {
  const fs::path scene = write("bad.json", "{\"mesh\": {\"primitive\": \"grid\",,}}");
  expect_failure(run_scene(scene), {scene.string() + ": malformed JSON", "line 1"});
}

TEST_F(CliTest, UnknownKeyFails) {
  const fs::path scene = write("unknown.json", R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4]},
      "loads": {"gravty": [0, 0, -9.81]}})");
  expect_failure(run_scene(scene), {scene.string() + ": loads.gravty: unknown key", "gravity"});
}

TEST_F(CliTest, MissingMeshFileFails) {
  const fs::path scene = write("missing_mesh.json", R"({"mesh": {"obj": "missing.obj"}})");
  expect_failure(run_scene(scene), {scene.string() + ": mesh.obj: ", "missing.obj"});
}

TEST_F(CliTest, NonManifoldObjFails) {
  // Three triangles share the edge 1-2.
  write("fin.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
  const fs::path scene = write("fin.json", R"({"mesh": {"obj": "fin.obj"}})");
  expect_failure(run_scene(scene), {scene.string() + ": mesh.obj: ", "fin.obj"});
}

TEST_F(CliTest, NegativeThicknessFails) {
  const fs::path scene = write("thin.json", R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4]},
      "material": {"thickness": -0.01}})");
  expect_failure(run_scene(scene), {scene.string() + ": material.thickness: must be > 0 [m] (got -0.01)"});
}

TEST_F(CliTest, FailedRunLeavesExistingOutputAlone) {
  fs::create_directories(out_ / "thin");
  std::ofstream(out_ / "thin" / "keep.txt") << "old";
  const fs::path scene = write("thin.json", R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4]},
      "material": {"thickness": -0.01}})");
  const RunResult r = run_scene(scene);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(fs::exists(out_ / "thin" / "keep.txt"));
  int entries = 0;
  for (const auto& e : fs::directory_iterator(out_)) {
    (void)e;
    ++entries;
  }
  EXPECT_EQ(entries, 1);
}

TEST_F(CliTest, StaticRunWritesOutputs) {
  const fs::path scene = write("plate.json", kGridPlate);
  // An older result folder is replaced as a whole.
  fs::create_directories(out_ / "plate");
  std::ofstream(out_ / "plate" / "stale.txt") << "old";

  const RunResult r = run_scene(scene);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "center")) << r.out;
  const fs::path result_dir = out_ / "plate";
  EXPECT_FALSE(fs::exists(result_dir / "stale.txt"));
  ASSERT_TRUE(fs::exists(result_dir / "result.json"));
  ASSERT_TRUE(fs::exists(result_dir / "limit.obj"));
  for (const auto& e : fs::directory_iterator(out_))
    EXPECT_NE(e.path().filename().string().front(), '.') << "left behind: " << e.path();

  const nlohmann::json j = nlohmann::json::parse(read_text(result_dir / "result.json"));
  ASSERT_TRUE(j.contains("probes"));
  for (const std::string name : {"center", "edge"}) {
    ASSERT_TRUE(j["probes"].contains(name)) << j.dump();
    const nlohmann::json& p = j["probes"][name];
    EXPECT_TRUE(p["vertex"].is_number_integer());
    ASSERT_TRUE(p["rest_position"].is_array());
    ASSERT_TRUE(p["displacement"].is_array());
    EXPECT_EQ(p["rest_position"].size(), 3u);
    EXPECT_EQ(p["displacement"].size(), 3u);
  }
  EXPECT_NEAR(j["probes"]["center"]["rest_position"][0].get<double>(), 0.0, 1e-9);
  EXPECT_LT(j["probes"]["center"]["displacement"][2].get<double>(), 0.0);  // sags under the downward load
  EXPECT_TRUE(j["vertices"].is_number_integer());
  EXPECT_GE(j["vertices"].get<int>(), 81);
  EXPECT_TRUE(j["dofs"].is_number_integer());
  EXPECT_GT(j["dofs"].get<int>(), 0);
  EXPECT_LT(j["dofs"].get<int>(), 3 * j["vertices"].get<int>());
  EXPECT_TRUE(j["seconds"]["assemble"].is_number());
  EXPECT_TRUE(j["seconds"]["solve"].is_number());

  // limit.obj has one vertex line per control vertex.
  std::istringstream obj(read_text(result_dir / "limit.obj"));
  int vertex_lines = 0;
  for (std::string line; std::getline(obj, line);) vertex_lines += line.rfind("v ", 0) == 0 ? 1 : 0;
  EXPECT_EQ(vertex_lines, j["vertices"].get<int>());
}

}  // namespace

// The clothsim command: runs the built binary on scenes written to a fresh temporary folder and
// checks exit codes, error messages, that invalid input leaves no output behind, and the streamed
// outputs of dynamic runs (also when they fail part-way).
#include "render/png_io.hpp"
#include "sim/solver/linear_solver.hpp"

#include "tests/support/process.hpp"

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

std::string read_text(const fs::path& path) { return clothsim::testing::read_file_bytes(path); }
using clothsim::testing::shell_quote;

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

// A 0.2 m × 0.2 m cloth (4 × 4 cells, 25 vertices) pinned along its edge y = +0.1 m, falling
// under gravity for 10 steps of 1 ms; frames at 500 fps (t = 0, 2, 4, 6, 8, 10 ms).
const char* const kFallingCloth = R"({
  "name": "cloth",
  "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "cotton"},
  "boundary": [{"select": {"box": [[-0.11, 0.09, -1], [0.11, 0.11, 1]]}, "fix": ["x", "y", "z"]}],
  "loads": {"gravity": [0, 0, -9.81]},
  "time": {"dt": 0.001, "end": 0.01, "output_fps": 500},
  "damping": {"stiffness": 0.001},
  "probes": [{"name": "free_edge", "at": [0, -0.1, 0]}, {"name": "corner", "at": [0.1, -0.1, 0]}],
  "output": {"obj": true}
})";

// A free sheet thrown at 1 km/s: 100 m per step of 0.1 s, so step 3 takes it past 1000 times its
// size (0.28 m) and the run stops as diverged. (A conjugate gradient solver that cannot converge
// no longer stops a run: the direct solver finishes the solve.)
const char* const kFailingCloth = R"({
  "name": "stiff",
  "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "metal"},
  "initial": {"velocity": [0, 0, 1000]},
  "loads": {"gravity": [0, 0, -9.81]},
  "time": {"dt": 0.1, "end": 1.0},
  "probes": [{"name": "free_edge", "at": [0, -0.1, 0]}],
  "output": {"obj": true}
})";

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> fields;
  std::istringstream in(line);
  for (std::string field; std::getline(in, field, ',');) fields.push_back(field);
  return fields;
}

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

TEST_F(CliTest, VersionPrintsTheProjectVersion) {
  const RunResult r = run("--version");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "clothsim " CLOTHSIM_TEST_VERSION "\n");
}

// Regression: `clothsim render --size 64x48abc` was accepted while a normal run refused it.
TEST_F(CliTest, RenderRefusesTrailingCharactersInSize) {
  const RunResult r = run("render " + shell_quote(dir_.string()) + " --size 64x48abc");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "--size: expected WxH with 16 <= W, H <= 8192 (got \"64x48abc\")")) << r.err;
}

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

TEST_F(CliTest, DynamicRunWritesOutputs) {
  const fs::path scene = write("cloth.json", kFallingCloth);
  fs::create_directories(out_ / "cloth");
  std::ofstream(out_ / "cloth" / "stale.txt") << "old";

  const RunResult r = run_scene(scene);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "free_edge")) << r.out;
  EXPECT_TRUE(contains(r.err, "step 10/10")) << r.err;  // progress lines
  const fs::path dir = out_ / "cloth";
  EXPECT_FALSE(fs::exists(dir / "stale.txt"));
  for (const auto& e : fs::directory_iterator(out_))
    EXPECT_NE(e.path().filename().string().front(), '.') << "left behind: " << e.path();
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_NE(e.path().filename().string().front(), '.') << "left behind: " << e.path();

  // probes.csv: 11 states (steps 0..10) × 2 probes.
  const std::vector<std::string> probes = lines_of(read_text(dir / "probes.csv"));
  ASSERT_EQ(probes.size(), 1u + 11u * 2u);
  EXPECT_EQ(probes[0], "step,t,name,ux,uy,uz");
  EXPECT_EQ(probes[1], "0,0,free_edge,0,0,0");
  EXPECT_EQ(probes[2], "0,0,corner,0,0,0");
  for (std::size_t i = 1; i < probes.size(); ++i) {
    const std::vector<std::string> f = split_csv(probes[i]);
    ASSERT_EQ(f.size(), 6u) << probes[i];
    EXPECT_EQ(std::stoi(f[0]), static_cast<int>((i - 1) / 2));
    EXPECT_NEAR(std::stod(f[1]), 0.001 * std::stoi(f[0]), 1e-12);
    EXPECT_EQ(f[2], i % 2 == 1 ? "free_edge" : "corner");
  }
  const std::vector<std::string> last = split_csv(probes[probes.size() - 2]);
  EXPECT_EQ(last[0], "10");
  EXPECT_LT(std::stod(last[5]), -1e-5);  // the free edge falls (½ g t² ≈ 4.9e-4 m without stiffness)

  // stats.csv: one row per step.
  const std::vector<std::string> stats = lines_of(read_text(dir / "stats.csv"));
  ASSERT_EQ(stats.size(), 11u);
  EXPECT_EQ(stats[0], "step,t,solver_iterations,residual,rotate_ms,assemble_ms,solve_ms,kinetic_energy,elastic_energy,external_work,boundary_work,factorizations,factor_ms,direct_fallbacks");
  double work = 0.0;  // cumulative work of the loads and supports
  for (std::size_t i = 1; i < stats.size(); ++i) {
    const std::vector<std::string> f = split_csv(stats[i]);
    ASSERT_EQ(f.size(), 14u) << stats[i];
    EXPECT_EQ(f[13], "0");  // no direct fallbacks
    work += std::stod(f[9]) + std::stod(f[10]);
    EXPECT_EQ(std::stoi(f[0]), static_cast<int>(i));
    EXPECT_GE(std::stoi(f[2]), 1);
    EXPECT_GT(std::stod(f[7]), 0.0);   // kinetic energy of the falling cloth
    EXPECT_GT(std::stod(f[9]), 0.0);   // gravity does work on it
    EXPECT_LE(std::stod(f[7]) + std::stod(f[8]), 1.001 * work);  // implicit Euler only dissipates
  }

  // Frames at t = 0, 2, ..., 10 ms, each with one vertex per control vertex.
  for (int k = 0; k <= 5; ++k) {
    const fs::path frame = dir / "frames" / ("mesh_000" + std::to_string(k) + ".obj");
    ASSERT_TRUE(fs::exists(frame)) << frame;
    int vertex_lines = 0, face_lines = 0;
    for (const std::string& line : lines_of(read_text(frame))) {
      vertex_lines += line.rfind("v ", 0) == 0 ? 1 : 0;
      face_lines += line.rfind("f ", 0) == 0 ? 1 : 0;
    }
    EXPECT_EQ(vertex_lines, 25);
    EXPECT_EQ(face_lines, 32);
  }
  EXPECT_FALSE(fs::exists(dir / "frames" / "mesh_0006.obj"));

  const nlohmann::json j = nlohmann::json::parse(read_text(dir / "summary.json"));
  EXPECT_EQ(j["scene"], "cloth");
  EXPECT_EQ(j["analysis"], "dynamic");
  EXPECT_EQ(j["status"], "completed");
  EXPECT_FALSE(j.contains("error"));
  EXPECT_EQ(j["steps"], 10);
  EXPECT_NEAR(j["simulated_time"].get<double>(), 0.01, 1e-12);
  EXPECT_EQ(j["frames"], 6);
  EXPECT_GE(j["max_solver_iterations"].get<int>(), 1);
  // The scene names no solver: both choices were automatic, and the summary says what they were.
  EXPECT_EQ(j["solver"]["type"], "pcg");
  EXPECT_EQ(j["solver"]["preconditioner"], "cholesky");
  EXPECT_EQ(j["solver"]["tolerance"].get<double>(), clothsim::LinearSolverSettings().tolerance);
  EXPECT_EQ(j["solver"]["chosen_automatically"], nlohmann::json::array({"type", "preconditioner"}));
  EXPECT_TRUE(j["wall_seconds"].is_number());
  for (const std::string part : {"rotate", "assemble", "solve"}) EXPECT_TRUE(j["seconds"][part].is_number()) << part;
  EXPECT_TRUE(j["warnings"].is_array());

  // Deterministic: a second run writes the same probes.csv and frames.
  const RunResult again = run(shell_quote(scene.string()) + " --out " + shell_quote((dir_ / "again").string()));
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(read_text(dir_ / "again" / "cloth" / "probes.csv"), read_text(dir / "probes.csv"));
  EXPECT_EQ(read_text(dir_ / "again" / "cloth" / "frames" / "mesh_0005.obj"), read_text(dir / "frames" / "mesh_0005.obj"));
}

TEST_F(CliTest, DynamicEndOptionShortensRun) {
  const fs::path scene = write("cloth.json", kFallingCloth);
  const RunResult r = run(shell_quote(scene.string()) + " --out " + shell_quote(out_.string()) + " --end 0.004");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines_of(read_text(out_ / "cloth" / "stats.csv")).size(), 5u);
  EXPECT_EQ(lines_of(read_text(out_ / "cloth" / "probes.csv")).size(), 1u + 5u * 2u);
  const nlohmann::json j = nlohmann::json::parse(read_text(out_ / "cloth" / "summary.json"));
  EXPECT_EQ(j["steps"], 4);
  EXPECT_EQ(j["frames"], 3);
}

TEST_F(CliTest, DynamicInvalidInputWritesNothing) {
  const fs::path scene = write("cloth.json", kFallingCloth);
  expect_failure(run(shell_quote(scene.string()) + " --out " + shell_quote(out_.string()) + " --end 0"),
                 {"--end: must be a finite number > 0 [s] (got 0.0)"});
  expect_failure(run(shell_quote(scene.string()) + " --out " + shell_quote(out_.string()) + " --end 0.0001"),
                 {"--end: must be >= time.dt = 0.001 [s] (got 0.0001)"});
  const fs::path plate = write("plate.json", kGridPlate);
  expect_failure(run(shell_quote(plate.string()) + " --out " + shell_quote(out_.string()) + " --end 1"),
                 {"--end: only applies to dynamic scenes"});
  // Step and frame counts beyond the limits (they once overflowed int and ran -2147483648 steps).
  expect_failure(run(shell_quote(scene.string()) + " --out " + shell_quote(out_.string()) + " --end 3e6"),
                 {"--end: time.end / time.dt = 3000000.0 / 0.001 needs 3000000000 steps, more than the limit of 100000000"});
  expect_failure(run(shell_quote(scene.string()) + " --out " + shell_quote(out_.string()) + " --frames 2147483647"),
                 {"--frames: time.end / time.dt", "more than the limit of 100000000"});
  const fs::path bad = write("bad_dt.json", R"({"analysis": "dynamic",
      "mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4]}, "time": {"dt": -0.01}})");
  expect_failure(run_scene(bad), {bad.string() + ": time.dt: must be > 0 [s] (got -0.01)"});
  const fs::path motion = write("bad_motion.json", R"({"analysis": "dynamic",
      "mesh": {"primitive": "grid", "size": [1, 1], "divisions": [4, 4]},
      "boundary": [{"select": {"box": [[-1, -1, -1], [1, 1, 1]]}, "motion": [{"type": "rotate", "start": 0, "end": 1}]}]})");
  expect_failure(run_scene(motion), {motion.string() + ": boundary[0].motion[0].axis: required key is missing"});
}

// A conjugate gradient solver allowed one iteration towards 1e-14 on a stiff sheet with a huge
// step fails every solve; the direct solver finishes each (LinearSolver::solve), so the run
// completes, with a warning naming the step and time for each, a count in stats.csv and a
// summary.json warning listing the steps.
TEST_F(CliTest, FailedPcgSolvesFallBackToTheDirectSolver) {
  const fs::path scene = write("stiff_pcg.json", R"({
  "name": "stiff_pcg",
  "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "metal"},
  "boundary": [{"select": {"box": [[-0.11, 0.09, -1], [0.11, 0.11, 1]]}}],
  "loads": {"gravity": [0, 0, -9.81]},
  "time": {"dt": 0.1, "end": 0.3},
  "solver": {"type": "pcg", "max_iterations": 1, "tolerance": 1e-14},
  "probes": [{"name": "free_edge", "at": [0, -0.1, 0]}]
})");
  const RunResult r = run_scene(scene);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* step : {"step 1 (t = 0.1 s)", "step 2 (t = 0.2 s)", "step 3 (t = 0.3 s)"})
    EXPECT_TRUE(contains(r.err, std::string("clothsim: warning: ") + step +
                                    ": 1 linear solve(s) fell back to the direct solver (CHOLMOD), which solved them: "
                                    "the conjugate gradient solver did not converge"))
        << step << "\n" << r.err;
  const std::vector<std::string> stats = lines_of(read_text(out_ / "stiff_pcg" / "stats.csv"));
  ASSERT_EQ(stats.size(), 4u);
  for (std::size_t i = 1; i < stats.size(); ++i) EXPECT_EQ(split_csv(stats[i]).at(13), "1") << stats[i];
  const nlohmann::json j = nlohmann::json::parse(read_text(out_ / "stiff_pcg" / "summary.json"));
  EXPECT_EQ(j["status"], "completed");
  bool listed = false;
  for (const auto& w : j["warnings"]) listed = listed || contains(w.get<std::string>(), "(steps 1, 2, 3)");
  EXPECT_TRUE(listed) << j["warnings"].dump();
}

TEST_F(CliTest, DynamicRunFailureKeepsOutputs) {
  const fs::path scene = write("stiff.json", kFailingCloth);
  const RunResult r = run_scene(scene);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "clothsim: error: " + scene.string() + ": step ")) << r.err;
  EXPECT_TRUE(contains(r.err, " s): ")) << r.err;
  const fs::path dir = out_ / "stiff";
  ASSERT_TRUE(fs::exists(dir / "summary.json"));
  ASSERT_TRUE(fs::exists(dir / "probes.csv"));
  ASSERT_TRUE(fs::exists(dir / "stats.csv"));
  ASSERT_TRUE(fs::exists(dir / "frames" / "mesh_0000.obj"));  // the initial state

  const nlohmann::json j = nlohmann::json::parse(read_text(dir / "summary.json"));
  EXPECT_EQ(j["status"], "failed");
  ASSERT_TRUE(j["error"].is_string());
  EXPECT_TRUE(contains(j["error"].get<std::string>(), "step ")) << j["error"];
  const int steps = j["steps"].get<int>();
  EXPECT_EQ(steps, 2);  // step 3 diverges
  EXPECT_EQ(j["frames"].get<int>(), 1 + 3 * steps);  // 30 fps with 0.1 s steps: three frames per step

  // Everything up to the failed step is kept: step 0 and every completed step.
  const std::vector<std::string> probes = lines_of(read_text(dir / "probes.csv"));
  ASSERT_EQ(probes.size(), 1u + static_cast<std::size_t>(steps) + 1u);
  EXPECT_EQ(probes[0], "step,t,name,ux,uy,uz");
  EXPECT_EQ(probes[1], "0,0,free_edge,0,0,0");
  const std::vector<std::string> stats = lines_of(read_text(dir / "stats.csv"));
  ASSERT_EQ(stats.size(), 1u + static_cast<std::size_t>(steps));
  EXPECT_EQ(stats[0], "step,t,solver_iterations,residual,rotate_ms,assemble_ms,solve_ms,kinetic_energy,elastic_energy,external_work,boundary_work,factorizations,factor_ms,direct_fallbacks");
}

TEST_F(CliTest, FramesOptionSizeAndNoRender) {
  const fs::path scene = write("cloth.json", kFallingCloth);
  // --frames 3 at 500 fps: t = 0, 2, 4 ms, one PNG each at the requested size.
  RunResult r = run(shell_quote(scene.string()) + " --out " + shell_quote(out_.string()) + " --frames 3 --size 64x48");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The end --frames chooses is a whole number of steps: no warning about the run's own option.
  EXPECT_FALSE(contains(r.err, "not a multiple of time.dt")) << r.err;
  int pngs = 0;
  for (const auto& e : fs::directory_iterator(out_ / "cloth")) pngs += e.path().extension() == ".png";
  EXPECT_EQ(pngs, 3);
  const clothsim::render::Image image = clothsim::render::read_png((out_ / "cloth" / "frame_0002.png").string());
  EXPECT_EQ(image.width, 64);
  EXPECT_EQ(image.height, 48);
  // --no-render: the same run writes no image.
  r = run(shell_quote(scene.string()) + " --out " + shell_quote(out_.string()) + " --frames 3 --no-render");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const auto& e : fs::directory_iterator(out_ / "cloth")) EXPECT_NE(e.path().extension(), ".png") << e.path();
  // A malformed size is an input error that writes nothing.
  r = run(shell_quote(scene.string()) + " --out " + shell_quote((dir_ / "other").string()) + " --size 64by48");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.err, "--size")) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "other"));
}

TEST_F(CliTest, RenderCommandRedrawsSavedFrames) {
  const fs::path scene = write("cloth.json", kFallingCloth);
  ASSERT_EQ(run(shell_quote(scene.string()) + " --out " + shell_quote(out_.string()) + " --no-render").exit_code, 0);
  const fs::path run_dir = out_ / "cloth";
  RunResult r = run("render " + shell_quote(run_dir.string()) + " --size 80x60");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int objs = 0, pngs = 0;
  for (const auto& e : fs::directory_iterator(run_dir / "frames")) objs += e.path().extension() == ".obj";
  for (const auto& e : fs::directory_iterator(run_dir / "render")) pngs += e.path().extension() == ".png";
  EXPECT_EQ(objs, 6);
  EXPECT_EQ(pngs, objs);
  const clothsim::render::Image image = clothsim::render::read_png((run_dir / "render" / "frame_0005.png").string());
  EXPECT_EQ(image.width, 80);
  // Not plain background: the (red) cloth is in the picture.
  int coloured = 0;
  for (std::size_t i = 0; i + 2 < image.rgb.size(); i += 3) coloured += image.rgb[i] > image.rgb[i + 1] + 40;
  EXPECT_GT(coloured, 50);
  // A folder without saved frames is an error naming it.
  r = run("render " + shell_quote(dir_.string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.err, "frames")) << r.err;
}

// Frames of the refined surface (output.obj_level > 0) are refused by the render command (it
// would subdivide an already refined surface), with a message naming the file and the key.
TEST_F(CliTest, RenderCommandRefusesRefinedFrames) {
  std::string text = kFallingCloth;
  text.replace(text.find(R"("output": {"obj": true})"), std::string(R"("output": {"obj": true})").size(),
               R"("output": {"obj": true, "obj_level": 1})");
  const fs::path scene = write("cloth.json", text);
  ASSERT_EQ(run(shell_quote(scene.string()) + " --out " + shell_quote(out_.string()) + " --no-render").exit_code, 0);
  const RunResult r = run("render " + shell_quote((out_ / "cloth").string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "mesh_0000.obj")) << r.err;
  EXPECT_TRUE(contains(r.err, "obj_level")) << r.err;
  int pngs = 0;
  for (const auto& e : fs::directory_iterator(out_ / "cloth")) pngs += e.path().extension() == ".png";
  EXPECT_EQ(pngs, 0);
}

TEST_F(CliTest, VideoWithoutFfmpegFailsBeforeSimulating) {
  const fs::path scene = write("cloth.json", kFallingCloth);
  // A PATH without ffmpeg (the binary is named by its absolute path).
  const fs::path bin = dir_ / "bin";
  fs::create_directories(bin);
  const std::string command = "PATH=" + shell_quote(bin.string()) + " " + shell_quote(CLOTHSIM_BINARY) + " " +
                              shell_quote(scene.string()) + " --out " + shell_quote((dir_ / "v").string()) +
                              " --frames 4 --video 2>" + shell_quote((dir_ / "err.txt").string());
  EXPECT_EQ(clothsim::testing::run_shell(command), 1);
  const std::string err = read_text(dir_ / "err.txt");
  EXPECT_TRUE(contains(err, "--video: ffmpeg is not installed")) << err;
  EXPECT_FALSE(contains(err, "dynamic analysis:")) << "it simulated first: " << err;
  EXPECT_FALSE(fs::exists(dir_ / "v")) << "an output folder was created";
}

TEST_F(CliTest, VideoOptionEncodesTheFramesWithFfmpeg) {
  if (std::system("command -v ffmpeg > /dev/null 2>&1") != 0) GTEST_SKIP() << "ffmpeg is not installed";
  const fs::path scene = write("cloth.json", kFallingCloth);
  const RunResult r =
      run(shell_quote(scene.string()) + " --out " + shell_quote(out_.string()) + " --frames 4 --size 65x49 --video");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path video = out_ / "cloth" / "cloth.mp4";
  ASSERT_TRUE(fs::exists(video)) << r.err;
  EXPECT_GT(fs::file_size(video), 500u);  // odd sizes are padded for x264
}

}  // namespace

// Output folders stay consistent under concurrent runs, leftovers of killed runs and full disks:
// a second run into a folder that a live run holds is refused naming its PID (the first run's
// outputs stay its own); hidden temporaries of dead runs are removed, those of live ones kept;
// a run that cannot write (file-size limit, standing in for a full disk) fails naming the file,
// records "failed" in summary.json and leaves no temporary or half-written file.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using testing::make_temp_dir;
using testing::read_file_bytes;
using testing::run_shell;
using testing::shell_quote;

// A hanging cloth: 16 x 16 cells, held along one edge, 2 ms steps, OBJ frames at 30 fps.
std::string scene_text(double end) {
  return R"({"name": "hang", "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.3, 0.3], "divisions": [16, 16]},
  "material": {"preset": "cotton"}, "loads": {"gravity": [0, -9.81, 0]},
  "boundary": [{"select": {"box": [[-1, 0.149, -1], [1, 1, 1]]}, "rotation": "free"}],
  "time": {"dt": 0.002, "end": )" +
         std::to_string(end) + R"(, "output_fps": 30}, "damping": {"stiffness": 0.001},
  "probes": [{"name": "corner", "at": [-0.15, -0.15, 0]}],
  "output": {"obj": true}, "render": {"width": 48, "height": 36}})";
}

class OutputSafetyTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = make_temp_dir("clothsim_output_safety_"); }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path write_scene(double end) const {
    const fs::path path = dir_ / "hang.json";
    std::ofstream(path) << scene_text(end);
    return path;
  }
  // Runs `command` through sh with stderr appended to the log; its exit code.
  int sh(const std::string& command) const {
    return run_shell(command + " >/dev/null 2>>" + shell_quote(log_path().string()));
  }
  fs::path log_path() const { return dir_ / "log.txt"; }
  std::string log() const { return read_file_bytes(log_path()); }
  fs::path dir_;
};

// Hidden temporaries (".*tmp*") anywhere under `dir`.
std::vector<std::string> temporaries(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name[0] == '.' && name.find("tmp") != std::string::npos) found.push_back(entry.path().string());
  }
  return found;
}

TEST_F(OutputSafetyTest, ASecondRunIntoAFolderInUseIsRefusedNamingThePid) {
  const fs::path scene = write_scene(2.0);  // long enough to be still running under load
  const fs::path out = dir_ / "out";
  const pid_t first = testing::spawn_process(CLOTHSIM_BINARY, {scene.string(), "--out", out.string(), "--no-render"}, dir_ / "first.txt");
  ASSERT_GT(first, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!fs::exists(out / "hang" / "summary.json") && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(fs::exists(out / "hang" / "summary.json")) << read_file_bytes(dir_ / "first.txt");

  // Same scene, same root, while the first runs: refused, nothing of it written.
  EXPECT_EQ(sh(shell_quote(CLOTHSIM_BINARY) + " " + shell_quote(scene.string()) + " --out " + shell_quote(out.string())), 1);
  EXPECT_NE(log().find("is in use by another clothsim run (PID " + std::to_string(first) + ")"), std::string::npos)
      << log();

  int status = 0;
  ::waitpid(first, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_file_bytes(dir_ / "first.txt");
  const std::string summary = read_file_bytes(out / "hang" / "summary.json");
  EXPECT_NE(summary.find("\"status\": \"completed\""), std::string::npos);
  EXPECT_NE(summary.find("\"frames\": 61"), std::string::npos) << summary;  // 2 s at 30 fps: frames 0..60
  int objs = 0;
  for (const auto& e : fs::directory_iterator(out / "hang" / "frames")) objs += e.path().extension() == ".obj";
  EXPECT_EQ(objs, 61);
  EXPECT_FALSE(fs::exists(out / "hang" / "frame_0000.png")) << "a PNG of the refused run (the first has --no-render)";
  EXPECT_FALSE(fs::exists(out / ".hang.lock")) << "the lock file goes with its run";

  // Free again: a later run goes ahead.
  EXPECT_EQ(sh(shell_quote(CLOTHSIM_BINARY) + " " + shell_quote(scene.string()) + " --out " + shell_quote(out.string()) +
               " --end 0.01 --no-render"),
            0)
      << log();
}

TEST_F(OutputSafetyTest, LeftoversOfDeadRunsAreRemovedThoseOfLiveOnesKept) {
  // A PID that is certainly not running: a child that has exited and been reaped.
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  const fs::path out = dir_ / "out";
  const std::string d = std::to_string(dead), live = std::to_string(::getpid());
  for (const std::string& name : {".hang.tmp-" + d, ".other.old-" + d, ".study_folds.tmp-" + live})
    fs::create_directories(out / name / "inner");
  std::ofstream(out / (".summary.json.tmp-" + d)) << "{";
  std::ofstream(out / ("keep.tmp-" + d)) << "not hidden: not ours";

  ASSERT_EQ(sh(shell_quote(CLOTHSIM_BINARY) + " " + shell_quote(write_scene(0.01).string()) + " --out " +
               shell_quote(out.string()) + " --no-render"),
            0)
      << log();
  EXPECT_FALSE(fs::exists(out / (".hang.tmp-" + d)));
  EXPECT_FALSE(fs::exists(out / (".other.old-" + d)));
  EXPECT_FALSE(fs::exists(out / (".summary.json.tmp-" + d)));
  EXPECT_TRUE(fs::exists(out / (".study_folds.tmp-" + live))) << "a live process's temporary is left alone";
  EXPECT_TRUE(fs::exists(out / ("keep.tmp-" + d)));
  EXPECT_NE(log().find("left by a run that is no longer running (PID " + d + ")"), std::string::npos) << log();
}

TEST_F(OutputSafetyTest, AWriteFailureKeepsWholeFilesAndRecordsFailed) {
  // A file-size limit of 48 KiB (SIGXFSZ ignored, so writes past it fail with EFBIG) stands in for
  // a full disk: stats.csv reaches it part-way through the 500 steps.
  const fs::path out = dir_ / "out";
  const int code = sh("trap '' XFSZ; ulimit -f 96; exec " + shell_quote(CLOTHSIM_BINARY) + " " +
                      shell_quote(write_scene(1.0).string()) + " --out " + shell_quote(out.string()));
  EXPECT_EQ(code, 1) << log();
  EXPECT_NE(log().find("cannot write"), std::string::npos) << log();
  const fs::path run = out / "hang";
  const std::string summary = read_file_bytes(run / "summary.json");
  EXPECT_NE(summary.find("\"status\": \"failed\""), std::string::npos) << summary;
  EXPECT_EQ(temporaries(out), std::vector<std::string>{});
  // Every OBJ frame written is whole: 289 vertices and 512 triangles.
  int frames = 0;
  for (const auto& e : fs::directory_iterator(run / "frames")) {
    std::ifstream in(e.path());
    int v = 0, f = 0;
    for (std::string line; std::getline(in, line);) {
      v += line.rfind("v ", 0) == 0;
      f += line.rfind("f ", 0) == 0;
    }
    EXPECT_EQ(v, 289) << e.path();
    EXPECT_EQ(f, 512) << e.path();
    ++frames;
  }
  EXPECT_GT(frames, 0);
  // stats.csv ends on a whole row.
  const std::string stats = read_file_bytes(run / "stats.csv");
  ASSERT_FALSE(stats.empty());
  EXPECT_EQ(stats.back(), '\n');
}

}  // namespace
}  // namespace clothsim

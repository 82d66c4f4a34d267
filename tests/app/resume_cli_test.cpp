// Interrupt and resume: a dynamic run stopped by SIGINT (or killed with SIGKILL after a
// checkpoint) and continued with `clothsim SCENE --resume DIR` writes the same bytes as a run
// that was never stopped: probes.csv, every OBJ and PNG frame, and stats.csv apart from its
// timing columns. The scene has self-contact and ground contact, the Cholesky preconditioner (a
// factor of an earlier step's matrix is part of the state) and both framings are exercised.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
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

// A small falling sheet (12 x 12 cells, 250 steps of 2 ms) that lands on the ground and on itself.
std::string scene_text(const std::string& framing) {
  return R"({"name": "fall", "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.4, 0.4], "divisions": [12, 12], "rotate": {"axis": [1, 0, 0], "angle_deg": -3}, "translate": [0, 0.4997, 0]},
  "material": {"preset": "cotton"}, "loads": {"gravity": [0, -9.81, 0]}, "initial": {"velocity": [0, 0, 0.6]},
  "time": {"dt": 0.002, "end": 0.5, "output_fps": 30}, "damping": {"stiffness": 0.001, "mass": 0.1},
  "solver": {"type": "pcg", "tolerance": 1e-08, "preconditioner": "cholesky"},
  "collision": {"self": true, "thickness": 0.002, "friction": 0.3},
  "obstacles": [{"name": "ground", "primitive": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "friction": 0.5}],
  "probes": [{"name": "low_corner", "at": [0.2, 0.3, 0.0105]}],
  "output": {"obj": true, "checkpoint_every": 3},
  "render": {"width": 64, "height": 48, "framing": ")" +
         framing + R"(", "camera": {"eye": [0.85, 0.55, 0.9], "target": [0.0, 0.2, 0.15]}}})";
}

int count_lines(const fs::path& file) {
  std::ifstream in(file);
  int n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

// stats.csv without its wall-time columns (*_ms), which differ between any two runs.
std::string stats_without_timings(const fs::path& file) {
  std::ifstream in(file);
  std::string header;
  std::getline(in, header);
  std::vector<bool> keep;
  std::stringstream h(header);
  for (std::string field; std::getline(h, field, ',');)
    keep.push_back(field.size() < 3 || field.compare(field.size() - 3, 3, "_ms") != 0);
  std::string out;
  for (std::string line = header; !in.fail(); std::getline(in, line)) {
    std::stringstream row(line);
    std::size_t column = 0;
    for (std::string field; std::getline(row, field, ','); ++column)
      if (column >= keep.size() || keep[column]) out += field + ",";
    out += "\n";
  }
  return out;
}

// Every file of the run folder (relative path → bytes), stats.csv without timings, summary.json
// left out (it holds wall times).
std::map<std::string, std::string> run_files(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = fs::relative(entry.path(), dir).string();
    if (name == "summary.json") continue;
    files[name] = name == "stats.csv" ? stats_without_timings(entry.path()) : read_file_bytes(entry.path());
  }
  return files;
}

class ResumeTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = make_temp_dir("clothsim_resume_test_"); }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  fs::path write_scene(const std::string& framing) const {
    const fs::path path = dir_ / "fall.json";
    std::ofstream(path) << scene_text(framing);
    return path;
  }

  // Runs clothsim to the end; its exit code.
  int run(const std::string& args) const {
    return run_shell(shell_quote(CLOTHSIM_BINARY) + " " + args + " >/dev/null 2>>" + shell_quote((dir_ / "log.txt").string()));
  }

  // Starts clothsim in the background; its PID.
  pid_t spawn(const std::vector<std::string>& args) const {
    return testing::spawn_process(CLOTHSIM_BINARY, args, dir_ / "spawned.txt");
  }

  // Waits until `ready()` holds (polling), at most 120 s; false if the process ended first.
  template <typename Ready>
  bool wait_until(pid_t pid, Ready ready) const {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (std::chrono::steady_clock::now() < deadline) {
      if (ready()) return true;
      int status = 0;
      if (::waitpid(pid, &status, WNOHANG) == pid) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  }

  static int wait_exit(pid_t pid, bool* signalled = nullptr) {
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (signalled) *signalled = WIFSIGNALED(status);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }

  std::string log() const { return read_file_bytes(dir_ / "log.txt") + read_file_bytes(dir_ / "spawned.txt"); }

  fs::path dir_;
};

void expect_same_run(const fs::path& a, const fs::path& b) {
  const auto files_a = run_files(a), files_b = run_files(b);
  std::set<std::string> names_a, names_b;
  for (const auto& [name, bytes] : files_a) names_a.insert(name);
  for (const auto& [name, bytes] : files_b) names_b.insert(name);
  EXPECT_EQ(names_a, names_b);
  int compared = 0;
  for (const auto& [name, bytes] : files_a) {
    const auto other = files_b.find(name);
    if (other == files_b.end()) continue;
    EXPECT_TRUE(bytes == other->second) << name << " differs";
    ++compared;
  }
  EXPECT_GE(compared, 2 * 16 + 2);  // 16 OBJ and 16 PNG frames, probes.csv, stats.csv
}

TEST_F(ResumeTest, InterruptedBySigintAndResumedGivesTheSameBytes) {
  const fs::path scene = write_scene("motion");
  ASSERT_EQ(run(shell_quote(scene.string()) + " --out " + shell_quote((dir_ / "a").string())), 0) << log();

  const fs::path b = dir_ / "b" / "fall";
  const pid_t pid = spawn({scene.string(), "--out", (dir_ / "b").string()});
  ASSERT_GT(pid, 0);
  // Interrupt between two checkpoints (after step 40 of 250).
  ASSERT_TRUE(wait_until(pid, [&] { return fs::exists(b / "stats.csv") && count_lines(b / "stats.csv") > 41; }))
      << "the run ended before it could be interrupted\n" << log();
  ::kill(pid, SIGINT);
  EXPECT_EQ(wait_exit(pid), 128 + SIGINT) << log();
  const std::string summary = read_file_bytes(b / "summary.json");
  EXPECT_NE(summary.find("\"status\": \"interrupted\""), std::string::npos) << summary;
  EXPECT_TRUE(fs::exists(b / "checkpoint.bin"));
  EXPECT_NE(log().find("--resume"), std::string::npos) << "the message says how to continue: " << log();
  const int steps_at_interrupt = count_lines(b / "stats.csv") - 1;
  EXPECT_LT(steps_at_interrupt, 250);

  ASSERT_EQ(run(shell_quote(scene.string()) + " --resume " + shell_quote(b.string())), 0) << log();
  EXPECT_NE(read_file_bytes(b / "summary.json").find("\"status\": \"completed\""), std::string::npos);
  EXPECT_FALSE(fs::exists(b / "checkpoint.bin")) << "a completed run keeps no checkpoint";
  expect_same_run(dir_ / "a" / "fall", b);
}

TEST_F(ResumeTest, KilledAfterACheckpointAndResumedGivesTheSameBytes) {
  // Sequence framing: the pictures are drawn after the run from the spooled frames.
  const fs::path scene = write_scene("sequence");
  ASSERT_EQ(run(shell_quote(scene.string()) + " --out " + shell_quote((dir_ / "a").string())), 0) << log();

  const fs::path b = dir_ / "b" / "fall";
  const pid_t pid = spawn({scene.string(), "--out", (dir_ / "b").string()});
  ASSERT_GT(pid, 0);
  // SIGKILL a few steps after the second checkpoint: the CSV files and frames are then ahead of it.
  int checkpoints = 0;
  fs::file_time_type last{};
  ASSERT_TRUE(wait_until(pid, [&] {
    std::error_code ec;
    const auto t = fs::last_write_time(b / "checkpoint.bin", ec);
    if (!ec && t != last) {
      last = t;
      ++checkpoints;
    }
    return checkpoints >= 2;
  })) << log();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ::kill(pid, SIGKILL);
  bool signalled = false;
  wait_exit(pid, &signalled);
  ASSERT_TRUE(signalled) << "the run ended before it was killed\n" << log();
  EXPECT_NE(read_file_bytes(b / "summary.json").find("\"status\": \"running\""), std::string::npos);

  ASSERT_EQ(run(shell_quote(scene.string()) + " --resume " + shell_quote(b.string())), 0) << log();
  expect_same_run(dir_ / "a" / "fall", b);
  EXPECT_FALSE(fs::exists(b / ".frames.bin")) << "the spool is deleted once the pictures are drawn";
}

TEST_F(ResumeTest, ResumeRefusesWhatItCannotContinue) {
  const fs::path scene = write_scene("motion");
  const std::string quoted = shell_quote(scene.string());
  // No such folder; a folder without a checkpoint; a static scene.
  EXPECT_EQ(run(quoted + " --resume " + shell_quote((dir_ / "nothing").string())), 1);
  EXPECT_NE(log().find("no such folder"), std::string::npos) << log();
  fs::create_directories(dir_ / "empty");
  EXPECT_EQ(run(quoted + " --resume " + shell_quote((dir_ / "empty").string())), 1);
  EXPECT_NE(log().find("no checkpoint to resume from"), std::string::npos) << log();
  EXPECT_EQ(run(shell_quote((fs::path(CLOTHSIM_SOURCE_DIR) / "scenes" / "plate_ss.json").string()) + " --resume " +
                shell_quote((dir_ / "empty").string())),
            1);
  EXPECT_NE(log().find("only dynamic runs can be resumed"), std::string::npos) << log();
  // --out together with --resume.
  EXPECT_EQ(run(quoted + " --out x --resume " + shell_quote((dir_ / "empty").string())), 1);

  // A completed run has nothing to resume; a checkpoint of other options is refused, unchanged.
  const fs::path out = dir_ / "out";
  ASSERT_EQ(run(quoted + " --out " + shell_quote(out.string()) + " --end 0.1"), 0) << log();
  EXPECT_EQ(run(quoted + " --end 0.1 --resume " + shell_quote((out / "fall").string())), 1);
  EXPECT_NE(log().find("the run is complete"), std::string::npos) << log();
  // A run killed after its first checkpoint, resumed with another --end.
  const pid_t pid = spawn({scene.string(), "--out", out.string(), "--end", "0.4"});
  ASSERT_TRUE(wait_until(pid, [&] { return fs::exists(out / "fall" / "checkpoint.bin"); })) << log();
  ::kill(pid, SIGKILL);
  wait_exit(pid);
  const std::string stats_before = read_file_bytes(out / "fall" / "stats.csv");
  EXPECT_EQ(run(quoted + " --end 0.3 --resume " + shell_quote((out / "fall").string())), 1);
  EXPECT_NE(log().find("written for another scene or other options"), std::string::npos) << log();
  EXPECT_EQ(read_file_bytes(out / "fall" / "stats.csv"), stats_before) << "a refused resume changes nothing";
  // A damaged checkpoint.
  const std::string checkpoint = read_file_bytes(out / "fall" / "checkpoint.bin");
  std::ofstream(out / "fall" / "checkpoint.bin", std::ios::binary) << checkpoint.substr(0, checkpoint.size() / 2);
  EXPECT_EQ(run(quoted + " --end 0.4 --resume " + shell_quote((out / "fall").string())), 1);
  EXPECT_NE(log().find("checkpoint.bin: not a usable clothsim checkpoint"), std::string::npos) << log();
}

}  // namespace
}  // namespace clothsim

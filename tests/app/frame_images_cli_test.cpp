// The PNG frames of dynamic runs, through the built clothsim binary: with the default framing
// ("motion") each frame's picture is drawn while the simulation goes on (on a drawing thread, at
// most two frames behind; CLOTHSIM_RENDER_THREAD=0 draws on the simulating thread) and gives the
// same bytes either way, a run killed part-way keeps whole pictures of its first frames, a picture
// that cannot be written fails the run as it did when drawn inline, and the camera fixed before
// the run keeps the cloth in the picture; framing "sequence" (scene key or --framing) draws after
// the run and leaves no spool file behind; a bad render.framing is an input error that writes
// nothing.
#include "render/image.hpp"
#include "render/png_io.hpp"

#include "tests/support/process.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace {

namespace fs = std::filesystem;
using clothsim::testing::read_file_bytes;
using clothsim::testing::shell_quote;

struct RunResult {
  int exit_code = -1;
  std::string err;  // stderr
};

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// A 0.2 m × 0.2 m cloth pinned along y = +0.1 m falling under gravity, frames at 500 fps
// (t = 0, 2, ..., 10 ms) at 160 × 120 px. `render` is spliced into the "render" object.
std::string falling_cloth(const std::string& render = "") {
  return R"({
  "name": "cloth",
  "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "cotton"},
  "boundary": [{"select": {"box": [[-0.11, 0.09, -1], [0.11, 0.11, 1]]}, "fix": ["x", "y", "z"]}],
  "loads": {"gravity": [0, 0, -9.81]},
  "time": {"dt": 0.001, "end": 0.01, "output_fps": 500},
  "damping": {"stiffness": 0.001},
  "render": {"width": 160, "height": 120)" +
         (render.empty() ? "" : ", " + render) + R"(}
})";
}

// The same cloth with a camera of its own, simulated for 100 s (far longer than the test waits):
// frames at 200 fps.
const char* const kLongClothWithCamera = R"({
  "name": "long",
  "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "cotton"},
  "boundary": [{"select": {"box": [[-0.11, 0.09, -1], [0.11, 0.11, 1]]}, "fix": ["x", "y", "z"]}],
  "loads": {"gravity": [0, 0, -9.81]},
  "time": {"dt": 0.001, "end": 100, "output_fps": 200},
  "damping": {"stiffness": 0.001},
  "render": {"width": 160, "height": 120, "camera": {"eye": [0.3, -0.3, 0.6], "target": [0, 0, -0.05]}}
})";

// The cloth hanging from its pinned edge (gravity −y) while that edge is dragged 0.3 m along +x
// in 0.1 s: the cloth ends far from where it started, outside a camera framed on its rest shape.
const char* const kDraggedCloth = R"({
  "name": "dragged",
  "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "cotton"},
  "boundary": [{"select": {"box": [[-0.11, 0.09, -1], [0.11, 0.11, 1]]}, "fix": ["x", "y", "z"],
                "motion": [{"type": "translate", "displacement": [0.3, 0, 0], "start": 0, "end": 0.1}]}],
  "loads": {"gravity": [0, -9.81, 0]},
  "time": {"dt": 0.001, "end": 0.15, "output_fps": 100},
  "damping": {"stiffness": 0.001},
  "render": {"width": 160, "height": 120, "ground": false}
})";

// The frame_NNNN.png files of `dir`, in order; fails the test if they are not numbered 0, 1, ...
std::vector<fs::path> frame_files(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("frame_", 0) == 0 && e.path().extension() == ".png") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  for (std::size_t k = 0; k < files.size(); ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%04zu.png", k);
    EXPECT_EQ(files[k].filename().string(), name);
  }
  return files;
}

// Pixels of `image` that differ from white, the default background.
int non_background_pixels(const clothsim::render::Image& image) {
  int count = 0;
  for (std::size_t i = 0; i + 2 < image.rgb.size(); i += 3)
    count += image.rgb[i] != 255 || image.rgb[i + 1] != 255 || image.rgb[i + 2] != 255;
  return count;
}

// Pixels on the image's outermost rows and columns that differ from white (a scene with gravity
// draws a ground unless it says "ground": false).
int non_background_border_pixels(const clothsim::render::Image& image) {
  int count = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      if (x != 0 && y != 0 && x != image.width - 1 && y != image.height - 1) continue;
      const std::size_t i = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) + x);
      count += image.rgb[i] != 255 || image.rgb[i + 1] != 255 || image.rgb[i + 2] != 255;
    }
  return count;
}

// Mean column of the non-background pixels [px].
double mean_column(const clothsim::render::Image& image) {
  double sum = 0.0;
  int count = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::size_t i = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) + x);
      if (image.rgb[i] == 255 && image.rgb[i + 1] == 255 && image.rgb[i + 2] == 255) continue;
      sum += x;
      ++count;
    }
  return count > 0 ? sum / count : -1.0;
}

class FrameImagesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "clothsim_frames_test_XXXXXX").string();
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

  // Runs `clothsim SCENE --out OUT <args>` with stdout and stderr captured; `environment`:
  // assignments put in front of the command.
  RunResult run(const fs::path& scene, const std::string& args = "", const std::string& environment = "") const {
    const fs::path err_file = dir_ / "stderr.txt";
    const std::string command = environment + " " + shell_quote(CLOTHSIM_BINARY) + " " + shell_quote(scene.string()) + " --out " +
                                shell_quote(out_.string()) + " " + args + " >/dev/null 2>" +
                                shell_quote(err_file.string());
    const int status = std::system(command.c_str());
    RunResult r;
    r.exit_code = (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
    r.err = read_file_bytes(err_file);
    return r;
  }

  fs::path dir_;
  fs::path out_;
};

TEST_F(FrameImagesTest, KilledRunKeepsTheFramesWrittenSoFar) {
  const fs::path scene = write("long.json", kLongClothWithCamera);
  const std::string binary = CLOTHSIM_BINARY, scene_arg = scene.string(), out_arg = out_.string();
  const std::string log = (dir_ / "log.txt").string();
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<char*> argv{const_cast<char*>(binary.c_str()), const_cast<char*>(scene_arg.c_str()),
                          const_cast<char*>("--out"), const_cast<char*>(out_arg.c_str()), nullptr};
  pid_t pid = 0;
  ASSERT_EQ(::posix_spawn(&pid, binary.c_str(), &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);

  // Wait (at most 60 s) until the fourth frame's picture exists, then kill the run.
  const fs::path run_dir = out_ / "long";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  bool exited = false;
  while (!fs::exists(run_dir / "frame_0003.png") && std::chrono::steady_clock::now() < deadline) {
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) {
      exited = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!exited) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, nullptr, 0);
  }
  ASSERT_FALSE(exited) << "the run ended by itself: " << read_file_bytes(log);
  ASSERT_TRUE(fs::exists(run_dir / "frame_0003.png")) << "no frame_0003.png after 60 s: " << read_file_bytes(log);

  // The run was killed part-way (summary.json still says so) ...
  const nlohmann::json summary = nlohmann::json::parse(read_file_bytes(run_dir / "summary.json"));
  EXPECT_EQ(summary["status"], "running");
  // ... and every picture it wrote is there and whole: frame 0, 1, ... without gaps.
  const std::vector<fs::path> files = frame_files(run_dir);
  ASSERT_GE(files.size(), 4u);
  for (const fs::path& file : files) {
    const clothsim::render::Image image = clothsim::render::read_png(file.string());
    EXPECT_EQ(image.width, 160) << file;
    EXPECT_EQ(image.height, 120) << file;
    EXPECT_GT(non_background_pixels(image), 100) << file;  // the cloth is in the picture
  }
}

// Every file of a run folder but summary.json and stats.csv (wall times), by name.
std::map<std::string, std::string> run_files(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string name = fs::relative(e.path(), dir).string();
    if (e.is_regular_file() && name != "summary.json" && name != "stats.csv") files[name] = read_file_bytes(e.path());
  }
  return files;
}

TEST_F(FrameImagesTest, DrawingThreadWritesTheBytesOfDrawingOnTheSimulatingThread) {
  // 320 x 240 with a ground, steps of 2 ms and frames every 1 ms (every other picture repeats
  // the previous one), and a checkpoint every 7 frames (which waits for the pictures): drawing
  // takes longer than a step, so the drawing thread falls behind and the run waits for it.
  std::string text = falling_cloth(R"("ground": true)");
  const std::string time = R"("time": {"dt": 0.001, "end": 0.01, "output_fps": 500})";
  text.replace(text.find(time), time.size(),
               R"("time": {"dt": 0.002, "end": 0.05, "output_fps": 1000}, "output": {"checkpoint_every": 7})");
  const fs::path scene = write("steps.json", text);
  RunResult r = run(scene, "--size 320x240");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::map<std::string, std::string> threaded = run_files(out_ / "cloth");
  r = run(scene, "--size 320x240", "CLOTHSIM_RENDER_THREAD=0");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::map<std::string, std::string> inline_drawn = run_files(out_ / "cloth");
  ASSERT_EQ(frame_files(out_ / "cloth").size(), 51u);  // t = 0, 1, ..., 50 ms
  ASSERT_EQ(threaded.size(), inline_drawn.size());
  for (const auto& [name, bytes] : inline_drawn) {
    const auto other = threaded.find(name);
    ASSERT_NE(other, threaded.end()) << name << " is missing from the run with the drawing thread";
    EXPECT_TRUE(other->second == bytes) << name << " differs";
  }
  EXPECT_EQ(threaded.at("frame_0001.png"), threaded.at("frame_0002.png"));  // a repeated frame
  EXPECT_NE(threaded.at("frame_0002.png"), threaded.at("frame_0003.png"));
}

// A picture that cannot be written (a folder stands where frame N's PNG goes: the rename onto
// it fails) ends the run as on the simulating thread: the error names the step of frame N and
// the file, the exit code is 1, summary.json says "failed", frames 0 .. N-1 are all there and
// whole, nothing after N, no temporary file. The folder is made while the run is stopped
// (SIGSTOP), 20 frames after the last picture on disk, so that the run has not reached it.
TEST_F(FrameImagesTest, PictureThatCannotBeWrittenFailsTheRunAsWhenDrawnInline) {
  const fs::path scene = write("long.json", kLongClothWithCamera);
  const fs::path run_dir = out_ / "long";
  for (const bool drawing_thread : {true, false}) {
    SCOPED_TRACE(drawing_thread ? "drawing thread" : "CLOTHSIM_RENDER_THREAD=0");
    std::error_code ec;
    fs::remove_all(out_, ec);
    if (!drawing_thread) ::setenv("CLOTHSIM_RENDER_THREAD", "0", 1);
    const fs::path log = dir_ / (drawing_thread ? "threaded.txt" : "inline.txt");
    const pid_t pid = clothsim::testing::spawn_process(CLOTHSIM_BINARY, {scene.string(), "--out", out_.string()}, log);
    ::unsetenv("CLOTHSIM_RENDER_THREAD");
    ASSERT_GT(pid, 0);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    bool exited = false;
    while (!fs::exists(run_dir / "frame_0003.png") && std::chrono::steady_clock::now() < deadline) {
      if (::waitpid(pid, nullptr, WNOHANG) == pid) {
        exited = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ASSERT_FALSE(exited) << read_file_bytes(log);
    ::kill(pid, SIGSTOP);
    int last = -1;
    for (const auto& e : fs::directory_iterator(run_dir)) {
      const std::string name = e.path().filename().string();
      if (name.rfind("frame_", 0) == 0 && name.size() == 14 && e.path().extension() == ".png")
        last = std::max(last, std::stoi(name.substr(6, 4)));
    }
    const int blocked = last + 20;
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%04d.png", blocked);
    fs::create_directory(run_dir / name);
    ::kill(pid, SIGCONT);
    int status = 0;
    while (::waitpid(pid, &status, WNOHANG) != pid) {
      if (std::chrono::steady_clock::now() > deadline + std::chrono::seconds(60)) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        FAIL() << "the run did not stop at frame " << blocked << ": " << read_file_bytes(log);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_TRUE(WIFEXITED(status)) << read_file_bytes(log);
    EXPECT_EQ(WEXITSTATUS(status), 1);

    // Frame k shows t = k / 200 s, the state after step 5 k (dt = 1 ms).
    const int step = 5 * blocked;
    const std::string err = read_file_bytes(log);
    EXPECT_TRUE(contains(err, "clothsim: error: " + scene.string() + ": step " + std::to_string(step) + " (t = " +
                                  std::to_string(step * 0.001) + " s): write_png: writing " +
                                  (run_dir / name).string() + " failed: "))
        << err;
    EXPECT_FALSE(contains(err, "rendering failed")) << err;  // reported once, as the error
    const nlohmann::json summary = nlohmann::json::parse(read_file_bytes(run_dir / "summary.json"));
    EXPECT_EQ(summary["status"], "failed");
    EXPECT_TRUE(contains(summary["error"].get<std::string>(), name)) << summary["error"];
    fs::remove(run_dir / name);
    const std::vector<fs::path> files = frame_files(run_dir);  // numbered 0, 1, ... without gaps
    EXPECT_EQ(static_cast<int>(files.size()), blocked);
    for (const fs::path& file : files) EXPECT_EQ(clothsim::render::read_png(file.string()).width, 160) << file;
    for (const auto& e : fs::directory_iterator(run_dir))
      EXPECT_FALSE(contains(e.path().filename().string(), ".tmp")) << "left behind: " << e.path();
  }
}

TEST_F(FrameImagesTest, MotionFramingKeepsTheDraggedClothInThePicture) {
  const fs::path scene = write("dragged.json", kDraggedCloth);
  const RunResult r = run(scene);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<fs::path> files = frame_files(out_ / "dragged");
  ASSERT_EQ(files.size(), 16u);  // t = 0, 10, ..., 150 ms
  for (const fs::path& file : files) {
    const clothsim::render::Image image = clothsim::render::read_png(file.string());
    EXPECT_GT(non_background_pixels(image), 100) << file;
    EXPECT_EQ(non_background_border_pixels(image), 0) << file << ": the cloth touches the edge of the picture";
  }
  // The camera stayed put while the cloth moved across the picture.
  const double first = mean_column(clothsim::render::read_png(files.front().string()));
  const double last = mean_column(clothsim::render::read_png(files.back().string()));
  EXPECT_GT(last - first, 30.0) << "first " << first << " px, last " << last << " px";
}

TEST_F(FrameImagesTest, MotionFramingKeepsTheTwistedSleeveInThePicture) {
  const fs::path scene = fs::path(CLOTHSIM_SOURCE_DIR) / "scenes" / "sleeve_twist.json";
  const RunResult r = run(scene, "--size 160x120 --end 0.2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<fs::path> files = frame_files(out_ / "sleeve_twist");
  ASSERT_EQ(files.size(), 7u);  // t = 0, 1/30, ..., 0.2 s
  for (const fs::path& file : files) {
    const clothsim::render::Image image = clothsim::render::read_png(file.string());
    EXPECT_GT(non_background_pixels(image), 1000) << file;
    EXPECT_EQ(non_background_border_pixels(image), 0) << file << ": the sleeve touches the edge of the picture";
  }
}

TEST_F(FrameImagesTest, SequenceFramingDrawsAfterTheRunAndRemovesItsSpool) {
  // The scene key and the command-line option give the same pictures.
  const fs::path keyed = write("keyed.json", falling_cloth(R"("framing": "sequence")"));
  RunResult r = run(keyed);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path run_dir = out_ / "cloth";
  ASSERT_EQ(frame_files(run_dir).size(), 6u);
  for (const auto& e : fs::directory_iterator(run_dir))
    EXPECT_NE(e.path().filename().string().front(), '.') << "left behind: " << e.path();
  const std::string keyed_last = read_file_bytes(run_dir / "frame_0005.png");

  const fs::path plain = write("plain.json", falling_cloth());
  r = run(plain, "--framing sequence");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_file_bytes(run_dir / "frame_0005.png"), keyed_last);

  // --framing motion overrides the scene key, and frames differently.
  r = run(keyed, "--framing motion");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_EQ(frame_files(run_dir).size(), 6u);
  EXPECT_NE(read_file_bytes(run_dir / "frame_0005.png"), keyed_last);
  for (const auto& e : fs::directory_iterator(run_dir))
    EXPECT_NE(e.path().filename().string().front(), '.') << "left behind: " << e.path();
}

TEST_F(FrameImagesTest, RepeatedFramesInBothFramings) {
  // Steps of 2 ms and frames every 1 ms: frames 1 and 2 both show the state after the first step.
  std::string text = falling_cloth();
  const std::string time = R"("time": {"dt": 0.001, "end": 0.01, "output_fps": 500})";
  text.replace(text.find(time), time.size(), R"("time": {"dt": 0.002, "end": 0.01, "output_fps": 1000})");
  const fs::path scene = write("steps.json", text);
  for (const std::string framing : {"motion", "sequence"}) {
    SCOPED_TRACE(framing);
    const RunResult r = run(scene, "--framing " + framing);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const fs::path run_dir = out_ / "cloth";
    ASSERT_EQ(frame_files(run_dir).size(), 11u);  // t = 0, 1, ..., 10 ms
    EXPECT_EQ(read_file_bytes(run_dir / "frame_0001.png"), read_file_bytes(run_dir / "frame_0002.png"));
    EXPECT_NE(read_file_bytes(run_dir / "frame_0002.png"), read_file_bytes(run_dir / "frame_0003.png"));
  }
}

TEST_F(FrameImagesTest, FailedRunHasPicturesOfItsFramesInBothFramings) {
  // A free sheet thrown at 1 km/s diverges in step 3 (cli_test's kFailingCloth); frames 0-6 were
  // produced before.
  const fs::path scene = write("stiff.json", R"({
  "name": "stiff",
  "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "metal"},
  "initial": {"velocity": [0, 0, 1000]},
  "loads": {"gravity": [0, 0, -9.81]},
  "time": {"dt": 0.1, "end": 1.0},
  "render": {"width": 64, "height": 48}
})");
  for (const std::string framing : {"motion", "sequence"}) {
    SCOPED_TRACE(framing);
    const RunResult r = run(scene, "--framing " + framing);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    const fs::path run_dir = out_ / "stiff";
    const nlohmann::json summary = nlohmann::json::parse(read_file_bytes(run_dir / "summary.json"));
    EXPECT_EQ(summary["status"], "failed");
    const std::vector<fs::path> files = frame_files(run_dir);
    EXPECT_EQ(static_cast<int>(files.size()), summary["frames"].get<int>());
    ASSERT_GE(files.size(), 1u);
    EXPECT_EQ(clothsim::render::read_png(files.front().string()).width, 64);
    EXPECT_FALSE(fs::exists(run_dir / ".frames.bin"));
  }
}

TEST_F(FrameImagesTest, BadFramingIsAnInputError) {
  const fs::path scene = write("bad.json", falling_cloth(R"("framing": "whole")"));
  RunResult r = run(scene);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "clothsim: error: " + scene.string() + ": render.framing: unknown framing \"whole\""))
      << r.err;
  EXPECT_FALSE(fs::exists(out_)) << "output root was created";

  const fs::path good = write("good.json", falling_cloth());
  r = run(good, "--framing whole");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.err, "--framing")) << r.err;
  EXPECT_FALSE(fs::exists(out_)) << "output root was created";
}

}  // namespace

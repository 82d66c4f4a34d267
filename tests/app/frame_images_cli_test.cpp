// The PNG frames of dynamic runs, through the built clothsim binary: with the default framing
// ("motion") each frame's picture is on disk as soon as the frame is produced, so a run killed
// part-way keeps whole pictures of its first frames, and the camera fixed before the run keeps
// the cloth in the picture; framing "sequence" (scene key or --framing) draws after the run and
// leaves no spool file behind; a bad render.framing is an input error that writes nothing.
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
  "render": {"width": 160, "height": 120}
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

// Pixels on the image's outermost rows and columns that differ from white.
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

  // Runs `clothsim SCENE --out OUT <args>` with stdout and stderr captured.
  RunResult run(const fs::path& scene, const std::string& args = "") const {
    const fs::path err_file = dir_ / "stderr.txt";
    const std::string command = shell_quote(CLOTHSIM_BINARY) + " " + shell_quote(scene.string()) + " --out " +
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
  // A stiff sheet with a huge step and a conjugate gradient solver allowed one iteration: the
  // first step fails; frame 0 (the initial state) was produced before.
  const fs::path scene = write("stiff.json", R"({
  "name": "stiff",
  "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "metal"},
  "boundary": [{"select": {"box": [[-0.11, 0.09, -1], [0.11, 0.11, 1]]}}],
  "loads": {"gravity": [0, 0, -9.81]},
  "time": {"dt": 0.1, "end": 1.0},
  "solver": {"type": "pcg", "max_iterations": 1, "tolerance": 1e-14},
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

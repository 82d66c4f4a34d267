// "render.surface" through the clothsim command: a static linear_fe plate records the flat mesh as
// its drawn surface by default and draws limit.png; a short dynamic linear_fe run with
// "loop_limit" records it in summary.json, draws its frames, and writes OBJ frames at
// obj_level 1 that name the surface and hold the Loop limit surface (a corner of the hanging
// cloth's drawn surface is not at the corner node, as it is on the flat mesh); a bad value fails
// naming the key and writes nothing.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <stdlib.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using clothsim::testing::read_file_bytes;
using clothsim::testing::shell_quote;

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// A 0.2 m square of 4 × 4 cells pinned along y = +0.1 m, falling for 4 steps of 2 ms.
std::string falling_cloth(const std::string& surface) {
  return R"({
  "name": "cloth", "analysis": "dynamic", "method": "linear_fe",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "cotton"},
  "boundary": [{"select": {"box": [[-0.11, 0.09, -1], [0.11, 0.11, 1]]}, "fix": ["x", "y", "z"]}],
  "loads": {"gravity": [0, 0, -9.81]},
  "time": {"dt": 0.002, "end": 0.008, "output_fps": 250},
  "output": {"obj": true, "obj_level": 1},
  "render": {"width": 64, "height": 48, "refine": 1, "surface": )" + surface + R"(}
})";
}

class DrawnSurfaceCli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "clothsim_drawn_surface_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  // Runs clothsim on `scene_text`; returns the exit code, stderr in `err`.
  int run(const std::string& scene_text, std::string& err) const {
    const fs::path scene = dir_ / "scene.json";
    std::ofstream(scene) << scene_text;
    const std::string command = shell_quote(CLOTHSIM_BINARY) + " " + shell_quote(scene.string()) + " --out " +
                                shell_quote((dir_ / "out").string()) + " >/dev/null 2>" +
                                shell_quote((dir_ / "err.txt").string());
    const int status = std::system(command.c_str());
    err = read_file_bytes(dir_ / "err.txt");
    return (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
  }
  fs::path dir_;
};

// Vertex lines ("v x y z") of an OBJ file.
std::vector<std::array<double, 3>> obj_vertices(const fs::path& file) {
  std::istringstream in(read_file_bytes(file));
  std::vector<std::array<double, 3>> out;
  for (std::string line; std::getline(in, line);)
    if (line.rfind("v ", 0) == 0) {
      std::istringstream v(line.substr(2));
      std::array<double, 3> p{};
      v >> p[0] >> p[1] >> p[2];
      out.push_back(p);
    }
  return out;
}

TEST_F(DrawnSurfaceCli, StaticDefaultRecordsTheFlatMesh) {
  std::string err;
  ASSERT_EQ(run(R"({"name": "plate", "method": "linear_fe",
      "mesh": {"primitive": "grid", "size": [1.0, 1.0], "divisions": [4, 4]},
      "material": {"youngs_modulus": 1e7, "poisson_ratio": 0.3, "thickness": 0.01},
      "boundary": [{"select": {"box": [[-0.51, -0.51, -1], [0.51, -0.49, 1]]}},
                   {"select": {"box": [[-0.51, 0.49, -1], [0.51, 0.51, 1]]}}],
      "loads": {"surface_load": [0, 0, -1]}, "render": {"width": 64, "height": 48}})",
                err),
            0)
      << err;
  const nlohmann::json j = nlohmann::json::parse(read_file_bytes(dir_ / "out" / "plate" / "result.json"));
  EXPECT_EQ(j["drawn_surface"]["surface"], "flat");
  EXPECT_EQ(j["drawn_surface"]["refine"], 2);
  EXPECT_EQ(j["drawn_surface"]["description"], "flat mesh refined 2x");
  EXPECT_TRUE(fs::exists(dir_ / "out" / "plate" / "limit.png"));
}

TEST_F(DrawnSurfaceCli, DynamicLoopLimitIsRecordedDrawnAndWrittenToObjFrames) {
  std::string err;
  ASSERT_EQ(run(falling_cloth("\"loop_limit\""), err), 0) << err;
  const fs::path out = dir_ / "out" / "cloth";
  const nlohmann::json j = nlohmann::json::parse(read_file_bytes(out / "summary.json"));
  EXPECT_EQ(j["drawn_surface"]["surface"], "loop_limit");
  EXPECT_EQ(j["drawn_surface"]["refine"], 1);
  EXPECT_EQ(j["drawn_surface"]["description"], "Loop limit surface refined 1x");
  for (const char* png : {"frame_0000.png", "frame_0001.png", "frame_0002.png"}) EXPECT_TRUE(fs::exists(out / png)) << png;
  const std::string obj = read_file_bytes(out / "frames" / "mesh_0002.obj");
  EXPECT_TRUE(contains(obj.substr(0, obj.find('\n')), "(refined 1 times: Loop limit surface refined 1x)"))
      << obj.substr(0, obj.find('\n'));
  // The same run drawing the flat mesh: its OBJ frame has the same number of points (the same
  // fine triangles), and point 0 (the first triangle's first corner: the free corner node
  // (-0.1, -0.1)) differs — the Loop limit point is a weighted average over the corner's ring
  // (with its ghosts), which is not symmetric about a corner, so it lies inside the sheet.
  const std::vector<std::array<double, 3>> smooth = obj_vertices(out / "frames" / "mesh_0002.obj");
  const std::vector<std::array<double, 3>> smooth_rest = obj_vertices(out / "frames" / "mesh_0000.obj");
  ASSERT_FALSE(smooth_rest.empty());
  std::printf("Loop limit point of the free corner at rest: (%.6f, %.6f, %.6f) m\n", smooth_rest[0][0], smooth_rest[0][1],
              smooth_rest[0][2]);
  fs::remove_all(dir_ / "out");
  ASSERT_EQ(run(falling_cloth("\"method\""), err), 0) << err;
  const nlohmann::json k = nlohmann::json::parse(read_file_bytes(out / "summary.json"));
  EXPECT_EQ(k["drawn_surface"]["description"], "flat mesh refined 1x");
  const std::vector<std::array<double, 3>> flat = obj_vertices(out / "frames" / "mesh_0002.obj");
  ASSERT_EQ(smooth.size(), flat.size());
  ASSERT_FALSE(flat.empty());
  const double shift = std::hypot(smooth[0][0] - flat[0][0], smooth[0][1] - flat[0][1], smooth[0][2] - flat[0][2]);
  std::printf("corner of the falling cloth after 8 ms: flat (%.6f, %.6f, %.6f) m, Loop limit moved by %.2e m\n", flat[0][0],
              flat[0][1], flat[0][2], shift);
  EXPECT_NEAR(flat[0][0], -0.1, 0.01);
  EXPECT_NEAR(flat[0][1], -0.1, 0.01);
  EXPECT_GT(shift, 1e-7);
}

TEST_F(DrawnSurfaceCli, BadValueFailsNamingTheKeyAndWritesNothing) {
  std::string err;
  EXPECT_NE(run(falling_cloth("\"smooth\""), err), 0);
  EXPECT_TRUE(contains(err, "render.surface: unknown surface \"smooth\" (allowed: \"method\", \"loop_limit\", \"flat\")"))
      << err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

}  // namespace

// The PC2 point cache (app/point_cache.hpp, docs/animation_tools.md): a pattern skirt run with
// "output": {"obj": true, "cache": "pc2"} through the command line; cache.pc2 is read back here by
// its byte layout (not with the writer's code) and every sample equals its OBJ frame to float
// precision; cache_rest.obj is the first frame with unit normals and the pattern's texture
// coordinates; `clothsim cache` on the finished run writes the same bytes; bad input is named.
#include "sim/mesh/obj_io.hpp"

#include "tests/support/cli_fixture.hpp"
#include "tests/support/skirt_scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

class PointCacheCli : public testing::CliFixture {};

const std::string kSkirt = std::string(R"({"name": "skirt", "analysis": "dynamic", )") + testing::kCoarseTubeSkirtMesh +
                          R"(, "material": {"preset": "cotton"}, "settle": {"time": 0.05}, "loads": {"gravity": [0, -9.81, 0]},
  "time": {"dt": 0.01, "end": 0.04, "output_fps": 50}, "output": {"obj": true, "obj_level": 1, "cache": "pc2"}})";

std::int32_t int_at(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(b[at + static_cast<std::size_t>(k)]);
  return static_cast<std::int32_t>(v);
}
float float_at(const std::string& b, std::size_t at) {
  const std::uint32_t bits = static_cast<std::uint32_t>(int_at(b, at));
  float f = 0;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

TEST_F(PointCacheCli, SamplesAreTheObjFramesAndTheRestMeshCarriesNormalsAndUv) {
  const auto scene = write("skirt.json", kSkirt);
  const testing::CliResult r = run(q(scene) + " --no-render --out " + q(dir_ / "out"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path run_dir = dir_ / "out" / "skirt";
  const std::string bytes = testing::read_file_bytes(run_dir / "cache.pc2");
  ASSERT_GE(bytes.size(), 32u);
  EXPECT_EQ(bytes.substr(0, 12), std::string("POINTCACHE2\0", 12));
  EXPECT_EQ(int_at(bytes, 12), 1);  // version
  const int points = int_at(bytes, 16);
  EXPECT_EQ(float_at(bytes, 20), 0.0f);  // start frame
  EXPECT_EQ(float_at(bytes, 24), 1.0f);  // sample rate
  const int samples = int_at(bytes, 28);
  EXPECT_EQ(samples, 3);  // frames at t = 0, 0.02, 0.04
  ASSERT_EQ(bytes.size(), 32u + 12u * static_cast<std::size_t>(points) * static_cast<std::size_t>(samples));
  double moved = 0;
  for (int s = 0; s < samples; ++s) {
    char name[32];
    std::snprintf(name, sizeof name, "mesh_%04d.obj", s);
    const TriMesh frame = read_obj((run_dir / "frames" / name).string());
    ASSERT_EQ(frame.num_vertices(), points);
    for (int v = 0; v < points; ++v)
      for (int k = 0; k < 3; ++k) {
        const double x = float_at(bytes, 32 + 12 * (static_cast<std::size_t>(s) * static_cast<std::size_t>(points) + static_cast<std::size_t>(v)) + 4 * static_cast<std::size_t>(k));
        EXPECT_NEAR(x, frame.vertices(v, k), 1e-6 * (1 + std::abs(frame.vertices(v, k)))) << s << " " << v;
        if (s == samples - 1) {
          const double x0 = float_at(bytes, 32 + 12 * static_cast<std::size_t>(v) + 4 * static_cast<std::size_t>(k));
          moved = std::max(moved, std::abs(x - x0));
        }
      }
  }
  EXPECT_GT(moved, 1e-4);  // the skirt falls: the samples are not one frame repeated

  // The rest mesh: the first frame's vertices, unit normals, the pattern's coordinates.
  const TriMesh rest = read_obj((run_dir / "cache_rest.obj").string());
  const TriMesh first = read_obj((run_dir / "frames" / "mesh_0000.obj").string());
  EXPECT_EQ(rest.vertices, first.vertices);
  EXPECT_EQ(rest.triangles, first.triangles);
  ASSERT_EQ(rest.uv.size(), rest.triangles.size());
  std::ifstream in(run_dir / "cache_rest.obj");
  int normals = 0;
  for (std::string line; std::getline(in, line);)
    if (line.rfind("vn ", 0) == 0) {
      std::istringstream l(line.substr(3));
      double x = 0, y = 0, z = 0;
      l >> x >> y >> z;
      EXPECT_NEAR(x * x + y * y + z * z, 1.0, 1e-9) << line;
      ++normals;
    }
  EXPECT_EQ(normals, points);

  // The command on the finished run writes the same cache.
  fs::rename(run_dir / "cache.pc2", dir_ / "first.pc2");
  const testing::CliResult again = run("cache " + q(run_dir));
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(testing::read_file_bytes(run_dir / "cache.pc2"), testing::read_file_bytes(dir_ / "first.pc2"));
}

TEST_F(PointCacheCli, BadInputIsNamed) {
  const testing::CliResult none = run("cache " + q(dir_));
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_NE(none.err.find("no OBJ frames"), std::string::npos) << none.err;
  std::string text = kSkirt;
  text.replace(text.find("\"obj\": true"), 11, "\"obj\": false");
  const auto scene = write("skirt.json", text);
  const testing::CliResult r = run(q(scene) + " --no-render --out " + q(dir_ / "out"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("output.cache: \"pc2\" is built from the OBJ frames: needs \"obj\": true"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out" / "skirt"));
}

}  // namespace
}  // namespace clothsim

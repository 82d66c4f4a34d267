// Mesh input limits and scale (issue 16): the degeneracy test of check_triangles does not depend
// on the mesh's units, and read_obj refuses devices, pipes and directories, over-long lines and
// files with more vertices or triangles than its limit — stopping as soon as the limit is passed.
#include "sim/mesh/generators.hpp"
#include "sim/mesh/mesh.hpp"
#include "sim/mesh/obj_io.hpp"

#include <gtest/gtest.h>

#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <istream>
#include <streambuf>
#include <string>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TriMesh scaled(TriMesh mesh, double factor) {
  mesh.vertices *= factor;
  return mesh;
}

// The MeshError message of `f`, or "no error".
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const MeshError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CheckTriangles, ValidMeshesPassAtAnyScale) {
  // The reproducer: the grid scaled by 1e-160 (squared edges underflow) or 1e300 (overflow) was
  // refused as "triangle 0 is degenerate".
  const TriMesh grid = make_grid(1.0, 0.5, 6, 3);
  const TriMesh sleeve = make_cylinder(0.05, 0.2, 12, 5);
  for (const double factor : {1.0, 1e-160, 1e-150, 1e-300, 1e150, 1e300, 1e307}) {
    EXPECT_NO_THROW(check_triangles(scaled(grid, factor))) << factor;
    EXPECT_NO_THROW(check_triangles(scaled(sleeve, factor))) << factor;
  }
  // Far from the origin too (the test is on the mesh moved to its centre).
  TriMesh moved = scaled(grid, 1e300);
  moved.vertices.col(0).array() += 1e301;
  EXPECT_NO_THROW(check_triangles(moved));
}

TEST(CheckTriangles, DegenerateTrianglesAreFoundAtAnyScale) {
  for (const double factor : {1.0, 1e-160, 1e300}) {
    // Triangle 0 of the 2 x 2 grid is (0, 1, 4); vertex 1 moved onto the segment 0-4 flattens it.
    TriMesh collinear = scaled(make_grid(1.0, 1.0, 2, 2), factor);
    collinear.vertices.row(1) = 0.5 * collinear.vertices.row(0) + 0.5 * collinear.vertices.row(4);
    EXPECT_EQ(error_of([&] { check_triangles(collinear); }), "triangle 0 (0, 1, 4) is degenerate: zero area") << factor;
  }
  TriMesh all_at_one_point = make_grid(1.0, 1.0, 1, 1);
  all_at_one_point.vertices.setConstant(1e300);
  EXPECT_TRUE(contains(error_of([&] { check_triangles(all_at_one_point); }), "triangle 0 (0, 1, 3) is degenerate"));
}

class ObjLimits : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "clothsim_obj_limits_XXXXXX").string();
    ASSERT_NE(::mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
  }
  fs::path dir_;
};

TEST_F(ObjLimits, ScaledMeshesReadBack) {
  for (const double factor : {1e-160, 1e300}) {
    const TriMesh grid = scaled(make_grid(1.0, 1.0, 4, 4), factor);
    const std::string path = (dir_ / "scaled.obj").string();
    write_obj(path, grid.vertices, grid.triangles);
    EXPECT_EQ(read_obj(path).num_triangles(), 32) << factor;
  }
}

TEST_F(ObjLimits, DevicesPipesAndDirectoriesAreRefusedUnread) {
  // The reproducer: {"obj": "/dev/zero"} was read until memory ran out.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(error_of([] { read_obj("/dev/zero"); }),
            "/dev/zero: not a regular file (a device, pipe or socket); a mesh must be an OBJ file");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  // A named pipe with no writer would block an open(): it is refused before.
  const std::string fifo = (dir_ / "pipe.obj").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(error_of([&] { read_obj(fifo); }), fifo + ": not a regular file (a device, pipe or socket); a mesh must be an OBJ file");
  EXPECT_EQ(error_of([&] { read_obj(dir_.string()); }),
            dir_.string() + ": not a regular file (a directory); a mesh must be an OBJ file");
  // A link to a regular file is fine; a missing file keeps its message.
  const std::string file = write("square.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  fs::create_symlink(file, dir_ / "link.obj");
  EXPECT_EQ(read_obj((dir_ / "link.obj").string()).num_triangles(), 2);
  EXPECT_EQ(error_of([&] { read_obj((dir_ / "missing.obj").string()); }), (dir_ / "missing.obj").string() + ": cannot open file");
}

TEST_F(ObjLimits, VertexAndTriangleCountsAreLimited) {
  std::string text;
  for (int v = 0; v < 10; ++v) text += "v " + std::to_string(v) + " " + std::to_string(v * v) + " 0\n";
  text += "f 1 2 3\n";
  const std::string path = write("ten.obj", text);
  // At the limit the file is read (and then refused for its isolated vertices, not for the limit).
  EXPECT_TRUE(contains(error_of([&] { read_obj(path, 10); }), "isolated vertex"));
  try {
    read_obj(path, 9);
    FAIL() << "no error";
  } catch (const MeshLimitError& e) {
    EXPECT_EQ(std::string(e.what()), path + ":10: more than 9 vertices");
  }
  // Triangles: at most 4 x the vertex limit (a fan-triangulated polygon counts its triangles).
  std::string many = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  for (int f = 0; f < 17; ++f) many += "f 1 2 3\n";
  EXPECT_EQ(error_of([&] { read_obj(write("many.obj", many), 4); }),
            (dir_ / "many.obj").string() + ":21: more than 16 triangles (4 x the limit of 4 vertices)");
  EXPECT_EQ(error_of([&] { read_obj(write("polygon.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3 1 2 3 1 2 3 1 2 3 1 2 3\n"), 3); }),
            (dir_ / "polygon.obj").string() + ":4: more than 12 triangles (4 x the limit of 3 vertices)");
}

TEST_F(ObjLimits, OverlongLinesAreRefused) {
  const std::string path = write("long.obj", "v 0 0 0\n# " + std::string(kMaxObjLineLength, 'x') + "\n");
  EXPECT_EQ(error_of([&] { read_obj(path); }),
            path + ":2: line longer than " + std::to_string(kMaxObjLineLength) + " characters (not an OBJ file?)");
  // Exactly the limit is fine (it is a comment here).
  const std::string fits = write("fits.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n#" + std::string(kMaxObjLineLength - 1, 'x') +
                                                 "\nf 1 2 3\n");
  EXPECT_EQ(read_obj(fits).num_triangles(), 1);
}

// An endless stream: `line` over and over (or one endless line without a line break).
class EndlessBuffer : public std::streambuf {
 public:
  explicit EndlessBuffer(std::string line) : line_(std::move(line)) {}
  long long served = 0;  // characters handed out

 protected:
  int_type underflow() override {
    setg(line_.data(), line_.data(), line_.data() + line_.size());
    served += static_cast<long long>(line_.size());
    return traits_type::to_int_type(line_.front());
  }

 private:
  std::string line_;
};

TEST(ObjLimitsStream, ReadingStopsAsSoonAsTheLimitIsPassed) {
  EndlessBuffer vertices("v 1 2 3\n");
  std::istream in(&vertices);
  try {
    read_obj(in, "endless", 1000);
    FAIL() << "no error";
  } catch (const MeshLimitError& e) {
    EXPECT_EQ(std::string(e.what()), "endless:1001: more than 1000 vertices");
  }
  EXPECT_LT(vertices.served, 1002 * 8);

  EndlessBuffer no_breaks("0000000000000000");
  std::istream zeros(&no_breaks);
  EXPECT_EQ(error_of([&] { read_obj(zeros, "zeros"); }),
            "zeros:1: line longer than " + std::to_string(kMaxObjLineLength) + " characters (not an OBJ file?)");
  EXPECT_LT(no_breaks.served, static_cast<long long>(kMaxObjLineLength) + 32);
}

}  // namespace
}  // namespace clothsim

// OBJ reading and writing: exact round trip, face-entry forms, fan triangulation, and errors
// that name the file and line.
#include "sim/mesh/obj_io.hpp"

#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

// Gives each test its own scratch directory under the system temp directory.
class ObjIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::random_device device;
    dir_ = fs::temp_directory_path() /
           ("clothsim_obj_io_" + std::string(info->name()) + "_" + std::to_string(device()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  // Writes `text` to a file called `name` in the scratch directory and returns its path.
  std::string write_file(const std::string& name, const std::string& text) const {
    const std::string path = (dir_ / name).string();
    std::ofstream out(path, std::ios::binary);
    out << text;
    return path;
  }

  // The MeshError message read_obj throws for `path`, or "no error".
  static std::string error_of(const std::string& path) {
    try {
      read_obj(path);
    } catch (const MeshError& e) {
      return e.what();
    }
    return "no error";
  }

  fs::path dir_;
};

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// A unit square split into two triangles, as an OBJ prelude of four vertices.
const std::string kFourVertices = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

TEST_F(ObjIoTest, RoundTripIsBitExact) {
  TriMesh mesh = make_grid(1.3, 0.7, 5, 4);
  // Coordinates with long binary expansions and extreme magnitudes.
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> noise(-1.0, 1.0);
  for (int v = 0; v < mesh.num_vertices(); ++v) mesh.vertices(v, 2) = noise(rng) / 3.0;
  mesh.vertices(0, 2) = 1e-300;
  mesh.vertices(1, 2) = -0.0;
  mesh.vertices(2, 2) = 0.1;
  mesh.vertices(3, 2) = 0.123456789123456789;
  mesh.vertices(5, 2) = std::nextafter(0.25, 1.0);
  mesh.vertices(4, 2) = 5e-324;  // smallest subnormal

  const std::string path = (dir_ / "round_trip.obj").string();
  write_obj(path, mesh.vertices, mesh.triangles, "round trip test");
  {
    std::ifstream in(path);
    std::string first;
    std::getline(in, first);
    EXPECT_EQ(first, "# round trip test");
  }
  const TriMesh back = read_obj(path);
  ASSERT_EQ(back.num_vertices(), mesh.num_vertices());
  for (int v = 0; v < mesh.num_vertices(); ++v)
    for (int k = 0; k < 3; ++k)
      EXPECT_TRUE(same_bits(back.vertices(v, k), mesh.vertices(v, k)))
          << "vertex " << v << " coordinate " << k << ": " << back.vertices(v, k) << " vs " << mesh.vertices(v, k);
  EXPECT_EQ(back.triangles, mesh.triangles);
}

TEST_F(ObjIoTest, TextureCoordinatesRoundTripOnePerVertexAndPair) {
  // Two triangles of the unit square: their shared edge has equal coordinates on both sides
  // (4 vt), then different ones on one side, as across a seam between two pattern pieces (6 vt).
  TriMesh m;
  m.vertices.resize(4, 3);
  m.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  const Eigen::Vector2d a(0.1, 0.2), b(1.1, 0.2), c(1.1, 1.2), d(0.1, 1.2);
  for (const bool seam : {false, true}) {
    std::vector<std::array<Eigen::Vector2d, 3>> uv = {{a, b, c}, {a, c, d}};
    if (seam) uv[1] = {Eigen::Vector2d(5, 5), Eigen::Vector2d(6, 6), d};
    const std::string path = (dir_ / "uv.obj").string();
    Eigen::MatrixX3d normals = Eigen::MatrixX3d::Zero(4, 3);
    normals.col(2).setOnes();
    write_obj(path, m.vertices, m.triangles, "", &normals, &uv);
    std::ifstream in(path);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::size_t count = 0;
    for (std::size_t at = text.find("\nvt "); at != std::string::npos; at = text.find("\nvt ", at + 1)) ++count;
    EXPECT_EQ(count + (text.rfind("vt ", 0) == 0 ? 1 : 0), seam ? 6u : 4u) << text;
    EXPECT_NE(text.find("f 1/1/1 2/2/2 3/3/3"), std::string::npos) << text;
    const TriMesh back = read_obj(path);
    ASSERT_EQ(back.uv.size(), 2u);
    for (std::size_t t = 0; t < 2; ++t)
      for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(back.uv[t][k], uv[t][k]) << t << ' ' << k;
  }
  std::vector<std::array<Eigen::Vector2d, 3>> one = {{a, b, c}};
  EXPECT_THROW(write_obj((dir_ / "bad.obj").string(), m.vertices, m.triangles, "", nullptr, &one), MeshError);
}

TEST_F(ObjIoTest, WritesOneBasedFacesAndNoCommentWhenEmpty) {
  const TriMesh mesh = make_grid(1.0, 1.0, 1, 1);
  const std::string path = (dir_ / "plain.obj").string();
  write_obj(path, mesh.vertices, mesh.triangles);
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.rfind("v ", 0), 0u) << text;
  EXPECT_NE(text.find("\nf 1 2 4\nf 1 4 3\n"), std::string::npos) << text;
}

TEST_F(ObjIoTest, WriteToUnwritablePathThrowsNamingPath) {
  const TriMesh mesh = make_grid(1.0, 1.0, 1, 1);
  const std::string path = (dir_ / "no_such_dir" / "out.obj").string();
  try {
    write_obj(path, mesh.vertices, mesh.triangles);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST_F(ObjIoTest, PolygonsAreFanTriangulated) {
  // A pentagon 1..5 and, sharing edge 2-3, a quad 3 2 6 7.
  const std::string path = write_file("polygons.obj",
                                      "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\n"
                                      "v 3 -1 0\nv 4 0 0\n"
                                      "f 1 2 3 4 5\n"
                                      "f 3 2 6 7\n");
  const TriMesh mesh = read_obj(path);
  EXPECT_EQ(mesh.num_vertices(), 7);
  const std::vector<Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {2, 1, 5}, {2, 5, 6}};
  EXPECT_EQ(mesh.triangles, expected);
}

TEST_F(ObjIoTest, ParsesSlashFormsAndNegativeIndices) {
  const std::string path = write_file("forms.obj",
                                      kFourVertices +
                                          "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
                                          "f 1/1/1 2/2/1 3/3/1\n"
                                          "v 2 0 0\nv 2 1 0\n"
                                          "f 1//1 3//1 4//1\n"
                                          // Six vertices so far: -1 is vertex 6, -4 vertex 3, -5 vertex 2.
                                          "f 2/2 5/1 -1/3\n"
                                          "f -5/1/1 -1/1/1 -4\n");
  const TriMesh mesh = read_obj(path);
  EXPECT_EQ(mesh.num_vertices(), 6);
  const std::vector<Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {1, 4, 5}, {1, 5, 2}};
  EXPECT_EQ(mesh.triangles, expected);
  EXPECT_EQ(mesh.vertices(5, 0), 2.0);
  EXPECT_EQ(mesh.vertices(5, 1), 1.0);
}

TEST_F(ObjIoTest, IgnoresOtherLineTypesCommentsAndCrlf) {
  const std::string path = write_file("decorated.obj",
                                      "# exported by something\r\n"
                                      "mtllib cloth.mtl\r\n"
                                      "o cloth\r\n"
                                      "g panel\r\n"
                                      "\r\n"
                                      "v 0 0 0   # origin\r\n"
                                      "v 1.0e0 0 0\r\n"
                                      "v\t1 1 0 1.0\r\n"  // with w
                                      "v 0 1 0 0.5 0.5 0.5\r\n"  // with a colour
                                      "vn 0 0 1\r\n"
                                      "vt 0.5 0.5\r\n"
                                      "usemtl cotton\r\n"
                                      "s off\r\n"
                                      "f 1 2 3 4\r\n"
                                      "l 1 3\r\n");
  const TriMesh mesh = read_obj(path);
  EXPECT_EQ(mesh.num_vertices(), 4);
  EXPECT_EQ(mesh.triangles, (std::vector<Triangle>{{0, 1, 2}, {0, 2, 3}}));
  EXPECT_EQ(mesh.vertices(1, 0), 1.0);
}

TEST_F(ObjIoTest, MissingFile) {
  const std::string path = (dir_ / "absent.obj").string();
  EXPECT_EQ(error_of(path), path + ": cannot open file");
}

TEST_F(ObjIoTest, FaceIndexOutOfRangeNamesFileAndLine) {
  std::string text;
  for (int i = 0; i < 10; ++i) text += "v " + std::to_string(i) + " " + std::to_string(i * i) + " 0\n";
  text += "f 1 2 3\n";
  text += "f 1 3 40\n";  // line 12
  const std::string path = write_file("mesh.obj", text);
  EXPECT_EQ(error_of(path), path + ":12: face index 40 out of range (file has 10 vertices)");
}

TEST_F(ObjIoTest, NegativeIndexBeforeFirstVertexIsOutOfRange) {
  const std::string path = write_file("negative.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n");
  const std::string message = error_of(path);
  EXPECT_NE(message.find(path + ":3: face index -3 out of range"), std::string::npos) << message;
}

TEST_F(ObjIoTest, MalformedLinesNameFileAndLine) {
  const std::string bad_vertex = write_file("bad_vertex.obj", "v 0 0 0\nv 1 0 0\nv 1 1\nf 1 2 3\n");
  EXPECT_EQ(error_of(bad_vertex), bad_vertex + ":3: malformed vertex line");

  const std::string bad_number = write_file("bad_number.obj", "v 0 0 0\nv 1 0x 0\nv 1 1 0\nf 1 2 3\n");
  EXPECT_EQ(error_of(bad_number), bad_number + ":2: malformed vertex line");

  const std::string nan_vertex = write_file("nan_vertex.obj", "v 0 0 0\nv 1 nan 0\nv 1 1 0\nf 1 2 3\n");
  EXPECT_NE(error_of(nan_vertex).find(nan_vertex + ":2: non-finite vertex coordinate"), std::string::npos);

  const std::string short_face = write_file("short_face.obj", kFourVertices + "f 1 2\n");
  EXPECT_NE(error_of(short_face).find(short_face + ":5: malformed face line"), std::string::npos);

  const std::string bad_entry = write_file("bad_entry.obj", kFourVertices + "f 1 2 3\nf 1 3 4/a\n");
  EXPECT_EQ(error_of(bad_entry), bad_entry + ":6: malformed face entry '4/a'");

  const std::string zero = write_file("zero.obj", kFourVertices + "f 0 1 2\n");
  EXPECT_NE(error_of(zero).find(zero + ":5: face index 0 is invalid"), std::string::npos);
}

TEST_F(ObjIoTest, FileWithoutFaces) {
  const std::string path = write_file("points.obj", kFourVertices);
  EXPECT_EQ(error_of(path), path + ": file has no faces");
}

TEST_F(ObjIoTest, NonManifoldEdgeIsRejectedNamingFile) {
  // Three triangles share edge 1-2 (0-based 0-1).
  const std::string path = write_file("fin.obj",
                                      "v 0 0 0\nv 1 0 0\nv 0.5 1 0\nv 0.5 -1 0\nv 0.5 0 1\n"
                                      "f 1 2 3\nf 2 1 4\nf 1 2 5\n");
  const std::string message = error_of(path);
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  EXPECT_NE(message.find("non-manifold edge (0, 1)"), std::string::npos) << message;
}

TEST_F(ObjIoTest, InconsistentOrientationIsRejectedNamingFile) {
  // The second triangle runs along 1→2 in the same direction as the first.
  const std::string path = write_file("flipped.obj", kFourVertices + "f 1 2 3\nf 1 2 4\n");
  const std::string message = error_of(path);
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  EXPECT_NE(message.find("inconsistent orientation at edge (0, 1)"), std::string::npos) << message;
}

TEST_F(ObjIoTest, IsolatedVertexIsRejectedNamingFile) {
  const std::string path = write_file("isolated.obj", kFourVertices + "v 5 5 5\nf 1 2 3 4\n");
  const std::string message = error_of(path);
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  EXPECT_NE(message.find("isolated vertex 4"), std::string::npos) << message;
}

TEST_F(ObjIoTest, DegenerateTriangleIsRejectedNamingFile) {
  const std::string path = write_file("collinear.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  const std::string message = error_of(path);
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  EXPECT_NE(message.find("degenerate"), std::string::npos) << message;
}

}  // namespace
}  // namespace clothsim

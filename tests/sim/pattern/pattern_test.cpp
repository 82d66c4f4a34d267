// Sewing patterns → control mesh (sim/pattern/pattern.hpp): a square piece (topology, uv, areas,
// edge lengths, edge runs, irregular vertices, shape, grain), a tube sewn from one rectangle, the
// two-piece skirt, three pieces meeting at one point (sectors; an L), a seam along a wrapping
// two-edge path, the placement (wrap, rotation order, translation), the errors (each naming
// piece, edge or seam) and determinism.
#include "sim/pattern/pattern.hpp"

#include "sim/mesh/topology.hpp"
#include "sim/shell/ghost_layer.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <numbers>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace clothsim {
namespace {

constexpr double kPi = std::numbers::pi;

std::size_t at(int i) { return static_cast<std::size_t>(i); }

Eigen::Vector3d vertex(const TriMesh& mesh, int v) { return mesh.vertices.row(v).transpose(); }

double pattern_area(const std::array<Eigen::Vector2d, 3>& uv) {
  const Eigen::Vector2d a = uv[1] - uv[0], b = uv[2] - uv[0];
  return 0.5 * (a.x() * b.y() - a.y() * b.x());
}

// Unique undirected edges of the mesh.
std::set<std::pair<int, int>> edges_of(const TriMesh& mesh) {
  std::set<std::pair<int, int>> edges;
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[at(k)], b = t[at((k + 1) % 3)];
      edges.emplace(std::min(a, b), std::max(a, b));
    }
  return edges;
}

PatternPiece rectangle(const std::string& name, double w, double h) {
  PatternPiece piece;
  piece.name = name;
  piece.points = {{0.0, 0.0}, {w, 0.0}, {w, h}, {0.0, h}};
  return piece;
}

// The contract's two-piece skirt.
PatternSpec skirt(double edge_length) {
  PatternSpec spec;
  spec.edge_length = edge_length;
  for (const char* name : {"front", "back"}) {
    PatternPiece piece;
    piece.name = name;
    piece.points = {{-0.25, 0.0}, {0.25, 0.0}, {0.25, 0.5}, {-0.25, 0.5}};
    piece.placement.wrap_radius = 0.17;
    piece.placement.translate = Eigen::Vector3d(0.0, 0.45, 0.0);
    spec.pieces.push_back(piece);
  }
  spec.pieces[1].placement.rotate_deg = Eigen::Vector3d(0.0, 180.0, 0.0);
  spec.seams.push_back({{"front", 1, 1}, {"back", 3, 3}, true});
  spec.seams.push_back({{"front", 3, 3}, {"back", 1, 1}, true});
  return spec;
}

// Expects build_pattern to throw a MeshError whose message contains every one of `parts`.
void expect_error(const PatternSpec& spec, const std::vector<std::string>& parts) {
  try {
    (void)build_pattern(spec);
    ADD_FAILURE() << "no error; expected one mentioning " << parts.front();
  } catch (const MeshError& error) {
    const std::string what = error.what();
    EXPECT_EQ(what.rfind("pattern: ", 0), 0u) << what;
    for (const std::string& part : parts) EXPECT_NE(what.find(part), std::string::npos) << "'" << part << "' not in: " << what;
  }
}

// Every triangle's normal points away from the y axis (seen from its centroid).
void expect_outward(const TriMesh& mesh) {
  for (const Triangle& t : mesh.triangles) {
    const Eigen::Vector3d a = vertex(mesh, t[0]), b = vertex(mesh, t[1]), c = vertex(mesh, t[2]);
    const Eigen::Vector3d centroid = (a + b + c) / 3.0;
    const Eigen::Vector3d radial(centroid.x(), 0.0, centroid.z());
    ASSERT_GT((b - a).cross(c - a).dot(radial), 0.0);
  }
}

void expect_isolated_irregular(const TriMesh& mesh) {
  const ExtendedMesh ext = build_ghost_layer(mesh);
  for (const Triangle& t : mesh.triangles) ASSERT_LE(irregular_vertex_count(ext, t), 1);
}

// A tube (an annulus): manifold, two boundary loops, Euler characteristic 0.
void expect_tube(const TriMesh& mesh) {
  const Topology topology(mesh.num_vertices(), mesh.triangles);
  EXPECT_EQ(topology.boundary_loops().size(), 2u);
  const long euler = static_cast<long>(mesh.num_vertices()) - static_cast<long>(edges_of(mesh).size()) + mesh.num_triangles();
  EXPECT_EQ(euler, 0);
}

TEST(BuildPattern, SquarePiece) {
  PatternSpec spec;
  spec.edge_length = 0.05;
  spec.pieces.push_back(rectangle("square", 0.5, 0.5));
  spec.pieces[0].grain_deg = 30.0;
  const PatternMesh out = build_pattern(spec);
  const TriMesh& mesh = out.mesh;
  ASSERT_GT(mesh.num_triangles(), 0);
  ASSERT_EQ(mesh.uv.size(), mesh.triangles.size());
  ASSERT_EQ(mesh.warp.size(), mesh.triangles.size());
  ASSERT_EQ(out.triangle_piece.size(), mesh.triangles.size());
  const Topology topology(mesh.num_vertices(), mesh.triangles);
  EXPECT_EQ(topology.boundary_loops().size(), 1u);

  double area = 0.0;
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    EXPECT_EQ(out.triangle_piece[at(t)], 0);
    const auto& uv = mesh.uv[at(t)];
    const double a = pattern_area(uv);
    EXPECT_GT(a, 0.0) << "triangle " << t;
    area += a;
    for (int k = 0; k < 3; ++k) {
      // The uv of a corner is its pattern point: inside the square, and (no placement) the
      // vertex's start position.
      const Eigen::Vector2d q = uv[at(k)];
      EXPECT_GE(q.x(), -1e-12);
      EXPECT_LE(q.x(), 0.5 + 1e-12);
      EXPECT_GE(q.y(), -1e-12);
      EXPECT_LE(q.y(), 0.5 + 1e-12);
      EXPECT_EQ(vertex(mesh, mesh.triangles[at(t)][at(k)]), Eigen::Vector3d(q.x(), q.y(), 0.0));
    }
    EXPECT_NEAR((mesh.warp[at(t)] - Eigen::Vector3d(std::cos(kPi / 6), std::sin(kPi / 6), 0.0)).norm(), 0.0, 1e-12);
  }
  EXPECT_NEAR(area, 0.25, 1e-12);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    EXPECT_EQ(vertex(mesh, v).z(), 0.0);
    EXPECT_EQ(out.placed[at(v)].size(), 1u);
  }

  const std::set<std::pair<int, int>> edges = edges_of(mesh);
  double sum = 0.0;
  for (const auto& [a, b] : edges) sum += (vertex(mesh, a) - vertex(mesh, b)).norm();
  const double mean = sum / static_cast<double>(edges.size());
  EXPECT_NEAR(mean, 0.05, 0.25 * 0.05);

  // Edge runs: from corner i to corner i + 1 along the edge, 2·5 + 1 vertices, evenly spaced.
  ASSERT_EQ(out.edge_vertices.size(), 1u);
  ASSERT_EQ(out.edge_vertices[0].size(), 4u);
  const auto& corners = spec.pieces[0].points;
  for (int e = 0; e < 4; ++e) {
    const std::vector<int>& run = out.edge_vertices[0][at(e)];
    ASSERT_EQ(run.size(), 11u) << "edge " << e;
    const Eigen::Vector3d p(corners[at(e)].x(), corners[at(e)].y(), 0.0);
    const Eigen::Vector3d q(corners[at((e + 1) % 4)].x(), corners[at((e + 1) % 4)].y(), 0.0);
    for (std::size_t k = 0; k < run.size(); ++k) {
      const Eigen::Vector3d expected = p + (static_cast<double>(k) / 10.0) * (q - p);
      EXPECT_NEAR((vertex(mesh, run[k]) - expected).norm(), 0.0, 1e-12) << "edge " << e << " vertex " << k;
      EXPECT_TRUE(topology.is_boundary(run[k]));
    }
  }
  expect_isolated_irregular(mesh);

  // Shape: no pattern angle below 30° (measured 32.6°: the lattice keeps 0.6·spacing off the
  // boundary), and the lattice follows the grain: most pattern edges are at 30° + k·60°.
  double min_angle = 180.0;
  int along = 0, total = 0;
  for (const auto& uv : mesh.uv)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d a = uv[at((k + 1) % 3)] - uv[at(k)], b = uv[at((k + 2) % 3)] - uv[at(k)];
      min_angle = std::min(min_angle, std::acos(a.normalized().dot(b.normalized())) * 180.0 / kPi);
      const double deg = std::atan2(a.y(), a.x()) * 180.0 / kPi - 30.0;
      const double off = std::abs(deg / 60.0 - std::round(deg / 60.0)) * 60.0;
      along += off < 1.0 ? 1 : 0;
      ++total;
    }
  EXPECT_GE(min_angle, 30.0);
  EXPECT_GT(static_cast<double>(along) / total, 0.5) << along << " of " << total;
}

TEST(BuildPattern, TubeFromOneRectangle) {
  const double r = 0.1;
  PatternSpec spec;
  spec.edge_length = 0.02;
  spec.pieces.push_back(rectangle("tube", 2 * kPi * r, 0.4));
  spec.pieces[0].placement.wrap_radius = r;
  spec.seams.push_back({{"tube", 1, 1}, {"tube", 3, 3}, true});
  const PatternMesh out = build_pattern(spec);
  const TriMesh& mesh = out.mesh;
  expect_tube(mesh);
  ASSERT_EQ(out.seam_gap.size(), 1u);
  EXPECT_LT(out.seam_gap[0], 1e-9 * r);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d x = vertex(mesh, v);
    EXPECT_NEAR(std::hypot(x.x(), x.z()), r, 1e-9);
  }
  expect_outward(mesh);
  expect_isolated_irregular(mesh);
  // The seam's vertices are one piece vertex from each side.
  const std::vector<int>& right = out.edge_vertices[0][1];
  const std::vector<int>& left = out.edge_vertices[0][3];
  ASSERT_EQ(right.size(), left.size());
  for (std::size_t k = 0; k < right.size(); ++k) {
    EXPECT_EQ(right[k], left[left.size() - 1 - k]);
    EXPECT_EQ(out.placed[at(right[k])].size(), 2u);
  }
}

TEST(BuildPattern, TwoPieceSkirt) {
  const double r = 0.17;
  const PatternSpec spec = skirt(0.02);
  const PatternMesh out = build_pattern(spec);
  const TriMesh& mesh = out.mesh;
  expect_tube(mesh);
  expect_outward(mesh);
  expect_isolated_irregular(mesh);

  // Independently: the placed corners of front edge 1 (x = 0.25) and back edge 3 (x = -0.25).
  const auto wrap = [r](double x, double y) { return Eigen::Vector3d(r * std::sin(x / r), y, r * std::cos(x / r)); };
  Eigen::Matrix3d ry;  // 180° about y
  ry << std::cos(kPi), 0.0, std::sin(kPi), 0.0, 1.0, 0.0, -std::sin(kPi), 0.0, std::cos(kPi);
  const Eigen::Vector3d shift(0.0, 0.45, 0.0);
  const Eigen::Vector3d front = wrap(0.25, 0.0) + shift;
  const Eigen::Vector3d back = ry * wrap(-0.25, 0.0) + shift;
  const double gap = (front - back).norm();
  EXPECT_NEAR(gap, 2 * r * std::abs(std::cos(0.25 / r)), 1e-12);
  ASSERT_EQ(out.seam_gap.size(), 2u);
  EXPECT_NEAR(out.seam_gap[0], gap, 1e-12);
  EXPECT_NEAR(out.seam_gap[1], gap, 1e-12);

  // Vertex count: the two pieces alone, minus the vertices merged along the two seams.
  int alone = 0;
  for (int p = 0; p < 2; ++p) {
    PatternSpec one;
    one.edge_length = spec.edge_length;
    one.pieces.push_back(spec.pieces[at(p)]);
    alone += build_pattern(one).mesh.num_vertices();
  }
  const int seam_vertices = static_cast<int>(out.edge_vertices[0][1].size() + out.edge_vertices[0][3].size());
  EXPECT_EQ(seam_vertices, 2 * (2 * 13 + 1));  // 0.5 m / 0.04 m → 13 segments, split → 26
  EXPECT_EQ(mesh.num_vertices(), alone - seam_vertices);
  int two = 0;
  for (const auto& list : out.placed) two += list.size() == 2 ? 1 : 0;
  EXPECT_EQ(two, seam_vertices);
  // A merged vertex sits at the mean of its placed positions.
  for (int v : out.edge_vertices[0][1]) {
    const auto& list = out.placed[at(v)];
    EXPECT_NEAR((vertex(mesh, v) - 0.5 * (list[0] + list[1])).norm(), 0.0, 1e-15);
    EXPECT_NEAR((list[0] - list[1]).norm(), gap, 1e-12);
  }
}

TEST(BuildPattern, ThreeSectorsMeetAtTheCentre) {
  const double radius = 0.3;
  PatternSpec spec;
  spec.edge_length = 0.03;
  for (int i = 0; i < 3; ++i) {
    PatternPiece piece;
    piece.name = "sector" + std::to_string(i);
    piece.points.emplace_back(0.0, 0.0);
    for (int k = 0; k <= 8; ++k) {
      const double phi = (2 * kPi / 3) * k / 8.0;
      piece.points.emplace_back(radius * std::cos(phi), radius * std::sin(phi));
    }
    piece.placement.rotate_deg = Eigen::Vector3d(0.0, 0.0, 120.0 * i);
    spec.pieces.push_back(piece);
  }
  // Sector i's last edge (arc end → centre) onto sector i+1's first edge (centre → arc start).
  for (int i = 0; i < 3; ++i)
    spec.seams.push_back({{"sector" + std::to_string(i), 9, 9}, {"sector" + std::to_string((i + 1) % 3), 0, 0}, true});
  const PatternMesh out = build_pattern(spec);
  const TriMesh& mesh = out.mesh;
  const Topology topology(mesh.num_vertices(), mesh.triangles);
  EXPECT_EQ(topology.boundary_loops().size(), 1u);
  const int centre = out.edge_vertices[0][0].front();
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(out.edge_vertices[at(i)][0].front(), centre);
    EXPECT_EQ(out.edge_vertices[at(i)][9].back(), centre);
  }
  EXPECT_EQ(out.placed[at(centre)].size(), 3u);
  EXPECT_FALSE(topology.is_boundary(centre));
  EXPECT_NEAR(vertex(mesh, centre).norm(), 0.0, 1e-15);
  for (double gap : out.seam_gap) EXPECT_LT(gap, 1e-12);
  expect_isolated_irregular(mesh);
}

TEST(BuildPattern, ThreeSquaresInAnL) {
  PatternSpec spec;
  spec.edge_length = 0.05;
  spec.pieces = {rectangle("a", 0.3, 0.3), rectangle("b", 0.3, 0.3), rectangle("c", 0.3, 0.3)};
  spec.pieces[1].placement.translate = Eigen::Vector3d(0.3, 0.0, 0.0);
  spec.pieces[2].placement.translate = Eigen::Vector3d(0.0, 0.3, 0.0);
  spec.seams.push_back({{"a", 1, 1}, {"b", 3, 3}, true});  // a's right edge, b's left edge
  spec.seams.push_back({{"a", 2, 2}, {"c", 0, 0}, true});  // a's top edge, c's bottom edge
  const PatternMesh out = build_pattern(spec);
  const Topology topology(out.mesh.num_vertices(), out.mesh.triangles);
  EXPECT_EQ(topology.boundary_loops().size(), 1u);
  // a's corner (0.3, 0.3) = b's (0, 0.3) = c's (0.3, 0): one vertex.
  const int corner = out.edge_vertices[0][1].back();
  EXPECT_EQ(out.edge_vertices[1][3].front(), corner);
  EXPECT_EQ(out.edge_vertices[2][0].back(), corner);
  EXPECT_EQ(out.placed[at(corner)].size(), 3u);
  EXPECT_TRUE(topology.is_boundary(corner));
  EXPECT_NEAR((vertex(out.mesh, corner) - Eigen::Vector3d(0.3, 0.3, 0.0)).norm(), 0.0, 1e-15);
  expect_isolated_irregular(out.mesh);
}

TEST(BuildPattern, SeamAlongATwoEdgePathThatWraps) {
  // A square sewn along its top edge to a piece whose bottom is two edges, 4 → 0 (wrapping).
  PatternSpec spec;
  spec.edge_length = 0.05;
  spec.pieces.push_back(rectangle("lower", 0.4, 0.4));
  PatternPiece upper;
  upper.name = "upper";
  upper.points = {{0.2, 0.0}, {0.4, 0.0}, {0.4, 0.3}, {0.0, 0.3}, {0.0, 0.0}};
  upper.placement.translate = Eigen::Vector3d(0.0, 0.4, 0.0);
  spec.pieces.push_back(upper);
  spec.seams.push_back({{"lower", 2, 2}, {"upper", 4, 0}, true});
  const PatternMesh out = build_pattern(spec);
  const TriMesh& mesh = out.mesh;
  const Topology topology(mesh.num_vertices(), mesh.triangles);
  EXPECT_EQ(topology.boundary_loops().size(), 1u);
  EXPECT_LT(out.seam_gap[0], 1e-12);
  double area = 0.0;
  for (const auto& uv : mesh.uv) area += pattern_area(uv);
  EXPECT_NEAR(area, 0.4 * 0.4 + 0.4 * 0.3, 1e-12);
  // upper's edge 4 runs from (0, 0) to (0.2, 0) and edge 0 on to (0.4, 0), placed 0.4 m up.
  const std::vector<int>& e4 = out.edge_vertices[1][4];
  const std::vector<int>& e0 = out.edge_vertices[1][0];
  EXPECT_NEAR((vertex(mesh, e4.front()) - Eigen::Vector3d(0.0, 0.4, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((vertex(mesh, e4.back()) - Eigen::Vector3d(0.2, 0.4, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_EQ(e4.back(), e0.front());
  EXPECT_NEAR((vertex(mesh, e0.back()) - Eigen::Vector3d(0.4, 0.4, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_EQ(e4.size() + e0.size() - 1, out.edge_vertices[0][2].size());
  expect_isolated_irregular(mesh);
}

TEST(BuildPattern, PlacementWrapsThenRotatesAboutXThenYThenZThenTranslates) {
  const double r = 0.3;
  PatternSpec spec;
  spec.edge_length = 0.05;
  spec.pieces.push_back(rectangle("panel", 0.4, 0.3));
  spec.pieces[0].placement.wrap_radius = r;
  spec.pieces[0].placement.rotate_deg = Eigen::Vector3d(30.0, 45.0, 60.0);
  spec.pieces[0].placement.translate = Eigen::Vector3d(1.0, 2.0, 3.0);
  const PatternMesh out = build_pattern(spec);
  // Rotation matrices written out: Rz(60°)·Ry(45°)·Rx(30°).
  const auto c = [](double deg) { return std::cos(deg * kPi / 180.0); };
  const auto s = [](double deg) { return std::sin(deg * kPi / 180.0); };
  Eigen::Matrix3d rx, ry, rz;
  rx << 1, 0, 0, 0, c(30), -s(30), 0, s(30), c(30);
  ry << c(45), 0, s(45), 0, 1, 0, -s(45), 0, c(45);
  rz << c(60), -s(60), 0, s(60), c(60), 0, 0, 0, 1;
  const Eigen::Matrix3d rotation = rz * ry * rx;
  ASSERT_EQ(out.mesh.uv.size(), out.mesh.triangles.size());
  for (std::size_t t = 0; t < out.mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d q = out.mesh.uv[t][at(k)];
      const Eigen::Vector3d wrapped(r * std::sin(q.x() / r), q.y(), r * std::cos(q.x() / r));
      const Eigen::Vector3d expected = rotation * wrapped + Eigen::Vector3d(1.0, 2.0, 3.0);
      ASSERT_NEAR((vertex(out.mesh, out.mesh.triangles[t][at(k)]) - expected).norm(), 0.0, 1e-12);
    }
  // The normal points away from the (rotated, translated) wrap axis.
  const Eigen::Vector3d axis = rotation * Eigen::Vector3d::UnitY(), origin(1.0, 2.0, 3.0);
  for (const Triangle& t : out.mesh.triangles) {
    const Eigen::Vector3d a = vertex(out.mesh, t[0]), b = vertex(out.mesh, t[1]), cc = vertex(out.mesh, t[2]);
    Eigen::Vector3d radial = (a + b + cc) / 3.0 - origin;
    radial -= radial.dot(axis) * axis;
    ASSERT_GT((b - a).cross(cc - a).dot(radial), 0.0);
  }
  // Grain 0 (along the pattern's x): around the cylinder, perpendicular to its axis.
  for (const Eigen::Vector3d& w : out.mesh.warp) {
    EXPECT_NEAR(w.norm(), 1.0, 1e-12);
    EXPECT_LT(std::abs(w.dot(axis)), 1e-9);
  }
}

TEST(BuildPattern, ErrorsNameThePieceEdgeAndSeam) {
  {  // lengths differ by more than 1 %
    PatternSpec spec = skirt(0.05);
    spec.pieces[1].points = {{-0.25, 0.0}, {0.25, 0.0}, {0.25, 0.48}, {-0.25, 0.48}};
    spec.seams.pop_back();
    expect_error(spec, {"seam 0 (front edge 1 \u2013 back edge 3)", "0.500 m", "0.480 m", "4.1 %", "more than 1 %"});
  }
  {  // an edge sewn twice
    PatternSpec spec = skirt(0.05);
    spec.seams[1] = {{"back", 1, 1}, {"front", 1, 1}, true};
    expect_error(spec, {"front edge 1 is sewn twice", "seam 0", "seam 1"});
  }
  {  // a self-intersecting (bow-tie) piece
    PatternSpec spec;
    spec.edge_length = 0.05;
    spec.pieces.push_back({"bow", {{0.0, 0.0}, {1.0, 1.0}, {1.0, 0.0}, {0.0, 1.0}}, 0.0, {}});
    expect_error(spec, {"piece bow", "edge 0", "edge 2", "intersect"});
  }
  {  // a clockwise piece
    PatternSpec spec;
    spec.edge_length = 0.05;
    spec.pieces.push_back({"cw", {{0.0, 0.0}, {0.0, 1.0}, {1.0, 1.0}, {1.0, 0.0}}, 0.0, {}});
    expect_error(spec, {"piece cw", "clockwise"});
  }
  {  // the wrong `reversed`
    PatternSpec spec = skirt(0.05);
    spec.seams[0].reversed = false;
    expect_error(spec, {"seam 0 (front edge 1 \u2013 back edge 3)", "reversed = true"});
  }
  {  // the wrong `reversed` on a tube: a Möbius band
    PatternSpec spec;
    spec.edge_length = 0.05;
    spec.pieces.push_back(rectangle("band", 1.0, 0.3));
    spec.seams.push_back({{"band", 1, 1}, {"band", 3, 3}, false});
    expect_error(spec, {"seam 0 (band edge 1 \u2013 band edge 3)", "reversed = true"});
  }
  {  // unknown piece
    PatternSpec spec = skirt(0.05);
    spec.seams[1].b.piece = "sleeve";
    expect_error(spec, {"seam 1 side b", "unknown piece 'sleeve'"});
  }
  {  // edge out of range
    PatternSpec spec = skirt(0.05);
    spec.seams[0].a.first_edge = spec.seams[0].a.last_edge = 4;
    expect_error(spec, {"seam 0 side a", "front", "edge 4 is out of range", "4 edges"});
  }
  for (double bad : {0.0, -0.01, std::nan("")}) {  // non-positive or non-finite edge_length
    PatternSpec spec = skirt(bad);
    expect_error(spec, {"edge_length must be positive and finite"});
  }
  {  // duplicate and empty names, a repeated point, a zero-length edge, a bad wrap radius
    PatternSpec spec = skirt(0.05);
    spec.pieces[1].name = "front";
    expect_error(spec, {"pieces 0 and 1 are both named front"});
    spec.pieces[1].name = "";
    expect_error(spec, {"piece 1 has an empty name"});
    spec = skirt(0.05);
    spec.pieces[0].points = {{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.5, 0.0}, {0.0, 1.0}};
    expect_error(spec, {"piece front", "edge"});
    spec.pieces[0].points = {{0.0, 0.0}, {1.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}};
    expect_error(spec, {"piece front", "edge 1", "zero length"});
    spec.pieces[0].points = {{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 0.0}, {-1.0, 1.0}, {-1.0, 0.5}};
    expect_error(spec, {"piece front", "points 0 and 3 coincide"});
    spec = skirt(0.05);
    spec.pieces[1].placement.wrap_radius = 0.0;
    expect_error(spec, {"piece back", "wrap radius"});
  }
  {  // a seam too short for the edge length: a tube whose sewn edges are one segment long
    PatternSpec spec;
    spec.edge_length = 0.2;
    spec.pieces.push_back(rectangle("thin", 0.2, 0.05));
    spec.seams.push_back({{"thin", 1, 1}, {"thin", 3, 3}, true});
    expect_error(spec, {"seam 0 (thin edge 1 \u2013 thin edge 3)", "edge_length"});
  }
}

TEST(BuildPattern, Deterministic) {
  const PatternSpec spec = skirt(0.02);
  const PatternMesh a = build_pattern(spec);
  const PatternMesh b = build_pattern(spec);
  ASSERT_EQ(a.mesh.num_vertices(), b.mesh.num_vertices());
  EXPECT_TRUE(a.mesh.vertices == b.mesh.vertices);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  ASSERT_EQ(a.mesh.uv.size(), b.mesh.uv.size());
  for (std::size_t t = 0; t < a.mesh.uv.size(); ++t)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(a.mesh.uv[t][at(k)] == b.mesh.uv[t][at(k)]);
  for (std::size_t t = 0; t < a.mesh.warp.size(); ++t) EXPECT_TRUE(a.mesh.warp[t] == b.mesh.warp[t]);
  EXPECT_EQ(a.edge_vertices, b.edge_vertices);
  EXPECT_EQ(a.seam_gap, b.seam_gap);
}

}  // namespace
}  // namespace clothsim

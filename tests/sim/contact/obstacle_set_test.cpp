// The obstacles combined for the contact stage (sim/contact/obstacle_set.hpp), built directly:
// numbering, ownership, flat and nearly flat edges, and the flat-face redundancy test.
#include "sim/contact/obstacle_set.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>
#include <vector>

namespace clothsim::contact {
namespace {

Obstacle box() {
  Obstacle o;
  o.name = "box";
  o.shape = Obstacle::Shape::box;
  o.center = Eigen::Vector3d(0, 0, 0);
  o.size = Eigen::Vector3d(1, 2, 3);
  return o;
}

Obstacle plane() {
  Obstacle o;
  o.name = "ground";
  o.shape = Obstacle::Shape::plane;
  return o;
}

Obstacle capsule() {
  Obstacle o;
  o.name = "arm";
  o.shape = Obstacle::Shape::capsule;
  o.from = Eigen::Vector3d(0, 0, 0);
  o.to = Eigen::Vector3d(0, 0.3, 0);
  o.radius = 0.035;
  return o;
}

// The unit square z = 0 as an open mesh obstacle, split along the diagonal 0–2.
Obstacle square(const char* name) {
  Obstacle o;
  o.name = name;
  o.shape = Obstacle::Shape::mesh;
  o.mesh.vertices.resize(4, 3);
  o.mesh.vertices << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return o;
}

int owned_edge_count(const ObstacleSet& s) {
  int n = 0;
  for (const auto& owned : s.owned_edges) n += static_cast<int>(owned.size());
  return n;
}

TEST(ObstacleSet, PlanesStayApartAndMeshesAreNumberedInTurn) {
  std::vector<Obstacle> obstacles = {box(), plane(), box()};
  const ObstacleSet s(obstacles);
  EXPECT_EQ(s.planes, std::vector<int>{1});
  ASSERT_EQ(s.vertex_offset.size(), 3u);
  EXPECT_EQ(s.vertex_offset[0], 0);
  EXPECT_EQ(s.vertex_offset[2], 8);  // the plane adds no vertex
  EXPECT_EQ(s.obstacle_of_vertex.size(), 16u);
  EXPECT_EQ(s.obstacle_of_vertex[7], 0);
  EXPECT_EQ(s.obstacle_of_vertex[8], 2);
  EXPECT_EQ(s.triangles.size(), 24u);
  EXPECT_EQ(obstacles[0].mesh.num_triangles(), 12);  // tessellated in place
  // Every vertex is owned by exactly one triangle.
  std::multiset<int> owners;
  for (const auto& owned : s.owned_points) owners.insert(owned.begin(), owned.end());
  EXPECT_EQ(owners.size(), 16u);
  for (int v = 0; v < 16; ++v) EXPECT_EQ(owners.count(v), 1u) << v;
}

TEST(ObstacleSet, BoxDiagonalsAreFlatAndOwnedByNoTriangle) {
  std::vector<Obstacle> obstacles = {box()};
  const ObstacleSet s(obstacles);
  ASSERT_EQ(s.edges.size(), 18u);  // 12 box edges + 6 face diagonals
  int flat = 0;
  for (size_t e = 0; e < s.edges.size(); ++e) {
    if (s.edge_flat[e]) {
      ++flat;
      EXPECT_NEAR(s.edge_tangent[e], 0.0, 1e-12);
    } else {
      EXPECT_NEAR(s.edge_tangent[e], 1.0, 1e-12);  // a right angle: tan 45°
    }
  }
  EXPECT_EQ(flat, 6);
  EXPECT_EQ(owned_edge_count(s), 12);
  for (char f : s.vertex_flat) EXPECT_EQ(f, 0);  // every corner has a box edge
}

TEST(ObstacleSet, CapsuleEdgesBendByTheTessellationStep) {
  std::vector<Obstacle> obstacles = {capsule()};
  const ObstacleSet s(obstacles);
  // 72 segments around: neighbouring side quads meet at 5°; the caps' diagonals a little more.
  int ring = 0;
  double largest = 0.0;
  for (size_t e = 0; e < s.edges.size(); ++e) {
    ASSERT_TRUE(std::isfinite(s.edge_tangent[e])) << "a closed capsule has no border edge";
    largest = std::max(largest, s.edge_tangent[e]);
    if (std::abs(s.edge_tangent[e] - std::tan(0.5 * 5.0 * M_PI / 180.0)) < 1e-9) ++ring;
  }
  EXPECT_GT(ring, 72);
  EXPECT_LT(largest, std::tan(0.5 * 8.0 * M_PI / 180.0));
  for (size_t v = 0; v < s.vertex_tangent.size(); ++v) EXPECT_LE(s.vertex_tangent[v], largest);
}

TEST(ObstacleSet, OpenMeshBorderEdgesCountAsSharp) {
  std::vector<Obstacle> obstacles = {square("sheet")};
  const ObstacleSet s(obstacles);
  int border = 0;
  for (size_t e = 0; e < s.edges.size(); ++e)
    if (std::isinf(s.edge_tangent[e])) ++border;
  EXPECT_EQ(border, 4);
  EXPECT_EQ(owned_edge_count(s), 4);  // the diagonal is flat
  for (double t : s.vertex_tangent) EXPECT_TRUE(std::isinf(t));
}

TEST(ObstacleSet, MeshObstacleWithoutTrianglesIsAnError) {
  Obstacle o;
  o.name = "empty";
  o.shape = Obstacle::Shape::mesh;
  std::vector<Obstacle> obstacles = {o};
  EXPECT_THROW(ObstacleSet{obstacles}, std::invalid_argument);
}

TEST(ObstacleSet, PointBesideAFlatDiagonalIsRedundant) {
  // The square z = 0 split along the diagonal 0–2: a point above triangle 1 (x < y), closest to
  // triangle 0 (x > y) on their shared diagonal, adds nothing through triangle 0.
  std::vector<Obstacle> obstacles = {square("square")};
  const ObstacleSet s(obstacles);
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(1, 1, 0);
  // The point (0.3, 0.5, 0.1): closest point on triangle 0 is on its edge 2–0 (weight of b zero),
  // and the direction to it is not the face normal.
  const Eigen::Vector3d p(0.3, 0.5, 0.1), q(0.4, 0.4, 0.0);
  const Eigen::Vector3d normal = (p - q).normalized();
  EXPECT_TRUE(s.redundant_on_flat_face(0, {0.6, 0.0, 0.4}, normal, a, b, c));
  // Right above the triangle (normal along the face normal): kept.
  EXPECT_FALSE(s.redundant_on_flat_face(0, {0.6, 0.0, 0.4}, Eigen::Vector3d::UnitZ(), a, b, c));
  // Closest to a border edge (0–1, weight of c zero): that edge is not flat, kept.
  EXPECT_FALSE(s.redundant_on_flat_face(0, {0.5, 0.5, 0.0}, Eigen::Vector3d(0, -1, 1).normalized(), a, b, c));
}

}  // namespace
}  // namespace clothsim::contact

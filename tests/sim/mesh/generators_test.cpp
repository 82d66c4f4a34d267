// Grid and cylinder generators: counts, indexing, regularity, boundary loops, orientation and
// geometry.
#include "sim/mesh/generators.hpp"

#include "sim/mesh/topology.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace clothsim {
namespace {

Eigen::Vector3d corner(const TriMesh& mesh, const Triangle& tri, int k) {
  return mesh.vertices.row(tri[static_cast<std::size_t>(k)]).transpose();
}

// (p1 − p0) × (p2 − p0): twice the area times the unit normal.
Eigen::Vector3d area_vector(const TriMesh& mesh, const Triangle& tri) {
  return (corner(mesh, tri, 1) - corner(mesh, tri, 0)).cross(corner(mesh, tri, 2) - corner(mesh, tri, 0));
}

TEST(MakeGrid, CountsAndVertexIndexing) {
  const double sx = 2.0, sy = 1.5;
  const int m = 4, n = 3;
  const TriMesh mesh = make_grid(sx, sy, m, n);
  ASSERT_EQ(mesh.num_vertices(), (m + 1) * (n + 1));
  EXPECT_EQ(mesh.num_triangles(), 2 * m * n);
  EXPECT_NO_THROW(check_triangles(mesh));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= m; ++i) {
      const int v = j * (m + 1) + i;
      EXPECT_NEAR(mesh.vertices(v, 0), -sx / 2 + sx * i / m, 1e-15) << "vertex " << v;
      EXPECT_NEAR(mesh.vertices(v, 1), -sy / 2 + sy * j / n, 1e-15) << "vertex " << v;
      EXPECT_EQ(mesh.vertices(v, 2), 0.0);
    }
  // Centred at the origin.
  EXPECT_NEAR(mesh.vertices.col(0).minCoeff(), -sx / 2, 1e-15);
  EXPECT_NEAR(mesh.vertices.col(0).maxCoeff(), sx / 2, 1e-15);
  EXPECT_NEAR(mesh.vertices.col(1).minCoeff(), -sy / 2, 1e-15);
  EXPECT_NEAR(mesh.vertices.col(1).maxCoeff(), sy / 2, 1e-15);
}

TEST(MakeGrid, InteriorValenceSixAndOneBoundaryLoop) {
  for (const auto& [m, n] : {std::pair{1, 1}, std::pair{3, 2}, std::pair{7, 5}, std::pair{10, 10}}) {
    const TriMesh mesh = make_grid(1.0, 2.0, m, n);
    const Topology top(mesh.num_vertices(), mesh.triangles);
    int interior = 0;
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      const int i = v % (m + 1), j = v / (m + 1);
      const bool on_rim = i == 0 || i == m || j == 0 || j == n;
      EXPECT_EQ(top.is_boundary(v), on_rim) << m << "x" << n << " vertex " << v;
      if (!on_rim) {
        ++interior;
        EXPECT_EQ(top.valence(v), 6) << m << "x" << n << " vertex " << v;
      }
    }
    EXPECT_EQ(interior, (m - 1) * (n - 1));
    ASSERT_EQ(top.boundary_loops().size(), 1u) << m << "x" << n;
    EXPECT_EQ(top.boundary_loops()[0].size(), static_cast<std::size_t>(2 * (m + n))) << m << "x" << n;
  }
}

TEST(MakeGrid, NormalsPointUpAndAreaIsExact) {
  const double sx = 1.7, sy = 0.9;
  const TriMesh mesh = make_grid(sx, sy, 9, 6);
  double area = 0.0;
  for (const Triangle& tri : mesh.triangles) {
    const Eigen::Vector3d a = area_vector(mesh, tri);
    EXPECT_GT(a.z(), 0.0);
    EXPECT_EQ(a.x(), 0.0);
    EXPECT_EQ(a.y(), 0.0);
    area += 0.5 * a.norm();
  }
  EXPECT_NEAR(area, sx * sy, 1e-13);
}

TEST(MakeGrid, RejectsInvalidArguments) {
  EXPECT_THROW(make_grid(0.0, 1.0, 2, 2), std::invalid_argument);
  EXPECT_THROW(make_grid(1.0, -1.0, 2, 2), std::invalid_argument);
  EXPECT_THROW(make_grid(std::nan(""), 1.0, 2, 2), std::invalid_argument);
  EXPECT_THROW(make_grid(1.0, 1.0, 0, 2), std::invalid_argument);
  EXPECT_THROW(make_grid(1.0, 1.0, 2, -1), std::invalid_argument);
  EXPECT_NO_THROW(make_grid(1.0, 1.0, 1, 1));
}

TEST(MakeCylinder, CountsAndRadius) {
  const double radius = 0.12, length = 0.5;
  const int segments = 26, rings = 19;
  const TriMesh mesh = make_cylinder(radius, length, segments, rings);
  ASSERT_EQ(mesh.num_vertices(), 494);
  EXPECT_EQ(mesh.num_triangles(), 2 * segments * (rings - 1));
  EXPECT_NO_THROW(check_triangles(mesh));
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    EXPECT_NEAR(std::hypot(mesh.vertices(v, 0), mesh.vertices(v, 2)), radius, 1e-15) << "vertex " << v;
    EXPECT_NEAR(mesh.vertices(v, 1), length * (v / segments) / (rings - 1), 1e-15) << "vertex " << v;
  }
  EXPECT_EQ(mesh.vertices.col(1).minCoeff(), 0.0);
  EXPECT_NEAR(mesh.vertices.col(1).maxCoeff(), length, 1e-15);
  // No duplicated seam: the vertices of one ring are pairwise distinct.
  for (int a = 0; a < segments; ++a)
    for (int b = a + 1; b < segments; ++b)
      EXPECT_GT((mesh.vertices.row(a) - mesh.vertices.row(b)).norm(), 1e-3) << a << ", " << b;
}

TEST(MakeCylinder, InteriorValenceSixRimThreeTrianglesTwoLoops) {
  for (const auto& [segments, rings] : {std::pair{3, 2}, std::pair{5, 3}, std::pair{26, 19}}) {
    const TriMesh mesh = make_cylinder(1.0, 2.0, segments, rings);
    const Topology top(mesh.num_vertices(), mesh.triangles);
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      const int ring = v / segments;
      const bool on_rim = ring == 0 || ring == rings - 1;
      EXPECT_EQ(top.is_boundary(v), on_rim) << "vertex " << v;
      if (on_rim)
        EXPECT_EQ(top.num_incident_triangles(v), 3) << "vertex " << v;
      else
        EXPECT_EQ(top.valence(v), 6) << "vertex " << v;
    }
    const auto& loops = top.boundary_loops();
    ASSERT_EQ(loops.size(), 2u) << segments << "x" << rings;
    for (const auto& loop : loops) {
      ASSERT_EQ(loop.size(), static_cast<std::size_t>(segments));
      // Each loop is one whole rim ring.
      const int ring = loop.front() / segments;
      EXPECT_TRUE(ring == 0 || ring == rings - 1);
      for (const int v : loop) EXPECT_EQ(v / segments, ring);
    }
    EXPECT_NE(loops[0].front() / segments, loops[1].front() / segments);
  }
}

TEST(MakeCylinder, NormalsPointAwayFromAxis) {
  const TriMesh mesh = make_cylinder(0.3, 1.0, 12, 5);
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    const Triangle& tri = mesh.triangles[static_cast<std::size_t>(t)];
    const Eigen::Vector3d centroid = (corner(mesh, tri, 0) + corner(mesh, tri, 1) + corner(mesh, tri, 2)) / 3.0;
    const Eigen::Vector3d radial(centroid.x(), 0.0, centroid.z());
    const Eigen::Vector3d normal = area_vector(mesh, tri).normalized();
    EXPECT_GT(normal.dot(radial.normalized()), 0.9) << "triangle " << t;
    EXPECT_NEAR(normal.y(), 0.0, 1e-12) << "triangle " << t;
  }
}

TEST(MakeCylinder, RejectsInvalidArguments) {
  EXPECT_THROW(make_cylinder(0.0, 1.0, 8, 3), std::invalid_argument);
  EXPECT_THROW(make_cylinder(1.0, -2.0, 8, 3), std::invalid_argument);
  EXPECT_THROW(make_cylinder(INFINITY, 1.0, 8, 3), std::invalid_argument);
  EXPECT_THROW(make_cylinder(1.0, 1.0, 2, 3), std::invalid_argument);
  EXPECT_THROW(make_cylinder(1.0, 1.0, 8, 1), std::invalid_argument);
  EXPECT_NO_THROW(make_cylinder(1.0, 1.0, 3, 2));
}

}  // namespace
}  // namespace clothsim

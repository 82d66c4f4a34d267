// mesh_part (sim/mesh/mesh_part.hpp): cutting a mesh into parts by planes, as the body's arms
// and torso are cut into obstacles that move apart.
#include "sim/mesh/mesh_part.hpp"

#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace clothsim {
namespace {

TEST(MeshPart, ComplementaryPartsShareNothingAndHoldEverything) {
  const TriMesh grid = make_grid(1.0, 1.0, 10, 10);  // 200 triangles in z = 0, x and y in [-0.5, 0.5]
  // The corner region x > 0.2 and y > 0.2, and the rest.
  const std::vector<HalfSpace> corner = {{{0.2, 0, 0}, {1, 0, 0}}, {{0, 0.2, 0}, {0, 1, 0}}};
  const TriMesh a = mesh_part(grid, corner, {});
  const TriMesh b = mesh_part(grid, {}, {corner});
  EXPECT_EQ(a.num_triangles() + b.num_triangles(), grid.num_triangles());
  // Cells with x in [0.2, 0.5] and y in [0.2, 0.5]: 3 x 3 cells of two triangles.
  EXPECT_EQ(a.num_triangles(), 18);
  EXPECT_EQ(a.num_vertices(), 16);  // 4 x 4, the others dropped
  for (Eigen::Index v = 0; v < a.vertices.rows(); ++v) {
    EXPECT_GE(a.vertices(v, 0), 0.2 - 1e-12);
    EXPECT_GE(a.vertices(v, 1), 0.2 - 1e-12);
  }
  // Vertices keep their order; triangles still point at the same positions.
  for (Eigen::Index v = 1; v < a.vertices.rows(); ++v)
    EXPECT_TRUE(a.vertices(v, 1) > a.vertices(v - 1, 1) ||
                (a.vertices(v, 1) == a.vertices(v - 1, 1) && a.vertices(v, 0) > a.vertices(v - 1, 0)));
  check_triangles(a);
  check_triangles(b);
  EXPECT_EQ(b.num_vertices(), 121 - 9);  // only the corner's 3 x 3 inner vertices go
}

TEST(MeshPart, EmptySelectionsAndBadPlanes) {
  const TriMesh grid = make_grid(1.0, 1.0, 2, 2);
  EXPECT_EQ(mesh_part(grid, {}, {}).num_triangles(), grid.num_triangles());
  EXPECT_EQ(mesh_part(grid, {{{0, 0, 1}, {0, 0, 1}}}, {}).num_triangles(), 0);  // all below z = 1
  EXPECT_THROW(mesh_part(grid, {{{0, 0, 0}, {0, 0, 0}}}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace clothsim

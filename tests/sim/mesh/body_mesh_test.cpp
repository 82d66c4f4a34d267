// The shipped body to dress (scenes/bodies/human_female.obj, docs/body.md): read by the
// project's own OBJ reader, it must be one closed, edge-manifold, consistently oriented surface
// facing outward (positive enclosed volume), in metres, standing on y = 0 and mirror-symmetric in
// x, as the garment scenes assume.
#include "sim/mesh/obj_io.hpp"
#include "sim/mesh/topology.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <utility>

namespace clothsim {
namespace {

TEST(BodyMesh, IsOneClosedOutwardSurfaceInMetresStandingOnTheGround) {
  const TriMesh body = read_obj(std::string(CLOTHSIM_SOURCE_DIR) + "/scenes/bodies/human_female.obj");
  ASSERT_EQ(body.num_vertices(), 13380);
  ASSERT_EQ(body.num_triangles(), 26756);
  const Topology top(body.num_vertices(), body.triangles);  // throws for non-manifold or mis-oriented
  EXPECT_TRUE(top.boundary_loops().empty());
  // Euler characteristic 2: a sphere-like closed surface (genus 0).
  std::set<std::pair<int, int>> edges;
  for (const Triangle& t : body.triangles)
    for (int k = 0; k < 3; ++k) edges.insert(std::minmax(t[static_cast<size_t>(k)], t[static_cast<size_t>((k + 1) % 3)]));
  EXPECT_EQ(body.num_vertices() - static_cast<int>(edges.size()) + body.num_triangles(), 2);
  // Enclosed volume by the divergence theorem: positive when the triangles face outward; a
  // woman of 1.66 m and about 55 kg encloses about 55 litres.
  double volume = 0;
  for (const Triangle& t : body.triangles)
    volume += body.vertices.row(t[0]).dot(body.vertices.row(t[1]).cross(body.vertices.row(t[2]))) / 6.0;
  EXPECT_GT(volume, 0.045);
  EXPECT_LT(volume, 0.065);
  const Eigen::Vector3d lo = body.vertices.colwise().minCoeff(), hi = body.vertices.colwise().maxCoeff();
  EXPECT_NEAR(lo.y(), 0.0, 1e-3);
  EXPECT_NEAR(hi.y() - lo.y(), 1.659, 2e-3);
  EXPECT_NEAR(lo.x(), -hi.x(), 1e-6);  // mirror-symmetric about x = 0
  EXPECT_LT(hi.z() - lo.z(), 0.5);     // faces +z, a body's depth
}

}  // namespace
}  // namespace clothsim

// Topology: ordered one-rings, boundary loops and the validity checks.
#include "sim/mesh/topology.hpp"

#include <gtest/gtest.h>

namespace clothsim {
namespace {

// Two triangles forming a square 0-1-2-3 (counter-clockwise), diagonal 0-2.
const std::vector<Triangle> kSquare = {{0, 1, 2}, {0, 2, 3}};

TEST(Topology, SquareRingsAndBoundary) {
  Topology top(4, kSquare);
  EXPECT_EQ(top.ring(0), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(top.ring(1), (std::vector<int>{2, 0}));
  EXPECT_TRUE(top.is_boundary(0));
  EXPECT_EQ(top.num_incident_triangles(0), 2);
  EXPECT_EQ(top.opposite(0, 1), 2);
  EXPECT_EQ(top.opposite(1, 0), -1);
  ASSERT_EQ(top.boundary_loops().size(), 1u);
  EXPECT_EQ(top.boundary_loops()[0], (std::vector<int>{0, 1, 2, 3}));
}

TEST(Topology, ClosedFanIsInterior) {
  // Vertex 0 surrounded by 1..5.
  std::vector<Triangle> fan;
  for (int i = 0; i < 5; ++i) fan.push_back({0, 1 + i, 1 + (i + 1) % 5});
  Topology top(6, fan);
  EXPECT_FALSE(top.is_boundary(0));
  EXPECT_EQ(top.valence(0), 5);
  EXPECT_EQ(top.ring_from(0, 3), (std::vector<int>{3, 4, 5, 1, 2}));
}

TEST(Topology, RejectsInvalidMeshesNamingTheElement) {
  auto message = [](int n, std::vector<Triangle> tris) {
    try {
      Topology top(n, tris);
    } catch (const MeshError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(4, {{0, 1, 2}, {0, 1, 3}}).find("inconsistent orientation at edge (0, 1)"), std::string::npos);
  EXPECT_NE(message(5, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}).find("non-manifold edge (0, 1)"), std::string::npos);
  EXPECT_NE(message(5, {{0, 1, 2}, {0, 3, 4}}).find("non-manifold vertex 0"), std::string::npos);
  EXPECT_NE(message(4, {{0, 1, 2}}).find("isolated vertex 3"), std::string::npos);
  EXPECT_NE(message(3, {{0, 1, 1}}).find("degenerate"), std::string::npos);
}

}  // namespace
}  // namespace clothsim

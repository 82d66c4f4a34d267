// find_cracks: distinct border vertices at one position (a surface split where it should be
// connected), at any scale, without false alarms on connected or merely close meshes, and fast
// on large meshes (a spatial hash, not a comparison of all pairs).
#include "sim/mesh/cracks.hpp"

#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <utility>
#include <vector>

namespace clothsim {
namespace {

using Pairs = std::vector<std::pair<int, int>>;

// An nx x ny grid on [0, 1]² whose columns i >= split are a separate sheet: the vertices of
// column `split` are duplicated, so the grid has a seam of border edges there. Returns the mesh
// and the expected pairs (original vertex of the column, its copy).
std::pair<TriMesh, Pairs> split_grid(int nx, int ny, int split) {
  TriMesh mesh = make_grid(1.0, 1.0, nx, ny);
  Pairs expected;
  const int columns = nx + 1;
  const int original = mesh.num_vertices();
  std::vector<int> copy_of(static_cast<std::size_t>(original), -1);
  mesh.vertices.conservativeResize(original + ny + 1, 3);
  for (int j = 0; j <= ny; ++j) {
    const int v = j * columns + split;
    copy_of[static_cast<std::size_t>(v)] = original + j;
    mesh.vertices.row(original + j) = mesh.vertices.row(v);
    expected.emplace_back(v, original + j);
  }
  // Triangles right of the seam use the copies.
  for (Triangle& t : mesh.triangles) {
    bool right = false;
    for (int v : t) right = right || v % columns > split;
    if (right)
      for (int& v : t)
        if (copy_of[static_cast<std::size_t>(v)] >= 0) v = copy_of[static_cast<std::size_t>(v)];
  }
  return {mesh, expected};
}

TEST(FindCracks, ConnectedMeshesHaveNone) {
  EXPECT_TRUE(find_cracks(make_grid(1.0, 1.0, 8, 8)).empty());
  EXPECT_TRUE(find_cracks(make_cylinder(0.05, 0.2, 16, 6)).empty());
  // A nearly closed panel: its two straight borders are 1e-3 of the size apart, not coincident.
  EXPECT_TRUE(find_cracks(make_cylinder_panel(1.0, 1.0, 359.9, 64, 4)).empty());
}

TEST(FindCracks, FindsTheSeamOfASplitGrid) {
  const auto [mesh, expected] = split_grid(6, 4, 3);
  EXPECT_EQ(find_cracks(mesh), expected);
  // The same at extreme scales, and after a small perturbation well inside the tolerance.
  for (const double factor : {1e-150, 1e-9, 1e9, 1e300}) {
    TriMesh s = mesh;
    s.vertices *= factor;
    EXPECT_EQ(find_cracks(s), expected) << factor;
  }
  TriMesh perturbed = mesh;
  perturbed.vertices(expected[0].second, 0) += 1e-9;
  EXPECT_EQ(find_cracks(perturbed), expected);
  // A gap larger than the tolerance is a gap, not a crack.
  TriMesh gap = mesh;
  for (const auto& [original, copy] : expected) gap.vertices(copy, 0) += 1e-3;
  EXPECT_TRUE(find_cracks(gap).empty());
  EXPECT_EQ(find_cracks(gap, 1e-2).size(), expected.size());
}

TEST(FindCracks, WrappedSleeveWithADuplicatedSeam) {
  // A grid rolled into a cylinder keeps two copies of its seam column: one crack pair per ring.
  const int segments = 12, rings = 5;
  TriMesh sleeve = make_grid(1.0, 1.0, segments, rings - 1);
  for (int v = 0; v < sleeve.num_vertices(); ++v) {
    const double theta = 2 * M_PI * (sleeve.vertices(v, 0) + 0.5);
    const double y = sleeve.vertices(v, 1);
    sleeve.vertices.row(v) << std::cos(theta), y, -std::sin(theta);
  }
  const Pairs cracks = find_cracks(sleeve);
  ASSERT_EQ(cracks.size(), static_cast<std::size_t>(rings));
  for (int r = 0; r < rings; ++r)
    EXPECT_EQ(cracks[static_cast<std::size_t>(r)], std::make_pair(r * (segments + 1), r * (segments + 1) + segments));
}

TEST(FindCracks, LargeMeshesAreFast) {
  // 1001 x 1001 = 1 002 001 vertices with a seam of 1001: all-pairs comparison of the ~5000 border
  // vertices would still be quick, so the seam runs along one coordinate (all border vertices of
  // the seam share x), the worst case of a sweep along x.
  const auto [mesh, expected] = split_grid(1000, 1000, 500);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(find_cracks(mesh), expected);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
}

}  // namespace
}  // namespace clothsim

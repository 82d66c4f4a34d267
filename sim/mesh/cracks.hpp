// Cracks: a mesh whose surface is split where it should be connected, because two distinct
// vertices sit at the same position (an OBJ exported with vertices split at a texture seam, or
// two parts modelled separately). Each side of such a seam is a border, so the mesh is valid and
// the cloth simply comes apart there; find_cracks finds the vertex pairs so that the scene can
// warn about them (a cut made on purpose is fine, hence no error).
#pragma once

#include "sim/mesh/mesh.hpp"

#include <utility>
#include <vector>

namespace clothsim {

// Relative tolerance of find_cracks' default: two vertices closer than this fraction of the
// mesh's bounding-box diagonal count as coincident.
inline constexpr double kCrackTolerance = 1e-6;

// Pairs (a, b), a < b, sorted, of distinct vertices that both lie on border edges (edges of only
// one triangle), do not share a triangle, and are at most `relative_tolerance` × the bounding-box
// diagonal apart. Independent of the mesh's scale (1e-150 m or 1e150 m meshes give the same
// pairs as at 1 m). Uses a spatial hash of the border vertices: O(n log n) for n vertices, not
// O(n²). Triangle indices must be in range (check_triangles).
std::vector<std::pair<int, int>> find_cracks(const TriMesh& mesh, double relative_tolerance = kCrackTolerance);

}  // namespace clothsim

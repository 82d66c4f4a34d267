// Triangle meshes: the control mesh of a subdivision shell, and the one error type every mesh
// check throws. Conventions used throughout clothsim:
//  - positions are #V × 3 matrices, one vertex per row, in metres [m];
//  - flat DOF vectors are [x0 y0 z0 x1 y1 z1 ...] (vertex-major), length 3·#V;
//  - triangles are counter-clockwise seen from the side the normal points to.
#pragma once

#include <Eigen/Core>

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {

using Triangle = std::array<int, 3>;

struct TriMesh {
  Eigen::MatrixX3d vertices;        // #V × 3 rest positions [m]
  std::vector<Triangle> triangles;  // vertex indices, counter-clockwise
  // Per triangle, the rest warp (grain) direction of a woven material [unit 3-vector, in or near
  // the triangle's plane], or empty when the mesh has none (docs/materials.md, Grain). Only an
  // orthotropic material reads it; it is projected into the surface's tangent plane where used.
  std::vector<Eigen::Vector3d> warp;
  // Per triangle, the texture coordinates (u, v) of its three corners (OBJ `vt`), or empty when
  // the mesh has none (read_obj fills it only when every face gives them). Used for the grain.
  std::vector<std::array<Eigen::Vector2d, 3>> uv;

  int num_vertices() const { return static_cast<int>(vertices.rows()); }
  int num_triangles() const { return static_cast<int>(triangles.size()); }
};

// Thrown by every mesh check; the message names the offending vertex, edge or triangle.
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Thrown when a mesh is larger than the limit it is read with (read_obj's max_vertices).
class MeshLimitError : public MeshError {
 public:
  using MeshError::MeshError;
};

// The default limit on a mesh's vertex count (the scene key mesh.max_vertices; read_obj's
// max_vertices): a million, ten times the 100k-vertex meshes the solvers are tuned for, checked
// before anything of that size is allocated.
inline constexpr long long kDefaultMaxVertices = 1'000'000;

// Throws MeshError for a triangle with a repeated or out-of-range index or (near) zero area
// (twice its area below 1e-12 of the squared bounding-box diagonal), naming the triangle. The
// test is relative: it runs on the mesh scaled to unit size, so a valid mesh passes at any scale
// (1e-150 m or 1e150 m as at 1 m).
void check_triangles(const TriMesh& mesh);

// Lumped mass per vertex [kg]: a third of each incident triangle's rest area [m²] times
// `areal_density` [kg/m²].
Eigen::VectorXd lumped_vertex_mass(const TriMesh& mesh, double areal_density);

}  // namespace clothsim

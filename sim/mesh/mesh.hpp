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

  int num_vertices() const { return static_cast<int>(vertices.rows()); }
  int num_triangles() const { return static_cast<int>(triangles.size()); }
};

// Thrown by every mesh check; the message names the offending vertex, edge or triangle.
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws MeshError for a triangle with a repeated or out-of-range index or (near) zero area
// (area below 1e-12 of the squared bounding-box diagonal), naming the triangle.
void check_triangles(const TriMesh& mesh);

// Lumped mass per vertex [kg]: a third of each incident triangle's rest area [m²] times
// `areal_density` [kg/m²].
Eigen::VectorXd lumped_vertex_mass(const TriMesh& mesh, double areal_density);

}  // namespace clothsim

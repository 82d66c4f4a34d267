#include "sim/mesh/mesh.hpp"

#include <Eigen/Geometry>

namespace clothsim {

void check_triangles(const TriMesh& mesh) {
  const int n = mesh.num_vertices();
  if (n == 0) throw MeshError("mesh has no vertices");
  if (mesh.triangles.empty()) throw MeshError("mesh has no triangles");
  if (!mesh.vertices.allFinite()) throw MeshError("mesh has a non-finite vertex coordinate");
  // The test runs on the mesh moved to the origin and scaled to unit size (dividing before
  // subtracting, so no difference overflows), so that it does not depend on the mesh's units: a
  // valid mesh scaled by 1e-160 or 1e300 passes as it does at 1 m (its squared edges would
  // underflow to zero or overflow to infinity).
  const Eigen::RowVector3d lo = mesh.vertices.colwise().minCoeff(), hi = mesh.vertices.colwise().maxCoeff();
  double scale = (0.5 * hi - 0.5 * lo).cwiseAbs().maxCoeff();
  if (!(scale > 0)) scale = 1.0;  // every vertex at one point: every triangle is degenerate
  const Eigen::RowVector3d center = 0.5 * lo + 0.5 * hi;
  auto unit = [&](int v) -> Eigen::Vector3d {
    return (mesh.vertices.row(v) / scale - center / scale).transpose();
  };
  const double diag2 = (hi / scale - lo / scale).squaredNorm();
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    const std::string name = "triangle " + std::to_string(t) + " (" + std::to_string(tri[0]) + ", " +
                             std::to_string(tri[1]) + ", " + std::to_string(tri[2]) + ")";
    for (int k = 0; k < 3; ++k)
      if (tri[k] < 0 || tri[k] >= n)
        throw MeshError(name + ": vertex index out of range (mesh has " + std::to_string(n) + " vertices)");
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      throw MeshError(name + " is degenerate: repeated vertex");
    const Eigen::Vector3d p0 = unit(tri[0]);
    const Eigen::Vector3d e1 = unit(tri[1]) - p0, e2 = unit(tri[2]) - p0;
    if (e1.cross(e2).norm() <= 1e-12 * diag2) throw MeshError(name + " is degenerate: zero area");
  }
}

Eigen::VectorXd lumped_vertex_mass(const TriMesh& mesh, double areal_density) {
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (const Triangle& t : mesh.triangles) {
    const Eigen::Vector3d x0 = mesh.vertices.row(t[0]), x1 = mesh.vertices.row(t[1]), x2 = mesh.vertices.row(t[2]);
    const double area = 0.5 * (x1 - x0).cross(x2 - x0).norm();
    for (int v : t) mass(v) += areal_density * area / 3.0;
  }
  return mass;
}

}  // namespace clothsim

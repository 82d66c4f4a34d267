#include "sim/mesh/grain.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>
#include <numbers>
#include <string>

namespace clothsim {

namespace {

double radians(double deg) { return deg * std::numbers::pi / 180.0; }

}  // namespace

std::vector<Eigen::Vector3d> grid_warp(const TriMesh& mesh, double warp_deg) {
  const double phi = radians(warp_deg);
  return std::vector<Eigen::Vector3d>(mesh.triangles.size(), Eigen::Vector3d(std::cos(phi), std::sin(phi), 0.0));
}

std::vector<Eigen::Vector3d> cylinder_warp(const TriMesh& mesh, double warp_deg) {
  const double phi = radians(warp_deg);
  std::vector<Eigen::Vector3d> out;
  out.reserve(mesh.triangles.size());
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitY();
  for (const Triangle& t : mesh.triangles) {
    const Eigen::Vector3d c = (mesh.vertices.row(t[0]) + mesh.vertices.row(t[1]) + mesh.vertices.row(t[2])).transpose() / 3.0;
    const Eigen::Vector3d radial = Eigen::Vector3d(c.x(), 0.0, c.z()).normalized();
    const Eigen::Vector3d around = axis.cross(radial);
    out.push_back((std::cos(phi) * axis + std::sin(phi) * around).normalized());
  }
  return out;
}

std::vector<Eigen::Vector3d> uv_warp(const TriMesh& mesh, double warp_deg) {
  if (mesh.uv.size() != mesh.triangles.size())
    throw MeshError("the mesh has no texture coordinates (vt) to measure the grain from");
  const double phi = radians(warp_deg);
  const Eigen::Vector2d dir(std::cos(phi), std::sin(phi));
  std::vector<Eigen::Vector3d> out;
  out.reserve(mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const Triangle& t = mesh.triangles[i];
    const auto& uv = mesh.uv[i];
    Eigen::Matrix2d duv;
    duv << uv[1] - uv[0], uv[2] - uv[0];
    Eigen::Matrix<double, 3, 2> dx;
    dx << (mesh.vertices.row(t[1]) - mesh.vertices.row(t[0])).transpose(),
        (mesh.vertices.row(t[2]) - mesh.vertices.row(t[0])).transpose();
    const double scale = std::max(duv.cwiseAbs().maxCoeff(), 1e-300);
    if (!(std::abs(duv.determinant()) > 1e-12 * scale * scale))
      throw MeshError("triangle " + std::to_string(i) + " has degenerate texture coordinates (zero area in uv)");
    const Eigen::Vector3d w = dx * (duv.inverse() * dir);
    if (!(w.norm() > 0) || !w.allFinite())
      throw MeshError("triangle " + std::to_string(i) + ": no grain direction from its texture coordinates");
    out.push_back(w.normalized());
  }
  return out;
}

}  // namespace clothsim

#include "sim/shell/moment_load.hpp"

#include <Eigen/Geometry>

namespace clothsim {

bool add_moment_forces(const MomentLoad& load, const Eigen::MatrixX3d& x, Eigen::VectorXd& f) {
  if (load.vertices.empty()) return false;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int v : load.vertices) centroid += x.row(v).transpose();
  centroid /= static_cast<double>(load.vertices.size());
  const double m2 = load.moment.squaredNorm();
  if (m2 == 0.0) return true;
  const Eigen::Vector3d axis = load.moment / std::sqrt(m2);
  double sum = 0.0;
  std::vector<Eigen::Vector3d> r(load.vertices.size());
  for (size_t i = 0; i < load.vertices.size(); ++i) {
    const Eigen::Vector3d d = x.row(load.vertices[i]).transpose() - centroid;
    r[i] = d - axis.dot(d) * axis;
    sum += r[i].squaredNorm();
  }
  if (!(sum > 0.0)) return false;
  for (size_t i = 0; i < load.vertices.size(); ++i) f.segment<3>(3 * load.vertices[i]) += load.moment.cross(r[i]) / sum;
  return true;
}

}  // namespace clothsim

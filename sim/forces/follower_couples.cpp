#include "sim/forces/follower_couples.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>
#include <string>

namespace clothsim {

bool add_moment_forces(const MomentLoad& load, const Eigen::VectorXd& x, Eigen::VectorXd& f) {
  if (load.vertices.empty()) return false;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int v : load.vertices) centroid += x.segment<3>(3 * v);
  centroid /= static_cast<double>(load.vertices.size());
  const double m2 = load.moment.squaredNorm();
  if (m2 == 0.0) return true;
  const Eigen::Vector3d axis = load.moment / std::sqrt(m2);
  double sum = 0.0, spread = 0.0;
  std::vector<Eigen::Vector3d> r(load.vertices.size());
  for (size_t i = 0; i < load.vertices.size(); ++i) {
    const Eigen::Vector3d d = x.segment<3>(3 * load.vertices[i]) - centroid;
    r[i] = d - axis.dot(d) * axis;
    sum += r[i].squaredNorm();
    spread += d.squaredNorm();
  }
  // Offsets perpendicular to M that are round-off of a group on one line parallel to it would
  // give forces of order M / 1e-18: such a group cannot carry the moment.
  if (!(sum > 1e-20 * spread)) return false;
  for (size_t i = 0; i < load.vertices.size(); ++i) f.segment<3>(3 * load.vertices[i]) += load.moment.cross(r[i]) / sum;
  return true;
}

void FollowerCouples::update(const Eigen::VectorXd& x, const Eigen::VectorXd& /*u*/, double /*t*/) {
  Eigen::VectorXd scratch = Eigen::VectorXd::Zero(x.size());
  for (size_t i = 0; i < couples_.size(); ++i)
    if (!add_moment_forces(couples_[i], x, scratch))
      throw std::runtime_error("moment " + std::to_string(i) + ": its vertices have come to lie on a line parallel to the moment");
  x_ = x;
}

void FollowerCouples::add_force(Eigen::VectorXd& f) const {
  for (const MomentLoad& c : couples_) add_moment_forces(c, x_, f);
}

}  // namespace clothsim

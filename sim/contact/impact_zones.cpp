#include "sim/contact/impact_zones.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>

namespace clothsim::contact {

RigidMap fit_rigid(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) {
  RigidMap m;
  if (from.empty()) return m;
  Eigen::Vector3d cf = Eigen::Vector3d::Zero(), ct = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    cf += from[i];
    ct += to[i];
  }
  cf /= static_cast<double>(from.size());
  ct /= static_cast<double>(from.size());
  if (from.size() >= 3) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < from.size(); ++i) h += (from[i] - cf) * (to[i] - ct).transpose();
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
    d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
    m.r = svd.matrixV() * d * svd.matrixU().transpose();
  }
  m.c = ct - m.r * cf;
  return m;
}

}  // namespace clothsim::contact

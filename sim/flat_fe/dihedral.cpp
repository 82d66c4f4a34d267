#include "sim/flat_fe/dihedral.hpp"

#include <Eigen/Geometry>
#include <unsupported/Eigen/AutoDiff>

#include <cmath>

namespace clothsim {

namespace {

template <class S>
using Vec3 = Eigen::Matrix<S, 3, 1>;

// The gradient formula of dihedral.hpp for any scalar type (double, or AutoDiffScalar for the
// Hessian).
template <class S>
std::array<Vec3<S>, 4> gradient_of(const std::array<Vec3<S>, 4>& x) {
  using std::sqrt;
  const Vec3<S> e = x[1] - x[0];
  const S length2 = e.squaredNorm();
  const S length = sqrt(length2);
  const Vec3<S> normal_a = e.cross(Vec3<S>(x[2] - x[0]));
  const Vec3<S> normal_b = Vec3<S>(x[3] - x[0]).cross(e);
  // n / h = |e| N / |N|².
  const Vec3<S> ga = normal_a * S(length / normal_a.squaredNorm());
  const Vec3<S> gb = normal_b * S(length / normal_b.squaredNorm());
  const S sa = S(Vec3<S>(x[2] - x[0]).dot(e) / length2);
  const S sb = S(Vec3<S>(x[3] - x[0]).dot(e) / length2);
  const S one(1.0);
  std::array<Vec3<S>, 4> g;
  g[0] = ga * S(one - sa) + gb * S(one - sb);
  g[1] = ga * sa + gb * sb;
  g[2] = -ga;
  g[3] = -gb;
  return g;
}

}  // namespace

double dihedral_angle(const HingePositions& x) {
  const Eigen::Vector3d e = x[1] - x[0];
  const Eigen::Vector3d na = e.cross(x[2] - x[0]).normalized();
  const Eigen::Vector3d nb = (x[3] - x[0]).cross(e).normalized();
  return std::atan2(na.cross(nb).dot(e.normalized()), na.dot(nb));
}

HingeVector dihedral_gradient(const HingePositions& x) {
  const std::array<Eigen::Vector3d, 4> g = gradient_of<double>(x);
  HingeVector out;
  for (int k = 0; k < 4; ++k) out.segment<3>(3 * k) = g[static_cast<size_t>(k)];
  return out;
}

HingeMatrix dihedral_hessian(const HingePositions& x) {
  using Dual = Eigen::AutoDiffScalar<HingeVector>;
  std::array<Vec3<Dual>, 4> xd;
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c)
      xd[static_cast<size_t>(k)](c) = Dual(x[static_cast<size_t>(k)](c), 12, 3 * k + c);
  const std::array<Vec3<Dual>, 4> g = gradient_of<Dual>(xd);
  HingeMatrix h;
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c) h.row(3 * k + c) = g[static_cast<size_t>(k)](c).derivatives().transpose();
  return 0.5 * (h + h.transpose());  // symmetric analytically; this removes the round-off
}

bool hinge_is_degenerate(const HingePositions& x) {
  const Eigen::Vector3d e = x[1] - x[0];
  return !(e.squaredNorm() > 0) || !(e.cross(x[2] - x[0]).squaredNorm() > 0) ||
         !((x[3] - x[0]).cross(e).squaredNorm() > 0);
}

}  // namespace clothsim

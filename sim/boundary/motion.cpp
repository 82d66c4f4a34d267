#include "sim/boundary/motion.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace clothsim {

Eigen::Vector3d apply_motions(const std::vector<Motion>& motions, const Eigen::Vector3d& rest, double t) {
  Eigen::Vector3d p = rest;
  for (const Motion& m : motions) {
    const double s = m.end > m.start ? std::clamp((t - m.start) / (m.end - m.start), 0.0, 1.0) : (t >= m.end ? 1.0 : 0.0);
    switch (m.type) {
      case Motion::Type::rotate: {
        const double angle = s * m.angle_deg * std::numbers::pi / 180.0;
        p = m.center + Eigen::AngleAxisd(angle, m.axis.normalized()) * (p - m.center);
        break;
      }
      case Motion::Type::translate:
        p += s * m.displacement;
        break;
      case Motion::Type::hold:
        break;
    }
  }
  return p;
}

std::string validate(const Motion& m) {
  std::ostringstream s;
  if (!(std::isfinite(m.start) && std::isfinite(m.end) && m.start >= 0 && m.end >= m.start))
    s << "needs 0 <= start <= end [s] (got start " << m.start << ", end " << m.end << ")";
  else if (m.type == Motion::Type::rotate && !(m.axis.allFinite() && m.axis.norm() > 0))
    s << "rotation axis must be a non-zero vector";
  else if (!m.center.allFinite() || !m.displacement.allFinite() || !std::isfinite(m.angle_deg))
    s << "values must be finite";
  return s.str();
}

}  // namespace clothsim

// Scripted motion of boundary vertices (twisting and compressing a sleeve, paper §6, Fig. 7, 9,
// 11): a chain of rigid motions, each active between its start and end time and advancing at a
// constant rate, applied in order to the vertices' rest positions.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

namespace clothsim {

struct Motion {
  enum class Type { rotate, translate, hold };
  Type type = Type::hold;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();    // rotate: axis direction (normalised on use)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();   // rotate: a point on the axis [m]
  double angle_deg = 0.0;                             // rotate: total angle [deg], right-handed
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();  // translate: total displacement [m]
  double start = 0.0, end = 0.0;                      // active time interval [s], start <= end
};

// Position at time t [s] of a point with rest position `rest` [m] under the chain `motions`.
Eigen::Vector3d apply_motions(const std::vector<Motion>& motions, const Eigen::Vector3d& rest, double t);

// Empty string when valid, else a message naming the bad field.
std::string validate(const Motion& m);

}  // namespace clothsim

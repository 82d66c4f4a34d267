// A moment (couple) applied to a group of control vertices, e.g. at the end of a strip: forces
// f_i = M × r_i / Σ_j |r_j|², with r_i the part of (x_i − c) perpendicular to M and c the group's
// centroid. They sum to zero and their moment about c is exactly M. Evaluated on the current
// positions in a dynamic run, so the couple follows the group's rotation (a follower load).
#pragma once

#include <Eigen/Core>

#include <vector>

namespace clothsim {

struct MomentLoad {
  std::vector<int> vertices;                          // the group (at least two rows, not on one
                                                      // line parallel to the moment)
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();   // [N·m]
};

// Adds the couple's nodal forces for positions x (#V × 3) to f (3·#V). Returns false when the
// group cannot carry the moment (all offsets parallel to it).
bool add_moment_forces(const MomentLoad& load, const Eigen::MatrixX3d& x, Eigen::VectorXd& f);

}  // namespace clothsim

// Follower couples: a moment applied to a group of nodes, e.g. at the end of a strip, as forces
// f_i = M × r_i / Σ_j |r_j|², with r_i the part of (x_i − c) perpendicular to M and c the group's
// centroid. They sum to zero and their moment about c is exactly M. Evaluated on the current
// positions, so the couple follows the group's rotation (a follower load). Such a load derives from
// no potential and its Jacobian is neither symmetric nor inside the system matrix's pattern: the
// term is integrated explicitly (no energy, no matrix).
#pragma once

#include "sim/core/force_term.hpp"

#include <Eigen/Core>

#include <vector>

namespace clothsim {

struct MomentLoad {
  std::vector<int> vertices;                          // the group (at least two rows, not on one
                                                      // line parallel to the moment)
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();   // [N·m]
};

// Adds the couple's nodal forces for positions x (flat, 3·#nodes) [m] to f (3·#nodes) [N].
// Returns false when the group cannot carry the moment (all offsets parallel to it, to 1e-10 of
// the group's size).
bool add_moment_forces(const MomentLoad& load, const Eigen::VectorXd& x, Eigen::VectorXd& f);

class FollowerCouples final : public ForceTerm {
 public:
  explicit FollowerCouples(std::vector<MomentLoad> couples) : couples_(std::move(couples)) {}

  std::string name() const override { return "follower couples"; }
  // Throws std::runtime_error ("moment i: ...") when a group has come to lie on a line parallel
  // to its moment.
  void update(const Eigen::VectorXd& x, const Eigen::VectorXd& u, double t) override;
  void add_force(Eigen::VectorXd& f) const override;

  const std::vector<MomentLoad>& couples() const { return couples_; }

 private:
  std::vector<MomentLoad> couples_;
  Eigen::VectorXd x_;  // positions of the last update()
};

}  // namespace clothsim

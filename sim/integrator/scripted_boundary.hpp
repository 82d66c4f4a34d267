// The prescribed components of a dynamic run: every fixed DOF of the discretisation, with the
// motion chain of the boundary condition that fixed it (held at rest without one). Gives their
// positions at any time, which the integrator turns into the velocities that put them exactly on
// their motion at the end of each step.
#pragma once

#include "sim/boundary/boundary_condition.hpp"
#include "sim/discretization/discretization.hpp"

#include <Eigen/Core>

#include <vector>

namespace clothsim {

class ScriptedBoundary {
 public:
  ScriptedBoundary(const Discretization& d, const std::vector<BoundaryCondition>& conditions);

  // The fixed DOFs, ascending.
  const std::vector<int>& dofs() const { return dofs_; }
  // Position [m] of prescribed DOF number i (an index into dofs()) at time t [s].
  double position(size_t i, double t) const;

 private:
  std::vector<int> dofs_;
  std::vector<std::vector<Motion>> chains_;  // distinct motion chains (index 0: hold)
  std::vector<int> chain_of_;                // per prescribed DOF
  Eigen::VectorXd rest_;
};

}  // namespace clothsim

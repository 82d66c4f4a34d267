// Point loads: a constant force at the surface point of a node (the limit point for the Loop
// shell), turned into nodal forces with the transpose of the discretisation's surface operator
// (Discretization::add_point_forces).
#pragma once

#include "sim/discretization/discretization.hpp"
#include "sim/forces/gravity.hpp"

#include <vector>

namespace clothsim {

struct PointLoad {
  int vertex = 0;                                   // node (vertex of the prepared mesh)
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  // [N]
};

// The nodal force of each load, summed load by load. Throws std::out_of_range naming a load whose
// vertex is not a node.
std::unique_ptr<ConstantForce> make_point_loads(const Discretization& d, const std::vector<PointLoad>& loads);

}  // namespace clothsim

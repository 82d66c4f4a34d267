// Surface loads over the rest surface, as consistent nodal forces f_I = ∫ N_I t dA (dead loads:
// they keep their rest direction and magnitude):
//  - a traction q [N/m² of reference area] in a fixed direction (wind without drag, snow);
//  - a pressure p [N/m²] along the rest surface's unit normal (the triangles' orientation).
#pragma once

#include "sim/discretization/discretization.hpp"
#include "sim/forces/gravity.hpp"

namespace clothsim {

std::unique_ptr<ConstantForce> make_surface_load(const Discretization& d, const Eigen::Vector3d& q);
std::unique_ptr<ConstantForce> make_pressure(const Discretization& d, double p);

}  // namespace clothsim

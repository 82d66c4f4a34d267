#include "sim/forces/surface_load.hpp"

namespace clothsim {

std::unique_ptr<ConstantForce> make_surface_load(const Discretization& d, const Eigen::Vector3d& q) {
  return std::make_unique<ConstantForce>("surface load", d.traction_load([&](const Eigen::Vector3d&) { return q; }));
}

std::unique_ptr<ConstantForce> make_pressure(const Discretization& d, double p) {
  return std::make_unique<ConstantForce>(
      "pressure", d.traction_load([&](const Eigen::Vector3d& normal) -> Eigen::Vector3d { return p * normal; }));
}

}  // namespace clothsim

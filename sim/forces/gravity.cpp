#include "sim/forces/gravity.hpp"

namespace clothsim {

std::unique_ptr<ConstantForce> make_gravity(const Discretization& d, double areal_density, const Eigen::Vector3d& g,
                                            GravityModel model) {
  Eigen::VectorXd f;
  if (model == GravityModel::lumped) {
    const Eigen::VectorXd mass = d.lumped_mass(areal_density);
    f = Eigen::VectorXd::Zero(3 * mass.size());
    for (Eigen::Index v = 0; v < mass.size(); ++v) f.segment<3>(3 * v) = mass(v) * g;
    return std::make_unique<ConstantForce>("gravity (lumped)", std::move(f));
  }
  const Eigen::Vector3d q = areal_density * g;
  return std::make_unique<ConstantForce>("gravity (consistent)", d.traction_load([&](const Eigen::Vector3d&) { return q; }));
}

}  // namespace clothsim

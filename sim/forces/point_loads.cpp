#include "sim/forces/point_loads.hpp"

#include <stdexcept>
#include <string>

namespace clothsim {

std::unique_ptr<ConstantForce> make_point_loads(const Discretization& d, const std::vector<PointLoad>& loads) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * d.num_nodes());
  for (size_t i = 0; i < loads.size(); ++i) {
    const PointLoad& l = loads[i];
    if (l.vertex < 0 || l.vertex >= d.num_nodes())
      throw std::out_of_range("point load " + std::to_string(i) + " at vertex " + std::to_string(l.vertex) + ": no such vertex");
    Eigen::VectorXd one = Eigen::VectorXd::Zero(f.size());
    d.add_point_forces(d.node_points({l.vertex}), l.force.transpose(), one);
    f += one;
  }
  return std::make_unique<ConstantForce>("point loads", std::move(f));
}

}  // namespace clothsim

#include "sim/forces/external_loads.hpp"

#include <algorithm>
#include <stdexcept>

namespace clothsim {

ExternalLoads::ExternalLoads(std::vector<std::unique_ptr<ForceTerm>> constant, std::vector<std::unique_ptr<ForceTerm>> varying,
                             double ramp_time, int num_dofs)
    : constant_(std::move(constant)), varying_(std::move(varying)), ramp_time_(ramp_time) {
  if (!(ramp_time >= 0)) throw std::invalid_argument("loads.ramp_time must be >= 0 [s]");
  constant_force_ = Eigen::VectorXd::Zero(num_dofs);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(num_dofs);
  for (const auto& term : constant_) {
    term->update(zero, zero, 0.0);
    term->add_force(constant_force_);
  }
  force_ = constant_force_;
}

void ExternalLoads::update(const Eigen::VectorXd& x, const Eigen::VectorXd& u, double t) {
  ramp_ = ramp_time_ > 0 ? std::min(1.0, t / ramp_time_) : 1.0;
  for (const auto& term : constant_) term->update(x, u, t);
  force_ = constant_force_;
  for (const auto& term : varying_) {
    term->update(x, u, t);
    term->add_force(force_);
  }
  force_ *= ramp_;
}

bool ExternalLoads::has_energy() const {
  if (ramp_time_ > 0) return false;  // λ(t) makes the load time-dependent
  for (const auto& term : varying_)
    if (!term->has_energy()) return false;
  return true;
}

double ExternalLoads::energy() const {
  double e = 0.0;
  for (const auto& term : constant_) e += term->energy();
  for (const auto& term : varying_) e += term->energy();
  return ramp_ * e;
}

}  // namespace clothsim

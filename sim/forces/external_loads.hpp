// The external loads of a problem as one force term: gravity, surface loads, pressure, point
// loads and follower couples, summed in that order and scaled by the load ramp
// λ(t) = min(1, t / ramp_time) (λ = 1 without a ramp): f = λ(t) Σ f_i. The integrator counts the
// work of this term as the external work of a run (Simulator::external_work). The state-independent
// members are summed once, at construction.
#pragma once

#include "sim/core/force_term.hpp"

#include <memory>
#include <vector>

namespace clothsim {

class ExternalLoads final : public ForceTerm {
 public:
  // `ramp_time` >= 0 [s] (0: full loads from the start). `constant` members must not depend on
  // the state or time (their force is read once, after an update at the rest state).
  ExternalLoads(std::vector<std::unique_ptr<ForceTerm>> constant, std::vector<std::unique_ptr<ForceTerm>> varying,
                double ramp_time, int num_dofs);

  std::string name() const override { return "external loads"; }
  void update(const Eigen::VectorXd& x, const Eigen::VectorXd& u, double t) override;
  bool has_energy() const override;
  double energy() const override;
  void add_force(Eigen::VectorXd& f) const override { f += force_; }
  // The ramp factor λ of the last update() [-].
  double ramp() const { return ramp_; }
  bool empty() const { return constant_.empty() && varying_.empty(); }

 private:
  std::vector<std::unique_ptr<ForceTerm>> constant_, varying_;
  double ramp_time_;
  Eigen::VectorXd constant_force_;  // Σ of the constant members (before the ramp)
  Eigen::VectorXd force_;           // λ (constant + varying) at the last update()
  double ramp_ = 1.0;
};

}  // namespace clothsim

#include "sim/integrator/scripted_boundary.hpp"

namespace clothsim {

ScriptedBoundary::ScriptedBoundary(const Discretization& d, const std::vector<BoundaryCondition>& conditions)
    : rest_(d.rest()) {
  const int n = d.num_nodes();
  chains_.emplace_back();  // hold
  std::vector<int> chain_of_dof(3 * static_cast<size_t>(n), 0);
  for (const BoundaryCondition& bc : conditions) {
    chains_.push_back(bc.motion);
    for (int v : bc.vertices)
      for (int c = 0; c < 3; ++c)
        if (bc.fix[c]) chain_of_dof[3 * static_cast<size_t>(v) + c] = static_cast<int>(chains_.size()) - 1;
  }
  for (int dof = 0; dof < 3 * n; ++dof)
    if (d.status(dof) == DofStatus::fixed) {
      dofs_.push_back(dof);
      chain_of_.push_back(chain_of_dof[static_cast<size_t>(dof)]);
    }
}

double ScriptedBoundary::position(size_t i, double t) const {
  const int dof = dofs_[i];
  return apply_motions(chains_[static_cast<size_t>(chain_of_[i])], rest_.segment<3>(3 * (dof / 3)), t)(dof % 3);
}

}  // namespace clothsim

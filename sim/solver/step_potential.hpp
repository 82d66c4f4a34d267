// A potential of the step's end positions that the implicit step minimises together with the
// elastic model (contact inside the step: sim/contact/barrier_potential.hpp, docs/contact.md).
//
// Implicit Euler with the velocities v as unknowns is the minimisation of the incremental
// potential
//     Φ(v) = ½ vᵀ A v − bᵀ v + E(x + h v) + h Ψ(v),
// A = M + h D + h² K and b = M v₀ + h f₀ the step's linearised elastic system
// (sim/integrator/implicit_euler.hpp), E a potential energy of the end positions [J] (a contact
// barrier) and Ψ a convex dissipation potential of the velocities [W] (lagged friction). The
// integrator takes Newton steps on Φ: at v_k it asks the potential for E, Ψ, their gradients and
// their Hessians as blocks Bᵀ H B on rows B (sim/solver/coupled_matrix.hpp), and solves
//     (A + h² ∇²E + h ∇²Ψ) v = b − h ∇E − h ∇Ψ + (h² ∇²E + h ∇²Ψ) v_k.
// The weights h² and h are the integrator's; the potential reports ∇ₓE and ∇ᵥΨ per node DOF.
#pragma once

#include "sim/solver/coupled_matrix.hpp"

#include <Eigen/Core>

#include <vector>

namespace clothsim {

// A potential's value, gradients and Hessian blocks at one velocity v_k.
struct PotentialLinearisation {
  double energy = 0.0;       // E(x + h v_k) [J]
  double dissipation = 0.0;  // Ψ(v_k) [W]
  Eigen::VectorXd energy_gradient;       // ∇ₓE at x + h v_k, 3·#nodes [N] (zero-sized: none)
  Eigen::VectorXd dissipation_gradient;  // ∇ᵥΨ at v_k, 3·#nodes [N] (zero-sized: none)
  struct Block {
    NodeRow row;              // B in node form, or
    PointRow on_points;       // B on the points of `point_map` (when on_points.count > 0)
    Eigen::Matrix3d hessian;  // H of Bᵀ H B: [N/m] for E, [N·s/m] for Ψ
    bool dissipative = false; // a block of ∇²Ψ (weight h) rather than ∇²E (weight h²)
    bool is_on_points() const { return on_points.count > 0; }
  };
  std::vector<Block> blocks;
  const PointMap* point_map = nullptr;  // the points of the blocks on points (the potential's own)
  // A block's row in either form: u = B x, y += Bᵀ f, and B in node form.
  Eigen::Vector3d apply(const Block& b, const Eigen::VectorXd& x) const {
    return b.is_on_points() ? b.on_points.apply(*point_map, x) : b.row.apply(x);
  }
  void scatter(const Block& b, const Eigen::Vector3d& f, Eigen::VectorXd& y) const {
    if (b.is_on_points()) {
      b.on_points.scatter(*point_map, f, y);
    } else {
      b.row.scatter(f, y);
    }
  }
  NodeRow node_row(const Block& b) const { return b.is_on_points() ? b.on_points.node_row(*point_map) : b.row; }
  int active = 0;  // active pairs (barrier) this linearisation holds
  bool empty() const { return blocks.empty() && energy == 0.0 && dissipation == 0.0; }
};

// What one step's potential did (summed into StepStats by the integrator's owner).
struct PotentialReport {
  int newton_iterations = 0;  // linearisations solved
  int active_pairs = 0;       // barrier pairs active at the end of the step
  int friction_pairs = 0;     // pairs with lagged friction in the step
  double energy = 0.0;        // E at the end of the step [J]
  double candidates_ms = 0.0; // the potential's candidate searches in the step [ms]
};

class StepPotential {
 public:
  virtual ~StepPotential() = default;
  // Starts the step from x (3·#nodes) [m] at time t [s] with length h [s]; v_guess [m/s] is the
  // integrator's start for the new velocities (the potential may prepare for end positions near
  // x + h v_guess). `diagonal`: the diagonal of the step's elastic matrix A per DOF (scales).
  virtual void begin_step(const Eigen::VectorXd& x, const Eigen::VectorXd& v_guess, double t, double h,
                          const Eigen::VectorXd& diagonal) = 0;
  // Linearises at the velocities v (end positions x + h v).
  virtual void linearise(const Eigen::VectorXd& v, PotentialLinearisation& out) = 0;
  // Called once per step with the accepted velocities and the report so far (to fill in).
  virtual void end_step(const Eigen::VectorXd& v, PotentialReport& report) = 0;
  // Whether the velocity change from v_k to v_{k+1} is small enough to stop Newton [m/s].
  virtual double velocity_tolerance(double h) const = 0;
  // The largest fraction α ∈ [0, 1] of the move of the end positions from velocities `from` to
  // `to` (x + h from → x + h to, linearly) over which the potential stays defined: for contact,
  // no pair of surfaces passes through another (continuous collision detection). The Newton
  // iterates stay free of crossings, as the barrier needs (it pushes a pair apart along the side
  // it is on).
  virtual double step_bound(const Eigen::VectorXd& from, const Eigen::VectorXd& to) = 0;
};

}  // namespace clothsim

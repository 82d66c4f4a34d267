// Dynamic simulation of a corotational subdivision shell (paper §4.2 eq. 28, §4.3): lumped mass,
// Kelvin–Voigt damping, implicit Euler with the velocities as unknowns, scripted boundaries.
//
// Each step solves (M + h D + h² K_R) v⁺ = M v + h (f_int(x) + f_ext), x⁺ = x + h v⁺ (paper eq.
// 28 as a first-order system), with the element rotations R extracted at x and frozen:
// K_R = Σ R K_e Rᵀ is the rest stiffness rotated per element, f_int = −Σ R K_e (Rᵀ x_e − X_e).
// Further Newton iterations (solver.newton_iterations) re-extract the rotations at x + h v_k and
// solve (M + h D + h² K_R) v⁺ = M v + h (f_int(x + h v_k) + f_ext) + h² K_R v_k.
// Measured trade-offs: with one solve the rotations lag the motion by a step, so a body that
// rotates fast gains a little strain energy per step (a strip flapping at 5 rad/s, h = 2 ms: up
// to 1.8e-4 of its energy; a sleeve spinning at 10 rad/s, h = 1 ms: 2.2e-5 of its size); two or
// three iterations remove both. Starting the iteration from the predicted state x + h v instead
// was tried and rejected: it sets twisted sleeves into a step-to-step oscillation that never
// decays (kinetic energy 8e-3 J against 4e-10 J from x).
// Scripted components get the velocity that puts them exactly on their motion at the end of the
// step. The simulator writes no files.
#pragma once

#include "sim/dynamics/dynamic_problem.hpp"
#include "sim/shell/ghost_layer.hpp"

#include <Eigen/Core>

#include <memory>

namespace clothsim {

struct DynamicState {
  Eigen::MatrixX3d x;  // #V × 3 control-vertex positions [m]
  Eigen::MatrixX3d v;  // #V × 3 control-vertex velocities [m/s]
  double t = 0.0;      // [s]
  int step = 0;        // steps taken
};

class Simulator {
 public:
  // Throws std::runtime_error (MeshError for mesh problems) naming the problem for an invalid
  // description (bad material, time step, unsupported structure for the chosen solver, ...).
  explicit Simulator(const DynamicProblem& problem);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  const DynamicState& state() const;
  int num_vertices() const;
  // Number of steps to reach problem.time.end.
  int num_steps() const;

  // Advances one time step. Throws SimulationError (naming the step and time) on NaN,
  // divergence or a linear solver that does not converge; the state is then left as it was
  // before the step.
  StepStats step();

  // Limit points of the control vertices at rest and now (#V × 3) [m]; limit displacement is
  // their difference.
  const Eigen::MatrixX3d& limit_rest() const;
  Eigen::MatrixX3d limit_positions() const;
  // The control mesh with its ghost layer, and the current positions of all its vertices
  // (#ext × 3) — what a limit-surface refinement operator acts on.
  const ExtendedMesh& extended_mesh() const;
  Eigen::MatrixX3d extended_positions() const;

  // Energy bookkeeping [J]: ½ vᵀ M v; the corotated strain energy of the current state; the
  // work done so far by the external loads (gravity, surface loads, point loads, couples) on the
  // free components, Σ f_extᵀ (x⁺ − x); and the work done so far on the cloth by the scripted
  // and held components (see below). Over a run, with E = kinetic + elastic energy,
  //     E(t) − E(0) = external_work + boundary_work − dissipated,
  // where `dissipated` >= 0 for a linear (non-rotating) system: Kelvin–Voigt and mass damping,
  // and implicit Euler's own ½|Δv|²_M + ½ Δxᵀ K Δx per step. A rise beyond the two works comes
  // from the nonlinearity of the corotation (rotations frozen over a step) or a bug.
  //
  // Boundary work. A prescribed component p is moved by Δx_p = h v⁺_p; the force the support
  // exerts on it is the reaction that makes its row of the step's system hold,
  //     h R_p = (A v⁺ − b)_p,   A = (1 + h c_M) M + (h c_K + h²) K_R,  b = M v + h (f_int + f_ext),
  // i.e. R_p = M (v⁺ − v)/h − [f_int − h K_R v⁺ − D v⁺]_p − f_ext,p: inertia minus the cloth's
  // (linearised end-of-step, damped) internal force and the load on that component. The work of
  // the support and of the load on the component, (R_p + f_ext,p) Δx_p, is summed. Using the
  // integrator's own force (not a quadrature of f_int over the step) makes the balance above
  // exact, step by step, for a linear system: a rise then measures the corotation's error alone.
  double kinetic_energy() const;
  double elastic_energy() const;
  double external_work() const;
  double boundary_work() const;
  // Largest |principal Green–Lagrange membrane strain| of the limit surface at the element
  // barycentres in the current state [-] (CorotationalElements::membrane_principal_strains);
  // computed on demand, a pass over the elements.
  double max_membrane_strain() const;
  // Lumped mass per control vertex [kg] (areal density × a third of the incident area).
  const Eigen::VectorXd& vertex_mass() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothsim

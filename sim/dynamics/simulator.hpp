// The dynamic analysis of a problem: builds the discretisation (sim/discretization/), the force
// terms (sim/forces/), the scripted boundary, the linear solver (sim/solver/linear_solver.hpp) and
// the integrator (sim/integrator/implicit_euler.hpp) from a Problem, and steps them. It holds
// the state; reading the surface goes through the discretisation's operators. Writes no files.
//
// Force terms of a dynamic run, in this order: the elastic term of the discretisation (corotated,
// with tension stiffening per solver.tension_stiffening), wrapped by Kelvin–Voigt damping when
// damping.stiffness > 0; mass damping when damping.mass > 0; then the external loads (lumped
// gravity, surface load, pressure, point loads, follower couples; ramped over loads.ramp_time).
// More terms can be added before the first step (add_term), e.g. by a test.
#pragma once

#include "sim/integrator/implicit_euler.hpp"
#include "sim/problem/problem.hpp"
#include "sim/solver/linear_solver.hpp"

#include <Eigen/Core>

#include <memory>

namespace clothsim {

// Everything later steps depend on, so that a run restored from it continues bit for bit as the
// run it was taken from (the terms and the contact stage keep no state between steps beyond what
// they recompute from the state).
struct SimulatorCheckpoint {
  DynamicState state;
  IntegratorCheckpoint integrator;
  LinearSolverCheckpoint solver;
};

// What the settling phase did (Problem::settle): its steps, and the largest membrane strain of
// the surface at its start and end (a garment's seams start open: the bands of cloth that join
// them start stretched and relax while it settles).
struct SettleReport {
  int steps = 0;
  double strain_start = 0.0;  // [-]
  double strain_end = 0.0;    // [-]
  // The largest seam gap: how much longer than in the pattern (its texture coordinates) a control
  // edge is, at most — an open seam is a band of edges stretched across the gap [m]; 0 without
  // texture coordinates.
  double gap_start = 0.0, gap_end = 0.0;
  // Where its time went: the settle's steps as a run's are booked (StepStats), summed [ms], and
  // their linear solver's iterations and factorisations.
  double step_ms = 0.0;
  long long solver_iterations = 0, factorizations = 0;
  ContactCounters contact;
};

class Simulator {
 public:
  // Throws std::runtime_error (MeshError for mesh problems) naming the problem for an invalid
  // description (bad material, time step, unsupported structure for the chosen solver, ...).
  // With problem.settle.time > 0 it first settles the cloth: the same problem with the loads off,
  // the obstacles held where they start, no boundary conditions (pins act from t = 0, where the
  // settling leaves their vertices) and mass damping of at least settle.damping, run for
  // settle.time; the run then starts (t = 0, at rest) from the settled positions, which replace
  // the mesh's as the configuration displacements are measured from (so it needs a rest state of
  // its own, RestShape::pattern). Deterministic, so a resumed run settles to the same start.
  explicit Simulator(const Problem& problem);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  // Adds a force term (internal: its energy counts as elastic energy) to the run. Only before
  // the first step; the term must refer to this simulator's discretisation.
  void add_term(std::unique_ptr<ForceTerm> term);

  const DynamicState& state() const;
  int num_vertices() const;
  // Number of steps to reach problem.time.end.
  int num_steps() const;

  // Advances one time step. Throws SimulationError (naming the step and time) on NaN,
  // divergence or a linear solver that does not converge; the state is then left as it was
  // before the step.
  StepStats step();

  // The discretisation of the run (shared: results and outputs keep it alive).
  const Discretization& discretization() const;
  std::shared_ptr<const Discretization> shared_discretization() const;
  // Positions (#P × 3) [m] of an operator's surface points in the current state and at rest.
  Eigen::MatrixX3d surface_points(const SurfaceOperator& op) const;
  Eigen::MatrixX3d rest_surface_points(const SurfaceOperator& op) const;
  // The surface point of every node (for the Loop shell its limit point) now and at rest
  // (#nodes × 3) [m]; their difference is the nodes' surface displacement.
  Eigen::MatrixX3d node_points() const;
  const Eigen::MatrixX3d& node_points_rest() const;

  // Energy bookkeeping [J] (ImplicitEuler: kinetic_energy, elastic_energy, external_work,
  // boundary_work, and the balance they satisfy).
  double kinetic_energy() const;
  double elastic_energy() const;
  double external_work() const;
  double boundary_work() const;
  // The contact barrier's energy at the current state [J] (0 without contact or with
  // collision.method "constraints"): a potential energy of the positions, part of the mechanical
  // energy with kinetic and elastic (docs/contact.md, "Contact inside the step").
  double contact_energy() const;
  // Pairs of drawn triangles left out of the self-collision because they touch at rest without
  // being neighbours in the material (ContactStage::joined_at_rest); 0 without contact.
  long long contact_joined_at_rest() const;
  // Largest |principal Green–Lagrange membrane strain| of the surface in the current state [-]
  // (Discretization::max_membrane_strain: for loop_kl of the limit surface at the element
  // barycentres, for linear_fe and mass_spring of the flat triangles); computed on demand, a pass
  // over the elements.
  double max_membrane_strain() const;
  // Lumped mass per node [kg] (areal density × a third of the incident area).
  const Eigen::VectorXd& vertex_mass() const;

  // The state after the last step, for continuing the run later (restore()).
  SimulatorCheckpoint checkpoint() const;

  // The settling phase's report (all zero without one).
  const SettleReport& settle_report() const;
  // Continues from `c`, taken from a Simulator of the same problem: the next step() gives what
  // the original's next step gave, to the bit. Throws std::invalid_argument if `c` does not fit
  // the problem (mesh size, solver settings); the Simulator is then unusable.
  void restore(const SimulatorCheckpoint& c);

 private:
  void init(const Problem& problem);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothsim

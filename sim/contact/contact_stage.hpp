// Contact in the time step, in two roles. By default (collision.method "barrier") proximity is a
// barrier potential minimised inside the implicit step (sim/contact/barrier_potential.hpp, through
// the StepPotential calls below), and this stage's filter is the fail-safe after the solve. With
// "constraints" the filter does all of it, as described next.
//
// The filter: a velocity filter applied after the linear solve (Bridson, Fedkiw & Anderson 2002,
// as the paper's §6 does), so the system matrix keeps its fixed pattern. It takes the step's
// start positions x and new velocities v (end positions
// x + h v) and changes the free components of v so that the step ends with the cloth's collision
// surface separated from itself and from the obstacles (docs/contact.md has the algorithm, its
// parameters and what is guaranteed).
//
// The collision surface. Contact acts on the surface that is drawn: the discretisation's display
// operator at `surface_level` (the Loop shell's limit surface refined that many times, its points
// an affine function of the nodes, P = P(X) + J (x − X)). A constraint between surface points is a
// constraint on the node velocities through Jᵀ, with the nodes' lumped masses: impulses on the
// surface spread over the control nodes that carry it, and nothing is assumed about which node
// is "nearest".
//
// Per step:
//  1. broad phase: the boxes of the surface triangles swept over the step and grown by the
//     thickness, against each other (self-collision) and against the obstacles' swept triangles
//     (sim/contact/candidates.hpp, with Embree: sim/contact/broad_phase.hpp); candidate
//     point–triangle and edge–edge pairs;
//  2. proximity: pairs closer than the thickness at the start of the step get inelastic impulses
//     that stop their approach, a repulsion of at most 10 % of the overlap per step, and Coulomb
//     friction bounded by μ times the normal impulse;
//  3. continuous collision detection over the step (additive CCD, sim/contact/narrow_phase.hpp)
//     down to a minimum separation of 10 % of the thickness; colliding pairs get inelastic
//     impulses; repeated up to `ccd_passes` times;
//  4. fail-safe: pairs still colliding are merged into impact zones (nodes that share a pair or a
//     node) that move as one affine map for the step — a rigid motion fitted to the zone's
//     momentum, or the obstacle's or the prescribed nodes' motion when the zone holds them — which
//     cannot create an intersection inside the zone; repeated until the step is free.
// A scene without self-collision and obstacles builds no ContactStage at all.
#pragma once

#include "sim/contact/broad_phase.hpp"
#include "sim/contact/obstacle.hpp"
#include "sim/core/contact_counters.hpp"
#include "sim/discretization/discretization.hpp"
#include "sim/solver/step_potential.hpp"
#include "sim/solver/pcg.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <vector>

namespace clothsim {

// What one step's contact stage did: the counters that add up over a run (pairs_tested,
// impulses, impact_zones, unresolved, the response's iterations, the phases' times; its `ms` and
// the potential's fields are left to the integrator), and two of its own.
struct ContactReport : ContactCounters {
  int proximity_pairs = 0;     // pairs within the thickness at the start of the step
  int ccd_collisions = 0;      // colliding pairs found by CCD, summed over the passes
  double total_ms() const { return broad_ms + narrow_ms + response_ms; }
};

struct ContactParameters {
  int surface_level = 2;             // display refinement levels of the collision surface
  double min_separation_ratio = 0.1; // CCD keeps this fraction of the thickness
  double near_separation_ratio = 0.01;  // ... and this fraction between parts near each other at rest
  double repulsion_ratio = 0.1;      // pairs that start a step closer than the minimum separation are
                                     // pushed apart by this fraction of the shortfall per step
  int ccd_passes = 8;                // CCD and response passes before the fail-safe
  int zone_rounds = 100;             // fail-safe rounds before giving up (reported as unresolved)
  // The implicit response (augmented Lagrangian on the step's system): penalty per constraint
  // as a multiple of its effective stiffness on the system's diagonal, outer iterations at most,
  // and the relative tolerance of the inner conjugate-gradient solves.
  double penalty_ratio = 10.0;
  int response_iterations = 10;
  int friction_updates = 3;          // updates in which the friction bound follows the normal impulse
  double response_cg_tolerance = 1e-6;
  int refactor_iterations = 15;      // refactorise the Newton matrix after a solve that needed more
  // The contact potential inside the step (docs/contact.md, "Contact inside the step"): the
  // barrier's stiffness k per pair, as k h² = barrier_ratio × the effective mass of its lightest
  // cloth point through the step's matrix.
  double barrier_ratio = 4.0;
};

// The step's linear system for the implicit response: A = M + h D + h² K (only the rows and
// columns of the free DOFs are read) and an approximate inverse of A on the free DOFs.
struct ResponseSystem {
  const Eigen::SparseMatrix<double>& matrix;
  Preconditioner inverse;
};

class ContactStage {
 public:
  // `discretization` and the masses must outlive the stage. `node_mass`: lumped mass per node
  // [kg]; `free`: per DOF (3·#nodes), whether it is an unknown (others are prescribed or derived
  // and are never changed). Throws std::invalid_argument for bad settings.
  ContactStage(const Discretization& discretization, const Eigen::VectorXd& node_mass, const std::vector<char>& free,
               const CollisionSettings& settings, std::vector<Obstacle> obstacles, const ContactParameters& parameters);
  ~ContactStage();

  // Filters the step from time t to t + h: x the start positions (3·#nodes) [m], v the new
  // velocities [m/s] (the solution of `system`), changed in place on free components only.
  ContactReport filter(const Eigen::VectorXd& x, double t, double h, Eigen::VectorXd& v, const ResponseSystem& system);

  // Contact inside the implicit step (sim/solver/step_potential.hpp): after
  // enable_potential(), proximity is a barrier energy of the end positions with lagged friction,
  // which the integrator minimises with the elastic model (begin_step / linearise / end_step), and
  // filter() is the fail-safe only: continuous collision detection with the implicit response
  // on colliding pairs, then impact zones.
  void enable_potential();
  bool potential_enabled() const;
  void begin_step(const Eigen::VectorXd& x, const Eigen::VectorXd& v_guess, double t, double h, const Eigen::VectorXd& diagonal);
  void linearise(const Eigen::VectorXd& v, PotentialLinearisation& out);
  void end_step(const Eigen::VectorXd& v, PotentialReport& report);
  double velocity_tolerance(double h) const;
  // StepPotential::step_bound: the fraction of the move from end positions x + h from to
  // x + h to free of crossings (pairs kept a tenth of the thickness apart, a hundredth between
  // parts near each other at rest; a pair already closer keeps half its distance).
  double step_bound(const Eigen::VectorXd& from, const Eigen::VectorXd& to);

  // The collision surface (the display operator at surface_level) and its points at x.
  const SurfaceOperator& surface() const;
  // Pairs of drawn triangles that touch at rest (closer than a hundredth of the thickness) without
  // being neighbours in the material: a surface that meets itself at rest. They are left out of
  // the contact (the cloth is taken to be joined there); 0 without self-collision.
  long long joined_at_rest() const;
  const std::vector<Obstacle>& obstacles() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothsim

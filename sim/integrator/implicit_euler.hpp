// Implicit Euler with the velocities as unknowns (paper §4.2 eq. 28 as a first-order system),
// over any discretisation and any set of force terms (sim/core/force_term.hpp).
//
// Each step solves the linearised
//     (M + h D + h² K) v⁺ = M v + h f₀(x),     x⁺ = x + h v⁺,
// with f = f₀ − D v the terms' force, K = −∂f₀/∂x and D their stiffness and damping at the
// linearisation point x (for the corotated shell: the rotations extracted at x and frozen, so
// K = Σ R K_e Rᵀ). The weights (1, h, h²) belong to this integrator and nowhere else. Further
// Newton iterations (newton_iterations > 1) re-evaluate the terms at x + h v_k and solve
//     (M + h D + h² K) v⁺ = M v + h f₀(x + h v_k) + h² K v_k.
// Measured trade-offs: with one solve the rotations lag the motion by a step, so a body that
// rotates fast gains a little strain energy per step (a strip flapping at 5 rad/s, h = 2 ms: up
// to 1.8e-4 of its energy; a sleeve spinning at 10 rad/s, h = 1 ms: 2.2e-5 of its size); two or
// three iterations remove both. Starting the iteration from the predicted state x + h v instead
// was tried and rejected: it sets twisted sleeves into a step-to-step oscillation that never
// decays (kinetic energy 8e-3 J against 4e-10 J from x).
//
// Constraints: fixed DOFs get the velocity that puts them exactly on their scripted motion at
// t + h (ScriptedBoundary); dependent DOFs follow the discretisation's rule
// (Discretization::make_consistent); only free DOFs are unknowns of the linear solve.
// Writes no files.
#pragma once

#include "sim/integrator/scripted_boundary.hpp"
#include "sim/core/contact_counters.hpp"
#include "sim/solver/block_sum.hpp"
#include "sim/solver/step_potential.hpp"
#include "sim/discretization/discretization.hpp"
#include "sim/core/force_term.hpp"
#include "sim/solver/linear_solver.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace clothsim {

// The state of a dynamic run, flat over the nodes (sim/core/layout.hpp).
struct DynamicState {
  Eigen::VectorXd x;  // positions, 3·#nodes [m]
  Eigen::VectorXd v;  // velocities, 3·#nodes [m/s]
  double t = 0.0;     // [s]
  int step = 0;       // steps taken
  // #nodes × 3 views.
  Eigen::Map<const RowMatrixX3d> positions() const { return as_rows(x); }
  Eigen::Map<const RowMatrixX3d> velocities() const { return as_rows(v); }
};

struct IntegratorSettings {
  double dt = 1e-3;           // time step [s]
  int newton_iterations = 1;  // linear solves per step; > 1 re-evaluates the terms (accuracy studies)
  // The iterative solver's start: the last velocity extrapolated by its last change,
  // v + (v − v_prev) (constant acceleration), or the last velocity itself.
  bool extrapolated_start = true;
  // Where contact acts in a step (the step potential is something), the step is linearised again
  // at its end positions while a force term's frame (a corotated element) turned by more than this
  // between the linearisation and the end positions [rad] (ForceTerm::frame_turn), up to four
  // times: the rotations follow a fast impact within the step. Infinite: never (a scene sets it
  // from solver.rotation_tolerance_deg).
  double rotation_tolerance = std::numeric_limits<double>::infinity();
};

// Per-step figures (one row of stats.csv).
struct StepStats {
  int step = 0;
  double t = 0.0;                // time at the end of the step [s]
  int solver_iterations = 0;     // pcg iterations summed over Newton iterations (1 per direct solve)
  double residual = 0.0;         // final relative residual of the linear system
  double newton_change = 0.0;    // ‖v⁺_k − v⁺_{k−1}‖ / ‖v⁺_k‖ of the last Newton iteration (0 with one)
  double rotate_ms = 0.0;        // rotation extraction (filled by the Simulator)
  double update_ms = 0.0;        // evaluating the force terms (rotations included)
  double assemble_ms = 0.0;      // system matrix and right-hand side (with the Simulator: element
                                 // forces too, as before the split)
  double solve_ms = 0.0;         // linear solve (with any factorisation)
  int factorizations = 0;        // Cholesky factorisations in this step (direct solve or preconditioner)
  double factor_ms = 0.0;        // their time, part of solve_ms
  // Linear solves of the step that conjugate gradients failed and the direct solver finished
  // (LinearSolveReport::direct_fallbacks), and why the first of them was needed.
  int direct_fallbacks = 0;
  std::string direct_fallback_reason;
  double step_ms = 0.0;          // the whole step (ImplicitEuler::step) [ms]
  double kinetic_energy = 0.0;   // ½ vᵀ M v [J]
  double elastic_energy = 0.0;   // energy of the internal terms [J]
  double external_work = 0.0;    // work of the external loads on the free components this step [J]
  double boundary_work = 0.0;    // work of the scripted and held components on the cloth this step
                                 // [J] (ImplicitEuler::boundary_work)
  // Contact's counts and times in this step (the velocity filter's and the potential's,
  // sim/contact/contact_stage.hpp; zero without contact). contact.ms is all of contact's time.
  ContactCounters contact;
  // The contact potential's state at the end of the step (StepPotential; zero without one).
  int contact_active_pairs = 0;       // barrier pairs active at the end of the step
  int contact_friction_pairs = 0;     // pairs with lagged friction in the step
  double contact_energy = 0.0;        // the barrier's energy at the end of the step [J]
};

// The step's linear system as the solve left it, for a velocity filter that responds implicitly:
// A = M + h D + h² K (full storage; only the rows and columns of the free components are
// meaningful), the mask of free components, and an approximate inverse of A on them (the
// solver's factorisation or preconditioner).
struct StepSystem {
  const Eigen::SparseMatrix<double>& matrix;
  const std::vector<char>& free;
  Preconditioner inverse;
};

// A stage of the step after the linear solve that may change the new velocities (contact): it
// gets the positions x at the start of the step (3·#nodes) [m], the step's start time t and
// length h [s], the new velocities v [m/s] and the step's system, and changes free components
// of v only (the integrator then moves x to x + h v and derives the dependent components). It
// reports what it did in `stats`. Throwing std::runtime_error stops the run with a
// SimulationError.
class VelocityFilter {
 public:
  virtual ~VelocityFilter() = default;
  virtual void filter(const Eigen::VectorXd& x, double t, double h, Eigen::VectorXd& v, const StepSystem& system,
                      StepStats& stats) = 0;
};

// A run that cannot go on: NaN, divergence or a linear solver that does not converge.
class SimulationError : public std::runtime_error {
 public:
  enum class Kind {
    other,     // anything else (e.g. a follower couple that lost its lever arm)
    nan,       // the state became NaN or infinite
    diverged,  // a vertex moved more than 1000 times the mesh size
    solver,    // the linear solver did not converge or the matrix was not positive definite
  };
  SimulationError(int step, double t, const std::string& what, Kind kind = Kind::other)
      : std::runtime_error("step " + std::to_string(step) + " (t = " + std::to_string(t) + " s): " + what),
        step_(step),
        t_(t),
        kind_(kind) {}
  int step() const { return step_; }
  double time() const { return t_; }
  Kind kind() const { return kind_; }

 private:
  int step_;
  double t_;
  Kind kind_;
};

// The integrator's own state beyond DynamicState, for a run continued from a checkpoint: the
// displacement as the step computed it (x − rest differs from it in the last bits), the previous
// step's start velocity (the extrapolated start) and the accumulated works [J].
struct IntegratorCheckpoint {
  Eigen::VectorXd u, v_previous;
  double external_work = 0.0, boundary_work = 0.0;
  // The coupled pattern of the last solve with a step potential (per node, the coupled nodes;
  // empty without one): the solver's factor is of a matrix with this pattern.
  std::vector<std::vector<int>> coupled_pattern;
  // Whether the step potential was something in the last step (the next step's Newton then starts
  // from the velocities, not the extrapolated guess).
  bool contact_last_step = false;
};

class ImplicitEuler {
 public:
  // `internal`: the cloth's own terms (elastic, damping), whose energies make elastic_energy();
  // `loads`: the external loads (may be null), whose work makes external_work(). All of them,
  // the discretisation, the boundary and the solver must outlive the integrator. `node_mass`: the
  // lumped mass per node [kg]. The terms are evaluated at `state` (its x consistent).
  ImplicitEuler(const IntegratorSettings& settings, const Discretization& discretization, const Eigen::VectorXd& node_mass,
                std::vector<ForceTerm*> internal, ForceTerm* loads, const ScriptedBoundary& boundary, LinearSolver& solver,
                const DynamicState& state);

  // Advances `state` by one step. Throws SimulationError (naming the step and time) on NaN,
  // divergence, a term that cannot be evaluated or a linear solver that does not converge;
  // `state` is then left as it was.
  StepStats step(DynamicState& state);

  // ½ vᵀ M v [J].
  double kinetic_energy(const DynamicState& state) const;
  // Σ energy of the internal terms at the last evaluated state [J].
  double elastic_energy() const;
  // Energy bookkeeping [J]: the work done so far by the external loads on the free components,
  // Σ f_extᵀ (x⁺ − x); and the work done so far on the cloth by the scripted and held
  // components. Over a run, with E = kinetic + elastic energy,
  //     E(t) − E(0) = external_work + boundary_work − dissipated,
  // where `dissipated` >= 0 for a linear (non-rotating) system: Kelvin–Voigt and mass damping,
  // and implicit Euler's own ½|Δv|²_M + ½ Δxᵀ K Δx per step. A rise beyond the two works comes
  // from the nonlinearity of the corotation (rotations frozen over a step) or a bug.
  //
  // Boundary work. A prescribed component p is moved by Δx_p = h v⁺_p; the force the support
  // exerts on it is the reaction that makes its row of the step's system hold,
  //     h R_p = (A v⁺ − b)_p,   A = M + h D + h² K,  b = M v + h f₀,
  // i.e. R_p = M (v⁺ − v)/h − [f₀ − h K v⁺ − D v⁺]_p: inertia minus the cloth's (linearised
  // end-of-step, damped) force on that component. The work of the support and of the load on the
  // component, (R_p + f_ext,p) Δx_p, is summed. Using the integrator's own force (not a
  // quadrature of f over the step) makes the balance above exact, step by step, for a linear
  // system: a rise then measures the corotation's error alone.
  double external_work() const { return work_; }
  double boundary_work() const { return boundary_work_; }
  // A filter of the new velocities after each solve (contact); null for none. Must outlive the
  // integrator.
  void set_velocity_filter(VelocityFilter* filter) { filter_ = filter; }
  // A potential of the end positions minimised inside the step (contact, step_potential.hpp);
  // null for none. Must outlive the integrator.
  void set_step_potential(StepPotential* potential) { potential_ = potential; }
  // The step potential's energy at the current state [J] (0 without one).
  double potential_energy() const { return potential_energy_; }
  // Which DOFs are unknowns of the linear solve (3·#nodes): the ones a velocity filter may change.
  const std::vector<char>& free_dofs() const { return free_; }
  IntegratorCheckpoint checkpoint() const;
  // Continues from `c`, taken at `state`: sets the integrator's state and evaluates the terms at
  // it, as the step that reached it did. Throws std::invalid_argument on a size mismatch.
  void restore(const DynamicState& state, const IntegratorCheckpoint& c);
  // The matrix of the last linear solve: the step's system matrix (its pattern fixed for the run),
  // or, with a step potential, that matrix with the potential's couplings (the solver's
  // checkpoint refers to it).
  const Eigen::SparseMatrix<double>& system_matrix() const { return coupled_in_use_ ? coupled_.matrix() : system_; }
  // Displacement from the rest state (3·#nodes) [m] of the last state reached, consistent.
  const Eigen::VectorXd& displacement() const { return u_; }

 private:
  void update_terms(const Eigen::VectorXd& x, const Eigen::VectorXd& u, double t);
  // a = Σ over the terms of w.stiffness K + w.damping D.
  void assemble(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const;

  IntegratorSettings settings_;
  const Discretization& discretization_;
  std::vector<ForceTerm*> internal_;
  ForceTerm* loads_;
  std::vector<ForceTerm*> all_;  // internal, then loads
  const ScriptedBoundary& boundary_;
  LinearSolver& solver_;
  Eigen::VectorXd mass_;            // 3·#nodes [kg]
  std::vector<char> free_;          // 3·#nodes: unknown in the linear solve
  std::vector<int> dependent_;      // dependent DOFs
  Eigen::VectorXd u_;               // displacement of the current state
  Eigen::VectorXd v_previous_;      // velocity at the start of the previous step (extrapolated start)
  Eigen::SparseMatrix<double> system_;    // the step's matrix, its storage reused from step to step
  Eigen::SparseMatrix<double> stiffness_;  // K alone (Newton iterations only)
  std::vector<Eigen::Index> diagonal_;    // value offsets of its diagonal entries
  double size_ = 1.0;                     // bounding-box diagonal of the rest state [m]
  double work_ = 0.0, boundary_work_ = 0.0;
  VelocityFilter* filter_ = nullptr;
  StepPotential* potential_ = nullptr;
  CoupledMatrix coupled_;          // the step's matrix with the potential's blocks
  bool coupled_in_use_ = false;    // the last solve was on coupled_
  double potential_energy_ = 0.0;
  // Newton on the incremental potential with the step potential in it (step_potential.hpp):
  // v holds the caller's start (and the fixed components) and receives the result, v_now is the
  // velocity at the start of the step; a and b are the elastic system. `first`: the step's first
  // linearisation of the elastic terms (the potential starts its step; later ones continue from
  // v, already free of crossings). Sets potential_acted_ where the potential is something.
  // `turned`, when given, is asked once Newton has taken kTurnCheck steps whether the elastic
  // terms' frames at the iterate's end positions turned beyond the rotation tolerance (it then
  // leaves the terms evaluated there); if so Newton stops there and newton_turned_ is set, so that
  // the step is linearised again without converging a linearisation it will discard.
  LinearSolveReport solve_with_potential(Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& b, const Eigen::VectorXd& x,
                                         const Eigen::VectorXd& v_now, double t, double h, bool first, Eigen::VectorXd& v,
                                         StepStats& stats, const std::function<bool(const Eigen::VectorXd&)>* turned = nullptr);
  bool newton_turned_ = false;  // the last solve_with_potential stopped for a turn (above)
  // Ends the potential's step at the accepted velocities v.
  void finish_potential(const Eigen::VectorXd& v, StepStats& stats);
  // The end positions of velocities v from x, as the step's end makes them: scripted components
  // at `target`, tied ones by their rule; x_end and u_end = x_end − rest.
  void end_positions(const Eigen::VectorXd& x, const Eigen::VectorXd& v, const Eigen::VectorXd& target,
                     Eigen::VectorXd& x_end, Eigen::VectorXd& u_end) const;
  bool potential_acted_ = false;  // the step potential was something in this step's Newton iterates
  // Scratch of solve_with_potential: the linearisation's blocks, merged by row and weighted.
  BlockSum blocks_;
  bool contact_last_step_ = false;  // ... in the last step's (the next step's Newton starts from v)
};

}  // namespace clothsim

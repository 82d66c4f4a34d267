// The contact potential inside the implicit step (docs/contact.md, "Contact inside the step";
// sim/solver/step_potential.hpp has how the integrator uses it): a cubic barrier of each pair's
// distance at the end positions (sim/contact/barrier.hpp), with a stiffness that follows the
// step's matrix under the pair's cloth points, and lagged friction on the pairs pressed at the
// start of the step. For each velocity the integrator asks about it gives the energy, the
// dissipation, their gradients and Hessian blocks (linearise), and for a move between two
// velocities the fraction that keeps every pair from passing through another (step_bound).
//
// Its candidates are a broad phase grown by twice the thickness, kept while the cloth stays
// within half the thickness of the motion they were made for (so from step to step while it
// rests, and through Newton's iterates within a step), with lower bounds of their distances at a
// reference so that most pairs of a slow cloth are decided without being looked at. The
// fail-safe after the step (ContactStage::filter) runs its collision detection on the same
// candidates when they serve its motion: hence serves / served / candidates / reference_bounds.
//
// What lasts across steps (the candidates and the motion they were made for, the distance bounds,
// the last linearisation, the friction rows) is kept here; the step's start positions and
// obstacle vertices (StepPositions, made by the stage), its length and the diagonal of its matrix
// are arguments. The surface, pair primitives, obstacles and search are referenced and must
// outlive the potential.
#pragma once

#include "sim/contact/barrier.hpp"
#include "sim/contact/candidates.hpp"
#include "sim/contact/collision_surface.hpp"
#include "sim/contact/obstacle.hpp"
#include "sim/contact/obstacle_set.hpp"
#include "sim/contact/pair_geometry.hpp"
#include "sim/contact/pair_types.hpp"
#include "sim/solver/coupled_matrix.hpp"
#include "sim/solver/step_potential.hpp"

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace clothsim::contact {

// The positions of the step in hand, made by the contact stage at the start of each step (and
// read by its fail-safe too).
struct StepPositions {
  Eigen::MatrixX3d p0;      // surface points at the start of the step (#P × 3) [m]
  Eigen::MatrixX3d o0, o1;  // obstacle vertices (ObstacleSet's numbering) at t and t + h [m]
  bool obstacle_boxes_current = false;  // the candidate search's obstacle boxes are those of o0 and o1
};

struct BarrierSettings {
  double thickness = 1e-3;   // d̂, the barrier's reach [m]
  double friction = 0.0;     // μ between cloth and cloth (obstacles have their own)
  double tolerance = 0.01;   // CollisionSettings::tolerance: velocities to this fraction of d̂ per step
  double barrier_ratio = 4.0;          // ContactParameters::barrier_ratio
  double min_separation_ratio = 0.1;   // step_bound keeps pairs this fraction of d̂ apart ...
  double near_separation_ratio = 0.01; // ... and near pairs this one (ContactParameters)
  bool obstacles_static = false;       // no meshed obstacle moves: o0 = o1, the same every step
};

// Lower bounds of the candidates' distances at a reference configuration, with how far each
// surface point has moved from it (BarrierPotential::reference_bounds).
struct ReferenceBounds {
  const Bounds& bounds;
  const Eigen::VectorXd& point_move;  // per surface point [m]
  double obstacle_motion = 0.0;       // the obstacles' largest move from theirs [m]
  double motion = 0.0;                // the largest change of any pair's distance these allow [m]
};

class BarrierPotential {
 public:
  BarrierPotential(CollisionSurface& surface, const PairPrimitives& pairs, const ObstacleSet& obstacle_set,
                   const std::vector<Obstacle>& obstacles, CandidateSearch& search, const BarrierSettings& settings);

  // Starts the step from node positions x at time t with length h [s]: `step` holds x's surface
  // points and the obstacles at t and t + h; v_guess is where Newton starts; `diagonal` the
  // diagonal of the step's matrix A per DOF (the barrier's stiffness follows it). Makes new
  // candidates where the kept ones do not serve the step, and the friction rows.
  void begin_step(StepPositions& step, const Eigen::VectorXd& x, const Eigen::VectorXd& v_guess, double t, double h,
                  const Eigen::VectorXd& diagonal);
  // StepPotential::linearise at velocities v (end positions x + h v).
  void linearise(StepPositions& step, const Eigen::VectorXd& v, PotentialLinearisation& out);
  // StepPotential::step_bound: the fraction of the move from the end points of velocities `from`
  // to those of `to` free of crossings (pairs kept a tenth of the thickness apart, a hundredth
  // between parts near each other at rest; a pair already closer keeps half its distance).
  double step_bound(StepPositions& step, const Eigen::VectorXd& from, const Eigen::VectorXd& to);
  // Velocities within this of each other are the same to the potential (StepPotential) [m/s].
  double velocity_tolerance(double h) const;
  // StepPotential::end_step: reports the step's pairs with lagged friction and the time its
  // candidate searches took (from begin_step on).
  void end_step(PotentialReport& report) {
    report.friction_pairs = static_cast<int>(friction_rows_.size());
    report.candidates_ms = candidates_ms_;
    candidates_ms_ = 0.0;
  }

  // --- What the fail-safe shares ---
  // Whether begin_step started this step (from x at t, length h).
  bool in_step(const Eigen::VectorXd& x, double t, double h) const;
  // The end points of velocities v when the potential has them (its last iterate), else nullptr.
  const Eigen::MatrixX3d* end_points(const Eigen::VectorXd& v) const;
  // Checks, once per step, whether the obstacles' motion over the step is served.
  void check_obstacles_serve(const StepPositions& step);
  // Whether the candidates serve surface points p and q (and any move between the two), with the
  // obstacles anywhere over the step; their sweep distances (below) in sp and sq when they do.
  bool serves(const Eigen::MatrixX3d& p, const Eigen::MatrixX3d& q, double& sp, double& sq) const;
  // The same for the end points p of velocities v, remembering the last velocities found served
  // (and a bound of their sweep distance, served_sweep_).
  bool served(const Eigen::VectorXd& v, const Eigen::MatrixX3d& p);
  const std::vector<Candidate>& candidates() const { return cands_; }
  // The candidates' distance bounds at the reference (the last linearisation's end points, else
  // the step's start) for surface points `points` (and `other`: any move between the two), with
  // the obstacles where they are at the end of the step or, with `whole_step`, anywhere over it.
  // The result refers to the potential's own storage, valid until its next call.
  // `moves`, when given, are the points' moves from the reference, known already (per point, the
  // larger of points' and other's).
  ReferenceBounds reference_bounds(const StepPositions& step, const Eigen::MatrixX3d& points, const Eigen::MatrixX3d* other,
                                   bool whole_step, const Eigen::VectorXd* moves = nullptr);
  // How many times the candidates were made (a broad phase grown by twice the thickness).
  long long candidate_builds() const { return builds_; }
  // The radius of motion around the path the candidates were made for that they serve [m].
  double serve_radius() const { return 0.5 * settings_.thickness; }

 private:
  // A row of the potential: on the surface's points where J's rows are in node form (so the
  // integrator applies it without merging the points' stencils), else over the DOFs.
  struct Row {
    PointRow points;
    NodeRow dofs;
    Eigen::Vector3d apply(const CollisionSurface& surf, const Eigen::VectorXd& v) const;
    void scatter(const CollisionSurface& surf, const Eigen::Vector3d& f, Eigen::VectorXd& y) const;
    void put_in(PotentialLinearisation::Block& block) const;
  };
  struct FrictionRow {
    Row row;
    Eigen::Vector3d constant = Eigen::Vector3d::Zero();  // the obstacle side's part of u [m/s]
    Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity();
    double bound = 0.0;  // μ λ [N]
  };

  Eigen::MatrixX3d end_points_of(const StepPositions& step, const Eigen::VectorXd& v) const;
  Row pair_row(const PairGeometry& g);
  Row point_row(int p);
  Eigen::Vector3d obstacle_side_velocity(const StepPositions& step, const PairGeometry& g) const;
  double pair_friction(const PairGeometry& g) const;
  double pair_stiffness(const Candidate& c);
  double mass_of_point(int p);
  double plane_stiffness(int p);
  static double sweep_distance(const Eigen::MatrixX3d& p, const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b);
  void make_candidates(StepPositions& step);
  void prepare_candidates(const StepPositions& step);
  const PairGeometry& start_geometry(const StepPositions& step, size_t i);
  // (`which`: the flagged candidates in increasing order; those unflagged are taken out of it too.)
  void keep_closest(const StepPositions& step, std::vector<char>& flagged, const std::vector<PairGeometry>& geometry_of,
                    std::vector<size_t>& which);
  std::vector<size_t> flagged_among(const Bounds::List& visited, const std::vector<char>& flagged) const;
  double close_reach() const { return 1.25 * settings_.thickness; }
  std::vector<double> close_reaches() const;
  double near_reach(size_t i);
  template <class Visit>
  Bounds::List for_candidates(const Bounds* bounds, double motion, double threshold, Visit visit);
  template <class MakeRow>
  void add_friction_row(const Eigen::Vector3d& normal, double mu, const Eigen::Vector3d& obstacle_velocity, double lambda,
                        MakeRow row);
  double friction_epsilon() const { return settings_.tolerance * settings_.thickness / h_; }

  CollisionSurface& surf_;
  const PairPrimitives& pairs_;
  const ObstacleSet& obs_;
  const std::vector<Obstacle>& obstacles_;
  CandidateSearch& search_;
  BarrierSettings settings_;

  // The step in hand (begin_step).
  double t_ = 0.0, h_ = 0.0;
  Eigen::VectorXd x_;                                // its start positions
  std::pair<double, double> step_start_{-1.0, 0.0};  // its t and h
  Eigen::MatrixX3d p1_;                              // the end points of the last iterate ...
  Eigen::VectorXd p1_velocity_;                      // ... and its velocities

  // The candidates (boxes grown by 2 d̂) and the motion they were made for: the start points,
  // the end points (guess_) and the obstacles at both ends. They serve every configuration, and
  // every motion between two, whose points (and obstacle vertices) each stay within serve_radius()
  // of the straight path from the start to the end point they were made for (barrier_potential.cpp).
  std::vector<Candidate> cands_;
  double candidates_ms_ = 0.0;  // the step's candidate searches so far [ms] (end_step reports it)
  Eigen::MatrixX3d guess_, built_p0_, built_o0_, built_o1_;
  long long builds_ = 0;
  bool obstacles_serve_ = false;       // the obstacles over this step (check_obstacles_serve)
  Eigen::VectorXd served_velocity_;
  bool served_known_ = false;          // served_velocity_'s end points are served by the candidates
  // Upper bounds of sweep_distance for served_velocity_'s end points and for the step's start
  // points (−1: not known) [m]. A move of every point by at most m changes a sweep distance by at
  // most m, so a Newton step from a served iterate is known served without a pass over the points
  // while its largest point move keeps the bound within serve_radius().
  double served_sweep_ = 0.0, start_sweep_ = -1.0;

  // Per candidate: its geometry at the start of the step (known or not), whether it is within the
  // thickness there, and a near pair's reach (−1 until needed).
  std::vector<PairGeometry> cand_start_;
  std::vector<char> cand_start_known_;
  std::vector<char> cand_start_close_;
  std::vector<size_t> start_close_;  // ... those, in increasing order
  std::vector<double> near_reach_of_;

  // Lower bounds of the candidates' distances at the step's start (start_bounds_) or at the end
  // points of the last linearisation (lin_bounds_: obstacles at t + h).
  Bounds start_bounds_, lin_bounds_;
  Eigen::MatrixX3d lin_points_;      // the end points of the last linearisation
  Eigen::VectorXd lin_velocity_;     // ... and the velocities they were made from
  bool lin_bounds_valid_ = false;    // lin_bounds_ hold for the current candidates
  double lin_time_ = -1.0;           // the time of lin_points_ (the end of its step) [s]
  Eigen::MatrixX3d lin_o1_;          // the obstacle vertices there (sized only, when they are static)
  Eigen::VectorXd bound_to_velocity_;  // the last step bound's velocities at the end of its move
  Eigen::MatrixX3d bound_to_points_;   // ... and their end points
  // The last step bound's per-point moves (|end − start|), and the linearisation it started from
  // (lin_serial_ then; −1: not from a linearisation): Newton's next linearisation, at its end,
  // has these as its moves from the reference.
  Eigen::VectorXd bound_move_;
  long long bound_move_lin_ = -1, lin_serial_ = 0;  // (lin_serial_ counts the changes of lin_points_)
  Eigen::VectorXd point_move_;       // per surface point, its move from the reference [m]

  // The step's effective masses: per node its scale s_k, per surface point its mass (NaN until made).
  Eigen::VectorXd node_scale_;
  Eigen::VectorXd point_mass_;

  std::vector<FrictionRow> friction_rows_;
  // Scratch: keep_closest's per (cloth point, obstacle) closest candidate (+1; 0 for none) and the
  // entries set; linearise's end geometry.
  std::vector<size_t> closest_;
  std::vector<size_t> closest_set_;
  std::vector<PairGeometry> end_geometry_;
  std::vector<char> end_known_;  // (which of end_geometry_ the last linearisation made)
  std::vector<double> pair_k_, pair_energy_;  // linearise's per active pair: stiffness, energy
  std::vector<Eigen::Vector3d> pair_force_;    // and the force on its row
};

}  // namespace clothsim::contact

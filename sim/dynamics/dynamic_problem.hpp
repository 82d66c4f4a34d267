// A dynamic analysis (paper §4.2 eq. 28, §4.3): the corotational subdivision shell integrated
// with implicit Euler, velocities as unknowns.
#pragma once

#include "sim/mesh/mesh.hpp"
#include "sim/shell/boundary_condition.hpp"
#include "sim/shell/material.hpp"
#include "sim/shell/quadrature.hpp"
#include "sim/static/static_solve.hpp"

#include <Eigen/Core>

#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {

struct TimeSettings {
  double dt = 1e-3;          // time step [s]
  double end = 1.0;          // simulated duration [s]
  double output_fps = 30.0;  // frames written per simulated second [1/s]
};

// Kelvin–Voigt damping proportional to the (rotated) stiffness, plus mass damping:
// D = stiffness · K_R + mass · M.
struct DampingSettings {
  double stiffness = 0.0;  // [s]
  double mass = 0.0;       // [1/s]
};

enum class LinearSolverType { pcg, cholmod };
enum class PreconditionerType {
  block_jacobi,  // inverse 3 × 3 diagonal blocks
  cholesky,      // a CHOLMOD factor of an earlier step's matrix, refreshed when PCG slows down
};

struct SolverSettings {
  LinearSolverType type = LinearSolverType::pcg;
  double tolerance = 1e-8;    // relative residual of the linear system (pcg)
  int max_iterations = 2000;  // pcg
  int newton_iterations = 1;  // linear solves per step; > 1 re-extracts rotations (accuracy studies)
  PreconditionerType preconditioner = PreconditionerType::block_jacobi;  // pcg
  int refresh_iterations = 50;  // cholesky preconditioner: refactor after a solve that needed more
  bool tension_stiffening = true;  // membrane geometric stiffness in the matrix (corotation.hpp)
  // pcg's start: the last velocity extrapolated by its last change, v + (v − v_prev)
  // (constant acceleration), or the last velocity itself.
  bool extrapolated_start = true;
};

// Rigid initial velocity field v = velocity + angular_velocity × (X − center).
struct InitialState {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          // [m/s]
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // [rad/s]
  Eigen::Vector3d center = Eigen::Vector3d::Zero();            // [m]
};

struct DynamicProblem {
  TriMesh mesh;  // prepared control mesh
  ShellMaterial material;
  std::vector<BoundaryCondition> boundary;  // fixed components follow BoundaryCondition::motion
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();       // [m/s²] (lumped, mass-proportional)
  Eigen::Vector3d surface_load = Eigen::Vector3d::Zero();  // [N/m² of reference area]
  double pressure = 0.0;                                   // [N/m²] along the reference normal
  std::vector<PointLoad> point_loads;                      // [N], constant
  std::vector<MomentLoad> moments;                         // [N·m], follower couples
  double ramp_time = 0.0;  // [s] external loads grow linearly from 0 to full over this time
  Quadrature quadrature = Quadrature::one_point;
  TimeSettings time;
  DampingSettings damping;
  SolverSettings solver;
  bool corotational = true;  // false: plain linear element (for comparison)
  InitialState initial;
};

// Per-step figures (one row of stats.csv).
struct StepStats {
  int step = 0;
  double t = 0.0;                // time at the end of the step [s]
  int solver_iterations = 0;     // pcg iterations summed over Newton iterations (1 per direct solve)
  double residual = 0.0;         // final relative residual of the linear system
  double newton_change = 0.0;    // ‖v⁺_k − v⁺_{k−1}‖ / ‖v⁺_k‖ of the last Newton iteration (0 with one)
  double rotate_ms = 0.0;        // rotation extraction
  double assemble_ms = 0.0;      // rotated stiffness, forces, system matrix
  double solve_ms = 0.0;         // linear solve (with any factorisation)
  int factorizations = 0;        // Cholesky factorisations in this step (direct solve or preconditioner)
  double factor_ms = 0.0;        // their time, part of solve_ms
  double kinetic_energy = 0.0;   // ½ vᵀ M v [J]
  double elastic_energy = 0.0;   // corotated strain energy [J]
  double external_work = 0.0;    // work of the external loads on the free components this step [J]
  double boundary_work = 0.0;    // work of the scripted and held components on the cloth this step
                                 // [J] (Simulator::boundary_work)
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

}  // namespace clothsim

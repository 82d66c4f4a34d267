// One problem: what a scene file describes, for a static or a dynamic analysis alike — the mesh,
// the material, the boundary conditions, the loads, the numerics and (read by a dynamic analysis
// only) time, damping, solver settings and the initial state. Built by the scene loader
// (sim/scene/), checked by sim/problem/validate.hpp, solved by sim/static/ (linear statics, paper
// eq. 25) or sim/dynamics/ (implicit Euler, paper eq. 28).
#pragma once

#include "sim/mesh/mesh.hpp"
#include "sim/boundary/boundary_condition.hpp"
#include "sim/contact/obstacle.hpp"
#include "sim/shell/flat_rest.hpp"
#include "sim/shell/material.hpp"
#include "sim/shell/quadrature.hpp"
#include "sim/forces/follower_couples.hpp"
#include "sim/forces/point_loads.hpp"
#include "sim/solver/linear_solver.hpp"

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

// The "solver" settings of a scene: the linear solver's own (sim/solver/linear_solver.hpp) and
// the integrator's and elastic term's numerical options.
struct SolverSettings : LinearSolverSettings {
  int newton_iterations = 1;  // linear solves per step; > 1 re-extracts rotations (accuracy studies)
  // In a step where contact acts, the step is solved again with the rotations re-extracted at its
  // end positions while an element turned by more than this within it [deg]
  // (IntegratorSettings::rotation_tolerance).
  double rotation_tolerance_deg = 6.0;
  bool tension_stiffening = true;  // membrane geometric stiffness in the matrix (corotational_elements.hpp)
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

// "settle": a phase before t = 0 in which a garment's seams close and its pieces relax onto the
// body (sim/dynamics/simulator.hpp): loads off, obstacles and scripted boundaries held at their
// start, strong mass damping; its end positions are where the run starts.
struct SettleSettings {
  double time = 0.0;      // [s] of settling (0: none)
  double damping = 20.0;  // [1/s] mass damping while settling (at least the scene's damping.mass)
};

struct Problem {
  // The discretisation (sim/setup/setup.hpp: discretization_methods): "loop_kl", the Loop-
  // subdivision Kirchhoff–Love shell, "linear_fe", flat corotated membrane triangles with hinge
  // bending (the baseline), or "mass_spring", edge and bending springs on the flat triangles
  // (dynamic analyses only).
  std::string method = "loop_kl";
  TriMesh mesh;  // control mesh, prepared for the method (sim/setup/setup.hpp: prepare_mesh)
  // The elements' rest state: the mesh as given, or flat, laid out from its texture coordinates
  // in metres (a garment's pattern; sim/shell/flat_rest.hpp). The mesh's positions are the start.
  RestShape rest = RestShape::initial;
  ShellMaterial material;
  std::vector<BoundaryCondition> boundary;  // dynamic: fixed components follow BoundaryCondition::motion
  // Gravity [m/s²]: lumped in a dynamic analysis, consistent in a static one (sim/forces/gravity.hpp).
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  Eigen::Vector3d surface_load = Eigen::Vector3d::Zero();  // [N/m² of reference area]
  double pressure = 0.0;                                   // [N/m²] along the reference normal
  std::vector<PointLoad> point_loads;                      // [N], constant
  std::vector<MomentLoad> moments;                         // [N·m], follower couples (static: at rest)
  Quadrature quadrature = Quadrature::one_point;
  // Dynamic analysis only:
  double ramp_time = 0.0;  // [s] external loads grow linearly from 0 to full over this time
  TimeSettings time;
  DampingSettings damping;
  SolverSettings solver;
  bool corotational = true;  // false: plain linear element (for comparison)
  InitialState initial;
  SettleSettings settle;
  // Contact (dynamic analysis only; sim/contact/): switched on by collision.self or any obstacle.
  CollisionSettings collision;
  std::vector<Obstacle> obstacles;
  int collision_level = 2;  // display refinement levels of the surface that collides (the drawn one)
  bool has_contact() const { return collision.self || !obstacles.empty(); }
};

}  // namespace clothsim

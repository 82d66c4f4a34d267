// Linear static analysis of a Kirchhoff–Love subdivision shell (Cirak et al. 2000; paper §4.2
// eq. 25, K u = f): assemble, apply boundary conditions, solve with CHOLMOD.
#pragma once

#include "sim/mesh/mesh.hpp"
#include "sim/shell/boundary_condition.hpp"
#include "sim/shell/material.hpp"
#include "sim/shell/moment_load.hpp"
#include "sim/shell/quadrature.hpp"

#include <Eigen/Core>

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace clothsim {

// A force applied at the limit point of a control vertex, spread with the limit-mask weights.
struct PointLoad {
  int vertex = 0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  // [N]
};

struct StaticProblem {
  TriMesh mesh;  // control mesh (already refined so that no triangle has two irregular vertices)
  ShellMaterial material;
  std::vector<BoundaryCondition> boundary;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();       // [m/s²], mass-proportional load
  Eigen::Vector3d surface_load = Eigen::Vector3d::Zero();  // [N/m² of reference area]
  double pressure = 0.0;  // [N/m²] along the reference surface normal (the triangles' orientation)
  std::vector<PointLoad> point_loads;
  std::vector<MomentLoad> moments;  // couples on vertex groups (at the rest positions)
  Quadrature quadrature = Quadrature::one_point;
};

struct StaticResult {
  Eigen::MatrixX3d displacement;        // #V × 3 control-vertex displacements [m]
  Eigen::MatrixX3d limit_rest;          // #V × 3 rest positions of the vertices' limit points [m]
  Eigen::MatrixX3d limit_displacement;  // #V × 3 displacement of those limit points [m]
  Eigen::MatrixX3d extended_displacement;  // displacement of the control mesh with its ghost
                                           // layer (build_ghost_layer(mesh) order) [m]
  int dofs = 0;                         // free degrees of freedom
  double assemble_seconds = 0.0;        // element matrices, assembly and loads [s]
  double solve_seconds = 0.0;           // factorisation and solve [s]
};

// Throws std::runtime_error (MeshError for mesh problems) with a message naming the problem,
// e.g. an unsupported structure (singular stiffness) or a non-finite solution.
StaticResult solve_static(const StaticProblem& problem);

// Messages for the user's log (one line each, no newline).
using LogFn = std::function<void(const std::string&)>;

// Returns `mesh`, refined once by Loop subdivision (crease rules on borders, corners kept) if any
// triangle has more than one irregular vertex (valence ≠ 6, counting the ghost layer at borders);
// logs what it did. Throws MeshError for invalid meshes (naming the element).
TriMesh prepare_control_mesh(const TriMesh& mesh, const LogFn& log);

}  // namespace clothsim

// Linear static analysis (Cirak et al. 2000; paper §4.2 eq. 25, K u = f) through the same seams
// as the dynamics: the problem's discretisation, its elastic term's matrix at the rest state (the
// linear element), the external loads as force terms (gravity in its consistent model, surface
// loads, pressure, point loads, couples at the rest positions), and CHOLMOD for the free DOFs.
#pragma once

#include "sim/discretization/discretization.hpp"
#include "sim/problem/problem.hpp"

#include <Eigen/Core>

#include <memory>

namespace clothsim {

struct StaticResult {
  std::shared_ptr<const Discretization> discretization;  // what the displacement lives on
  Eigen::VectorXd displacement;         // 3·#nodes control displacements, consistent [m] (flat)
  Eigen::MatrixX3d limit_rest;          // #nodes × 3 rest positions of the nodes' surface points [m]
  Eigen::MatrixX3d limit_displacement;  // #nodes × 3 displacement of those points [m]
  int dofs = 0;                         // free degrees of freedom
  double assemble_seconds = 0.0;        // element matrices, assembly and loads [s]
  double solve_seconds = 0.0;           // factorisation and solve [s]

  // Deformed node positions (3·#nodes) [m], for the discretisation's surface operators.
  Eigen::VectorXd positions() const { return discretization->rest() + displacement; }
};

// Throws std::runtime_error (MeshError for mesh problems) with a message naming the problem,
// e.g. an unsupported structure (singular stiffness) or a non-finite solution.
StaticResult solve_static(const Problem& problem);

}  // namespace clothsim

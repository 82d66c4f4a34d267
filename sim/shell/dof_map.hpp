// Displacement of every extended-mesh vertex (real and ghost) as a linear combination of the
// free real displacement components (paper §4.4: ghost vertices and boundary conditions are
// folded into the element matrices, so the system stays symmetric; docs/formulas.md §4,
// Borders).
//
// Rules (u(g') is the displacement interpolated at the mirror image g' of ghost g across its
// border edge (a, b), e its foot on the edge, c the real vertex opposite the edge):
//  - free and fixed (prescribed) components stand for themselves;
//  - free border edge: u_g = u_a + u_b − u_c (Cirak et al. 2000), component by component;
//  - a component fixed at both a and b (hinged): odd reflection u_g = 2 u(e) − u(g'), which
//    gives zero normal curvature at the edge;
//  - clamped edge (a and b selected by one clamped condition): the part of u_g along the
//    surface normal N at the edge is the even reflection N·u(g') (zero slope across the edge);
//    the tangential part follows the two rules above. A selected border vertex b whose normal
//    lies in the span of the fixed components is tied to its interior (non-border) neighbours m,
//    N·u_b = −½ mean(N·u_m), which holds the limit surface's value and slope at zero for data
//    constant along a straight edge (no interior neighbour: b stays fixed).
//  - symmetry edge (a and b selected by one symmetric condition): fixed components mirror oddly
//    (above), free components evenly, u_g = u(g'): the exact mirror image across a plane of
//    symmetry normal to a fixed Cartesian axis.
// For a flat plate (N = z) clamped gives the even rule for w and the odd rule in the plane.
#pragma once

#include "sim/boundary/boundary_condition.hpp"
#include "sim/core/layout.hpp"
#include "sim/shell/ghost_layer.hpp"

#include <Eigen/Core>

#include <array>
#include <utility>
#include <vector>

namespace clothsim {

// Mirror image g' of a ghost across its border edge, as a linear interpolation of real vertices.
struct GhostMirror {
  std::array<int, 3> vertices{};
  std::array<double, 3> weights{};
  double edge_parameter = 0.5;  // the foot of the ghost on the edge: (1 − s) x_a + s x_b
};
GhostMirror ghost_mirror(const ExtendedMesh& ext, int ghost);

// Σ weight · u[dof] over free and fixed real components, dof = 3·vertex + component (fixed
// components carry their prescribed displacement: zero in a static analysis, a scripted motion
// in a dynamic one).
using Combination = std::vector<std::pair<int, double>>;

class DofMap {
 public:
  DofMap(const ExtendedMesh& ext, const std::vector<BoundaryCondition>& conditions);

  int num_real() const { return num_real_; }
  int num_free() const { return num_free_; }
  DofStatus status(int real_vertex, int component) const { return status_[3 * real_vertex + component]; }
  bool is_free(int real_vertex, int component) const { return status(real_vertex, component) == DofStatus::free; }
  const Combination& combination(int vertex, int component) const { return combos_[3 * vertex + component]; }
  // True when every component of `vertex` is a real component standing for itself.
  bool is_identity(int vertex) const;

  // Displacements of all extended vertices (#ext × 3) from real displacements (#real × 3; the
  // free and fixed components are read, dependent ones are derived).
  Eigen::MatrixX3d expand(const Eigen::MatrixX3d& real) const;

 private:
  int num_real_ = 0;
  int num_free_ = 0;
  std::vector<DofStatus> status_;   // 3 per real vertex
  std::vector<Combination> combos_; // 3 per extended vertex
};

}  // namespace clothsim

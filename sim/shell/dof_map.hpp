// Displacement of every extended-mesh vertex (real and ghost) as a linear combination of the
// free real displacement components (paper §4.4: ghost vertices and boundary conditions are
// folded into the element matrices, so the system stays symmetric; formulas.md §6).
//
// All rules act per Cartesian component c ∈ {x, y, z}:
//  - a free real component is itself; a fixed one is zero;
//  - ghost g of a free border edge (a, b) opposite c: u_g = u_a + u_b − u_c (Cirak et al. 2000);
//  - hinged edge (u_a, u_b fixed): odd reflection about the edge, u_g = 2 u(e) − u(g'), where e
//    is the foot of g on the edge and g' the mirror image of g across it, u(g') interpolated
//    linearly in the real triangle that holds g' (zero normal curvature at the edge);
//  - on a clamped border edge (both ends selected by a clamped condition, component fixed):
//    u_g = u(g') (even reflection) and each selected border vertex b is tied to its interior
//    neighbours m, u_b = −½ mean(u_m), which holds the limit surface's value and slope at zero
//    for data constant along a straight edge (a border vertex with no interior neighbour is
//    fixed instead).
#pragma once

#include "sim/shell/boundary_condition.hpp"
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

enum class DofStatus : unsigned char { free, fixed, dependent };

// Σ weight · u[vertex] over free real components of the same Cartesian component.
using Combination = std::vector<std::pair<int, double>>;

class DofMap {
 public:
  DofMap(const ExtendedMesh& ext, const std::vector<BoundaryCondition>& conditions);

  int num_real() const { return num_real_; }
  int num_free() const { return num_free_; }
  DofStatus status(int real_vertex, int component) const { return status_[3 * real_vertex + component]; }
  bool is_free(int real_vertex, int component) const { return status(real_vertex, component) == DofStatus::free; }
  const Combination& combination(int vertex, int component) const { return combos_[3 * vertex + component]; }
  // True when every component of `vertex` is a free real component standing for itself.
  bool is_identity(int vertex) const;

  // Displacements of all extended vertices (#ext × 3) from real displacements (#real × 3; only
  // the free components are read).
  Eigen::MatrixX3d expand(const Eigen::MatrixX3d& real) const;

 private:
  int num_real_ = 0;
  int num_free_ = 0;
  std::vector<DofStatus> status_;   // 3 per real vertex
  std::vector<Combination> combos_; // 3 per extended vertex
};

}  // namespace clothsim

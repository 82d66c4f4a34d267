// Square and strip plates with analytic solutions (formulas.md §7), built through the public
// static-analysis API.
#pragma once

#include "sim/mesh/generators.hpp"
#include "sim/static/static_solve.hpp"

namespace clothsim::testing {

// Control vertices whose rest position satisfies `pred`.
template <class Pred>
std::vector<int> select_vertices(const TriMesh& mesh, Pred pred) {
  std::vector<int> out;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (pred(mesh.vertices.row(v))) out.push_back(v);
  return out;
}

inline int nearest_vertex(const TriMesh& mesh, const Eigen::Vector3d& p) {
  int best = 0;
  for (int v = 1; v < mesh.num_vertices(); ++v)
    if ((mesh.vertices.row(v).transpose() - p).squaredNorm() < (mesh.vertices.row(best).transpose() - p).squaredNorm())
      best = v;
  return best;
}

// Unit square plate (side a) with all four edges hinged or clamped, E = 1e7, ν = 0.3, t = 0.01.
inline StaticProblem square_plate(int divisions, bool clamped, Quadrature rule, double side = 1.0) {
  StaticProblem p;
  p.mesh = make_grid(side, side, divisions, divisions);
  p.material = ShellMaterial::from_solid(1e7, 0.3, 0.01, 1000);
  const double h = side / 2 - 1e-9 * side;
  BoundaryCondition bc;
  bc.vertices = select_vertices(p.mesh, [&](const auto& x) { return std::abs(x(0)) >= h || std::abs(x(1)) >= h; });
  bc.clamped = clamped;
  p.boundary = {bc};
  p.quadrature = rule;
  return p;
}

inline double plate_rigidity(const StaticProblem& p) {
  return p.material.bending_rigidity / (1 - p.material.poisson_ratio * p.material.poisson_ratio);
}

}  // namespace clothsim::testing

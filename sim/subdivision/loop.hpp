// Loop subdivision (Loop 1987; docs/formulas.md §1, Loop subdivision; paper §4.1, Figs. 3–4):
// vertex and edge masks with Loop's β, limit-position and limit-tangent masks, and one global
// refinement step.
#pragma once

#include "sim/mesh/mesh.hpp"

#include <Eigen/SparseCore>

#include <array>
#include <vector>

namespace clothsim {

// Loop's β(N) = (1/N) [5/8 − (3/8 + ¼ cos(2π/N))²]; β(6) = 1/16.
double loop_beta(int valence);

// Limit-position mask of an interior vertex of valence N: weight of each neighbour,
// ω = 1 / (N + 3/(8β)); the vertex itself weighs 1 − Nω (regular: 1/2 and 1/12).
double limit_neighbour_weight(int valence);

// Limit tangent masks over the ordered one-ring (centre weight 0):
// t1 = Σ cos(2πi/N) p_i, t2 = Σ sin(2πi/N) p_i; the limit normal is t1 × t2.
std::vector<double> limit_tangent_mask(int valence, int which /* 0: t1, 1: t2 */);

// One Loop refinement of the whole mesh. Interior vertices use Loop's masks; border edges and
// vertices use the crease rules (edge ½ ½; vertex ⅛ ¾ ⅛), and border vertices where the border
// turns by more than `corner_angle_deg` (or that have a single incident triangle) stay in place.
// New vertex ids: old vertices keep their index, then one vertex per edge. Each triangle
// (a, b, c) becomes four, in the order: corner a, corner b, corner c, middle. The children keep
// their parent's warp direction; texture coordinates (TriMesh::uv) are split at the edge
// midpoints (so a flat rest layout in uv stays the parent's, refined).
TriMesh loop_subdivide(const TriMesh& mesh, double corner_angle_deg = 30.0);

// Per-corner texture coordinates (TriMesh::uv) of the triangles `levels` 1-to-4 splits make, in
// the order of loop_subdivision_step (fine triangle i descends from triangle i / 4^levels; each
// split gives corner a, corner b, corner c, middle, with the new corners at the edge midpoints).
// The uv of a point shared by two triangles with equal corner uv comes out bit for bit equal.
std::vector<std::array<Eigen::Vector2d, 3>> refine_corner_uv(const std::vector<std::array<Eigen::Vector2d, 3>>& uv,
                                                             int levels);

// The same step as a linear operator: new positions = S · old positions (S is #new × #old), with
// the refined triangles. Corner decisions use `positions` (#V × 3).
struct SubdivisionStep {
  Eigen::SparseMatrix<double> matrix;
  std::vector<Triangle> triangles;
};
SubdivisionStep loop_subdivision_step(const Eigen::MatrixX3d& positions, const std::vector<Triangle>& triangles,
                                      double corner_angle_deg = 30.0);

}  // namespace clothsim

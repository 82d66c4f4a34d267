// Fitting a control mesh to its limit surface (the paper's §7 limitation: "the limit surface does
// not interpolate the vertices of the control mesh"; docs/fit_limit.md).
//
// A mesh made in another tool is meant as the surface itself, but the shell simulates and draws
// the Loop limit surface of the control mesh, which lies inside convex parts of the mesh. The fit
// finds control positions P on the same connectivity whose limit points are the given vertices
// X: L P = X, where L (#V × #V) is the limit-position mask of each real vertex over its closed
// one-ring in the ghost-layer extended mesh (loop.hpp limit_neighbour_weight, the same masks
// ShellModel::limit_points and LoopShellDiscretization::node_points apply), with each ghost
// vertex folded into the real vertices it is made of (DofMap with no boundary conditions: the
// free-edge rule x_g = x_a + x_b − x_c, which is also the rule of the rest control net). So the
// fit is exact for the surface the simulator builds from the fitted mesh, borders included.
//
// Solver: a sparse direct LU factorisation (Eigen::SparseLU, COLAMD ordering), followed by
// iterative refinement with the same factors while the residual is above 1e-12 (one solve has
// always been enough so far). Why: L is not symmetric (a vertex weighs its neighbours by ω of its
// own valence, and folded ghosts add one-sided entries at borders), so no Cholesky/LDLᵀ.
// Progressive iterative approximation P ← P + (X − L P) is proven to converge for Loop surfaces
// (Cheng et al. 2009), but that proof does not cover the ghost-layer border rule; on the meshes
// measured its error shrinks by ρ(I − L) ≈ 0.67–0.74 per sweep (3/4 on a closed regular lattice),
// 62–76 sweeps to 1e-12, 5–13 times faster than the LU at 100k–164k vertices. The LU is chosen
// because it needs no convergence argument: exact up to rounding for any non-singular L, and a
// loud failure otherwise; for a one-off preprocessing step its cost (2–3 s and 250 MB for a
// 100k-vertex panel, 8–9 s for a closed 164k-vertex mesh: faster than linear) is acceptable
// (docs/fit_limit.md).
//
// Meshes the shell refines on load: when a triangle has more than one irregular vertex (valence
// ≠ 6, ghost layer counted) the shell refines the mesh once by Loop subdivision
// (LoopShellDiscretization::prepare_mesh). On a closed mesh that keeps the limit surface, so the
// fit is still exact (the limit points of the original vertices are unchanged). On a mesh with
// borders it is not (the refinement's crease rule at borders differs from the ghost layer), so
// such a mesh is rejected: refine it first and fit the refined mesh.
#pragma once

#include "sim/mesh/mesh.hpp"
#include "sim/shell/ghost_layer.hpp"

#include <Eigen/SparseCore>

namespace clothsim {

struct LimitFit {
  TriMesh control;        // the mesh with fitted positions; triangles, uv and warp unchanged
  double residual = 0;    // max over vertices of |limit point − target| / bounding-box diagonal
  int iterations = 0;     // solves with the LU factors: 1 + iterative-refinement steps
};

// Control positions on mesh's connectivity whose Loop limit points are mesh's vertices.
// Throws MeshError (naming the vertex or triangle) for a mesh the shell cannot take — invalid or
// non-manifold triangles, valence above 12, non-finite positions, a mesh with borders that has a
// triangle with more than one irregular vertex (refine it first) — and std::runtime_error when L
// is singular or the residual stays above 1e-12.
LimitFit fit_limit(const TriMesh& mesh);

// The control-to-limit-point operator L of the real vertices of `ext` (#real × #real, row sums 1):
// row v is v's limit-position mask over its extended one-ring, ghost vertices folded into the
// real vertices they are made of.
Eigen::SparseMatrix<double> limit_point_operator(const ExtendedMesh& ext);

}  // namespace clothsim

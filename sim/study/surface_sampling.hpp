// Sampling a subdivision surface at fixed parameter points, so that runs on different meshes can
// be compared point by point (the convergence study's error norm, docs/convergence.md).
//
// A parameter point is located once in the rest control mesh through a 2D chart (per-vertex
// chart coordinates, e.g. (x, y) of a flat plate or (θ, s) of a cylinder): the triangle that
// contains it and its barycentric coordinates there. Its limit-surface position is then the
// subdivision basis of that triangle at those coordinates (sim/subdivision/patch.hpp, paper
// eqs. 22–23, 27) applied to the positions of the extended mesh (control mesh + ghost layer); the
// displacement of the surface at the point is the same operator applied to the extended-mesh
// displacements, so "deformed limit point minus rest limit point at the same parameter".
#pragma once

#include "sim/mesh/mesh.hpp"
#include "sim/shell/ghost_layer.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace clothsim {

// A point of the control mesh's parameter domain: triangle `triangle` = (a, b, c) of the mesh at
// barycentric parameters (v, w), i.e. (1 − v − w)·a + v·b + w·c (the convention of evaluate_patch).
struct SurfacePoint {
  int triangle = 0;
  double v = 0.0, w = 0.0;
};

// Locates each row of `targets` (#P × 2 chart coordinates) in the mesh whose vertices have chart
// coordinates `chart` (#V × 2): the first triangle (in mesh order) that contains the target (with a
// tolerance of 1e-10 in the barycentric coordinates), clamped onto the triangle. `period` > 0
// makes the first chart coordinate periodic with that period (a closed cylinder's angle);
// triangles are unwrapped across the seam. Throws std::invalid_argument naming the first target
// that lies in no triangle.
std::vector<SurfacePoint> locate_points(const std::vector<Triangle>& triangles, const Eigen::MatrixX2d& chart,
                                        const Eigen::MatrixX2d& targets, double period = 0.0);

// The chart (θ, s) of a mesh around the y axis: θ = atan2(−z, x) in [0, 2π) [rad] (so θ grows
// with the vertex index of make_cylinder) and s = (y − y_min) / (y_max − y_min) in [0, 1].
// `vertices` is #V × 3 [m]; returns #V × 2.
Eigen::MatrixX2d cylinder_chart(const Eigen::MatrixX3d& vertices);

// A regular grid of n_theta × n_s chart points (θ, s) at cell centres, θ_i = 2π (i + ½) / n_theta,
// s_j = (j + ½) / n_s; row j·n_theta + i. Cell centres keep the points off the rims and away from
// the vertices of the usual meshes.
Eigen::MatrixX2d cylinder_parameter_grid(int n_theta, int n_s);

// The linear map from extended-mesh vertex values (#ext × k, e.g. positions [m] or displacements
// [m]) to limit-surface values at the points (#P × k): row p holds the subdivision basis (value
// row) of the point's triangle at (v, w) over that patch's control vertices. Triangles index the
// real triangles of `ext` (the control mesh's own order). Rows sum to 1.
Eigen::SparseMatrix<double, Eigen::RowMajor> limit_sampling_matrix(const ExtendedMesh& ext,
                                                                   const std::vector<SurfacePoint>& points);

// RMS(|u − u_ref|) / RMS(|u_ref|) over all rows of all matrices: sqrt(Σ |u − u_ref|²) /
// sqrt(Σ |u_ref|²), sums over every point (row) and every sample time (matrix). `u` and `u_ref`
// are lists of #P × 3 displacements [m] of the same shapes. Throws std::invalid_argument for
// mismatched shapes or a reference that is zero everywhere.
double relative_rms_difference(const std::vector<Eigen::MatrixX3d>& u, const std::vector<Eigen::MatrixX3d>& u_ref);

// RMS(|u|) = sqrt(Σ |u|² / count) over all rows of all matrices [m].
double rms_norm(const std::vector<Eigen::MatrixX3d>& u);

}  // namespace clothsim

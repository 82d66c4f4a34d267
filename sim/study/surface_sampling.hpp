// Sampling a subdivision surface at fixed parameter points, so that runs on different meshes can
// be compared point by point (the convergence study's error norm, docs/convergence.md).
//
// A parameter point is located once in the rest control mesh through a 2D chart (per-vertex
// chart coordinates, e.g. (x, y) of a flat plate or (θ, s) of a cylinder): the triangle that
// contains it and its barycentric coordinates there, a SurfaceSample. Its surface position is
// then the discretisation's sampling operator (Discretization::samples; for the Loop shell the
// subdivision basis of that triangle, paper eqs. 22–23, 27) applied to the control net; the
// displacement of the surface at the point is "deformed surface point minus rest surface point at
// the same parameter".
#pragma once

#include "sim/mesh/mesh.hpp"
#include "sim/discretization/discretization.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace clothsim {

// Locates each row of `targets` (#P × 2 chart coordinates) in the mesh whose vertices have chart
// coordinates `chart` (#V × 2): the first triangle (in mesh order) that contains the target (with a
// tolerance of 1e-10 in the barycentric coordinates), clamped onto the triangle. `period` > 0
// makes the first chart coordinate periodic with that period (a closed cylinder's angle);
// triangles are unwrapped across the seam. Throws std::invalid_argument naming the first target
// that lies in no triangle.
std::vector<SurfaceSample> locate_points(const std::vector<Triangle>& triangles, const Eigen::MatrixX2d& chart,
                                        const Eigen::MatrixX2d& targets, double period = 0.0);

// The chart (θ, s) of a mesh around the y axis: θ = atan2(−z, x) in [0, 2π) [rad] (so θ grows
// with the vertex index of make_cylinder) and s = (y − y_min) / (y_max − y_min) in [0, 1].
// `vertices` is #V × 3 [m]; returns #V × 2.
Eigen::MatrixX2d cylinder_chart(const Eigen::MatrixX3d& vertices);

// A regular grid of n_theta × n_s chart points (θ, s) at cell centres, θ_i = 2π (i + ½) / n_theta,
// s_j = (j + ½) / n_s; row j·n_theta + i. Cell centres keep the points off the rims and away from
// the vertices of the usual meshes.
Eigen::MatrixX2d cylinder_parameter_grid(int n_theta, int n_s);

// RMS(|u − u_ref|) / RMS(|u_ref|) over all rows of all matrices: sqrt(Σ |u − u_ref|²) /
// sqrt(Σ |u_ref|²), sums over every point (row) and every sample time (matrix). `u` and `u_ref`
// are lists of #P × 3 displacements [m] of the same shapes. Throws std::invalid_argument for
// mismatched shapes or a reference that is zero everywhere.
double relative_rms_difference(const std::vector<Eigen::MatrixX3d>& u, const std::vector<Eigen::MatrixX3d>& u_ref);

// RMS(|u|) = sqrt(Σ |u|² / count) over all rows of all matrices [m].
double rms_norm(const std::vector<Eigen::MatrixX3d>& u);

}  // namespace clothsim

// The signed dihedral angle of a hinge — two triangles sharing an edge — with its exact gradient
// and Hessian (the discrete-shells bending of Grinspun, Hirani, Desbrun & Schröder 2003; the
// derivatives as in Tamstorf & Grinspun 2013).
//
// Hinge layout: x0 → x1 is the shared edge as it runs in triangle A = (x0, x1, x2); triangle
// B = (x1, x0, x3) runs it the other way (a consistently oriented mesh). With the edge
// e = x1 − x0, the unnormalised normals N_A = e × (x2 − x0) and N_B = (x3 − x0) × e (both the
// counter-clockwise normals of the triangles), their unit vectors n_A, n_B, and ê = e / |e|,
//     θ = atan2((n_A × n_B) · ê, n_A · n_B)  ∈ (−π, π],
// 0 for a flat hinge; θ < 0 when the hinge folds towards its normals (x2 or x3 lifted along them).
//
// Gradient. Only the rotation of each triangle about the edge changes θ, so with the heights
// h_A = |N_A| / |e|, h_B = |N_B| / |e| and the feet s_A = (x2 − x0)·e / |e|², s_B = (x3 − x0)·e / |e|²
// of the apexes on the edge:
//     ∂θ/∂x2 = −n_A / h_A,   ∂θ/∂x3 = −n_B / h_B,
//     ∂θ/∂x0 = (1 − s_A) n_A / h_A + (1 − s_B) n_B / h_B,
//     ∂θ/∂x1 = s_A n_A / h_A + s_B n_B / h_B
// (they sum to zero and have no moment: θ is invariant under rigid motions). The Hessian ∇²θ is
// the forward-mode derivative (Eigen's AutoDiff, unsupported/Eigen/AutoDiff) of this same gradient
// expression, so the two are consistent to round-off.
#pragma once

#include <Eigen/Core>

#include <array>

namespace clothsim {

using HingePositions = std::array<Eigen::Vector3d, 4>;  // x0, x1 (the edge), x2, x3 (the apexes) [m]
using HingeVector = Eigen::Matrix<double, 12, 1>;       // [∂/∂x0; ∂/∂x1; ∂/∂x2; ∂/∂x3]
using HingeMatrix = Eigen::Matrix<double, 12, 12>;

// θ [rad]. Requires both triangles to have non-zero area (see hinge_is_degenerate).
double dihedral_angle(const HingePositions& x);
// ∂θ/∂x [rad/m].
HingeVector dihedral_gradient(const HingePositions& x);
// ∂²θ/∂x² [rad/m²], symmetric.
HingeMatrix dihedral_hessian(const HingePositions& x);
// True when the edge or either triangle has zero length or area, where θ is undefined.
bool hinge_is_degenerate(const HingePositions& x);

}  // namespace clothsim

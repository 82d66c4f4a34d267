// The 12 quartic box-spline basis functions of a regular Loop patch (Stam 1998; Cirak et al.
// 2000 appendix; docs/formulas.md §2, Regular patches; paper eq. 22) with first and second
// derivatives.
//
// Control-vertex layout (rows of the regular triangular lattice), element = triangle (4, 7, 8):
//         1   2
//       3   4   5
//     6   7   8   9
//       10  11  12
// Barycentric coordinates (u, v, w), u = 1 − v − w: vertex 4 is u = 1, vertex 7 is v = 1,
// vertex 8 is w = 1. The element parameters are θ¹ = v, θ² = w.
#pragma once

#include <Eigen/Core>

namespace clothsim {

// Rows of a basis-evaluation matrix: value and derivatives with respect to (v, w).
enum BasisRow : int { kValue = 0, kDv = 1, kDw = 2, kDvv = 3, kDvw = 4, kDww = 5 };
using BoxSplineBasis = Eigen::Matrix<double, 6, 12>;

// Column i − 1 holds N_i and its derivatives at (v, w) (any real v, w; the patch is v, w ≥ 0,
// v + w ≤ 1).
BoxSplineBasis box_spline_basis(double v, double w);

}  // namespace clothsim

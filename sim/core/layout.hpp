// The one state layout of clothsim's simulation core.
//
// Positions, velocities, displacements and forces of the discretisation's nodes are FLAT vectors
// (Eigen::VectorXd) of length 3·#nodes, vertex-major: [x0 y0 z0 x1 y1 z1 ...]; degree of freedom
// `dof` is component dof % 3 of node dof / 3. System matrices are 3·#nodes square in the same
// order. Where a #nodes × 3 view is handier (one node per row), as_rows() maps the flat vector
// without copying: a row-major matrix over the same memory. Mesh data (TriMesh::vertices, a
// control net) stays #V × 3 column-major, as Eigen's default; to_flat() and the views convert at
// the edges (set-up, output), never inside a time step.
#pragma once

#include <Eigen/Core>

namespace clothsim {

using RowMatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

// #nodes × 3 views of a flat vector (3·#nodes) [same units as the vector].
inline Eigen::Map<RowMatrixX3d> as_rows(Eigen::VectorXd& flat) { return {flat.data(), flat.size() / 3, 3}; }
inline Eigen::Map<const RowMatrixX3d> as_rows(const Eigen::VectorXd& flat) { return {flat.data(), flat.size() / 3, 3}; }

// The flat vector (3·#rows) of a #rows × 3 matrix.
inline Eigen::VectorXd to_flat(const Eigen::MatrixX3d& rows) {
  Eigen::VectorXd out(3 * rows.rows());
  as_rows(out) = rows;
  return out;
}

}  // namespace clothsim

namespace clothsim {

// What a degree of freedom is: an unknown of the solve, prescribed (held, or following a scripted
// motion), or derived from the others (e.g. the tied components of a clamped border).
enum class DofStatus : unsigned char { free, fixed, dependent };

}  // namespace clothsim

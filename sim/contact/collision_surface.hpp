// The contact stage's collision surface: the surface that is drawn (the discretisation's display
// operator at the collision level), its points as an affine function of the nodes,
// P = P(X) + J (x − X), its edges and which fine triangle owns each point and edge, and the rows
// of J that turn a pair of surface points into a constraint on the node velocities (per DOF, or
// in node form when the three DOFs of each node share one weight: J = S ⊗ I₃, the usual case).
// It also finds, once per run, the fine triangles near each other (and those joined) at rest
// (sim/contact/candidates.hpp has what they do).
//
// Fixed for a run; the per-step positions (the points at the start of a step, the velocities)
// are arguments. The discretisation must outlive the surface.
#pragma once

#include "sim/contact/pair_types.hpp"
#include "sim/discretization/discretization.hpp"
#include "sim/solver/coupled_matrix.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <array>
#include <utility>
#include <vector>

namespace clothsim::contact {

// The distance between two triangles a and b of points `p` (rows) [m]: the least of their
// point–triangle and edge–edge distances.
double triangle_distance(const Eigen::MatrixX3d& p, const std::array<int, 3>& a, const std::array<int, 3>& b);

// y = A X for a row-major compressed sparse A and a dense X with `cols` columns (column-major,
// X.rows() = x_rows = A.cols()), rows on all cores; each entry is summed in the row's stored
// order, as Eigen does. Throws std::logic_error for an uncompressed A.
void parallel_product(const Eigen::SparseMatrix<double, Eigen::RowMajor>& a, const double* x, Eigen::Index x_rows, int cols,
                      double* y);

class CollisionSurface {
 public:
  using Jacobian = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  using DofRow = std::vector<std::pair<int, Eigen::Vector3d>>;  // (dof, B[dof])

  // The display operator of `d` at `level` (≥ 0) levels of refinement.
  CollisionSurface(const Discretization& d, int level);
  CollisionSurface(const CollisionSurface&) = delete;
  CollisionSurface& operator=(const CollisionSurface&) = delete;

  const SurfaceOperator& op() const { return op_; }
  const std::vector<Triangle>& triangles() const { return op_.triangles; }
  const Jacobian& jacobian() const { return jacobian_; }          // 3·#P × 3·#nodes
  const Eigen::MatrixX3d& rest_points() const { return rest_; }   // #P × 3 [m]
  Eigen::Index num_points() const { return rest_.rows(); }
  const std::vector<std::array<int, 2>>& edges() const { return edges_; }
  const std::vector<std::array<int, 3>>& triangle_edges() const { return triangle_edges_; }
  const std::vector<std::vector<int>>& owned_points() const { return owned_points_; }
  const std::vector<std::vector<int>>& owned_edges() const { return owned_edges_; }
  // Fine triangles per patch (the fine triangles over one surface triangle of the discretisation:
  // fine triangle i lies over patch i / fine_per_patch()).
  int fine_per_patch() const { return fine_per_patch_; }

  // The points (#P × 3) [m] at node positions x (3·#nodes).
  Eigen::MatrixX3d points(const Eigen::VectorXd& x) const;
  // The same points as the rest points moved by J (x − x_rest), the surface being linear in the
  // nodes: with the point rows in node form one pass over each point's nodes, cheaper than
  // points() (which builds the control net and applies the refinement); equal up to round-off.
  Eigen::MatrixX3d points_through_rows(const Eigen::VectorXd& x) const;
  // The end points p0 + h J v (#P × 3) [m] of a step of length h [s] from points p0 with node
  // velocities v [m/s]. With the point rows made (make_point_rows) and in node form, one pass
  // over each point's nodes gives all three components (the same sums, in the same order, as J's
  // three rows).
  Eigen::MatrixX3d end_points(const Eigen::MatrixX3d& p0, double h, const Eigen::VectorXd& v) const;

  // The rows of the pair's cloth points: B[dof] = Σ_k c_k ∂p_k/∂x[dof] over the cloth points k of
  // g with a coefficient other than 0 (obstacle points are left out), each DOF once, in the order
  // the points' rows first meet it.
  DofRow rows(const PairGeometry& g);
  // Moves `b` into the node form `nodes` (node k, weight w_k) when it has that shape: every node
  // with all three DOFs, B[3k + c] = w_k e_c; then `b` is emptied, else `nodes` is. The nodes
  // keep the order of their x DOFs in `b`, so sums over them are the same.
  void to_node_form(DofRow& b, std::vector<std::pair<int, double>>& nodes);
  // The row of a DOF list in node form where it has that shape.
  NodeRow node_row(const DofRow& b);

  // Per surface point, its row of J in node form with the nodes sorted (see end_points); when
  // some point's row does not have that form there are none, and the rows below take the long way.
  void make_point_rows();
  bool point_rows_in_node_form() const { return in_node_form_; }
  // The row of one surface point (a pair with a plane).
  NodeRow point_row(int p);
  // The row of a pair's relative position over the nodes, Σ_k c_k J_k (cloth points only).
  NodeRow pair_row(const PairGeometry& g);
  // The same rows on the points (sim/solver/coupled_matrix.hpp), through point_map(): J's rows in
  // node form (nullptr when they are not, see make_point_rows). A pair's row on its cloth points
  // with a coefficient other than 0, and the row of point p alone.
  const PointMap* point_map() const { return in_node_form_ ? &point_map_ : nullptr; }
  PointRow pair_points(const PairGeometry& g) const;
  PointRow point_alone(int p) const;

  // Whether fine triangles a and b are within `near` [m] of each other at rest: sharing a vertex,
  // two vertices closer than `near`, or else their exact distance below it.
  bool near_pair(const std::array<int, 3>& a, const std::array<int, 3>& b, double near) const;
  // Per fine triangle a: the sorted b > a within `near` of it at rest (near_at_rest), and those
  // of them closer than `joined` whose patches share no corner of `patch_corners` (the surface
  // triangles under the patches, as control nodes): joined_at_rest. Returns how many pairs are
  // joined.
  long long find_near_at_rest(double near, double joined, const std::vector<Triangle>& patch_corners,
                              std::vector<std::vector<int>>& near_at_rest, std::vector<std::vector<int>>& joined_at_rest) const;

 private:
  const Discretization& d_;
  SurfaceOperator op_;
  Jacobian jacobian_;
  Eigen::MatrixX3d rest_;
  std::vector<std::array<int, 2>> edges_;
  std::vector<std::array<int, 3>> triangle_edges_;
  std::vector<std::vector<int>> owned_points_, owned_edges_;
  int fine_per_patch_ = 1;

  // Scratch for merging rows: a slot per DOF (−1 when unused).
  std::vector<int> slot_;

  // J's rows in node form per point, packed (make_point_rows): end_points, and the rows on points.
  bool in_node_form_ = false;
  PointMap point_map_;
};

}  // namespace clothsim::contact

// A system matrix with room for couplings its base pattern lacks: the step's matrix A (the
// discretisation's fixed pattern) plus blocks that couple nodes far apart in the mesh, such as two
// cloth parts in contact. The pattern is A's plus full 3 × 3 node blocks for every pair of nodes
// of each coupled group; it is rebuilt (and a factorisation of it must be analysed again) only
// when a group needs a coupling it lacks. Values are written as A's (through a map from A's
// stored entries) plus the blocks.
//
// Used by the contact potential inside the implicit step (sim/integrator/implicit_euler.cpp) and
// by the contact fail-safe's implicit response (sim/contact/fail_safe.cpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <array>
#include <utility>
#include <vector>

namespace clothsim {

// A row of a contact-like term in node form: the relative velocity (or position) it measures is
// u = Σ_k w_k v_k over nodes k (3-vectors v_k), or, for rows that are not of that shape, per DOF,
// u = Σ_dof b_dof v_dof (3-vectors b_dof). Its block Bᵀ H B for a 3 × 3 H couples every pair of
// its nodes.
struct NodeRow {
  std::vector<std::pair<int, double>> nodes;           // (node, w)
  std::vector<std::pair<int, Eigen::Vector3d>> dofs;   // (dof, b), when not in node form

  Eigen::Vector3d apply(const Eigen::VectorXd& x) const {  // u = B x
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (const auto& [node, w] : nodes) u += w * x.segment<3>(3 * node);
    for (const auto& [dof, b] : dofs) u += b * x(dof);
    return u;
  }
  void scatter(const Eigen::Vector3d& force, Eigen::VectorXd& y) const {  // y += Bᵀ force
    for (const auto& [node, w] : nodes) y.segment<3>(3 * node) += w * force;
    for (const auto& [dof, b] : dofs) y(dof) += b.dot(force);
  }
  // The nodes the row touches, sorted and unique.
  std::vector<int> node_list() const;
};

// Points that are a linear map of the nodes, p_i = Σ_j w_ij x_j (+ a constant): per point its
// nodes and weights, packed (a collision surface's J in node form).
struct PointMap {
  std::vector<int> offsets{0};  // #points + 1: point i's entries are [offsets[i], offsets[i + 1])
  std::vector<int> nodes;
  std::vector<double> weights;
  int num_points() const { return static_cast<int>(offsets.size()) - 1; }
};

// A row on up to four points of a PointMap, u = Σ_k c_k p_k: a contact pair's relative position
// or velocity (a point against an obstacle: one point). Its node form is Σ_k c_k Σ_j w_kj x_j,
// over the union of the points' nodes (12–50 on a level-2 Loop surface), which applying the row
// on the points avoids building.
struct PointRow {
  std::array<int, 4> points{};
  std::array<double, 4> coefs{};
  int count = 0;

  Eigen::Vector3d apply(const PointMap& map, const Eigen::VectorXd& x) const {  // u = B x
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (int k = 0; k < count; ++k) {
      const int p = points[static_cast<size_t>(k)];
      const double c = coefs[static_cast<size_t>(k)];
      for (int e = map.offsets[static_cast<size_t>(p)]; e < map.offsets[static_cast<size_t>(p) + 1]; ++e)
        u += (c * map.weights[static_cast<size_t>(e)]) * x.segment<3>(3 * map.nodes[static_cast<size_t>(e)]);
    }
    return u;
  }
  void scatter(const PointMap& map, const Eigen::Vector3d& force, Eigen::VectorXd& y) const {  // y += Bᵀ force
    for (int k = 0; k < count; ++k) {
      const int p = points[static_cast<size_t>(k)];
      const double c = coefs[static_cast<size_t>(k)];
      for (int e = map.offsets[static_cast<size_t>(p)]; e < map.offsets[static_cast<size_t>(p) + 1]; ++e)
        y.segment<3>(3 * map.nodes[static_cast<size_t>(e)]) += (c * map.weights[static_cast<size_t>(e)]) * force;
    }
  }
  // Entries of its node form before merging (the cost of apply or scatter).
  int entries(const PointMap& map) const;
  // The node form, nodes sorted and merged.
  NodeRow node_row(const PointMap& map) const;
  bool operator==(const PointRow& o) const {
    if (count != o.count) return false;
    for (int k = 0; k < count; ++k)
      if (points[static_cast<size_t>(k)] != o.points[static_cast<size_t>(k)] || coefs[static_cast<size_t>(k)] != o.coefs[static_cast<size_t>(k)])
        return false;
    return true;
  }
};

class CoupledMatrix {
 public:
  // Whether the pattern holds A's pattern (same number of stored entries as `a`) and every
  // coupling among the nodes of each group.
  bool covers(const Eigen::SparseMatrix<double>& a, const std::vector<std::vector<int>>& groups) const;
  // Rebuilds the pattern: A's plus the couplings of `groups` (lists of nodes, sorted). With
  // `keep_previous`, the couplings of the pattern so far are kept too (contacts come and go from
  // one step to the next, and each new pattern costs a new analysis of the factorisation), as
  // long as the pattern stays within twice A's entries.
  void rebuild(const Eigen::SparseMatrix<double>& a, const std::vector<std::vector<int>>& groups, bool keep_previous = false);
  // Sets the values to A's (A with the pattern the last rebuild saw).
  void set_base(const Eigen::SparseMatrix<double>& a);
  // Adds Bᵀ H B of `row` (H symmetric, 3 × 3); every coupling of the row must be in the pattern.
  void add_block(const NodeRow& row, const Eigen::Matrix3d& h);
  // add_block for each of `blocks` in turn, with the same sums bit for bit; blocks in node form
  // are added one column node per thread.
  void add_blocks(const std::vector<std::pair<NodeRow, Eigen::Matrix3d>>& blocks);

  Eigen::SparseMatrix<double>& matrix() { return matrix_; }
  const Eigen::SparseMatrix<double>& matrix() const { return matrix_; }
  bool empty() const { return matrix_.rows() == 0; }
  // Per node, the nodes it is coupled with (sorted): A's node pattern plus the groups'.
  const std::vector<std::vector<int>>& adjacency() const { return adjacency_; }
  // Rebuilds from a saved adjacency (a checkpoint): the same pattern as the run that saved it.
  void restore(const Eigen::SparseMatrix<double>& a, const std::vector<std::vector<int>>& adjacency);
  void clear();

 private:
  void build_from_adjacency(const Eigen::SparseMatrix<double>& a);
  Eigen::SparseMatrix<double> matrix_;
  Eigen::Index a_entries_ = -1;
  std::vector<int> from_a_;                    // A's k-th stored entry is matrix_'s from_a_[k]-th
  std::vector<std::vector<int>> adjacency_;
};

}  // namespace clothsim

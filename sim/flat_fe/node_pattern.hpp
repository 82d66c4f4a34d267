// The sparsity pattern of a system matrix over nodes with 3 DOFs each (3·#nodes square,
// compressed, column-major, full symmetric storage, zero values) whose couplings come from groups
// of nodes — every pair of nodes in a group couples through a 3 × 3 block — and, per group, the
// value offsets of its blocks, so an element adds its blocks without searching. The same layout
// as the Loop shell's pattern (sim/shell/shell_model.hpp): in each column the rows are sorted,
// node by node, so the block of nodes (i, j) starts at one offset and its column d lies `stride(j)`
// entries after column d − 1.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace clothsim {

class NodeBlockPattern {
 public:
  NodeBlockPattern() = default;
  // `groups`: lists of node ids in [0, num_nodes); every node has its diagonal block, whether or
  // not a group names it. Throws std::out_of_range for a node id outside the range.
  NodeBlockPattern(int num_nodes, const std::vector<std::vector<int>>& groups);

  // The pattern (3·#nodes square, zero values).
  const Eigen::SparseMatrix<double>& pattern() const { return pattern_; }
  int num_groups() const { return static_cast<int>(group_start_.size()) - 1; }

  // values[slot(g, a, b) + d·stride(group node b) + c] is entry (3·node_a + c, 3·node_b + d), for
  // a, b indices into group g's list.
  int slot(int g, int a, int b) const {
    const int m = group_size(g);
    return slots_[static_cast<size_t>(slot_start_[static_cast<size_t>(g)] + a + m * b)];
  }
  int stride(int node) const { return stride_[static_cast<size_t>(node)]; }
  int group_size(int g) const { return group_start_[static_cast<size_t>(g) + 1] - group_start_[static_cast<size_t>(g)]; }
  int group_node(int g, int a) const { return nodes_[static_cast<size_t>(group_start_[static_cast<size_t>(g)] + a)]; }

  // Adds `block` (3 × 3) to the block (a, b) of group g in the values of a matrix with this
  // pattern. Groups that share no node may do this concurrently.
  void add_block(int g, int a, int b, const Eigen::Matrix3d& block, double* values) const {
    double* target = values + slot(g, a, b);
    const int s = stride(group_node(g, b));
    for (int d = 0; d < 3; ++d)
      for (int c = 0; c < 3; ++c) target[d * s + c] += block(c, d);
  }

 private:
  Eigen::SparseMatrix<double> pattern_;
  std::vector<int> nodes_;        // the groups' nodes, concatenated
  std::vector<int> group_start_;  // group g's nodes: [group_start_[g], group_start_[g + 1])
  std::vector<int> slot_start_;   // group g's slots: m² from slot_start_[g]
  std::vector<int> slots_;
  std::vector<int> stride_;       // per node j: entries in one column of block column j
};

}  // namespace clothsim

#include "sim/flat_fe/node_pattern.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace clothsim {

NodeBlockPattern::NodeBlockPattern(int num_nodes, const std::vector<std::vector<int>>& groups) {
  const size_t n = static_cast<size_t>(num_nodes);
  std::vector<std::vector<int>> neighbours(n);
  for (size_t v = 0; v < n; ++v) neighbours[v].push_back(static_cast<int>(v));
  group_start_.reserve(groups.size() + 1);
  group_start_.push_back(0);
  for (const std::vector<int>& group : groups) {
    for (int v : group) {
      if (v < 0 || v >= num_nodes)
        throw std::out_of_range("matrix pattern: node " + std::to_string(v) + " is not one of the " +
                                std::to_string(num_nodes) + " nodes");
      neighbours[static_cast<size_t>(v)].insert(neighbours[static_cast<size_t>(v)].end(), group.begin(), group.end());
    }
    nodes_.insert(nodes_.end(), group.begin(), group.end());
    group_start_.push_back(static_cast<int>(nodes_.size()));
  }
  for (std::vector<int>& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  // Column 3j + d holds the rows 3i + c of every neighbour i of j, in ascending order.
  std::vector<int> column_start(3 * n + 1, 0);
  stride_.resize(n);
  for (size_t j = 0; j < n; ++j) {
    stride_[j] = 3 * static_cast<int>(neighbours[j].size());
    for (size_t d = 0; d < 3; ++d) column_start[3 * j + d + 1] = column_start[3 * j + d] + stride_[j];
  }
  const int nnz = column_start[3 * n];
  const Eigen::Index size = 3 * static_cast<Eigen::Index>(n);
  pattern_ = Eigen::SparseMatrix<double>(size, size);
  pattern_.makeCompressed();
  pattern_.resizeNonZeros(nnz);
  std::copy(column_start.begin(), column_start.end(), pattern_.outerIndexPtr());
  for (size_t j = 0; j < n; ++j)
    for (size_t d = 0; d < 3; ++d) {
      int at = column_start[3 * j + d];
      for (int i : neighbours[j])
        for (int c = 0; c < 3; ++c) pattern_.innerIndexPtr()[at++] = 3 * i + c;
    }
  std::fill(pattern_.valuePtr(), pattern_.valuePtr() + nnz, 0.0);

  slot_start_.reserve(groups.size());
  for (size_t g = 0; g < groups.size(); ++g) {
    const std::vector<int>& group = groups[g];
    const size_t m = group.size();
    slot_start_.push_back(static_cast<int>(slots_.size()));
    for (size_t b = 0; b < m; ++b)
      for (size_t a = 0; a < m; ++a) {
        const std::vector<int>& list = neighbours[static_cast<size_t>(group[b])];
        const auto at = std::lower_bound(list.begin(), list.end(), group[a]) - list.begin();
        slots_.push_back(column_start[3 * static_cast<size_t>(group[b])] + 3 * static_cast<int>(at));
      }
  }
}

}  // namespace clothsim

#include "sim/solver/coupled_matrix.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>

namespace clothsim {

std::vector<int> NodeRow::node_list() const {
  std::vector<int> out;
  out.reserve(nodes.size() + dofs.size());
  for (const auto& entry : nodes) out.push_back(entry.first);
  for (const auto& entry : dofs) out.push_back(entry.first / 3);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

int PointRow::entries(const PointMap& map) const {
  int n = 0;
  for (int k = 0; k < count; ++k) {
    const size_t p = static_cast<size_t>(points[static_cast<size_t>(k)]);
    n += map.offsets[p + 1] - map.offsets[p];
  }
  return n;
}

NodeRow PointRow::node_row(const PointMap& map) const {
  NodeRow row;
  row.nodes.reserve(static_cast<size_t>(entries(map)));
  for (int k = 0; k < count; ++k) {
    const size_t p = static_cast<size_t>(points[static_cast<size_t>(k)]);
    const double c = coefs[static_cast<size_t>(k)];
    for (int e = map.offsets[p]; e < map.offsets[p + 1]; ++e)
      row.nodes.emplace_back(map.nodes[static_cast<size_t>(e)], c * map.weights[static_cast<size_t>(e)]);
  }
  std::stable_sort(row.nodes.begin(), row.nodes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  size_t out = 0;
  for (size_t i = 0; i < row.nodes.size(); ++i) {
    if (out > 0 && row.nodes[out - 1].first == row.nodes[i].first) {
      row.nodes[out - 1].second += row.nodes[i].second;
    } else {
      row.nodes[out++] = row.nodes[i];
    }
  }
  row.nodes.resize(out);
  return row;
}

bool CoupledMatrix::covers(const Eigen::SparseMatrix<double>& a, const std::vector<std::vector<int>>& groups) const {
  if (matrix_.rows() != a.rows() || a_entries_ != a.nonZeros()) return false;
  for (const std::vector<int>& nodes : groups)
    for (int p : nodes) {
      const std::vector<int>& row = adjacency_[static_cast<size_t>(p)];
      auto at = row.begin();
      for (int q : nodes) {  // both sorted: one merge
        at = std::lower_bound(at, row.end(), q);
        if (at == row.end() || *at != q) return false;
      }
    }
  return true;
}

void CoupledMatrix::rebuild(const Eigen::SparseMatrix<double>& a, const std::vector<std::vector<int>>& groups, bool keep_previous) {
  const Eigen::Index num_nodes = a.cols() / 3;
  const bool keep = keep_previous && matrix_.rows() == a.rows() && a_entries_ == a.nonZeros() &&
                    matrix_.nonZeros() <= 2 * a.nonZeros();
  if (!keep) adjacency_.assign(static_cast<size_t>(num_nodes), {});
  for (Eigen::Index col = 0; col < a.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, col); it; ++it)
      adjacency_[static_cast<size_t>(col / 3)].push_back(static_cast<int>(it.row() / 3));
  for (const std::vector<int>& nodes : groups)
    for (int p : nodes) adjacency_[static_cast<size_t>(p)].insert(adjacency_[static_cast<size_t>(p)].end(), nodes.begin(), nodes.end());
  for (std::vector<int>& row : adjacency_) {
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
  }
  build_from_adjacency(a);
}

void CoupledMatrix::restore(const Eigen::SparseMatrix<double>& a, const std::vector<std::vector<int>>& adjacency) {
  if (static_cast<Eigen::Index>(adjacency.size()) != a.cols() / 3)
    throw std::invalid_argument("CoupledMatrix::restore: the saved pattern does not fit the matrix");
  adjacency_ = adjacency;
  for (std::vector<int>& row : adjacency_) {
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
  }
  // A's couplings must be there too (they are in any adjacency a rebuild made).
  for (Eigen::Index col = 0; col < a.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, col); it; ++it) {
      const std::vector<int>& row = adjacency_[static_cast<size_t>(col / 3)];
      if (!std::binary_search(row.begin(), row.end(), static_cast<int>(it.row() / 3)))
        throw std::invalid_argument("CoupledMatrix::restore: the saved pattern lacks a coupling of the matrix");
    }
  build_from_adjacency(a);
}

void CoupledMatrix::clear() {
  matrix_ = Eigen::SparseMatrix<double>();
  a_entries_ = -1;
  from_a_.clear();
  adjacency_.clear();
}

void CoupledMatrix::build_from_adjacency(const Eigen::SparseMatrix<double>& a) {
  // Column 3p + j holds, for each coupled node q (ascending), the rows 3q, 3q + 1, 3q + 2.
  const Eigen::Index n3 = a.rows();
  std::vector<int> outer(static_cast<size_t>(n3) + 1, 0);
  for (size_t p = 0; p < adjacency_.size(); ++p)
    for (int j = 0; j < 3; ++j) outer[3 * p + static_cast<size_t>(j) + 1] = 3 * static_cast<int>(adjacency_[p].size());
  for (size_t c = 0; c < static_cast<size_t>(n3); ++c) outer[c + 1] += outer[c];
  matrix_.resize(n3, n3);
  matrix_.resizeNonZeros(outer.back());
  std::copy(outer.begin(), outer.end(), matrix_.outerIndexPtr());
  int* inner = matrix_.innerIndexPtr();
  for (size_t p = 0; p < adjacency_.size(); ++p)
    for (int j = 0; j < 3; ++j) {
      int at = outer[3 * p + static_cast<size_t>(j)];
      for (int q : adjacency_[p])
        for (int i = 0; i < 3; ++i) inner[at++] = 3 * q + i;
    }
  std::fill(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(), 0.0);
  a_entries_ = a.nonZeros();
  from_a_.assign(static_cast<size_t>(a.nonZeros()), 0);
  for (Eigen::Index col = 0; col < a.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, col); it; ++it) {
      const int* first = inner + outer[static_cast<size_t>(col)];
      const int* last = inner + outer[static_cast<size_t>(col) + 1];
      from_a_[static_cast<size_t>(&it.valueRef() - a.valuePtr())] =
          static_cast<int>(std::lower_bound(first, last, static_cast<int>(it.row())) - inner);
    }
}

void CoupledMatrix::set_base(const Eigen::SparseMatrix<double>& a) {
  if (a.nonZeros() != a_entries_) throw std::logic_error("CoupledMatrix::set_base: the matrix's pattern changed");
  double* values = matrix_.valuePtr();
  std::fill(values, values + matrix_.nonZeros(), 0.0);
  const double* av = a.valuePtr();
  for (Eigen::Index k = 0; k < a.nonZeros(); ++k) values[from_a_[static_cast<size_t>(k)]] += av[k];
}

void CoupledMatrix::add_block(const NodeRow& row, const Eigen::Matrix3d& h) {
  double* values = matrix_.valuePtr();
  const int* outer = matrix_.outerIndexPtr();
  if (row.dofs.empty()) {
    // Node form: Bₚᵀ H B_q = w_p w_q H. With the nodes sorted, each node's ranks among the
    // others' couplings are found by one merge.
    std::vector<std::pair<int, double>> sorted;
    const bool in_order = std::is_sorted(row.nodes.begin(), row.nodes.end());
    if (!in_order) sorted.assign(row.nodes.begin(), row.nodes.end()), std::sort(sorted.begin(), sorted.end());
    const std::vector<std::pair<int, double>>& weights = in_order ? row.nodes : sorted;
    for (const auto& [q, wq] : weights) {
      const Eigen::Matrix3d hq = h * wq;
      const std::vector<int>& coupled = adjacency_[static_cast<size_t>(q)];
      auto at = coupled.begin();
      for (const auto& [p, wp] : weights) {
        at = std::lower_bound(at, coupled.end(), p);
        const int rank = static_cast<int>(at - coupled.begin());
        for (int c = 0; c < 3; ++c) {
          double* column = values + outer[3 * q + c] + 3 * rank;
          for (int k = 0; k < 3; ++k) column[k] += wp * hq(k, c);
        }
      }
    }
    return;
  }
  // Per DOF: gather the 3 × 3 block B_k of each node, then Bₚᵀ H B_q.
  std::vector<std::pair<int, Eigen::Matrix3d>> blocks;
  for (const auto& [node, w] : row.nodes) blocks.emplace_back(node, w * Eigen::Matrix3d::Identity());
  for (const auto& [dof, b] : row.dofs) {
    const int node = dof / 3;
    auto it = std::find_if(blocks.begin(), blocks.end(), [node](const auto& e) { return e.first == node; });
    if (it == blocks.end()) {
      blocks.emplace_back(node, Eigen::Matrix3d::Zero());
      it = blocks.end() - 1;
    }
    it->second.col(dof % 3) += b;
  }
  for (const auto& [q, bq] : blocks) {
    const Eigen::Matrix3d hbq = h * bq;
    const std::vector<int>& coupled = adjacency_[static_cast<size_t>(q)];
    for (const auto& [p, bp] : blocks) {
      const int rank = static_cast<int>(std::lower_bound(coupled.begin(), coupled.end(), p) - coupled.begin());
      const Eigen::Matrix3d block = bp.transpose() * hbq;
      for (int c = 0; c < 3; ++c) {
        double* column = values + outer[3 * q + c] + 3 * rank;
        for (int k = 0; k < 3; ++k) column[k] += block(k, c);
      }
    }
  }
}

void CoupledMatrix::add_blocks(const std::vector<std::pair<NodeRow, Eigen::Matrix3d>>& blocks) {
  const bool node_form = std::all_of(blocks.begin(), blocks.end(), [](const auto& b) {
    return b.first.dofs.empty() && std::is_sorted(b.first.nodes.begin(), b.first.nodes.end());
  });
  if (!node_form) {
    for (const auto& [row, h] : blocks) add_block(row, h);
    return;
  }
  // Per column node q, the (block, entry of q in it) in increasing block: a column's values then
  // receive the blocks' terms in the order add_block, block by block, would add them.
  const size_t num_nodes = adjacency_.size();
  std::vector<int> start(num_nodes + 1, 0);
  for (const auto& [row, h] : blocks)
    for (const auto& entry : row.nodes) ++start[static_cast<size_t>(entry.first) + 1];
  std::vector<int> columns;
  for (size_t q = 0; q < num_nodes; ++q) {
    if (start[q + 1] > 0) columns.push_back(static_cast<int>(q));
    start[q + 1] += start[q];
  }
  std::vector<std::pair<int, int>> entries(static_cast<size_t>(start.back()));
  {
    std::vector<int> next(start.begin(), start.end() - 1);
    for (size_t b = 0; b < blocks.size(); ++b) {
      const NodeRow& row = blocks[b].first;
      for (size_t k = 0; k < row.nodes.size(); ++k)
        entries[static_cast<size_t>(next[static_cast<size_t>(row.nodes[k].first)]++)] = {static_cast<int>(b), static_cast<int>(k)};
    }
  }
  double* values = matrix_.valuePtr();
  const int* outer = matrix_.outerIndexPtr();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, columns.size(), 16), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t j = range.begin(); j != range.end(); ++j) {
      const int q = columns[j];
      const std::vector<int>& coupled = adjacency_[static_cast<size_t>(q)];
      for (int e = start[static_cast<size_t>(q)]; e < start[static_cast<size_t>(q) + 1]; ++e) {
        const auto [b, k] = entries[static_cast<size_t>(e)];
        const NodeRow& row = blocks[static_cast<size_t>(b)].first;
        const Eigen::Matrix3d hq = blocks[static_cast<size_t>(b)].second * row.nodes[static_cast<size_t>(k)].second;
        auto at = coupled.begin();
        for (const auto& [p, wp] : row.nodes) {
          at = std::lower_bound(at, coupled.end(), p);
          const int rank = static_cast<int>(at - coupled.begin());
          for (int c = 0; c < 3; ++c) {
            double* column = values + outer[3 * q + c] + 3 * rank;
            for (int r = 0; r < 3; ++r) column[r] += wp * hq(r, c);
          }
        }
      }
    }
  });
}

}  // namespace clothsim

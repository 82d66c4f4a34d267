// Small helpers on the fixed sparsity pattern of the system matrices (compressed, column-major).
#pragma once

#include <Eigen/SparseCore>

#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {

// Value offsets of the diagonal entries of a compressed column-major matrix whose pattern holds
// every diagonal entry (throws std::invalid_argument naming the first missing one).
inline std::vector<Eigen::Index> diagonal_offsets(const Eigen::SparseMatrix<double>& pattern) {
  std::vector<Eigen::Index> out(static_cast<size_t>(pattern.cols()));
  for (Eigen::Index col = 0; col < pattern.cols(); ++col) {
    Eigen::Index at = pattern.outerIndexPtr()[col];
    const Eigen::Index end = pattern.outerIndexPtr()[col + 1];
    while (at < end && pattern.innerIndexPtr()[at] != col) ++at;
    if (at == end) throw std::invalid_argument("matrix pattern: no diagonal entry in column " + std::to_string(col));
    out[static_cast<size_t>(col)] = at;
  }
  return out;
}

}  // namespace clothsim

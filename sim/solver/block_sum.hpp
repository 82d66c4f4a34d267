// The step potential's part of the Newton matrix, Σ_r w_r Bᵣᵀ Hᵣ Bᵣ over the blocks of one
// linearisation (sim/solver/step_potential.hpp), with the integrator's weights w_r (h² for blocks
// of the energy, h for blocks of the dissipation), as an operation on vectors.
//
// Blocks on one row (a surface point's barrier and its friction, or its pairs with two obstacles)
// are merged into one (rows of one point, and rows over the nodes; see build()). Rows on points
// (PointRow) are applied through their points: a product gathers the points' values once,
// u_p = Σ_j w_pj x_j for every point some row reads, applies the rows there (a 3 × 3 block and up
// to four points each) and scatters the points' forces back
// through the same weights. On a level-2 Loop surface a point's stencil has 12–16 nodes and a
// cloth–cloth pair's row 30–50, so a point read by several rows (a resting cloth's points are in
// a barrier row and a friction row, and in pairs with several neighbours) is gathered once
// instead of once per row. Rows over the nodes (NodeRow) are applied as they are. For a factor's
// matrix, node_blocks() gives every merged block in node form.
#pragma once

#include "sim/solver/coupled_matrix.hpp"
#include "sim/solver/step_potential.hpp"

#include <Eigen/Core>

#include <unordered_map>
#include <utility>
#include <vector>

namespace clothsim {

class BlockSum {
 public:
  // Takes the blocks of `lin` (which must outlive the sum's use: rows are referenced) with weight
  // h² (energy) or h (dissipation).
  void build(const PotentialLinearisation& lin, double h);
  bool empty() const { return merged_.empty(); }
  size_t size() const { return merged_.size(); }
  // y += Σ w Bᵀ H B x (x and y: 3·#nodes).
  void add_product(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  // The work of one product in stored-entry equivalents of a sparse matrix (for the solver's
  // refresh rule).
  double product_entries() const { return entries_; }
  // The merged blocks in node form with their weighted 3 × 3 matrices, in a fixed order.
  std::vector<std::pair<NodeRow, Eigen::Matrix3d>> node_blocks() const;

 private:
  using Block = PotentialLinearisation::Block;
  struct RowHash {
    size_t operator()(const Block* b) const;
  };
  struct RowEqual {
    bool operator()(const Block* a, const Block* b) const;
  };
  const PotentialLinearisation* lin_ = nullptr;
  std::vector<std::pair<const Block*, Eigen::Matrix3d>> merged_;  // first-occurrence order
  std::unordered_map<const Block*, size_t, RowHash, RowEqual> index_;
  // The points the rows on points read (sorted), each point's slot among them, and per merged
  // block on points its points' slots.
  std::vector<int> points_;
  std::vector<int> slot_;  // per point of the map (−1: unread); kept between builds
  std::vector<int> single_;  // per point: its merged one-point row while building (−1: none)
  std::vector<std::array<int, 4>> block_slots_;
  double entries_ = 0.0;
  // Scratch of add_product: the gathered point values and forces (3 per slot).
  mutable Eigen::VectorXd gathered_, forces_;
};

}  // namespace clothsim

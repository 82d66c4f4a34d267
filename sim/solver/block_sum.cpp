#include "sim/solver/block_sum.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <functional>
#include <stdexcept>

namespace clothsim {

// (Only rows over the nodes are hashed: rows on points merge through single_, see build().)
size_t BlockSum::RowHash::operator()(const Block* b) const {
  const NodeRow& r = b->row;
  size_t seed = r.nodes.size() * 31 + r.dofs.size();
  auto mix = [&seed](size_t v) { seed ^= v + 0x9e3779b97f4a7c15ULL + (seed << 6) + (seed >> 2); };
  for (const auto& [node, w] : r.nodes) {
    mix(std::hash<int>{}(node));
    mix(std::hash<double>{}(w));
  }
  for (const auto& entry : r.dofs) mix(std::hash<int>{}(entry.first));
  return seed;
}

bool BlockSum::RowEqual::operator()(const Block* a, const Block* b) const {
  return a->row.nodes == b->row.nodes && a->row.dofs == b->row.dofs;
}

void BlockSum::build(const PotentialLinearisation& lin, double h) {
  lin_ = &lin;
  merged_.clear();
  index_.clear();
  // Rows of one point (against an obstacle or a plane, and their friction) are merged through a
  // slot per point; rows over the nodes through a hash of their entries. Rows of several points
  // (cloth–cloth pairs) are not looked for: their barrier and friction rows have different
  // coefficients (the end's and the start's), so they almost never coincide. (Hashing every
  // block cost a fifth of the crushed sleeve's solves.)
  const PointMap* map = lin.point_map;
  if (map != nullptr && single_.size() != static_cast<size_t>(map->num_points()))
    single_.assign(static_cast<size_t>(map->num_points()), -1);
  for (const Block& block : lin.blocks) {
    const double weight = block.dissipative ? h : h * h;
    if (block.is_on_points()) {
      if (map == nullptr) throw std::invalid_argument("BlockSum: a block on points without the points' map");
      if (block.on_points.count == 1) {
        int& at = single_[static_cast<size_t>(block.on_points.points[0])];
        if (at >= 0 && merged_[static_cast<size_t>(at)].first->on_points.coefs[0] == block.on_points.coefs[0]) {
          merged_[static_cast<size_t>(at)].second += weight * block.hessian;
          continue;
        }
        at = static_cast<int>(merged_.size());
      }
      merged_.emplace_back(&block, weight * block.hessian);
      continue;
    }
    const auto [at, inserted] = index_.try_emplace(&block, merged_.size());
    if (inserted) {
      merged_.emplace_back(&block, weight * block.hessian);
    } else {
      merged_[at->second].second += weight * block.hessian;
    }
  }
  for (const auto& [block, hw] : merged_)
    if (block->is_on_points() && block->on_points.count == 1) single_[static_cast<size_t>(block->on_points.points[0])] = -1;
  // The points the rows on points read, sorted, and their slots.
  for (int p : points_) slot_[static_cast<size_t>(p)] = -1;
  points_.clear();
  block_slots_.assign(merged_.size(), {-1, -1, -1, -1});
  entries_ = 0.0;
  if (map != nullptr) {
    if (slot_.size() != static_cast<size_t>(map->num_points())) slot_.assign(static_cast<size_t>(map->num_points()), -1);
    // (Marked, then collected in increasing order: a sort of the rows' points took most of a build.)
    int first = map->num_points(), last = -1;
    for (const auto& [block, hw] : merged_)
      if (block->is_on_points())
        for (int k = 0; k < block->on_points.count; ++k) {
          const int p = block->on_points.points[static_cast<size_t>(k)];
          slot_[static_cast<size_t>(p)] = 0;
          first = std::min(first, p);
          last = std::max(last, p);
        }
    for (int p = first; p <= last; ++p)
      if (slot_[static_cast<size_t>(p)] == 0) points_.push_back(p);
    for (size_t i = 0; i < points_.size(); ++i) {
      const size_t p = static_cast<size_t>(points_[i]);
      slot_[p] = static_cast<int>(i);
      entries_ += 6.0 * (map->offsets[p + 1] - map->offsets[p]);  // gathered and scattered, 3 components
    }
  }
  for (size_t r = 0; r < merged_.size(); ++r) {
    const Block& block = *merged_[r].first;
    if (block.is_on_points()) {
      for (int k = 0; k < block.on_points.count; ++k)
        block_slots_[r][static_cast<size_t>(k)] = slot_[static_cast<size_t>(block.on_points.points[static_cast<size_t>(k)])];
      entries_ += 12.0;
    } else {
      entries_ += 6.0 * static_cast<double>(block.row.nodes.size() + block.row.dofs.size());
    }
  }
}

void BlockSum::add_product(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  if (merged_.empty()) return;
  const PointMap* map = lin_->point_map;
  const Eigen::Index n = static_cast<Eigen::Index>(points_.size());
  if (n > 0) {
    gathered_.resize(3 * n);
    forces_.setZero(3 * n);
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, 512), [&](const tbb::blocked_range<Eigen::Index>& range) {
      for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
        const size_t p = static_cast<size_t>(points_[static_cast<size_t>(i)]);
        Eigen::Vector3d u = Eigen::Vector3d::Zero();
        for (int e = map->offsets[p]; e < map->offsets[p + 1]; ++e)
          u += map->weights[static_cast<size_t>(e)] * x.segment<3>(3 * map->nodes[static_cast<size_t>(e)]);
        gathered_.segment<3>(3 * i) = u;
      }
    });
  }
  for (size_t r = 0; r < merged_.size(); ++r) {
    const auto& [block, hw] = merged_[r];
    if (!block->is_on_points()) {
      block->row.scatter(hw * block->row.apply(x), y);
      continue;
    }
    const PointRow& row = block->on_points;
    const std::array<int, 4>& slots = block_slots_[r];
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (int k = 0; k < row.count; ++k) u += row.coefs[static_cast<size_t>(k)] * gathered_.segment<3>(3 * slots[static_cast<size_t>(k)]);
    const Eigen::Vector3d f = hw * u;
    for (int k = 0; k < row.count; ++k) forces_.segment<3>(3 * slots[static_cast<size_t>(k)]) += row.coefs[static_cast<size_t>(k)] * f;
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const size_t p = static_cast<size_t>(points_[static_cast<size_t>(i)]);
    const Eigen::Vector3d f = forces_.segment<3>(3 * i);
    for (int e = map->offsets[p]; e < map->offsets[p + 1]; ++e)
      y.segment<3>(3 * map->nodes[static_cast<size_t>(e)]) += map->weights[static_cast<size_t>(e)] * f;
  }
}

std::vector<std::pair<NodeRow, Eigen::Matrix3d>> BlockSum::node_blocks() const {
  std::vector<std::pair<NodeRow, Eigen::Matrix3d>> out;
  out.reserve(merged_.size());
  for (const auto& [block, hw] : merged_) out.emplace_back(lin_->node_row(*block), hw);
  return out;
}

}  // namespace clothsim

// The fail-safe's impact zones (Provot 1997; Bridson, Fedkiw & Anderson 2002): nodes joined by
// colliding pairs are merged into zones (union–find), and each zone moves as one rigid map over
// the step, fitted to its nodes' motion (Kabsch).
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace clothsim::contact {

// Union–find over nodes for impact zones.
struct Zones {
  std::vector<int> parent;
  explicit Zones(int n) : parent(static_cast<size_t>(n)) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int i) {
    while (parent[static_cast<size_t>(i)] != i) {
      parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
      i = parent[static_cast<size_t>(i)];
    }
    return i;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
  }
};

// A rigid map p ↦ R p + c.
struct RigidMap {
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  Eigen::Vector3d operator()(const Eigen::Vector3d& p) const { return r * p + c; }
};

// The rigid map that best takes points `from` to `to` (Kabsch, equal weights); a translation
// for fewer than three points.
RigidMap fit_rigid(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to);

}  // namespace clothsim::contact

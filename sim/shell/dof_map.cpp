#include "sim/shell/dof_map.hpp"

#include <algorithm>
#include <Eigen/LU>

#include <limits>
#include <map>

namespace clothsim {

namespace {

Combination merged(const std::vector<std::pair<const Combination*, double>>& parts) {
  std::map<int, double> sum;
  for (const auto& [combo, scale] : parts)
    for (const auto& [v, w] : *combo) sum[v] += scale * w;
  Combination out;
  for (const auto& [v, w] : sum)
    if (w != 0.0) out.emplace_back(v, w);
  return out;
}

}  // namespace

DofMap::DofMap(const ExtendedMesh& ext, const std::vector<BoundaryCondition>& conditions)
    : num_real_(ext.num_real), status_(3 * ext.num_real, DofStatus::free), combos_(3 * ext.num_vertices()) {
  const Topology& top = ext.topology;
  const int n = ext.num_real;
  // Clamped border edges per component: ghost k is clamped in component c when both ends of its
  // border edge are selected by one clamped condition that fixes c.
  std::vector<std::array<bool, 3>> ghost_clamped(ext.ghosts.size(), {false, false, false});
  std::vector<std::array<bool, 3>> tied(n, {false, false, false});  // border vertex on a clamped edge
  for (const BoundaryCondition& bc : conditions) {
    std::vector<bool> selected(n, false);
    for (int v : bc.vertices) selected[v] = true;
    for (int v : bc.vertices)
      for (int c = 0; c < 3; ++c)
        if (bc.fix[c]) status_[3 * v + c] = DofStatus::fixed;
    if (!bc.clamped) continue;
    for (size_t k = 0; k < ext.ghosts.size(); ++k) {
      const GhostVertex& g = ext.ghosts[k];
      if (!selected[g.a] || !selected[g.b]) continue;
      for (int c = 0; c < 3; ++c)
        if (bc.fix[c]) ghost_clamped[k][c] = tied[g.a][c] = tied[g.b][c] = true;
    }
  }
  // Free components stand for themselves.
  for (int v = 0; v < n; ++v)
    for (int c = 0; c < 3; ++c)
      if (status_[3 * v + c] == DofStatus::free) {
        combos_[3 * v + c] = {{v, 1.0}};
        ++num_free_;
      }
  // Tied border vertices: u_b = −½ mean of the real neighbours that are not on a border.
  std::vector<bool> border(n, false);
  for (const GhostVertex& g : ext.ghosts) border[g.a] = border[g.b] = true;
  for (int v = 0; v < n; ++v)
    for (int c = 0; c < 3; ++c) {
      if (!tied[v][c]) continue;
      std::vector<std::pair<const Combination*, double>> parts;
      for (int m : top.ring(v))
        if (m < n && !border[m]) parts.emplace_back(&combos_[3 * m + c], 0.0);
      for (auto& part : parts) part.second = -0.5 / static_cast<double>(parts.size());
      status_[3 * v + c] = parts.empty() ? DofStatus::fixed : DofStatus::dependent;
      combos_[3 * v + c] = merged(parts);
    }
  // Ghosts, from the (now final) real combinations.
  for (size_t k = 0; k < ext.ghosts.size(); ++k) {
    const GhostVertex& g = ext.ghosts[k];
    const int id = n + static_cast<int>(k);
    const GhostMirror mirror = ghost_mirror(ext, static_cast<int>(k));
    for (int c = 0; c < 3; ++c) {
      std::vector<std::pair<const Combination*, double>> parts;
      if (ghost_clamped[k][c]) {  // even reflection: u_g = u(mirror point)
        for (int i = 0; i < 3; ++i) parts.emplace_back(&combos_[3 * mirror.vertices[i] + c], mirror.weights[i]);
      } else if (status_[3 * g.a + c] == DofStatus::fixed && status_[3 * g.b + c] == DofStatus::fixed) {
        // hinged: odd reflection about the edge, u_g = 2 u(edge point) − u(mirror point)
        parts.emplace_back(&combos_[3 * g.a + c], 2.0 * (1.0 - mirror.edge_parameter));
        parts.emplace_back(&combos_[3 * g.b + c], 2.0 * mirror.edge_parameter);
        for (int i = 0; i < 3; ++i) parts.emplace_back(&combos_[3 * mirror.vertices[i] + c], -mirror.weights[i]);
      } else {  // free edge (Cirak et al. 2000): u_g = u_a + u_b − u_c
        parts = {{&combos_[3 * g.a + c], 1.0}, {&combos_[3 * g.b + c], 1.0}, {&combos_[3 * g.c + c], -1.0}};
      }
      combos_[3 * id + c] = merged(parts);
    }
  }
}

GhostMirror ghost_mirror(const ExtendedMesh& ext, int ghost) {
  const GhostVertex& g = ext.ghosts[ghost];
  const Eigen::Vector3d xa = ext.rest.row(g.a), xb = ext.rest.row(g.b);
  const Eigen::Vector3d xg = ext.rest.row(ext.num_real + ghost);
  GhostMirror out;
  out.edge_parameter = (xg - xa).dot(xb - xa) / (xb - xa).squaredNorm();
  const Eigen::Vector3d foot = xa + out.edge_parameter * (xb - xa);
  const Eigen::Vector3d target = 2.0 * foot - xg;
  // The real triangle around a or b that holds the reflected point best (largest smallest
  // barycentric coordinate, measured in the triangle's plane).
  double best = -std::numeric_limits<double>::infinity();
  for (int centre : {g.a, g.b}) {
    const std::vector<int>& ring = ext.topology.ring(centre);
    for (size_t i = 0; i < ring.size(); ++i) {
      const int p = ring[i], q = ring[(i + 1) % ring.size()];
      if (p >= ext.num_real || q >= ext.num_real) continue;
      const Eigen::Vector3d x0 = ext.rest.row(centre), e1 = ext.rest.row(p) - x0.transpose(),
                            e2 = ext.rest.row(q) - x0.transpose();
      Eigen::Matrix2d gram;
      gram << e1.dot(e1), e1.dot(e2), e1.dot(e2), e2.dot(e2);
      const Eigen::Vector2d rhs(e1.dot(target - x0), e2.dot(target - x0));
      const Eigen::Vector2d l = gram.inverse() * rhs;
      const double l0 = 1.0 - l(0) - l(1);
      const double worst = std::min({l0, l(0), l(1)});
      if (worst > best + 1e-12) {
        best = worst;
        out.vertices = {centre, p, q};
        out.weights = {l0, l(0), l(1)};
      }
    }
  }
  return out;
}

bool DofMap::is_identity(int vertex) const {
  if (vertex >= num_real_) return false;
  for (int c = 0; c < 3; ++c) {
    const Combination& combo = combos_[3 * vertex + c];
    if (combo.size() != 1 || combo[0].first != vertex || combo[0].second != 1.0) return false;
  }
  return true;
}

Eigen::MatrixX3d DofMap::expand(const Eigen::MatrixX3d& real) const {
  const Eigen::Index total = static_cast<Eigen::Index>(combos_.size() / 3);
  Eigen::MatrixX3d out = Eigen::MatrixX3d::Zero(total, 3);
  for (Eigen::Index v = 0; v < total; ++v)
    for (int c = 0; c < 3; ++c)
      for (const auto& [r, w] : combos_[3 * v + c]) out(v, c) += w * real(r, c);
  return out;
}

}  // namespace clothsim

#include "sim/shell/dof_map.hpp"

#include <algorithm>
#include <Eigen/Geometry>
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

namespace {

// Area-weighted normals of the real vertices (from the real triangles).
std::vector<Eigen::Vector3d> vertex_normals(const ExtendedMesh& ext) {
  std::vector<Eigen::Vector3d> normals(ext.num_real, Eigen::Vector3d::Zero());
  for (int t = 0; t < ext.num_real_triangles; ++t) {
    const Triangle& tri = ext.triangles[t];
    const Eigen::Vector3d x0 = ext.rest.row(tri[0]), x1 = ext.rest.row(tri[1]), x2 = ext.rest.row(tri[2]);
    const Eigen::Vector3d n = (x1 - x0).cross(x2 - x0);
    for (int v : tri) normals[v] += n;
  }
  for (Eigen::Vector3d& n : normals) n.normalize();
  return normals;
}

}  // namespace

DofMap::DofMap(const ExtendedMesh& ext, const std::vector<BoundaryCondition>& conditions)
    : num_real_(ext.num_real), status_(3 * ext.num_real, DofStatus::free), combos_(3 * ext.num_vertices()) {
  const Topology& top = ext.topology;
  const int n = ext.num_real;
  const std::vector<Eigen::Vector3d> normal = vertex_normals(ext);
  std::vector<bool> ghost_clamped(ext.ghosts.size(), false), ghost_symmetric(ext.ghosts.size(), false);
  std::vector<std::array<bool, 3>> clamp_fix(n, {false, false, false});  // border vertex on a clamped edge
  std::vector<bool> on_clamped_edge(n, false);
  for (const BoundaryCondition& bc : conditions) {
    std::vector<bool> selected(n, false);
    for (int v : bc.vertices) selected[v] = true;
    for (int v : bc.vertices)
      for (int c = 0; c < 3; ++c)
        if (bc.fix[c]) status_[3 * v + c] = DofStatus::fixed;
    if (bc.symmetric)
      for (size_t k = 0; k < ext.ghosts.size(); ++k)
        if (selected[ext.ghosts[k].a] && selected[ext.ghosts[k].b]) ghost_symmetric[k] = true;
    if (!bc.clamped) continue;
    for (size_t k = 0; k < ext.ghosts.size(); ++k) {
      const GhostVertex& g = ext.ghosts[k];
      if (!selected[g.a] || !selected[g.b]) continue;
      ghost_clamped[k] = true;
      for (int v : {g.a, g.b}) {
        on_clamped_edge[v] = true;
        for (int c = 0; c < 3; ++c) clamp_fix[v][c] = clamp_fix[v][c] || bc.fix[c];
      }
    }
  }
  // Free and fixed (prescribed) components stand for themselves.
  for (int v = 0; v < n; ++v)
    for (int c = 0; c < 3; ++c) {
      combos_[3 * v + c] = {{3 * v + c, 1.0}};
      if (status_[3 * v + c] == DofStatus::free) ++num_free_;
    }
  // Tied border vertices on clamped edges: N·u_b = −½ mean(N·u_m) over interior neighbours,
  // when N lies in the span of the fixed components.
  std::vector<bool> border(n, false);
  for (const GhostVertex& g : ext.ghosts) border[g.a] = border[g.b] = true;
  for (int v = 0; v < n; ++v) {
    if (!on_clamped_edge[v]) continue;
    const Eigen::Vector3d& nv = normal[v];
    double in_span = 0.0;
    for (int c = 0; c < 3; ++c)
      if (clamp_fix[v][c] && status_[3 * v + c] == DofStatus::fixed) in_span += nv(c) * nv(c);
    if (in_span < 0.99) continue;
    std::vector<int> interior;
    for (int m : top.ring(v))
      if (m < n && !border[m]) interior.push_back(m);
    if (interior.empty()) continue;
    const double scale = -0.5 / static_cast<double>(interior.size());
    for (int c = 0; c < 3; ++c) {
      if (!clamp_fix[v][c] || status_[3 * v + c] != DofStatus::fixed) continue;
      std::vector<std::pair<const Combination*, double>> parts;
      for (int m : interior)
        for (int d = 0; d < 3; ++d) parts.emplace_back(&combos_[3 * m + d], scale * nv(c) * nv(d));
      combos_[3 * v + c] = merged(parts);
      status_[3 * v + c] = DofStatus::dependent;
    }
  }
  // Ghosts, from the (now final) real combinations.
  for (size_t k = 0; k < ext.ghosts.size(); ++k) {
    const GhostVertex& g = ext.ghosts[k];
    const int id = n + static_cast<int>(k);
    const GhostMirror mirror = ghost_mirror(ext, static_cast<int>(k));
    // Component-wise base rule: free edge or odd reflection.
    std::array<Combination, 3> base;
    for (int c = 0; c < 3; ++c) {
      std::vector<std::pair<const Combination*, double>> parts;
      if (status_[3 * g.a + c] != DofStatus::free && status_[3 * g.b + c] != DofStatus::free) {
        parts.emplace_back(&combos_[3 * g.a + c], 2.0 * (1.0 - mirror.edge_parameter));
        parts.emplace_back(&combos_[3 * g.b + c], 2.0 * mirror.edge_parameter);
        for (int i = 0; i < 3; ++i) parts.emplace_back(&combos_[3 * mirror.vertices[i] + c], -mirror.weights[i]);
      } else if (ghost_symmetric[k]) {  // even reflection of a free component
        for (int i = 0; i < 3; ++i) parts.emplace_back(&combos_[3 * mirror.vertices[i] + c], mirror.weights[i]);
      } else {
        parts = {{&combos_[3 * g.a + c], 1.0}, {&combos_[3 * g.b + c], 1.0}, {&combos_[3 * g.c + c], -1.0}};
      }
      base[c] = merged(parts);
    }
    if (!ghost_clamped[k]) {
      for (int c = 0; c < 3; ++c) combos_[3 * id + c] = std::move(base[c]);
      continue;
    }
    // Clamped: u_g = N Nᵀ u(g') + (I − N Nᵀ) base.
    const Eigen::Vector3d edge_normal = (normal[g.a] + normal[g.b]).normalized();
    for (int c = 0; c < 3; ++c) {
      std::vector<std::pair<const Combination*, double>> parts = {{&base[c], 1.0}};
      for (int d = 0; d < 3; ++d) {
        const double nn = edge_normal(c) * edge_normal(d);
        if (nn == 0.0) continue;
        for (int i = 0; i < 3; ++i) parts.emplace_back(&combos_[3 * mirror.vertices[i] + d], nn * mirror.weights[i]);
        parts.emplace_back(&base[d], -nn);
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
    if (combo.size() != 1 || combo[0].first != 3 * vertex + c || combo[0].second != 1.0) return false;
  }
  return true;
}

Eigen::MatrixX3d DofMap::expand(const Eigen::MatrixX3d& real) const {
  const Eigen::Index total = static_cast<Eigen::Index>(combos_.size() / 3);
  Eigen::MatrixX3d out = Eigen::MatrixX3d::Zero(total, 3);
  for (Eigen::Index v = 0; v < total; ++v)
    for (int c = 0; c < 3; ++c)
      for (const auto& [dof, w] : combos_[3 * v + c]) out(v, c) += w * real(dof / 3, dof % 3);
  return out;
}

}  // namespace clothsim

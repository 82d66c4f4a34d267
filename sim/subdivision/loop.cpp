#include "sim/subdivision/loop.hpp"

#include "sim/mesh/topology.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

namespace clothsim {

double loop_beta(int valence) {
  const double n = valence;
  const double c = 3.0 / 8.0 + 0.25 * std::cos(2.0 * std::numbers::pi / n);
  return (5.0 / 8.0 - c * c) / n;
}

double limit_neighbour_weight(int valence) {
  return 1.0 / (valence + 3.0 / (8.0 * loop_beta(valence)));
}

std::vector<double> limit_tangent_mask(int valence, int which) {
  std::vector<double> mask(valence);
  for (int i = 0; i < valence; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / valence;
    mask[i] = which == 0 ? std::cos(angle) : std::sin(angle);
  }
  return mask;
}

SubdivisionStep loop_subdivision_step(const Eigen::MatrixX3d& x, const std::vector<Triangle>& triangles,
                                      double corner_angle_deg) {
  const int n = static_cast<int>(x.rows());
  const Topology top(n, triangles);

  // Edges sorted by (min, max) vertex; an edge's id is its position in that order.
  auto key = [](int a, int b) { return std::make_pair(std::min(a, b), std::max(a, b)); };
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * triangles.size());
  for (const Triangle& t : triangles)
    for (int k = 0; k < 3; ++k) edges.push_back(key(t[k], t[(k + 1) % 3]));
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  auto edge_index = [&](int a, int b) {
    return static_cast<int>(std::lower_bound(edges.begin(), edges.end(), key(a, b)) - edges.begin());
  };

  std::vector<Eigen::Triplet<double>> w;
  const double cos_corner = std::cos(corner_angle_deg * std::numbers::pi / 180.0);
  for (int v = 0; v < n; ++v) {
    const std::vector<int>& ring = top.ring(v);
    if (!top.is_boundary(v)) {
      const int valence = top.valence(v);
      const double beta = loop_beta(valence);
      w.emplace_back(v, v, 1.0 - valence * beta);
      for (int r : ring) w.emplace_back(v, r, beta);
      continue;
    }
    // Border: the boundary neighbours are ring.front() (edge leaving v) and ring.back().
    const Eigen::RowVector3d d_in = (x.row(v) - x.row(ring.back())).normalized();
    const Eigen::RowVector3d d_out = (x.row(ring.front()) - x.row(v)).normalized();
    const bool corner = top.num_incident_triangles(v) == 1 || d_in.dot(d_out) < cos_corner;
    if (corner) {
      w.emplace_back(v, v, 1.0);
    } else {
      w.emplace_back(v, v, 0.75);
      w.emplace_back(v, ring.front(), 0.125);
      w.emplace_back(v, ring.back(), 0.125);
    }
  }
  for (int e = 0; e < static_cast<int>(edges.size()); ++e) {
    const auto [a, b] = edges[e];
    const int c = top.opposite(a, b), d = top.opposite(b, a);
    if (c >= 0 && d >= 0) {
      for (int v : {a, b}) w.emplace_back(n + e, v, 0.375);
      for (int v : {c, d}) w.emplace_back(n + e, v, 0.125);
    } else {
      for (int v : {a, b}) w.emplace_back(n + e, v, 0.5);
    }
  }
  SubdivisionStep out;
  out.matrix.resize(n + static_cast<Eigen::Index>(edges.size()), n);
  out.matrix.setFromTriplets(w.begin(), w.end());
  out.triangles.reserve(4 * triangles.size());
  for (const Triangle& t : triangles) {
    const int a = t[0], b = t[1], c = t[2];
    const int ab = n + edge_index(a, b), bc = n + edge_index(b, c), ca = n + edge_index(c, a);
    out.triangles.push_back({a, ab, ca});
    out.triangles.push_back({b, bc, ab});
    out.triangles.push_back({c, ca, bc});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

TriMesh loop_subdivide(const TriMesh& mesh, double corner_angle_deg) {
  const SubdivisionStep step = loop_subdivision_step(mesh.vertices, mesh.triangles, corner_angle_deg);
  TriMesh out;
  out.vertices = step.matrix * mesh.vertices;
  out.triangles = step.triangles;
  if (!mesh.warp.empty()) {  // each triangle's four children (in order) keep its warp direction
    out.warp.reserve(4 * mesh.warp.size());
    for (const Eigen::Vector3d& w : mesh.warp)
      for (int k = 0; k < 4; ++k) out.warp.push_back(w);
  }
  // The children's corners in the parent's texture space: its corners and edge midpoints.
  if (!mesh.uv.empty()) out.uv = refine_corner_uv(mesh.uv, 1);
  return out;
}

std::vector<std::array<Eigen::Vector2d, 3>> refine_corner_uv(const std::vector<std::array<Eigen::Vector2d, 3>>& uv,
                                                             int levels) {
  std::vector<std::array<Eigen::Vector2d, 3>> current = uv;
  for (int level = 0; level < levels; ++level) {
    std::vector<std::array<Eigen::Vector2d, 3>> next;
    next.reserve(4 * current.size());
    for (const auto& t : current) {
      // (x + y) / 2 is symmetric in x and y, so a midpoint shared by two triangles is the same double.
      const Eigen::Vector2d ab = 0.5 * (t[0] + t[1]), bc = 0.5 * (t[1] + t[2]), ca = 0.5 * (t[2] + t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({t[1], bc, ab});
      next.push_back({t[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    current = std::move(next);
  }
  return current;
}

}  // namespace clothsim

#include "sim/subdivision/loop.hpp"

#include "sim/mesh/topology.hpp"

#include <Eigen/Geometry>

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

TriMesh loop_subdivide(const TriMesh& mesh, double corner_angle_deg) {
  const Topology top(mesh.num_vertices(), mesh.triangles);
  const Eigen::MatrixX3d& x = mesh.vertices;
  const int n = mesh.num_vertices();

  // Edge ids in order of first appearance.
  std::map<std::pair<int, int>, int> edge_id;
  std::vector<std::pair<int, int>> edges;
  auto key = [](int a, int b) { return std::make_pair(std::min(a, b), std::max(a, b)); };
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      auto [it, inserted] = edge_id.emplace(key(t[k], t[(k + 1) % 3]), static_cast<int>(edges.size()));
      if (inserted) edges.push_back(it->first);
    }

  TriMesh out;
  out.vertices.resize(n + static_cast<Eigen::Index>(edges.size()), 3);
  const double cos_corner = std::cos(corner_angle_deg * std::numbers::pi / 180.0);
  for (int v = 0; v < n; ++v) {
    const std::vector<int>& ring = top.ring(v);
    if (!top.is_boundary(v)) {
      const int valence = top.valence(v);
      const double beta = loop_beta(valence);
      Eigen::RowVector3d p = (1.0 - valence * beta) * x.row(v);
      for (int r : ring) p += beta * x.row(r);
      out.vertices.row(v) = p;
      continue;
    }
    // Border: the boundary neighbours are ring.front() (edge leaving v) and ring.back().
    const Eigen::RowVector3d next = x.row(ring.front()), prev = x.row(ring.back());
    const Eigen::RowVector3d d_in = (x.row(v) - prev).normalized(), d_out = (next - x.row(v)).normalized();
    const bool corner = top.num_incident_triangles(v) == 1 || d_in.dot(d_out) < cos_corner;
    out.vertices.row(v) = corner ? Eigen::RowVector3d(x.row(v)) : Eigen::RowVector3d(0.75 * x.row(v) + 0.125 * (next + prev));
  }
  for (int e = 0; e < static_cast<int>(edges.size()); ++e) {
    const auto [a, b] = edges[e];
    const int c = top.opposite(a, b), d = top.opposite(b, a);
    Eigen::RowVector3d p;
    if (c >= 0 && d >= 0)
      p = 0.375 * (x.row(a) + x.row(b)) + 0.125 * (x.row(c) + x.row(d));
    else
      p = 0.5 * (x.row(a) + x.row(b));
    out.vertices.row(n + e) = p;
  }
  out.triangles.reserve(4 * mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    const int a = t[0], b = t[1], c = t[2];
    const int ab = n + edge_id.at(key(a, b)), bc = n + edge_id.at(key(b, c)), ca = n + edge_id.at(key(c, a));
    out.triangles.push_back({a, ab, ca});
    out.triangles.push_back({b, bc, ab});
    out.triangles.push_back({c, ca, bc});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

}  // namespace clothsim

#include "sim/contact/obstacle_set.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>

namespace clothsim::contact {

void build_edges(const std::vector<Triangle>& triangles, std::vector<std::array<int, 2>>& edges,
                 std::vector<std::array<int, 3>>& triangle_edges) {
  std::map<std::pair<int, int>, int> ids;
  triangle_edges.resize(triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto key = std::minmax(triangles[t][static_cast<size_t>(k)], triangles[t][static_cast<size_t>((k + 1) % 3)]);
      auto [it, inserted] = ids.emplace(key, static_cast<int>(edges.size()));
      if (inserted) edges.push_back({key.first, key.second});
      triangle_edges[t][static_cast<size_t>(k)] = it->second;
    }
}

void build_ownership(const std::vector<Triangle>& triangles, int num_points, const std::vector<std::array<int, 3>>& triangle_edges,
                     int num_edges, std::vector<std::vector<int>>& owned_points, std::vector<std::vector<int>>& owned_edges) {
  std::vector<char> point_taken(static_cast<size_t>(num_points), 0), edge_taken(static_cast<size_t>(num_edges), 0);
  owned_points.assign(triangles.size(), {});
  owned_edges.assign(triangles.size(), {});
  for (size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int v = triangles[t][static_cast<size_t>(k)], e = triangle_edges[t][static_cast<size_t>(k)];
      if (!point_taken[static_cast<size_t>(v)]) {
        point_taken[static_cast<size_t>(v)] = 1;
        owned_points[t].push_back(v);
      }
      if (!edge_taken[static_cast<size_t>(e)]) {
        edge_taken[static_cast<size_t>(e)] = 1;
        owned_edges[t].push_back(e);
      }
    }
}

ObstacleSet::ObstacleSet(std::vector<Obstacle>& obstacles) {
  for (size_t k = 0; k < obstacles.size(); ++k) {
    const Obstacle& o = obstacles[k];
    vertex_offset.push_back(static_cast<int>(obstacle_of_vertex.size()));
    if (o.shape == Obstacle::Shape::plane) {
      planes.push_back(static_cast<int>(k));
      continue;
    }
    if (o.mesh.num_triangles() == 0) {
      if (o.shape == Obstacle::Shape::mesh) throw std::invalid_argument("obstacle " + o.name + ": a mesh obstacle needs triangles");
      obstacles[k].mesh = tessellate(o);  // a primitive built in code without its tessellation
    }
    const int offset = vertex_offset.back();
    for (int v = 0; v < o.mesh.num_vertices(); ++v) obstacle_of_vertex.push_back(static_cast<int>(k));
    for (const Triangle& t : o.mesh.triangles) triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
  build_edges(triangles, edges, triangle_edges);
  build_ownership(triangles, static_cast<int>(obstacle_of_vertex.size()), triangle_edges, static_cast<int>(edges.size()),
                  owned_points, owned_edges);

  // An edge between two coplanar triangles (inside a flat face: a box side, a cylinder's cap)
  // makes no pair of its own. The obstacle is rigid, so the face stays flat; a segment's distance
  // to a flat region is attained at one of its end points (point–triangle pairs) or on the
  // region's boundary (its other edges), and so is its first contact when it moves (where it
  // touches the region's inside at an inner point, it lies in the plane and crosses the boundary
  // too). On the Cusick support's cap these edges made two thirds of the constraints.
  std::vector<std::vector<int>> edge_triangles(edges.size());
  for (size_t t = 0; t < triangle_edges.size(); ++t)
    for (int e : triangle_edges[t]) edge_triangles[static_cast<size_t>(e)].push_back(static_cast<int>(t));
  Eigen::MatrixX3d rest(static_cast<Eigen::Index>(obstacle_of_vertex.size()), 3);
  for (size_t k = 0; k < obstacles.size(); ++k)
    if (obstacles[k].shape != Obstacle::Shape::plane)
      rest.middleRows(vertex_offset[k], obstacles[k].mesh.num_vertices()) = obstacles[k].mesh.vertices;
  auto normal = [&](int t) {
    const Triangle& tri = triangles[static_cast<size_t>(t)];
    const Eigen::Vector3d a = rest.row(tri[0]), b = rest.row(tri[1]), c = rest.row(tri[2]);
    return Eigen::Vector3d((b - a).cross(c - a));
  };
  edge_flat.assign(edges.size(), 0);
  edge_tangent.assign(edges.size(), std::numeric_limits<double>::infinity());
  vertex_tangent.assign(obstacle_of_vertex.size(), 0.0);
  for (size_t e = 0; e < edges.size(); ++e) {
    if (edge_triangles[e].size() == 2) {
      const Eigen::Vector3d n1 = normal(edge_triangles[e][0]), n2 = normal(edge_triangles[e][1]);
      edge_flat[e] = n1.dot(n2) > 0 && n1.cross(n2).norm() <= 1e-12 * n1.norm() * n2.norm();
      edge_tangent[e] = std::tan(0.5 * std::atan2(n1.cross(n2).norm(), n1.dot(n2)));
    }
    for (int v : edges[e]) vertex_tangent[static_cast<size_t>(v)] = std::max(vertex_tangent[static_cast<size_t>(v)], edge_tangent[e]);
  }
  for (std::vector<int>& owned : owned_edges)
    owned.erase(std::remove_if(owned.begin(), owned.end(), [&](int e) { return edge_flat[static_cast<size_t>(e)] != 0; }), owned.end());
  vertex_flat.assign(obstacle_of_vertex.size(), 1);
  for (size_t e = 0; e < edges.size(); ++e)
    if (!edge_flat[e])
      for (int v : edges[e]) vertex_flat[static_cast<size_t>(v)] = 0;
}

bool ObstacleSet::redundant_on_flat_face(int t, const std::array<double, 3>& w, const Eigen::Vector3d& normal,
                                         const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) const {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  if (normal.cross(n).norm() <= 1e-9 * n.norm()) return false;
  const auto& tri = triangles[static_cast<size_t>(t)];
  const auto& tri_edges = triangle_edges[static_cast<size_t>(t)];
  int zeros = 0, zero = -1, nonzero = -1;
  for (int k = 0; k < 3; ++k) {
    if (w[static_cast<size_t>(k)] <= 0.0) {
      ++zeros;
      zero = k;
    } else {
      nonzero = k;
    }
  }
  if (zeros == 1) return edge_flat[static_cast<size_t>(tri_edges[static_cast<size_t>((zero + 1) % 3)])] != 0;
  if (zeros == 2) return vertex_flat[static_cast<size_t>(tri[static_cast<size_t>(nonzero)])] != 0;
  return false;
}

}  // namespace clothsim::contact

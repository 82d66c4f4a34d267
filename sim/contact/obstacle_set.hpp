// The obstacles as the contact stage sees them: every obstacle but the planes as one combined
// triangle mesh (vertices numbered obstacle after obstacle), its edges, which triangle owns each
// vertex and edge (so that pairs are made once), and how much the surface bends at each edge:
// edges inside flat faces make no pairs, and nearly flat ones make none near small cloth
// triangles (docs/contact.md, "Flat obstacle edges make no pairs").
#pragma once

#include "sim/contact/obstacle.hpp"
#include "sim/mesh/mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace clothsim::contact {

// The edges of a triangle list (each once, as sorted vertex pairs) and each triangle's three edges
// (edge k joins corners k and k + 1).
void build_edges(const std::vector<Triangle>& triangles, std::vector<std::array<int, 2>>& edges,
                 std::vector<std::array<int, 3>>& triangle_edges);

// Each point and each edge is owned by the first triangle that has it, so that expanding
// triangle pairs into point–triangle and edge–edge pairs makes each pair once.
void build_ownership(const std::vector<Triangle>& triangles, int num_points, const std::vector<std::array<int, 3>>& triangle_edges,
                     int num_edges, std::vector<std::vector<int>>& owned_points, std::vector<std::vector<int>>& owned_edges);

struct ObstacleSet {
  std::vector<Triangle> triangles;                  // combined
  std::vector<std::array<int, 2>> edges;
  std::vector<std::array<int, 3>> triangle_edges;   // per triangle
  std::vector<std::vector<int>> owned_points, owned_edges;  // per triangle; flat edges are not owned
  std::vector<char> edge_flat;     // between two coplanar triangles
  std::vector<char> vertex_flat;   // all of its edges flat (inside a flat face)
  // tan(θ/2) of the angle θ between the normals of an edge's two triangles (infinite for an edge
  // with one or more than two), and per vertex the largest of its edges'.
  std::vector<double> edge_tangent, vertex_tangent;
  std::vector<int> obstacle_of_vertex;  // obstacle index per combined vertex
  std::vector<int> vertex_offset;       // per obstacle: its first combined vertex
  std::vector<int> planes;              // indices of the plane obstacles (not in the mesh)

  ObstacleSet() = default;
  // Combines `obstacles`; a primitive without its tessellation (built in code) gets it here.
  // Throws std::invalid_argument naming a mesh obstacle without triangles.
  explicit ObstacleSet(std::vector<Obstacle>& obstacles);

  // A point's pair with triangle t adds nothing when the point's closest point on it (barycentric
  // weights w of corners a, b, c) lies on a flat edge, or on a vertex inside a flat face, while the
  // point is not over the triangle (the pair's normal is not the triangle's): then it is over a
  // coplanar neighbour (or beyond it), which is at least as close and makes its own pair; at a
  // first contact, that neighbour is touched first or at the same time. (A point right over the
  // shared edge or vertex keeps every pair: all give the same constraint.)
  bool redundant_on_flat_face(int t, const std::array<double, 3>& w, const Eigen::Vector3d& normal, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b, const Eigen::Vector3d& c) const;
};

}  // namespace clothsim::contact

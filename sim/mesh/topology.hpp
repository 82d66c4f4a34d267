// Connectivity of a manifold triangle mesh: ordered vertex one-rings, valence, boundary loops.
// The constructor validates the mesh and throws MeshError naming the offending element for a
// non-manifold edge or vertex, inconsistent orientation, or an isolated vertex.
#pragma once

#include "sim/mesh/mesh.hpp"

#include <vector>

namespace clothsim {

class Topology {
 public:
  Topology(int num_vertices, const std::vector<Triangle>& triangles);

  int num_vertices() const { return static_cast<int>(rings_.size()); }
  // Neighbours of v in counter-clockwise order (following the triangles' orientation: in a
  // triangle (v, a, b), b comes after a). For a boundary vertex the ring starts at the
  // neighbour across the boundary edge that leaves v and ends at the one across the boundary
  // edge that enters v, so ring(v).size() == number of incident triangles + 1.
  const std::vector<int>& ring(int v) const { return rings_[v]; }
  int valence(int v) const { return static_cast<int>(rings_[v].size()); }
  bool is_boundary(int v) const { return boundary_[v]; }
  int num_incident_triangles(int v) const {
    return boundary_[v] ? valence(v) - 1 : valence(v);
  }
  // The third vertex of the triangle that contains the directed edge a→b, or -1.
  int opposite(int a, int b) const;
  // Boundary loops, each listed in the direction of the boundary edges (a→b is a triangle edge
  // whose twin b→a does not exist).
  const std::vector<std::vector<int>>& boundary_loops() const { return loops_; }
  // Ring of v rotated so that it starts at neighbour `first` (which must be in the ring).
  std::vector<int> ring_from(int v, int first) const;

 private:
  std::vector<std::vector<int>> rings_;
  std::vector<bool> boundary_;
  std::vector<std::vector<int>> loops_;
  // For each vertex a: sorted (b, c) pairs of triangles (a, b, c).
  std::vector<std::vector<std::pair<int, int>>> next_;
};

}  // namespace clothsim

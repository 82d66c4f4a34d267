// The ghost-vertex layer at borders (paper §4.4; Cirak et al. 2000 §4.4; docs/formulas.md §4,
// Borders).
//
// Outside each border edge (a, b) of the triangle (a, b, c) sits one ghost vertex g with rest
// position x_g = x_a + x_b − x_c (the free-edge rule), joined by the ghost triangle (b, a, g);
// at each border vertex v one more ghost triangle (v, g_in, g_out) closes v's one-ring. In the
// extended mesh every real vertex has a closed one-ring, so every real triangle is a complete
// subdivision patch; a border vertex with k real triangles gets valence k + 3 (6 on a straight
// border of a regular mesh). Ghost positions and displacements are linear combinations of real
// vertices (see DofMap), so no unknowns are added.
#pragma once

#include "sim/mesh/mesh.hpp"
#include "sim/mesh/topology.hpp"

#include <array>
#include <vector>

namespace clothsim {

struct GhostVertex {
  int a, b;  // the border edge a → b (direction of the real triangle (a, b, c))
  int c;     // the real vertex opposite the edge
};

struct ExtendedMesh {
  int num_real = 0;                 // real vertices keep their ids 0 .. num_real − 1
  std::vector<GhostVertex> ghosts;  // ghost k has id num_real + k
  std::vector<Triangle> triangles;  // real triangles first, then ghost triangles
  int num_real_triangles = 0;
  Topology topology;                // of the extended mesh
  Eigen::MatrixX3d rest;            // rest positions of real and ghost vertices [m]

  int num_vertices() const { return num_real + static_cast<int>(ghosts.size()); }
};

// Builds the ghost layer around every border loop. Throws MeshError (naming the vertex) when a
// real vertex ends up with valence above 12.
ExtendedMesh build_ghost_layer(const TriMesh& mesh);

// Count of vertices of the triangle that are irregular (valence ≠ 6) in the extended mesh.
int irregular_vertex_count(const ExtendedMesh& ext, const Triangle& tri);

}  // namespace clothsim

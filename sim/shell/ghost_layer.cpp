#include "sim/shell/ghost_layer.hpp"

#include <string>

namespace clothsim {

namespace {

Topology make_extended(const TriMesh& mesh, std::vector<GhostVertex>& ghosts, std::vector<Triangle>& triangles) {
  const Topology real(mesh.num_vertices(), mesh.triangles);
  const int n = mesh.num_vertices();
  triangles = mesh.triangles;
  std::vector<int> ghost_of_out_edge(n, -1);  // border edge v → ring(v).front()
  for (const std::vector<int>& loop : real.boundary_loops())
    for (size_t i = 0; i < loop.size(); ++i) {
      const int a = loop[i], b = loop[(i + 1) % loop.size()];
      const int g = n + static_cast<int>(ghosts.size());
      ghosts.push_back({a, b, real.opposite(a, b)});
      ghost_of_out_edge[a] = g;
      triangles.push_back({b, a, g});
    }
  for (const std::vector<int>& loop : real.boundary_loops())
    for (size_t i = 0; i < loop.size(); ++i) {
      const int v = loop[i], prev = loop[(i + loop.size() - 1) % loop.size()];
      triangles.push_back({v, ghost_of_out_edge[prev], ghost_of_out_edge[v]});
    }
  return Topology(n + static_cast<int>(ghosts.size()), triangles);
}

}  // namespace

ExtendedMesh build_ghost_layer(const TriMesh& mesh) {
  std::vector<GhostVertex> ghosts;
  std::vector<Triangle> triangles;
  Topology top = make_extended(mesh, ghosts, triangles);
  ExtendedMesh ext{mesh.num_vertices(), std::move(ghosts), std::move(triangles), mesh.num_triangles(), std::move(top), {}};
  ext.rest.resize(ext.num_vertices(), 3);
  ext.rest.topRows(ext.num_real) = mesh.vertices;
  for (size_t k = 0; k < ext.ghosts.size(); ++k) {
    const GhostVertex& g = ext.ghosts[k];
    ext.rest.row(ext.num_real + static_cast<Eigen::Index>(k)) =
        mesh.vertices.row(g.a) + mesh.vertices.row(g.b) - mesh.vertices.row(g.c);
  }
  for (int v = 0; v < ext.num_real; ++v)
    if (ext.topology.valence(v) > 12)
      throw MeshError("vertex " + std::to_string(v) + " has valence " + std::to_string(ext.topology.valence(v)) +
                      " (border vertices count 3 more for the ghost layer); the subdivision element supports "
                      "valences up to 12");
  return ext;
}

int irregular_vertex_count(const ExtendedMesh& ext, const Triangle& tri) {
  int count = 0;
  for (int v : tri)
    if (ext.topology.valence(v) != 6) ++count;
  return count;
}

}  // namespace clothsim

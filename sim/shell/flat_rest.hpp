// A flat rest state from a layout in the plane (docs/pattern.md, "The rest state"): cloth is woven
// flat, so a garment sewn from pattern pieces rests flat everywhere, across its seams too, although
// no single flat embedding of the whole garment exists (a tube cannot be laid flat). What each
// element needs is only its own patch at rest: its control vertices (N + 6 of them, reaching into
// the neighbouring pieces at a seam) laid out in a plane with the pattern's lengths.
//
// The layout comes from the mesh's texture coordinates in metres (TriMesh::uv, per triangle
// corner: the pattern coordinates of that corner in its own piece, so a seam vertex has one per
// piece). Starting from the element's own triangle at its pattern coordinates, triangles are added
// across edges: each new triangle is moved rigidly in the plane (turned and shifted, mirrored if
// its uv run clockwise) so that its shared edge matches the edge already laid out (at the edge's
// midpoint and along its direction), which places its third vertex. Inside a piece every step is
// the identity (the coordinates agree); across a straight seam the pieces meet edge to edge;
// where pieces meet at a point whose pattern angles do not add up to a full turn, a vertex
// reached along several paths gets the mean of its placements (a least-squares compromise).
// Ghost vertices (ghost_layer.hpp) follow the free-edge rule x_g = x_a + x_b − x_c on the layout.
#pragma once

#include "sim/mesh/mesh.hpp"
#include "sim/shell/ghost_layer.hpp"

#include <Eigen/Core>

#include <vector>

namespace clothsim {

// Where the elements' rest state comes from (the scene key "rest"): the mesh's positions as
// given ("initial"), or flat, laid out from the texture coordinates in metres ("pattern").
enum class RestShape { initial, pattern };

// The flat layouts of the patches of one mesh.
class FlatRestLayout {
 public:
  // Throws MeshError when the mesh has no texture coordinates (or not one triplet per triangle),
  // or a triangle's texture coordinates are degenerate (zero area), naming the triangle.
  FlatRestLayout(const TriMesh& mesh, const ExtendedMesh& ext);

  // Rest positions (#patch × 3, z = 0) of the extended-mesh vertices `patch` of real triangle
  // `triangle`'s element, laid out as above with the triangle at its own texture coordinates.
  // Throws MeshError naming the triangle when a patch vertex cannot be reached across edges.
  Eigen::MatrixX3d patch(int triangle, const std::vector<int>& patch) const;

  // The 2D direction in the element's layout (z = 0) of a 3D direction `d` given on triangle
  // `triangle` at the mesh's positions (TriMesh::vertices): d mapped back through the triangle's
  // uv → xyz map (least squares), normalised. Used to carry the warp into the layout.
  Eigen::Vector3d to_layout(int triangle, const Eigen::Vector3d& d) const;

  // Rest area of each real triangle from its texture coordinates [m²].
  double area(int triangle) const;

 private:
  const TriMesh& mesh_;
  const ExtendedMesh& ext_;
  std::vector<std::vector<int>> vertex_triangles_;  // real triangles incident to each real vertex
  std::vector<char> mirrored_;                       // per triangle: its uv run clockwise
};

// Lumped mass per vertex [kg] from the texture-coordinate areas (a third of each incident
// triangle's uv area times `areal_density`).
Eigen::VectorXd lumped_vertex_mass_uv(const TriMesh& mesh, double areal_density);

}  // namespace clothsim

// The grain (warp direction) of a woven material per triangle of a control mesh
// (docs/materials.md, Grain; scenes/README.md, material.grain). Each function returns one unit
// 3-vector per triangle of `mesh` (TriMesh::warp), rotated by `warp_deg` [deg] from its
// reference direction.
#pragma once

#include "sim/mesh/mesh.hpp"

#include <Eigen/Core>

#include <vector>

namespace clothsim {

// A flat grid in the z = 0 plane (make_grid): (cos φ, sin φ, 0), φ = warp_deg from +x towards +y.
std::vector<Eigen::Vector3d> grid_warp(const TriMesh& mesh, double warp_deg);

// A cylinder or cylindrical panel about the y axis (make_cylinder, make_cylinder_panel):
// cos φ ŷ + sin φ t̂ with t̂ = ŷ × r̂ the circumferential direction (that of increasing θ of
// make_cylinder, φ of make_cylinder_panel) at the triangle's centroid, r̂ its radial direction:
// 0 is along the axis, 90 around the circumference.
std::vector<Eigen::Vector3d> cylinder_warp(const TriMesh& mesh, double warp_deg);

// From texture coordinates (TriMesh::uv): the +u direction turned by φ = warp_deg towards +v,
// mapped through each triangle's uv → xyz Jacobian J (the linear map taking the uv edges to the
// xyz edges): J (cos φ, sin φ), normalised. Throws MeshError naming the triangle when the mesh has
// no texture coordinates or a triangle's uv are degenerate (zero uv area).
std::vector<Eigen::Vector3d> uv_warp(const TriMesh& mesh, double warp_deg);

}  // namespace clothsim

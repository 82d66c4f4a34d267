// Part of a triangle mesh cut out by planes: for splitting one mesh into pieces that move
// separately (a body's arms and torso as obstacles with their own motions, scenes/README.md,
// obstacles[i].keep / cut).
#pragma once

#include "sim/mesh/mesh.hpp"

#include <Eigen/Core>

#include <vector>

namespace clothsim {

// The closed half-space {x : (x − point)·normal >= 0} [m].
struct HalfSpace {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();  // need not be unit; must be non-zero
};

// The triangles of `mesh` whose centroid lies in every half-space of `keep` and in no region of
// `cut` (a region: the intersection of its half-spaces), with the vertices no kept triangle uses
// dropped (the others renumbered in order; per-triangle warp and uv kept with their triangles).
// Two parts made with complementary selections (one keeps a region, the other cuts it) share no
// triangle and together hold every triangle. Throws std::invalid_argument for a zero normal.
TriMesh mesh_part(const TriMesh& mesh, const std::vector<HalfSpace>& keep,
                  const std::vector<std::vector<HalfSpace>>& cut);

}  // namespace clothsim

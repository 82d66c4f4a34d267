// The limit surface refined for display (paper §7: "the geometry can be locally evaluated and
// refined to the desired degree"): k Loop steps of the control mesh (with its ghost layer), then
// the limit position and tangent masks, composed once into sparse operators. Each frame is then
// three sparse matrix products: positions P·x and tangents T₁·x, T₂·x (normal = T₁x × T₂x).
#pragma once

#include "sim/mesh/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace clothsim {

struct LimitRefinement {
  Eigen::SparseMatrix<double, Eigen::RowMajor> position;  // #fine × #control
  Eigen::SparseMatrix<double, Eigen::RowMajor> tangent1;  // #fine × #control
  Eigen::SparseMatrix<double, Eigen::RowMajor> tangent2;  // #fine × #control
  std::vector<Triangle> triangles;  // fine triangles over the fine vertices (rows above)
  // Fine triangle i descends from control triangle i / 4^levels.
  int levels = 0;
};

// `control`: positions (#C × 3) and triangles of a mesh in which every vertex of the first
// `num_output_triangles` triangles has a closed one-ring (e.g. an ExtendedMesh: real triangles
// first, then the ghost layer). Only those triangles are refined into the output; `levels` >= 0.
LimitRefinement build_limit_refinement(const Eigen::MatrixX3d& control, const std::vector<Triangle>& triangles,
                                       int num_output_triangles, int levels);

// Limit positions (#fine × 3) and unit normals (#fine × 3) of the surface with control positions x.
void evaluate_limit(const LimitRefinement& refinement, const Eigen::MatrixX3d& x, Eigen::MatrixX3d& positions,
                    Eigen::MatrixX3d& normals);

}  // namespace clothsim

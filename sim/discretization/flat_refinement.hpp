// The flat triangles of a mesh refined for display by midpoint subdivision, as a display
// SurfaceOperator over the mesh's vertices: the flat methods' own surface
// (FlatDiscretization::display) and loop_kl's control mesh drawn flat ("render.surface": "flat").
#pragma once

#include "sim/discretization/discretization.hpp"

namespace clothsim {

// `mesh`'s triangles refined `levels` (>= 0) times by midpoint subdivision with loop_kl's
// conventions (sim/subdivision/limit_refinement.hpp): each step splits triangle (a, b, c) into
// the corner triangles of a, b, c and the middle one, in that order, so triangle i has the fine
// triangles [i·4^levels, (i + 1)·4^levels) and the children of triangle t are 4t … 4t + 3; one
// point per position (shared by the fine triangles around it), numbered in order of first use by
// the triangles. The points lie on the flat triangles. Tangents: a point takes the two edge
// vectors (b − a, c − a) of the first mesh triangle it lies on, so its normal is that facet's
// normal (flat shading; points on a mesh edge or vertex show one neighbour's facet). The
// operator's columns are the mesh's vertices followed by `num_columns` − #vertices unused ones
// (a control net that has more points than the mesh, e.g. loop_kl's ghost layer);
// `num_columns` >= #vertices. Throws std::invalid_argument for levels < 0.
SurfaceOperator midpoint_display(const TriMesh& mesh, int levels, Eigen::Index num_columns);

}  // namespace clothsim

// Basis functions of one subdivision element (paper §4.1–4.2, eqs. 22, 23 and 27).
//
// A regular element (three interior vertices of valence 6) is a quartic box-spline patch over
// 12 control vertices. An element with one irregular vertex (valence N ≠ 6) has N + 6 control
// vertices; it is evaluated by Loop-subdividing its patch locally (the subdivision matrix S),
// selecting the sub-triangle that contains the point (the selection P) and repeating until the
// sub-triangle is regular (Stam 1998). Each level halves the parameter domain, so first
// derivatives scale by 2 and second derivatives by 4 per level (folded in through the affine
// map of each sub-triangle).
#pragma once

#include "sim/mesh/topology.hpp"
#include "sim/subdivision/box_spline.hpp"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace clothsim {

struct PatchEvaluation {
  std::vector<int> vertices;                       // the patch's control vertices (mesh ids)
  Eigen::Matrix<double, 6, Eigen::Dynamic> basis;  // rows: BasisRow; one column per vertex
};

// True when all three vertices of `tri` are interior with valence 6.
bool is_regular(const Topology& top, const Triangle& tri);

// The 12 control vertices of a regular element in the layout of box_spline.hpp
// (index i holds vertex i + 1; tri = (4, 7, 8)).
std::array<int, 12> regular_patch(const Topology& top, const Triangle& tri);

// Basis of element `tri` = (a, b, c) at the parameter point (v, w): point = u·a + v·b + w·c
// in the element's barycentric parameters, u = 1 − v − w. The three vertices must be interior
// (closed one-rings) and at most one of them irregular. The point must not be the irregular
// vertex itself (use the limit masks there); throws std::invalid_argument otherwise.
// `min_levels` forces that many local subdivision steps even on regular elements (for tests:
// the subdivided evaluation must equal the direct one).
PatchEvaluation evaluate_patch(const Topology& top, const Triangle& tri, double v, double w, int min_levels = 0);

}  // namespace clothsim

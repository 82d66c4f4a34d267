// Internal to sim/pattern (not part of its interface): the planar geometry of one pattern piece —
// the simple-polygon check of an outline, the grain-aligned interior lattice, and the constrained
// Delaunay triangulation of a boundary loop with interior points (CGAL, in piece_mesh.cpp only).
#pragma once

#include "sim/mesh/mesh.hpp"

#include <Eigen/Core>

#include <vector>

namespace clothsim::pattern_detail {

// The first thing wrong with a closed polygon, in this order of kinds. Indices: `i` and `j` are
// points for not_finite and repeated_point, edges (edge k from point k to point k + 1) for
// zero_edge, crossing and overlap; the pair (i, j), i < j, is the lexicographically smallest one.
struct PolygonDefect {
  enum class Kind { none, too_few_points, not_finite, zero_edge, repeated_point, crossing, overlap, clockwise };
  Kind kind = Kind::none;
  int i = -1;
  int j = -1;
  double signed_area = 0.0;  // [m²], positive when counter-clockwise
};

// Checks that the polygon has at least 3 finite points, no zero-length edge, no repeated point, no
// two edges that cross or touch (other than neighbours at their shared point) or that overlap,
// and a positive signed area. Predicates are exact (CGAL's filtered kernel).
PolygonDefect find_polygon_defect(const std::vector<Eigen::Vector2d>& points);

// Shoelace signed area [m²] of a closed polygon.
double signed_area(const std::vector<Eigen::Vector2d>& points);

// The points of the triangular lattice origin + spacing·(i u + j v), u = (cos a, sin a),
// v = (cos(a + 60°), sin(a + 60°)), a = angle_deg, that lie inside the simple polygon `loop` and
// farther than `clearance` from every edge of it, in order of j, then i.
std::vector<Eigen::Vector2d> interior_lattice(const std::vector<Eigen::Vector2d>& loop, double spacing,
                                              double angle_deg, const Eigen::Vector2d& origin, double clearance);

// Constrained Delaunay triangulation of the simple counter-clockwise polygon formed by the first
// `num_boundary` points (its edges are the constraints) with the remaining points, all strictly
// inside it, as extra vertices; returns the triangles inside the polygon (indices into `points`,
// counter-clockwise), each rotated so its smallest index comes first, sorted. No point is added:
// throws MeshError (without the "pattern:" prefix; the caller adds the piece) if CGAL would add
// one, reports intersecting constraints, or the triangle count is not the one of a triangulated
// polygon (boundary + 2·interior − 2).
std::vector<Triangle> triangulate_polygon(const std::vector<Eigen::Vector2d>& points, int num_boundary);

}  // namespace clothsim::pattern_detail

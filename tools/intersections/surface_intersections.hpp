// Independent intersection check for triangle surfaces: does a surface intersect itself, or
// another triangle mesh? It is a verification tool, written apart from the simulator's collision
// code (sim/contact/) and sharing nothing with it, so that it can judge that code's results.
//
// Exactness. Every answer comes from exact geometric predicates (CGAL's
// Exact_predicates_inexact_constructions_kernel, whose predicates are exact for double input):
// vertex coordinates are used as given, nothing is constructed or rounded, and "touching"
// (a shared point, a vertex on a face, an edge crossing an edge, coplanar overlap) counts as
// intersecting. The broad phase (CGAL's box_intersection_d on each triangle's exact bounding box,
// closed boxes) only discards pairs whose boxes are disjoint, which never intersect.
//
// Degenerate triangles. A triangle whose corners are collinear (zero area) is tested as what it
// is geometrically: the segment between its two extreme corners, or a point if all three corners
// coincide. It therefore counts as intersecting exactly when that segment or point meets the
// other element; it never crashes or trips CGAL's non-degeneracy preconditions.
//
// Limitations.
//  - Self test: pairs of triangles that share one or more vertices (by index) are skipped
//    entirely, even if they also meet elsewhere. So a fold that collapses a vertex's one-ring
//    (two triangles around one vertex passing through each other), or a triangle folded onto its
//    edge-neighbour, is not seen. Only pairs with no common vertex index are tested.
//  - Sharing is by index only: two distinct vertices at the same position (e.g. an unwelded
//    seam) are not "shared", so the triangles around them are reported as touching.
//  - Touching counts, with no tolerance: a cloth resting exactly on an obstacle (distance 0)
//    is reported; any positive gap, however small, is not. The check says nothing about how
//    close surfaces come, only whether they meet.
//  - It is a static check of one configuration: it cannot see a surface that passed through
//    itself and back between two saved frames.
//
// Input checking: a triangle index outside [0, vertex count) or a non-finite coordinate in a
// vertex used by a triangle throws std::invalid_argument (unused vertices are not inspected).
//
// Cost: about 0.2-0.4 s for the self test of an 80k-triangle crumpled sheet (one core), more
// where many layers stack within each other's boxes (8.5 M exact tests: about 0.7 s).
//
// Output is deterministic: counts do not depend on traversal order, and `examples` holds the
// lexicographically smallest intersecting pairs.
#pragma once

#include <array>
#include <cstddef>
#include <utility>
#include <vector>

namespace clothsim::check {

struct Surface {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::array<int, 3>> triangles;  // 0-based vertex indices
};

struct IntersectionReport {
  long long pairs_tested = 0;        // exact tests done (after the box filter)
  long long intersecting_pairs = 0;  // pairs that intersect
  // Up to max_examples intersecting (triangle, triangle) pairs: the smallest in lexicographic
  // order, sorted. Self test: (i, j) with i < j. Two surfaces: (triangle of a, triangle of b).
  std::vector<std::pair<int, int>> examples;
  int triangles_involved = 0;  // distinct triangles of the first surface in some intersecting pair
};

inline constexpr std::size_t max_examples = 20;

// Self-intersections: pairs of triangles that share NO vertex (by index) and intersect
// (touching counts).
IntersectionReport self_intersections(const Surface& s);

// Intersections between the triangles of a and those of b (all pairs).
IntersectionReport intersections(const Surface& a, const Surface& b);

// How close a comes to b: the smallest distance from a vertex of a (one used by a triangle) to a
// triangle of b (degenerate triangles of b are skipped), computed in floating point (CGAL's AABB
// tree; not an exact predicate, a measurement). Vertex to face only: two edges crossing closer
// than that are not seen. +infinity when b has no proper triangle. Together with "no
// intersection", a positive value for a cloth that starts outside a closed obstacle says by how
// much the cloth stayed out of it.
double closest_vertex_distance(const Surface& a, const Surface& b);

}  // namespace clothsim::check

// The contact stage's candidate search (broad phase): from the collision surface's points at the
// start and end of a step, and the obstacles' vertices, the point–triangle and edge–edge pairs
// that can come within a distance (the growth) of each other over the step, each pair once, in
// an order that depends only on the inputs (docs/contact.md has why each cull is safe).
//
// How: swept boxes of the points (start to end of the step); a box hierarchy over the refinement
// (fine triangles up to their patches, the surface triangles of the discretisation) built in one
// pass with the patches' normal cones; self pairs of patches from Embree (sim/contact/
// broad_phase.hpp) less those in one flat region ("Flat regions"), down the hierarchy to pairs of
// fine triangles, which stand for the pairs of the points and edges they own (patches that are
// neighbours in the material, and fine triangles near each other at rest, make near pairs with
// boxes grown by the near separation only; pairs joined at rest make none); and pairs of patches
// with obstacle triangles, down to the fine triangles, less the obstacle edges and vertices that
// bend the obstacle too little to matter near a fine triangle ("Flat obstacle edges make no
// pairs").
#pragma once

#include "sim/contact/broad_phase.hpp"
#include "sim/contact/obstacle_set.hpp"
#include "sim/contact/pair_types.hpp"
#include "sim/core/contact_counters.hpp"
#include "sim/mesh/mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <utility>
#include <vector>

namespace clothsim::contact {

// The box of triangle t's corners at positions a and at positions b (rows: points) [m], grown by
// `grow` [m] on every side: the triangle's swept box over a linear motion from a to b.
Box swept_box(const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b, const std::array<int, 3>& t, double grow);

// Whether two triangles have a vertex in common.
bool shares_vertex(const std::array<int, 3>& a, const std::array<int, 3>& b);

// The collision surface as the search reads it; fixed for a run. Everything is referenced, so it
// must outlive the search.
struct SearchSurface {
  // The fine triangles (the display operator's): triangle i lies over patch i / 4^levels, and a
  // triangle t of one refinement level has the children 4t … 4t + 3 on the next
  // (sim/discretization/flat_refinement.hpp).
  const std::vector<Triangle>& triangles;
  int levels = 0;
  // The fine edges, each triangle's three edges, and the points and edges each triangle owns
  // (build_edges and build_ownership, sim/contact/obstacle_set.hpp).
  const std::vector<std::array<int, 2>>& edges;
  const std::vector<std::array<int, 3>>& triangle_edges;
  const std::vector<std::vector<int>>& owned_points;
  const std::vector<std::vector<int>>& owned_edges;
  // The surface triangle under each patch, as control nodes 0 … num_nodes − 1 (the first
  // triangles.size() / 4^levels are read: the discretisation's control triangles).
  const std::vector<Triangle>& patch_corners;
  int num_nodes = 0;
};

struct CandidateSettings {
  bool self = false;                     // pairs of the surface with itself
  double thickness = 1e-3;               // [m]
  // Patch pairs in one region whose normals stay within a cone of this half-angle [rad] over the
  // step are not tested (CollisionSettings::flat_region_angle); 0 tests every pair.
  double flat_region_angle = 0.0;
  double min_separation_ratio = 0.1;     // the CCD's minimum separation / thickness (ContactParameters)
  double near_separation_ratio = 0.01;   // the near pairs' separation / thickness (ContactParameters)
};

class CandidateSearch {
 public:
  // `near_at_rest` and `joined_at_rest`: per fine triangle a, the sorted fine triangles b > a
  // near it at rest, and those among them that touch it at rest without being neighbours in the
  // material (empty, or one list per fine triangle; only read with self-collision). The surface
  // and the obstacles are referenced and must outlive the search.
  CandidateSearch(const SearchSurface& surface, std::vector<std::vector<int>> near_at_rest,
                  std::vector<std::vector<int>> joined_at_rest, const ObstacleSet& obstacles, const CandidateSettings& settings);

  // The candidate pairs of the motion of the surface points from p0 to p1 (#P × 3 each) [m] and
  // of the obstacles' vertices from o0 to o1 (ObstacleSet's numbering, #V × 3 each; not read
  // when the obstacle set has no triangles) [m], with boxes grown by `grow` [m] (> 0; the
  // thickness, or more for candidates that are to serve nearby motions too):
  //  - self-collision: the points and edges owned by fine triangles of patches whose grown boxes
  //    overlap, with the fine triangles of the other patch, where their swept boxes grown by
  //    `grow` (a point) or by half of it each (two edges) overlap; between neighbour patches
  //    (a control vertex in common) and fine triangles near each other at rest the growth is the
  //    near separation instead, and the pair is marked `near`; fine triangles joined at rest, a
  //    point with a triangle that has it as a corner and edges with an end in common make no
  //    pairs; nor do patches in one flat region;
  //  - obstacles: patches whose swept boxes grown by `grow` overlap an obstacle triangle's swept
  //    box (not grown), then the patch's fine triangles whose boxes grown by `grow` overlap it: their owned points with the obstacle triangle and the obstacle vertices it
  //    owns with the fine triangle (points grown by `grow`), and their owned edges with its owned
  //    edges (each grown by half of `grow`), less the obstacle edges and vertices that bend the
  //    obstacle too little for the fine triangle (or edge) at hand.
  // Self pairs come first, then obstacle pairs, each in the order of the sorted broad-phase
  // pairs. `obstacle_boxes_valid`: o0 and o1 are those of the last call, whose obstacle boxes are
  // kept (false: they are made anew). Adds its time to report.broad_ms.
  std::vector<Candidate> find(const Eigen::MatrixX3d& p0, const Eigen::MatrixX3d& p1, const Eigen::MatrixX3d& o0,
                              const Eigen::MatrixX3d& o1, bool obstacle_boxes_valid, double grow, ContactCounters& report);

 private:
  using RowPoints = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  struct FlatRegions;

  FlatRegions flat_regions(const std::vector<Eigen::Vector3d>& axis, const std::vector<double>& angle) const;
  std::pair<Eigen::Vector3d, double> patch_cone(int q, const RowPoints& r0, const RowPoints& r1,
                                                std::vector<Eigen::Vector3d>& normals) const;
  int control_edge(int u, int w) const;
  void measure_smooth_tangents(const Eigen::MatrixX3d& p0, const Eigen::MatrixX3d& p1);

  SearchSurface surface_;
  const ObstacleSet& obs_;
  CandidateSettings settings_;

  // Patches: the fine triangles over one surface triangle of the discretisation. The search works
  // on patches, then down a box hierarchy to the fine triangles. Fine triangles of one patch never
  // collide with each other (one smooth polynomial piece), nor do fine triangles closer than twice
  // the thickness at rest (near_at_rest): they are neighbours in the material, which the shell
  // keeps apart by itself, and colliding them would hold the fine surface's neighbours apart when
  // it is compressed in its plane.
  int fine_per_patch_ = 1;
  int num_patches_ = 0;
  std::vector<std::array<int, 3>> patch_corners_;   // the surface triangle under each patch
  std::vector<std::vector<int>> near_at_rest_;      // per fine triangle a: the sorted b > a near it at rest
  // Per fine triangle a: the sorted b > a that touch it at rest (closer than the near separation)
  // without being neighbours in the material (their patches share no control vertex): a surface
  // that meets itself at rest, such as a panel rolled to 359.9999999999°. Such pairs start
  // colliding and could never be separated, so they make no pairs at all: the cloth is taken to be
  // joined there (ContactStage::joined_at_rest reports how many).
  std::vector<std::vector<int>> joined_at_rest_;
  std::vector<std::vector<int>> vertex_patches_;    // per control node: the patches that have it as a corner
  std::vector<std::vector<std::pair<int, int>>> control_edges_;  // per control node: (neighbour, edge id)
  size_t num_control_edges_ = 0;

  BroadPhase self_broad_, obstacle_broad_;

  // Scratch, kept for its memory.
  RowPoints rows0_, rows1_;
  std::vector<Box> scratch_point_box_;
  std::vector<std::vector<Box>> scratch_hierarchy_;
  std::vector<Eigen::Vector3d> cone_axis_;
  std::vector<double> cone_angle_;

  // The obstacles' boxes swept over the step (exact: grown where used), made when a call's
  // obstacle_boxes_valid is false (once per step, once per run for static obstacles).
  std::vector<Box> obstacle_boxes_, obstacle_point_box_, obstacle_edge_box_;

  // Obstacle edges and vertices that bend the obstacle's surface little make no pairs with a
  // cloth triangle (obstacle vertex–cloth triangle) or a cloth edge (cloth edge–obstacle edge)
  // near them: the cloth points' pairs with the obstacle's triangles keep them clear. A flat
  // piece of the cloth surface (a fine triangle, its longest edge L) whose corners are at least a
  // distance s from both triangles of an obstacle edge that bends by θ comes no closer to the
  // edge than s − (L / 2) tan(θ / 2), where it lies across the edge; with (L / 2) tan(θ / 2) at
  // most half the CCD's minimum separation η, corners kept η away keep the edge η / 2 away. So on
  // a finely tessellated smooth obstacle (a capsule at 5°) most of its edges and vertices need no
  // pairs. smooth_tangent holds, per fine triangle (and per fine edge: the smaller of its
  // triangles', i.e. that of the larger triangle), the largest tan(θ / 2) that allows, with L measured at the start and end of the
  // step (so it follows stretching).
  std::vector<double> smooth_tangent_triangle_, smooth_tangent_edge_;
};

}  // namespace clothsim::contact

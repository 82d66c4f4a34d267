// Sewing patterns → one control mesh: flat pattern pieces (2D outlines in metres), each placed in
// 3D (optionally wrapped around a cylinder, rotated, translated), sewn edge to edge by seams, are
// meshed into a single manifold triangle mesh fit for the Loop-subdivision shell (every triangle
// has at most one irregular vertex). The method, the conventions and the errors: docs/pattern.md.
#pragma once

#include "sim/mesh/mesh.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace clothsim {

// Where a piece goes in 3D. A pattern point (x, y) [m] is first mapped to
//   (R sin(x/R), y, R cos(x/R))   when wrap_radius = R is set (a cylinder about the y axis; the
//                                 piece's +z side faces away from the axis), else
//   (x, y, 0),
// then rotated by rotate_deg [deg]: about the world x axis, then about the world y axis, then
// about the world z axis (fixed axes, in that order: R = Rz·Ry·Rx), then translated [m].
struct PatternPlacement {
  std::optional<double> wrap_radius;                        // [m], > 0 when set
  Eigen::Vector3d rotate_deg = Eigen::Vector3d::Zero();     // [deg]
  Eigen::Vector3d translate = Eigen::Vector3d::Zero();      // [m]
};

// One flat piece of cloth. `points` is its outline, counter-clockwise seen from +z, in metres;
// edge i runs from point i to point i + 1 (the last edge back to point 0). The outline must be a
// simple polygon (no crossing, no repeated point). `grain_deg` is the warp direction [deg] from
// the pattern's +x axis towards +y.
struct PatternPiece {
  std::string name;
  std::vector<Eigen::Vector2d> points;
  double grain_deg = 0.0;
  PatternPlacement placement;
};

// One side of a seam: the path of consecutive edges first_edge, first_edge + 1, ..., last_edge of
// a piece (first == last for a single edge; the path may wrap past the last point, e.g. 3..0 of a
// four-point piece). It runs in the piece's counter-clockwise direction, from point first_edge to
// point last_edge + 1.
struct SeamSide {
  std::string piece;
  int first_edge = 0;
  int last_edge = 0;
};

// Sews side a to side b. Along the seam, a's start joins b's start and a's end b's end, unless
// `reversed`, in which case a's start joins b's end: the usual case (two pieces seen from the
// same side run along a shared seam in opposite directions; without it the surface would flip).
struct Seam {
  SeamSide a, b;
  bool reversed = false;
};

struct PatternSpec {
  double edge_length = 0.0;  // the target edge length of the control mesh [m]
  std::vector<PatternPiece> pieces;
  std::vector<Seam> seams;
};

struct PatternMesh {
  // The merged control mesh:
  //  - vertices: start positions, the placement of each pattern point; a vertex merged by seams
  //    gets the mean of its placed positions;
  //  - triangles: counter-clockwise as the piece's +z side maps through its placement;
  //  - uv: per triangle corner, the pattern coordinates [m] of that corner in its own piece (a
  //    seam vertex has different uv in the two pieces' triangles);
  //  - warp: per triangle, the unit grain direction in 3D: the piece's (cos g, sin g) mapped
  //    through the triangle's pattern → start Jacobian (as uv_warp does).
  TriMesh mesh;
  std::vector<int> triangle_piece;  // the piece index of every triangle
  // [piece][edge]: the merged vertex ids along edge i from point i to point i + 1, both corners
  // included. An edge inside a multi-edge seam path whose inner corners were resampled away runs
  // between the path vertices nearest (by arc length) to its corners (docs/pattern.md).
  std::vector<std::vector<std::vector<int>>> edge_vertices;
  // Per merged vertex: the placed positions [m] of every piece vertex merged into it (one entry
  // for a vertex no seam touches), in a fixed order.
  std::vector<std::vector<Eigen::Vector3d>> placed;
  // Per seam: the largest distance [m] between the placed positions it joins.
  std::vector<double> seam_gap;
};

// Meshes the pattern (docs/pattern.md): boundary points every ~2·edge_length, a grain-aligned
// triangular lattice inside, a constrained Delaunay triangulation per piece, seams merged, then
// every triangle split 1 → 4, so that control edges are about edge_length long and irregular
// vertices are isolated. Deterministic (the same spec gives the same mesh, bit for bit).
// Throws MeshError, whose message starts with "pattern: " and names the piece, edge and seam,
// for an invalid spec (see docs/pattern.md, Errors), and MeshLimitError when the mesh would have
// more than kDefaultMaxVertices vertices.
PatternMesh build_pattern(const PatternSpec& spec);

}  // namespace clothsim

// Procedural control meshes for test scenes: a flat rectangular cloth and an open cylindrical
// sleeve, both regular (every interior vertex has valence 6).
#pragma once

#include "sim/mesh/mesh.hpp"

namespace clothsim {

// Rectangle of size_x × size_y [m] in the z = 0 plane, centred at the origin, with
// (divisions_x + 1) × (divisions_y + 1) vertices. Vertex (i, j) — i along x, j along y — has
// index j·(divisions_x + 1) + i. Every cell is split along its (i, j)–(i+1, j+1) diagonal into
// two triangles, counter-clockwise seen from +z (normals point to +z).
// Throws std::invalid_argument for a non-positive or non-finite size or a division count < 1.
TriMesh make_grid(double size_x, double size_y, int divisions_x, int divisions_y);

// Open cylinder ("sleeve") of the given radius [m] whose axis is the y axis, from y = 0 to
// y = length [m]: `rings` circles of `segments` vertices each, no duplicated seam vertex, so
// segments·rings vertices and 2·segments·(rings − 1) triangles. Vertex k of ring r has index
// r·segments + k and position (radius·cos θ, r·length/(rings − 1), −radius·sin θ) with
// θ = 2πk/segments. Every quad is split along the same diagonal, so interior vertices have
// valence 6 and rim vertices 3 incident triangles; triangle normals point away from the axis.
// Throws std::invalid_argument for a non-positive or non-finite radius or length,
// segments < 3 or rings < 2.
TriMesh make_cylinder(double radius, double length, int segments, int rings);

// Open cylindrical panel (e.g. the Scordelis–Lo roof): the part of the cylinder of the given
// radius [m] about the y axis that spans `angle_deg` (0 < angle < 360) symmetrically about +z,
// from y = 0 to y = length [m], with `segments` divisions around (segments + 1 vertices per
// ring) and `rings` rings. Vertex k of ring r has index r·(segments + 1) + k and position
// (radius·sin φ, y, radius·cos φ), φ = angle·(k/segments − ½). Same diagonal everywhere;
// normals point away from the axis. Throws std::invalid_argument for bad arguments.
TriMesh make_cylinder_panel(double radius, double length, double angle_deg, int segments, int rings);

}  // namespace clothsim

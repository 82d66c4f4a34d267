// Reading and writing triangle meshes in the Wavefront OBJ format (geometry and texture
// coordinates: vertex positions, faces and `vt`, the latter only for the grain of a woven
// material; normals, groups and materials are ignored).
#pragma once

#include "sim/mesh/mesh.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace clothsim {

// Reads the `v x y z` and `f ...` lines of an OBJ file. Face entries may be `i`, `i/t`, `i//n`
// or `i/t/n`, with 1-based or negative (relative to the vertices read so far) indices; polygons
// with more than three corners are fan-triangulated as (c0, ck, ck+1). All other line types are
// ignored, but `vt u v` lines and the faces' texture indices fill TriMesh::uv when every face
// corner names a valid, finite one (otherwise uv stays empty: texture coordinates never make a file
// fail). Positions are taken as metres [m].
//
// Throws MeshError naming the file and, for parse errors, the line ("mesh.obj:12: face index
// 40 out of range (file has 10 vertices)"). The parsed mesh is then validated with
// check_triangles and Topology (degenerate triangles, non-manifold edges or vertices,
// inconsistent orientation, isolated vertices); those errors are rethrown prefixed with
// "<path>: ".
//
// Limits, so that no input makes it allocate without bound: `path` must be a regular file (or a
// link to one; a device such as /dev/zero, a pipe or a directory is refused before it is
// opened); a line may have at most kMaxObjLineLength characters; reading stops with a
// MeshLimitError ("<path>:<line>: more than N vertices") at the first vertex beyond
// `max_vertices`, or the first triangle beyond 4 × `max_vertices` (polygons counted by their fan
// triangles).
TriMesh read_obj(const std::string& path, long long max_vertices = kDefaultMaxVertices);
// The same for OBJ text read from `in` (a file's contents, a string); `name` stands for the file
// in error messages ("<name>:12: ..."). read_obj(path) opens the file and calls this.
TriMesh read_obj(std::istream& in, const std::string& name, long long max_vertices = kDefaultMaxVertices);
// The same for OBJ text in memory (the fuzz target in fuzz/ and tests).
TriMesh read_obj_text(std::string_view text, const std::string& name, long long max_vertices = kDefaultMaxVertices);

// The longest line read_obj accepts [characters] (a polygon of some 100 000 corners).
inline constexpr std::size_t kMaxObjLineLength = std::size_t{1} << 20;

// Writes `vertices` [m] and `triangles` (0-based, written 1-based) to an OBJ file, with every
// coordinate printed in the shortest form that reads back to the identical double. A non-empty
// `comment` is written as a leading `# comment` line (each line of a multi-line comment gets its
// own `#`). With `normals` (#V × 3, unit) it writes `vn` lines and faces `f a//a b//b c//c`; with
// `uv` (per triangle, its corners' texture coordinates, as TriMesh::uv) `vt` lines, one per
// distinct vertex and coordinate pair, and faces `f a/ta b/tb c/tc` (`a/ta/a` with normals).
// The file is written to a temporary sibling and renamed into place, so it is whole or absent.
// Throws MeshError (before touching the file) if a triangle has an out-of-range index or the
// normals do not match the vertices, and std::runtime_error naming the path if the file cannot
// be written.
void write_obj(const std::string& path, const Eigen::MatrixX3d& vertices,
               const std::vector<Triangle>& triangles, const std::string& comment = "",
               const Eigen::MatrixX3d* normals = nullptr,
               const std::vector<std::array<Eigen::Vector2d, 3>>* uv = nullptr);

}  // namespace clothsim

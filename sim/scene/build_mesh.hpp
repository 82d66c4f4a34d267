// The cloth's mesh from the scene's "mesh" object (internal to sim/scene/): an OBJ file or a
// primitive, placed, with its grain; and the warning about cracks. Failures are SceneErrors
// naming the key.
#pragma once

#include "sim/mesh/mesh.hpp"
#include "sim/pattern/pattern.hpp"
#include "sim/scene/read_settings.hpp"

#include <filesystem>
#include <optional>
#include <string>

namespace clothsim::scene_io {

// A pattern garment as read (the pieces and seams) and as built (sim/pattern/pattern.hpp).
struct SewnPattern {
  PatternSpec spec;
  PatternMesh built;
};

// Fails at `path` if a generated mesh would have more than `max_vertices` vertices (`count`,
// computed in 64 bits by the caller before anything is allocated).
void check_vertex_count(const Reader& r, const std::string& path, const std::string& what, long long count,
                        long long max_vertices);

// The mesh (an OBJ file, a primitive or a pattern garment) with its optional placement:
// "rotate": {"axis": [x, y, z], "angle_deg": a} about the origin, then "translate": [x, y, z] [m].
// For a pattern garment `pattern` receives the builder's result (its mesh before the placement:
// piece edges, seam gaps).
TriMesh build_mesh(const Reader& r, const Json& j, const std::filesystem::path& folder, const LogFn& log,
                   long long max_vertices, const GrainSpec& grain, bool need_grain, std::optional<SewnPattern>& pattern);

// Logs a warning if the mesh has cracks (find_cracks): distinct border vertices at one position.
void warn_about_cracks(const TriMesh& mesh, bool from_obj, const LogFn& log);

}  // namespace clothsim::scene_io

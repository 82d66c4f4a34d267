// The scene's "mesh": {"pattern": {...}} (scenes/README.md, Pattern garments): pieces, their
// placement and grain, and the seams, read into a PatternSpec (sim/pattern/pattern.hpp) with every
// key, type and range checked (internal to sim/scene/; failures are SceneErrors naming the key).
#pragma once

#include "sim/pattern/pattern.hpp"
#include "sim/scene/json_reader.hpp"

#include <string>

namespace clothsim::scene_io {

PatternSpec read_pattern(const Reader& r, const Json& j, const std::string& path);

// The index in `spec` of the piece named by the string `j` (an error at `path` listing the pieces
// otherwise).
std::size_t read_piece_name(const Reader& r, const Json& j, const std::string& path, const PatternSpec& spec);

// A seam side or a piece edge named in a scene: {"piece": name, "edge": i} or
// {"piece": name, "edge": [first, last]} (a path of consecutive edges), checked against `spec`
// (the piece exists, the edges are in range).
SeamSide read_piece_edge(const Reader& r, const Json& j, const std::string& path, const PatternSpec& spec);

}  // namespace clothsim::scene_io

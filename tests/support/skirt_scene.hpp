// The tube skirt of scenes/README.md (a front and a back, 0.5 m × 0.5 m, wrapped at 0.17 m, side
// seams 3.4 cm apart as placed) at a coarse edge length, as the "mesh" member of a scene file, for
// the command-line tests of pattern garments.
#pragma once

namespace clothsim::testing {

inline constexpr const char* kCoarseTubeSkirtMesh = R"("mesh": {"pattern": {"edge_length": 0.05, "pieces": [
    {"name": "front", "points": [[-0.25, 0.0], [0.25, 0.0], [0.25, 0.5], [-0.25, 0.5]],
     "placement": {"wrap": {"radius": 0.17}, "translate": [0, 0.45, 0]}},
    {"name": "back", "points": [[-0.25, 0.0], [0.25, 0.0], [0.25, 0.5], [-0.25, 0.5]],
     "placement": {"wrap": {"radius": 0.17}, "rotate_deg": [0, 180, 0], "translate": [0, 0.45, 0]}}],
    "seams": [{"a": {"piece": "front", "edge": 1}, "b": {"piece": "back", "edge": 3}, "reversed": true},
              {"a": {"piece": "front", "edge": 3}, "b": {"piece": "back", "edge": 1}, "reversed": true}]}})";

}  // namespace clothsim::testing

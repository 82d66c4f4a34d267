// Pattern garments in scene files (scenes/README.md, Pattern garments): "mesh": {"pattern": ...}
// as the issue writes it, "rest", "settle" and boundaries selected by a piece's edge; errors that
// name the key; and a skirt whose seams start open settling closed.
#include "sim/scene/scene.hpp"

#include "sim/dynamics/simulator.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/pattern/pattern.hpp"
#include "sim/shell/shell_model.hpp"

#include "tests/support/scene_files.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>
#include <string>
#include <vector>

namespace clothsim {
namespace {

class PatternScene : public testing::SceneFileTest {};

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// The tube skirt of issue 30's scene contract: front and back, their side edges 3.4 cm apart.
const char* const kSkirt = R"("mesh": {"pattern": {
  "edge_length": 0.02,
  "pieces": [
    {"name": "front", "points": [[-0.25, 0.0], [0.25, 0.0], [0.25, 0.5], [-0.25, 0.5]],
     "grain_deg": 90,
     "placement": {"wrap": {"radius": 0.17}, "rotate_deg": [0, 0, 0], "translate": [0, 0.45, 0]}},
    {"name": "back", "points": [[-0.25, 0.0], [0.25, 0.0], [0.25, 0.5], [-0.25, 0.5]],
     "placement": {"wrap": {"radius": 0.17}, "rotate_deg": [0, 180, 0], "translate": [0, 0.45, 0]}}
  ],
  "seams": [{"a": {"piece": "front", "edge": 1}, "b": {"piece": "back", "edge": 3}, "reversed": true},
            {"a": {"piece": "front", "edge": 3}, "b": {"piece": "back", "edge": 1}, "reversed": true}]
}})";

std::string dynamic(const std::string& extra) {
  return std::string(R"({"analysis": "dynamic", )") + kSkirt + R"(, "material": {"preset": "cotton"},
    "time": {"dt": 0.005, "end": 0.01})" + extra + "}";
}

// render.texture defaults to the checker where the mesh has texture coordinates (a pattern's),
// and a scene's own choice wins.
TEST_F(PatternScene, ThePicturesShowTheCheckerByDefault) {
  EXPECT_EQ(load(dynamic("")).render.texture, "checker");
  EXPECT_EQ(load(dynamic(R"(, "render": {"texture": "none"})")).render.texture, "none");
  EXPECT_EQ(load(dynamic(R"(, "render": {"texture": "grain"})")).render.texture, "grain");
  // A grid has no texture coordinates: plain colour.
  EXPECT_EQ(load(R"({"mesh": {"primitive": "grid", "size": [0.2, 0.1], "divisions": [4, 2]}})").render.texture, "none");
}

TEST_F(PatternScene, TheContractsSkirtIsSewnAndRestsFlat) {
  const Scene s = load(dynamic(R"(, "settle": {"time": 0.5})"));
  // The same mesh as the builder makes from the same pieces and seams.
  PatternSpec spec;
  spec.edge_length = 0.02;
  for (const char* name : {"front", "back"}) {
    PatternPiece p;
    p.name = name;
    p.points = {{-0.25, 0.0}, {0.25, 0.0}, {0.25, 0.5}, {-0.25, 0.5}};
    p.grain_deg = std::string(name) == "front" ? 90 : 0;
    p.placement.wrap_radius = 0.17;
    p.placement.rotate_deg = {0, std::string(name) == "front" ? 0.0 : 180.0, 0};
    p.placement.translate = {0, 0.45, 0};
    spec.pieces.push_back(p);
  }
  spec.seams = {{{"front", 1, 1}, {"back", 3, 3}, true}, {{"front", 3, 3}, {"back", 1, 1}, true}};
  const PatternMesh built = build_pattern(spec);
  ASSERT_EQ(s.problem.mesh.num_vertices(), built.mesh.num_vertices());
  EXPECT_EQ((s.problem.mesh.vertices - built.mesh.vertices).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(s.problem.mesh.uv.size(), s.problem.mesh.triangles.size());
  EXPECT_EQ(s.problem.rest, RestShape::pattern);  // the default for a pattern mesh
  EXPECT_EQ(s.problem.settle.time, 0.5);
  EXPECT_EQ(s.problem.settle.damping, 20.0);
  // "rest": "initial" keeps the placed shape as the rest state (today's behaviour).
  EXPECT_EQ(load(dynamic(R"(, "rest": "initial")")).problem.rest, RestShape::initial);
}

TEST_F(PatternScene, ABoundaryCanSelectAPiecesEdge) {
  const Scene s = load(dynamic(R"(, "boundary": [
    {"select": {"piece_edge": {"piece": "front", "edge": 2}}, "fix": ["x", "y", "z"]},
    {"select": {"piece_edge": {"piece": "back", "edge": [1, 3]}}, "fix": ["y"]}])"));
  ASSERT_EQ(s.problem.boundary.size(), 2u);
  // The top edge of the front: 0.5 m at a control edge of about 2 cm, corner to corner, at y = 0.95.
  const std::vector<int>& top = s.problem.boundary[0].vertices;
  EXPECT_EQ(top.size(), 27u);
  for (const int v : top) EXPECT_NEAR(s.problem.mesh.vertices(v, 1), 0.95, 1e-12);
  // The back's path 1..3: its right side, top and left side (two of them sewn to the front).
  EXPECT_EQ(s.problem.boundary[1].vertices.size(), 3u * 27u - 2u);
}

TEST_F(PatternScene, ABoundaryCanSelectAVertexGroupDrawnOnThePattern) {
  const Scene s = load(dynamic(R"(, "boundary": [
    {"select": {"piece": {"name": "front"}}, "fix": ["x"]},
    {"select": {"piece": {"name": "back"}}, "fix": ["x"]},
    {"select": {"piece_edge": {"piece": "front", "edge": 1}}, "fix": ["x"]},
    {"select": {"piece_edge": {"piece": "front", "edge": 3}}, "fix": ["x"]},
    {"select": {"piece": {"name": "front", "box": [[-0.3, 0.45], [0.3, 0.6]]}}, "fix": ["x", "y", "z"]},
    {"select": {"piece_edge": {"piece": "front", "edge": 2}}, "fix": ["x"]}])"));
  ASSERT_EQ(s.problem.boundary.size(), 6u);
  const auto& b = s.problem.boundary;
  // The two pieces cover the mesh and share exactly the front's two sewn sides.
  std::vector<int> both, all;
  std::set_intersection(b[0].vertices.begin(), b[0].vertices.end(), b[1].vertices.begin(), b[1].vertices.end(),
                        std::back_inserter(both));
  std::set_union(b[0].vertices.begin(), b[0].vertices.end(), b[1].vertices.begin(), b[1].vertices.end(),
                 std::back_inserter(all));
  std::vector<int> sides;
  std::set_union(b[2].vertices.begin(), b[2].vertices.end(), b[3].vertices.begin(), b[3].vertices.end(),
                 std::back_inserter(sides));
  EXPECT_EQ(both, sides);
  EXPECT_EQ(static_cast<int>(all.size()), s.problem.mesh.num_vertices());
  // The band v >= 0.45 m of the front: placed from y = 0.9 to 0.95 (the piece's top at v = 0.5
  // is placed at y = 0.95), its top edge included, nothing of the back but the sewn corners.
  ASSERT_FALSE(b[4].vertices.empty());
  for (const int v : b[4].vertices) {
    EXPECT_GE(s.problem.mesh.vertices(v, 1), 0.9 - 1e-9);
    EXPECT_LE(s.problem.mesh.vertices(v, 1), 0.95 + 1e-9);
    EXPECT_TRUE(std::binary_search(b[0].vertices.begin(), b[0].vertices.end(), v));
  }
  EXPECT_TRUE(std::includes(b[4].vertices.begin(), b[4].vertices.end(), b[5].vertices.begin(), b[5].vertices.end()));
  EXPECT_GT(b[4].vertices.size(), 2 * b[5].vertices.size());  // more than one row
}

TEST_F(PatternScene, ErrorsNameTheKey) {
  EXPECT_TRUE(contains(error(dynamic(R"(, "boundary": [{"select": {"piece_edge": {"piece": "frnot", "edge": 2}}, "fix": ["x"]}])")),
                       "boundary[0].select.piece_edge.piece: no piece \"frnot\" (pieces: \"front\", \"back\"); did you mean \"front\"?"));
  EXPECT_TRUE(contains(error(dynamic(R"(, "boundary": [{"select": {"piece_edge": {"piece": "front", "edge": 4}}, "fix": ["x"]}])")),
                       "boundary[0].select.piece_edge.edge: piece \"front\" has edges 0 to 3"));
  EXPECT_TRUE(contains(error(R"({"analysis": "dynamic", "mesh": {"primitive": "grid", "size": [0.2, 0.1], "divisions": [4, 2]},
      "boundary": [{"select": {"piece_edge": {"piece": "front", "edge": 0}}, "fix": ["x"]}]})"),
                       "boundary[0].select.piece_edge: needs a pattern mesh"));
  EXPECT_TRUE(contains(error(dynamic(R"(, "boundary": [{"select": {"box": [[-1, -1, -1], [1, 1, 1]], "piece_edge": {"piece": "front", "edge": 0}}, "fix": ["x"]}])")),
                       "boundary[0].select: give one of \"box\", \"ball\", \"piece_edge\" and \"piece\""));
  EXPECT_TRUE(contains(error(dynamic(R"(, "boundary": [{"select": {"piece": {"name": "fornt"}}, "fix": ["x"]}])")),
                       "boundary[0].select.piece.name: no piece \"fornt\""));
  EXPECT_TRUE(contains(error(dynamic(R"(, "boundary": [{"select": {"piece": {"name": "front", "box": [[1, 1], [2, 2]]}}, "fix": ["x"]}])")),
                       "boundary[0].select.piece.box: selects no vertex of piece \"front\""));
  EXPECT_TRUE(contains(error(dynamic(R"(, "boundary": [{"select": {"piece": {"name": "front", "box": [[1, 1]]}}, "fix": ["x"]}])")),
                       "boundary[0].select.piece.box: expected an array of 2 points"));
  EXPECT_TRUE(contains(error(dynamic(R"(, "boundary": [{"select": {"piece": {"name": "front", "box": [[1, 1], [0, 2]]}}, "fix": ["x"]}])")),
                       "boundary[0].select.piece.box: min must be <= max"));
  EXPECT_TRUE(contains(error(R"({"analysis": "dynamic", "mesh": {"primitive": "grid", "size": [0.2, 0.1], "divisions": [4, 2]},
      "boundary": [{"select": {"piece": {"name": "front"}}, "fix": ["x"]}]})"),
                       "boundary[0].select.piece: needs a pattern mesh"));
  EXPECT_TRUE(contains(error(dynamic(R"(, "rest": "initial", "settle": {"time": 0.5})")),
                       "settle: needs a rest state of its own (\"rest\": \"pattern\")"));
  EXPECT_TRUE(contains(error(dynamic(R"(, "settle": {"time": -1})")), "settle.time: must be >= 0 [s]"));
  EXPECT_TRUE(contains(error(dynamic(R"(, "rest": "flat")")), "rest: unknown value \"flat\""));
  EXPECT_TRUE(contains(error(std::string("{") + kSkirt + "}"), "rest: \"pattern\" (a flat rest state) needs \"analysis\": \"dynamic\""));
  EXPECT_TRUE(contains(error(std::string("{") + kSkirt + R"(, "settle": {"time": 1}})"), "settle: needs \"analysis\": \"dynamic\""));
  EXPECT_TRUE(contains(error(R"({"analysis": "dynamic", )" + std::string(kSkirt) +
                             R"(, "material": {"preset": "cotton_broadcloth_ortho", "grain": {"warp_deg": 10}}})"),
                       "material.grain: a pattern mesh takes its grain from its pieces"));
  EXPECT_TRUE(contains(error(R"({"mesh": {"primitive": "grid", "size": [0.2, 0.1], "divisions": [4, 2]}, "render": {"texture": "checker"}})"),
                       "render.texture: \"checker\" needs texture coordinates on the mesh"));
  // The builder's errors come back under the pattern's key.
  std::string bad = dynamic("");
  bad.replace(bad.find("[0.25, 0.5], [-0.25, 0.5]]"), 26, "[0.25, 0.48], [-0.25, 0.48]]");
  EXPECT_TRUE(contains(error(bad), "mesh.pattern: ")) << error(bad);
  EXPECT_TRUE(contains(error(bad), "differ by")) << error(bad);
}

TEST_F(PatternScene, AnOpenSkirtSettlesClosed) {
  // Seams 3.4 cm apart as placed: the bands of cloth that join them start stretched by more than
  // 100 %; after half a second of settling (no gravity, strong damping) less than 0.1 % is left.
  Scene s = load(dynamic(R"(, "settle": {"time": 0.5})"));
  const Simulator sim(s.problem);
  EXPECT_GT(sim.settle_report().strain_start, 1.0);
  EXPECT_LT(sim.settle_report().strain_end, 1e-3);
  EXPECT_EQ(sim.settle_report().steps, 100);
  // The seam gap: at the start the band across each 3.4 cm gap is a control edge about 1.7 cm
  // longer than in the pattern (each side moved half the gap); closed to below 0.1 mm.
  EXPECT_GT(sim.settle_report().gap_start, 0.012);
  EXPECT_LT(sim.settle_report().gap_start, 0.034);
  EXPECT_LT(sim.settle_report().gap_end, 1e-4);
  // The run starts at rest where the settling ended.
  EXPECT_EQ(sim.state().v.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT(sim.max_membrane_strain(), 1e-3);
}

}  // namespace
}  // namespace clothsim

namespace clothsim {
namespace {

class FitLimitScene : public testing::SceneFileTest {};

TEST_F(FitLimitScene, TheLimitSurfacePassesThroughTheMeshAsGiven) {
  // A 16-segment cylinder: its control points lie on the cylinder, its limit surface inside it;
  // with mesh.fit_limit the limit points are the given vertices.
  const std::string mesh = R"("primitive": "cylinder", "radius": 0.05, "length": 0.2, "segments": 16, "rings": 9)";
  const Scene plain = load(std::string(R"({"mesh": {)") + mesh + "}}");
  const Scene fitted = load(std::string(R"({"mesh": {)") + mesh + R"(, "fit_limit": true}})");
  const TriMesh given = make_cylinder(0.05, 0.2, 16, 9);
  const auto limit_points = [](const Scene& s) {
    const ShellModel model(s.problem.mesh, s.problem.material, {}, Quadrature::one_point);
    return Eigen::MatrixX3d(model.limit_points(model.extended().rest));
  };
  EXPECT_LT((limit_points(fitted) - given.vertices).cwiseAbs().maxCoeff(), 1e-9 * 0.2);
  EXPECT_GT((limit_points(plain) - given.vertices).cwiseAbs().maxCoeff(), 1e-4);  // 16 segments: about 0.3 mm inside
  EXPECT_TRUE(contains(error(std::string(R"({"method": "linear_fe", "mesh": {)") + mesh + R"(, "fit_limit": true}})"),
                       "mesh.fit_limit: needs \"method\": \"loop_kl\""));
  EXPECT_TRUE(contains(error(std::string(R"({"mesh": {)") + mesh + R"(, "fit_limit": 1}})"), "mesh.fit_limit: expected true or false"));
}

}  // namespace
}  // namespace clothsim

// Scene keys of dynamic scenes with contact: "collision", "obstacles", "output.obj_level" and the
// placement of a mesh ("mesh.rotate", "mesh.translate"). The contract example is read as written;
// either contact key works alone; every bad value is an error naming the file and the key path
// (also through the clothsim command, which then writes nothing); selections act on the placed
// mesh.
#include "sim/scene/scene.hpp"

#include "sim/contact/obstacle.hpp"

#include "tests/support/process.hpp"

#include <Eigen/Geometry>
#include "tests/support/scene_files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// A closed, outward-oriented tetrahedron (edges 0.1 m) and an open square (two triangles).
const char* const kTetrahedronObj =
    "# closed\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
const char* const kSquareObj = "v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 0 0.5\nv -0.5 0 0.5\nf 1 4 3 2\n";

// The contract example of the issue, as written (the cloth around it is ours).
const char* const kContractExample = R"({
  "analysis": "dynamic",
  "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
  "material": {"preset": "cotton"},
  "collision": {"self": true, "thickness": 0.001, "friction": 0.3},
  "obstacles": [
    {"name": "ground", "primitive": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "friction": 0.5},
    {"name": "ball", "primitive": "sphere", "center": [0, 0.1, 0], "radius": 0.05},
    {"name": "arm", "primitive": "capsule", "from": [0, 0, 0], "to": [0, 0.3, 0], "radius": 0.03,
     "motion": [{"type": "translate", "displacement": [0, 0.05, 0], "start": 0, "end": 1}]},
    {"name": "crate", "primitive": "box", "center": [0, 0, 0], "size": [0.1, 0.1, 0.1]},
    {"name": "post", "primitive": "cylinder", "from": [0, 0, 0], "to": [0, 0.2, 0], "radius": 0.02},
    {"name": "body", "obj": "body.obj", "friction": 0.4}
  ],
  "output": {"obj": true, "obj_level": 2}
})";

// A dynamic scene with a small grid; `rest` is spliced in after the mesh (", ..." or "").
std::string dynamic_scene(const std::string& rest) {
  return std::string(R"({"analysis": "dynamic", "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]})") +
         rest + "}";
}

// A scene with one obstacle list (and no collision block).
std::string with_obstacles(const std::string& list) { return dynamic_scene(R"(, "obstacles": )" + list); }

class ContactKeys : public testing::SceneFileTest {};

const Obstacle* find_obstacle(const Scene& s, const std::string& name) {
  for (const Obstacle& o : s.problem.obstacles)
    if (o.name == name) return &o;
  return nullptr;
}

// ---- Accepted input ------------------------------------------------------------------------

TEST_F(ContactKeys, ContractExampleAcceptedAsWritten) {
  write("body.obj", kTetrahedronObj);
  const Scene s = load(kContractExample);
  const Problem& p = s.problem;
  EXPECT_TRUE(p.collision.self);
  EXPECT_DOUBLE_EQ(p.collision.thickness, 0.001);
  EXPECT_DOUBLE_EQ(p.collision.friction, 0.3);
  EXPECT_EQ(p.collision_level, s.render.refine);  // surface_level defaults to render.refine (2)
  EXPECT_EQ(p.collision_level, 2);
  EXPECT_TRUE(p.has_contact());
  EXPECT_TRUE(s.write_obj_frames);
  EXPECT_EQ(s.obj_level, 2);

  ASSERT_EQ(p.obstacles.size(), 6u);
  const std::vector<std::string> names = {"ground", "ball", "arm", "crate", "post", "body"};
  for (std::size_t i = 0; i < names.size(); ++i) EXPECT_EQ(p.obstacles[i].name, names[i]);

  const Obstacle& ground = *find_obstacle(s, "ground");
  EXPECT_EQ(ground.shape, Obstacle::Shape::plane);
  EXPECT_EQ(ground.point, Eigen::Vector3d::Zero());
  EXPECT_EQ(ground.normal, Eigen::Vector3d(0, 1, 0));
  EXPECT_DOUBLE_EQ(ground.friction, 0.5);
  EXPECT_TRUE(ground.motion.empty());
  EXPECT_EQ(ground.mesh.num_triangles(), 0);  // a plane is exact, not tessellated

  const Obstacle& ball = *find_obstacle(s, "ball");
  EXPECT_EQ(ball.shape, Obstacle::Shape::sphere);
  EXPECT_EQ(ball.center, Eigen::Vector3d(0, 0.1, 0));
  EXPECT_DOUBLE_EQ(ball.radius, 0.05);
  EXPECT_DOUBLE_EQ(ball.friction, 0.3);  // collision.friction
  ASSERT_GT(ball.mesh.num_triangles(), 0);
  // Vertices on the true sphere; chords within 0.2 % of the radius.
  for (Eigen::Index v = 0; v < ball.mesh.vertices.rows(); ++v)
    ASSERT_NEAR((ball.mesh.vertices.row(v).transpose() - ball.center).norm(), 0.05, 1e-12);
  for (const Triangle& t : ball.mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d mid = 0.5 * (ball.mesh.vertices.row(t[static_cast<std::size_t>(k)]) +
                                         ball.mesh.vertices.row(t[static_cast<std::size_t>((k + 1) % 3)]))
                                            .transpose();
      ASSERT_GE((mid - ball.center).norm(), 0.998 * 0.05);
    }

  const Obstacle& arm = *find_obstacle(s, "arm");
  EXPECT_EQ(arm.shape, Obstacle::Shape::capsule);
  EXPECT_EQ(arm.from, Eigen::Vector3d::Zero());
  EXPECT_EQ(arm.to, Eigen::Vector3d(0, 0.3, 0));
  EXPECT_DOUBLE_EQ(arm.radius, 0.03);
  EXPECT_DOUBLE_EQ(arm.friction, 0.3);
  EXPECT_GT(arm.mesh.num_triangles(), 0);
  ASSERT_EQ(arm.motion.size(), 1u);
  EXPECT_EQ(arm.motion[0].type, Motion::Type::translate);
  EXPECT_EQ(arm.motion[0].displacement, Eigen::Vector3d(0, 0.05, 0));
  EXPECT_DOUBLE_EQ(arm.motion[0].start, 0.0);
  EXPECT_DOUBLE_EQ(arm.motion[0].end, 1.0);
  // The motion moves the whole tessellation rigidly: half-way at t = 0.5, all of it at t = 1.
  const Eigen::MatrixX3d half = mesh_at(arm, 0.5), done = mesh_at(arm, 1.0);
  for (Eigen::Index v = 0; v < arm.mesh.vertices.rows(); ++v) {
    ASSERT_LT((half.row(v) - arm.mesh.vertices.row(v) - Eigen::RowVector3d(0, 0.025, 0)).norm(), 1e-12);
    ASSERT_LT((done.row(v) - arm.mesh.vertices.row(v) - Eigen::RowVector3d(0, 0.05, 0)).norm(), 1e-12);
  }

  const Obstacle& crate = *find_obstacle(s, "crate");
  EXPECT_EQ(crate.shape, Obstacle::Shape::box);
  EXPECT_EQ(crate.center, Eigen::Vector3d::Zero());
  EXPECT_EQ(crate.size, Eigen::Vector3d(0.1, 0.1, 0.1));
  EXPECT_GT(crate.mesh.num_triangles(), 0);
  for (Eigen::Index v = 0; v < crate.mesh.vertices.rows(); ++v)  // exact: the corners
    EXPECT_NEAR(crate.mesh.vertices.row(v).cwiseAbs().maxCoeff(), 0.05, 1e-15);

  const Obstacle& post = *find_obstacle(s, "post");
  EXPECT_EQ(post.shape, Obstacle::Shape::cylinder);
  EXPECT_EQ(post.from, Eigen::Vector3d::Zero());
  EXPECT_EQ(post.to, Eigen::Vector3d(0, 0.2, 0));
  EXPECT_DOUBLE_EQ(post.radius, 0.02);
  EXPECT_DOUBLE_EQ(post.friction, 0.3);
  EXPECT_GT(post.mesh.num_triangles(), 0);

  const Obstacle& body = *find_obstacle(s, "body");
  EXPECT_EQ(body.shape, Obstacle::Shape::mesh);
  EXPECT_EQ(body.file, "body.obj");
  EXPECT_DOUBLE_EQ(body.friction, 0.4);
  EXPECT_EQ(body.mesh.num_triangles(), 4);
  EXPECT_EQ(body.mesh.num_vertices(), 4);
}

TEST_F(ContactKeys, PlaneNormalIsNormalised) {
  const Scene s = load(with_obstacles(R"([{"primitive": "plane", "point": [0, -1, 0], "normal": [3, 4, 0]}])"));
  ASSERT_EQ(s.problem.obstacles.size(), 1u);
  const Obstacle& o = s.problem.obstacles[0];
  EXPECT_NEAR(o.normal.norm(), 1.0, 1e-15);
  EXPECT_LT((o.normal - Eigen::Vector3d(0.6, 0.8, 0)).norm(), 1e-15);
  EXPECT_EQ(o.point, Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(o.name, "obstacle0");  // the default name
}

TEST_F(ContactKeys, ObstaclesWithoutCollisionBlock) {
  write("floor.obj", kSquareObj);  // an open OBJ obstacle
  const Scene s = load(with_obstacles(
      R"([{"name": "ball", "primitive": "sphere", "center": [0, -0.2, 0], "radius": 0.1},
          {"name": "floor", "obj": "floor.obj"}])"));
  const Problem& p = s.problem;
  EXPECT_FALSE(p.collision.self);
  EXPECT_DOUBLE_EQ(p.collision.thickness, 0.001);
  EXPECT_DOUBLE_EQ(p.collision.friction, 0.3);
  EXPECT_EQ(p.collision_level, 2);
  EXPECT_TRUE(p.has_contact());
  ASSERT_EQ(p.obstacles.size(), 2u);
  EXPECT_DOUBLE_EQ(p.obstacles[0].friction, 0.3);
  EXPECT_EQ(p.obstacles[1].shape, Obstacle::Shape::mesh);
  EXPECT_EQ(p.obstacles[1].mesh.num_triangles(), 2);  // the quad, fan-triangulated
  EXPECT_DOUBLE_EQ(p.obstacles[1].friction, 0.3);
  EXPECT_FALSE(s.write_obj_frames);
  EXPECT_EQ(s.obj_level, 0);
}

TEST_F(ContactKeys, CollisionWithoutObstacles) {
  const Scene s = load(dynamic_scene(R"(, "collision": {"self": true})"));
  EXPECT_TRUE(s.problem.collision.self);
  EXPECT_DOUBLE_EQ(s.problem.collision.thickness, 0.001);
  EXPECT_DOUBLE_EQ(s.problem.collision.friction, 0.3);
  EXPECT_DOUBLE_EQ(s.problem.collision.tolerance, 1e-3);
  EXPECT_DOUBLE_EQ(load(dynamic_scene(R"(, "collision": {"self": true, "tolerance": 1e-5})")).problem.collision.tolerance, 1e-5);
  EXPECT_TRUE(s.problem.obstacles.empty());
  EXPECT_TRUE(s.problem.has_contact());

  // An obstacle's friction defaults to collision.friction, its own value replaces it.
  const Scene f = load(dynamic_scene(R"(, "collision": {"friction": 0.7, "thickness": 0.004},
      "obstacles": [{"primitive": "box", "center": [0, 0, 0], "size": [1, 0.1, 1]},
                    {"primitive": "box", "center": [0, 1, 0], "size": [1, 0.1, 1], "friction": 0}])"));
  EXPECT_FALSE(f.problem.collision.self);
  EXPECT_DOUBLE_EQ(f.problem.collision.thickness, 0.004);
  ASSERT_EQ(f.problem.obstacles.size(), 2u);
  EXPECT_DOUBLE_EQ(f.problem.obstacles[0].friction, 0.7);
  EXPECT_DOUBLE_EQ(f.problem.obstacles[1].friction, 0.0);
}

TEST_F(ContactKeys, NoContactWithoutSelfOrObstacles) {
  EXPECT_FALSE(load(dynamic_scene("")).problem.has_contact());
  EXPECT_FALSE(load(dynamic_scene(R"(, "collision": {"self": false, "thickness": 0.01})")).problem.has_contact());
  EXPECT_FALSE(load(dynamic_scene(R"(, "obstacles": [])")).problem.has_contact());
}

TEST_F(ContactKeys, SurfaceLevelDefaultsToRenderRefine) {
  EXPECT_EQ(load(dynamic_scene(R"(, "render": {"refine": 3}, "collision": {"self": true})")).problem.collision_level, 3);
  EXPECT_EQ(load(dynamic_scene(R"(, "render": {"refine": 0})")).problem.collision_level, 0);
  EXPECT_EQ(load(dynamic_scene(R"(, "render": {"refine": 3}, "collision": {"surface_level": 1})")).problem.collision_level,
            1);
  EXPECT_EQ(load(dynamic_scene(R"(, "collision": {"surface_level": 4})")).problem.collision_level, 4);
  EXPECT_EQ(load(dynamic_scene(R"(, "collision": {"surface_level": 0})")).problem.collision_level, 0);
}

TEST_F(ContactKeys, ObjLevelRange) {
  for (int level = 0; level <= 4; ++level) {
    const Scene s = load(dynamic_scene(R"(, "output": {"obj": true, "obj_level": )" + std::to_string(level) + "}"));
    EXPECT_EQ(s.obj_level, level);
  }
  EXPECT_EQ(load(dynamic_scene(R"(, "output": {"obj": true})")).obj_level, 0);
}

// ---- Errors --------------------------------------------------------------------------------

TEST_F(ContactKeys, CollisionErrors) {
  auto collision = [&](const std::string& c) { return error(dynamic_scene(R"(, "collision": )" + c)); };
  EXPECT_EQ(collision(R"({"thickness": 0})"), expected("collision.thickness: must be > 0 [m] (got 0)"));
  EXPECT_EQ(collision(R"({"thickness": -1})"), expected("collision.thickness: must be > 0 [m] (got -1)"));
  EXPECT_EQ(collision(R"({"friction": -0.1})"), expected("collision.friction: must be >= 0 [-] (got -0.1)"));
  EXPECT_EQ(collision(R"({"tolerance": 0})"), expected("collision.tolerance: must be > 0 [-] (got 0)"));
  EXPECT_EQ(collision(R"({"tolerance": 0.5})"), expected("collision.tolerance: must be > 0 and at most 0.1 (got 0.5)"));
  EXPECT_EQ(collision(R"({"surface_level": 7})"),
            expected("collision.surface_level: must be an integer from 0 to 4 (got 7)"));
  EXPECT_EQ(collision(R"({"surface_level": -1})"),
            expected("collision.surface_level: must be an integer >= 0 (got -1)"));
  EXPECT_TRUE(contains(collision(R"({"surface_level": 1.5})"), expected("collision.surface_level: expected an integer")));
  EXPECT_EQ(collision(R"({"self": "yes"})"), expected("collision.self: expected true or false (got \"yes\")"));
  EXPECT_TRUE(contains(collision(R"({"thickness": "1mm"})"), expected("collision.thickness: expected a number")));
  EXPECT_EQ(collision(R"({"margin": 0.01})"),
            expected("collision.margin: unknown key (allowed: self, thickness, friction, tolerance, surface_level, method)"));
  EXPECT_TRUE(contains(collision("true"), expected("collision: expected an object")));
}

TEST_F(ContactKeys, ObstacleValueErrors) {
  const std::string plane = R"({"primitive": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]})";
  EXPECT_EQ(error(with_obstacles("[" + plane + R"(, {"primitive": "sphere", "center": [0, 0, 0], "radius": 0}])")),
            expected("obstacles[1].radius: must be > 0 [m] (got 0)"));
  EXPECT_EQ(error(with_obstacles(R"([{"primitive": "capsule", "from": [0, 0, 0], "to": [0, 1, 0], "radius": -0.1}])")),
            expected("obstacles[0].radius: must be > 0 [m] (got -0.1)"));
  for (const std::string size : {"[0.1, 0, 0.1]", "[0, 0.1, 0.1]", "[0.1, 0.1, -0.1]"}) {
    const std::string e = error(with_obstacles(R"([{"primitive": "box", "center": [0, 0, 0], "size": )" + size + "}]"));
    EXPECT_TRUE(contains(e, expected("obstacles[0].size: every edge length must be > 0 [m]"))) << size << ": " << e;
  }
  EXPECT_TRUE(contains(error(with_obstacles(R"([{"primitive": "plane", "point": [0, 0, 0], "normal": [0, 0, 0]}])")),
                       expected("obstacles[0].normal: must be a non-zero vector")));
  for (const std::string shape : {"capsule", "cylinder"})
    EXPECT_EQ(error(with_obstacles(R"([{"primitive": ")" + shape +
                                   R"(", "from": [0, 0.1, 0], "to": [0, 0.1, 0], "radius": 0.02}])")),
              expected("obstacles[0].to: must differ from \"from\""))
        << shape;
  EXPECT_EQ(error(with_obstacles(R"([{"primitive": "sphere", "center": [0, 0, 0], "radius": 0.1, "friction": -0.1}])")),
            expected("obstacles[0].friction: must be >= 0 [-] (got -0.1)"));
  EXPECT_EQ(error(with_obstacles(R"([{"primitive": "sphere", "center": [0, 0, 0]}])")),
            expected("obstacles[0].radius: required key is missing"));
  EXPECT_EQ(error(with_obstacles(R"([{"primitive": "plane", "normal": [0, 1, 0]}])")),
            expected("obstacles[0].point: required key is missing"));
  EXPECT_TRUE(contains(error(with_obstacles(R"([{"primitive": "sphere", "center": [0, 0], "radius": 0.1}])")),
                       expected("obstacles[0].center: expected an array of 3 numbers")));
  // The motion chain is checked as a boundary's.
  EXPECT_EQ(error(with_obstacles(R"([{"primitive": "sphere", "center": [0, 0, 0], "radius": 0.1,
                                     "motion": [{"type": "hold", "start": 2, "end": 1}]}])")),
            expected("obstacles[0].motion[0].end: must be >= start = 2.0 [s] (got 1.0)"));
  // A translation beyond a thousand times the cloth's size (the 0.2 m grid: diagonal 0.28 m).
  EXPECT_TRUE(contains(error(with_obstacles(R"([{"primitive": "sphere", "center": [0, -1, 0], "radius": 0.1,
      "motion": [{"type": "translate", "displacement": [0, -1e9, 0], "start": 0, "end": 1}]}])")),
                       expected("obstacles[0].motion[0].displacement: moves the obstacle by 1000000000.0 m, more than "
                                "1000.0 times the mesh's size")));
  EXPECT_EQ(error(with_obstacles(R"([{"primitive": "sphere", "center": [0, 0, 0], "radius": 0.1,
                                     "motion": [{"type": "spin", "start": 0, "end": 1}]}])")),
            expected("obstacles[0].motion[0].type: unknown motion type \"spin\" (allowed: \"rotate\", \"translate\", \"hold\")"));
}

TEST_F(ContactKeys, ObstacleObjErrors) {
  const std::string missing = error(with_obstacles(R"([{"name": "body", "obj": "missing.obj"}])"));
  EXPECT_TRUE(contains(missing, expected("obstacles[0].obj: "))) << missing;
  EXPECT_TRUE(contains(missing, "missing.obj")) << missing;

  write("garbage.obj", "this is not\nan OBJ file\n{}\n");
  const std::string garbage = error(with_obstacles(R"([{"obj": "garbage.obj"}])"));
  EXPECT_TRUE(contains(garbage, expected("obstacles[0].obj: "))) << garbage;
  EXPECT_TRUE(contains(garbage, "garbage.obj")) << garbage;

  write("bad_vertex.obj", "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n");
  const std::string bad_vertex = error(with_obstacles(R"([{"obj": "bad_vertex.obj"}])"));
  EXPECT_TRUE(contains(bad_vertex, expected("obstacles[0].obj: "))) << bad_vertex;
  EXPECT_TRUE(contains(bad_vertex, "bad_vertex.obj:2: malformed vertex line")) << bad_vertex;

  write("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  const std::string bad_index = error(with_obstacles(R"([{"obj": "bad_index.obj"}])"));
  EXPECT_TRUE(contains(bad_index, expected("obstacles[0].obj: "))) << bad_index;
  EXPECT_TRUE(contains(bad_index, "bad_index.obj:4: face index 9 out of range")) << bad_index;

  // The error names the failing obstacle's index.
  write("body.obj", kTetrahedronObj);
  const std::string second = error(with_obstacles(R"([{"obj": "body.obj"}, {"obj": "bad_index.obj"}])"));
  EXPECT_TRUE(contains(second, expected("obstacles[1].obj: "))) << second;

  EXPECT_EQ(error(with_obstacles(R"([{"obj": ""}])")), expected("obstacles[0].obj: expected a non-empty file path"));
  EXPECT_TRUE(contains(error(with_obstacles(R"([{"obj": 3}])")), expected("obstacles[0].obj: expected a string")));
}

TEST_F(ContactKeys, ObstacleShapeAndKeyErrors) {
  EXPECT_EQ(error(with_obstacles(R"([{"primitive": "cone", "center": [0, 0, 0], "radius": 0.1}])")),
            expected("obstacles[0].primitive: unknown primitive \"cone\" (allowed: \"plane\", \"sphere\", \"capsule\", "
                     "\"box\", \"cylinder\")"));
  EXPECT_EQ(error(with_obstacles(R"([{"primitive": "sphere", "center": [0, 0, 0], "radius": 0.1, "colour": "red"}])")),
            expected("obstacles[0].colour: unknown key (allowed: name, friction, motion, primitive, center, radius)"));
  // Keys of another shape are unknown too.
  EXPECT_TRUE(contains(error(with_obstacles(R"([{"primitive": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "radius": 1}])")),
                       expected("obstacles[0].radius: unknown key (allowed: name, friction, motion, primitive, point, normal)")));
  write("body.obj", kTetrahedronObj);
  EXPECT_TRUE(contains(error(with_obstacles(R"([{"obj": "body.obj", "center": [0, 0, 0]}])")),
                       expected("obstacles[0].center: unknown key (allowed: name, friction, motion, obj, keep, cut)")));
  EXPECT_EQ(error(with_obstacles(R"([{"obj": "body.obj", "primitive": "sphere", "center": [0, 0, 0], "radius": 0.1}])")),
            expected("obstacles[0]: give either \"obj\" or \"primitive\", not both"));
  const std::string neither = error(with_obstacles(R"([{"name": "x", "center": [0, 0, 0], "radius": 0.1}])"));
  EXPECT_TRUE(contains(neither, expected("obstacles[0]: needs \"primitive\""))) << neither;
  EXPECT_TRUE(contains(neither, "\"obj\"")) << neither;
  EXPECT_TRUE(contains(neither, "\"plane\", \"sphere\", \"capsule\", \"box\", \"cylinder\"")) << neither;
  EXPECT_EQ(error(with_obstacles(R"([{"name": "a", "primitive": "sphere", "center": [0, 0, 0], "radius": 0.1},
                                     {"name": "a", "primitive": "box", "center": [0, 0, 0], "size": [1, 1, 1]}])")),
            expected("obstacles[1].name: duplicate obstacle name \"a\""));
  EXPECT_EQ(error(with_obstacles(R"([{"name": "", "primitive": "sphere", "center": [0, 0, 0], "radius": 0.1}])")),
            expected("obstacles[0].name: must not be empty"));
  EXPECT_TRUE(contains(error(with_obstacles(R"({"primitive": "sphere"})")), expected("obstacles: expected an array")));
  EXPECT_TRUE(contains(error(with_obstacles("[1]")), expected("obstacles[0]: expected an object (got 1)")));
}

TEST_F(ContactKeys, OutputObjLevelErrors) {
  EXPECT_EQ(error(dynamic_scene(R"(, "output": {"obj": true, "obj_level": 5})")),
            expected("output.obj_level: must be an integer from 0 to 4 (got 5)"));
  EXPECT_EQ(error(dynamic_scene(R"(, "output": {"obj": true, "obj_level": -1})")),
            expected("output.obj_level: must be an integer >= 0 (got -1)"));
  EXPECT_TRUE(contains(error(dynamic_scene(R"(, "output": {"obj_level": 2.0})")),
                       expected("output.obj_level: expected an integer")));
}

TEST_F(ContactKeys, ContactKeysNeedDynamicScene) {
  const std::string grid = R"("mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]})";
  const std::string needs = ": needs \"analysis\": \"dynamic\" (this scene is static)";
  EXPECT_EQ(error("{" + grid + R"(, "collision": {"self": true}})"), expected("collision" + needs));
  EXPECT_EQ(error(R"({"analysis": "static", )" + grid +
                  R"(, "obstacles": [{"primitive": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}]})"),
            expected("obstacles" + needs));
  EXPECT_EQ(error("{" + grid + R"(, "output": {"obj_level": 2}})"), expected("output" + needs));
}

TEST_F(ContactKeys, MeshPlacementErrors) {
  auto mesh = [&](const std::string& placement) {
    return error(R"({"analysis": "dynamic", "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4], )" +
                 placement + "}}");
  };
  EXPECT_TRUE(contains(mesh(R"("rotate": {"axis": [0, 0, 0], "angle_deg": 90})"),
                       expected("mesh.rotate.axis: must be a non-zero vector")));
  EXPECT_EQ(mesh(R"("rotate": {"axis": [1, 0, 0], "angle_deg": 90, "center": [0, 0, 0]})"),
            expected("mesh.rotate.center: unknown key (allowed: axis, angle_deg)"));
  EXPECT_EQ(mesh(R"("rotate": {"angle_deg": 90})"), expected("mesh.rotate.axis: required key is missing"));
  EXPECT_EQ(mesh(R"("rotate": {"axis": [1, 0, 0]})"), expected("mesh.rotate.angle_deg: required key is missing"));
  EXPECT_TRUE(contains(mesh(R"("rotate": [1, 0, 0])"), expected("mesh.rotate: expected an object")));
  EXPECT_TRUE(contains(mesh(R"("translate": [0, 1])"), expected("mesh.translate: expected an array of 3 numbers")));
  // Also for a static scene and an OBJ mesh.
  write("square.obj", kSquareObj);
  EXPECT_TRUE(contains(error(R"({"mesh": {"obj": "square.obj", "rotate": {"axis": [0, 0, 0], "angle_deg": 1}}})"),
                       expected("mesh.rotate.axis: must be a non-zero vector")));
}

// ---- Mesh placement ------------------------------------------------------------------------

TEST_F(ContactKeys, PlacedGridIsHorizontalAndSelectionsUseIt) {
  // A 0.5 m grid in z = 0 (normal +z) turned -90° about x lies in y = 0 with normal +y; lifted to
  // y = 0.3 m. Its former edge y = +0.25 is now z = -0.25.
  const std::string placed =
      R"("mesh": {"primitive": "grid", "size": [0.5, 0.5], "divisions": [4, 4],
                  "rotate": {"axis": [1, 0, 0], "angle_deg": -90}, "translate": [0, 0.3, 0]})";
  const Scene s = load(R"({"analysis": "dynamic", )" + placed + R"(,
      "boundary": [{"select": {"box": [[-1, 0.29, -0.26], [1, 0.31, -0.24]]}}],
      "probes": [{"name": "corner", "at": [0.25, 0.3, 0.25]}]})");
  const TriMesh& m = s.problem.mesh;
  ASSERT_GE(m.num_vertices(), 25);
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v) {
    ASSERT_NEAR(m.vertices(v, 1), 0.3, 1e-12) << "vertex " << v;
    ASSERT_LE(std::abs(m.vertices(v, 0)), 0.25 + 1e-12);
    ASSERT_LE(std::abs(m.vertices(v, 2)), 0.25 + 1e-12);
  }
  for (const Triangle& t : m.triangles) {
    const Eigen::Vector3d a = m.vertices.row(t[0]), b = m.vertices.row(t[1]), c = m.vertices.row(t[2]);
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    ASSERT_GT(n.y(), 1.0 - 1e-12) << "normal " << n.transpose();
  }

  ASSERT_EQ(s.problem.boundary.size(), 1u);
  const std::vector<int>& edge = s.problem.boundary[0].vertices;
  EXPECT_GE(edge.size(), 5u);
  for (int v : edge) EXPECT_NEAR(m.vertices(v, 2), -0.25, 1e-12);
  ASSERT_EQ(s.probes.size(), 1u);
  EXPECT_LT((m.vertices.row(s.probes[0].vertex).transpose() - Eigen::Vector3d(0.25, 0.3, 0.25)).norm(), 1e-12);

  // A box around where that edge was before placement selects nothing.
  const std::string stale = error(R"({"analysis": "dynamic", )" + placed +
                                  R"(, "boundary": [{"select": {"box": [[-1, 0.24, -0.01], [1, 0.26, 0.01]]}}]})");
  EXPECT_TRUE(contains(stale, expected("boundary[0].select.box: selects no vertex of the mesh"))) << stale;
}

TEST_F(ContactKeys, PlacementRotatesThenTranslatesAnyMesh) {
  // An OBJ square in y = 0: a quarter turn about z takes (0.5, 0, -0.5) to (0, 0.5, -0.5); the
  // translation comes after the rotation.
  write("square.obj", kSquareObj);
  const Scene s = load(R"({"mesh": {"obj": "square.obj", "rotate": {"axis": [0, 0, 2], "angle_deg": 90},
                           "translate": [1, 0, 0]},
                           "probes": [{"name": "p", "at": [1, 0.5, -0.5]}]})");
  const TriMesh& m = s.problem.mesh;
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v) ASSERT_NEAR(m.vertices(v, 0), 1.0, 1e-12);
  EXPECT_LT((m.vertices.row(s.probes[0].vertex).transpose() - Eigen::Vector3d(1, 0.5, -0.5)).norm(), 1e-12);

  // Translation alone is exact; a zero angle changes nothing.
  const Scene t = load(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [2, 2], "translate": [0, 0, 2]}})");
  const Scene u = load(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [2, 2],
                           "rotate": {"axis": [0, 1, 0], "angle_deg": 0}}})");
  const Scene plain = load(R"({"mesh": {"primitive": "grid", "size": [1, 1], "divisions": [2, 2]}})");
  ASSERT_EQ(t.problem.mesh.num_vertices(), plain.problem.mesh.num_vertices());
  Eigen::MatrixX3d shifted = plain.problem.mesh.vertices;
  shifted.col(2).array() += 2.0;
  EXPECT_LT((t.problem.mesh.vertices - shifted).cwiseAbs().maxCoeff(), 1e-15);
  ASSERT_EQ(u.problem.mesh.num_vertices(), plain.problem.mesh.num_vertices());
  EXPECT_LT((u.problem.mesh.vertices - plain.problem.mesh.vertices).cwiseAbs().maxCoeff(), 1e-15);

  // A cylinder (axis +y) laid along -x by a quarter turn about z.
  const Scene c = load(R"({"mesh": {"primitive": "cylinder", "radius": 0.1, "length": 0.4, "segments": 8, "rings": 3,
                           "rotate": {"axis": [0, 0, 1], "angle_deg": 90}}})");
  const TriMesh& cyl = c.problem.mesh;
  for (Eigen::Index v = 0; v < cyl.vertices.rows(); ++v) {
    ASSERT_NEAR(std::hypot(cyl.vertices(v, 1), cyl.vertices(v, 2)), 0.1, 1e-12);
    ASSERT_LE(cyl.vertices(v, 0), 1e-12);
    ASSERT_GE(cyl.vertices(v, 0), -0.4 - 1e-12);
  }
}

// ---- Through the clothsim command ------------------------------------------------------------

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

class ContactKeysCli : public ContactKeys {
 protected:
  RunResult run_scene(const fs::path& scene, const std::string& extra = "") const {
    using clothsim::testing::shell_quote;
    const fs::path out_file = dir_ / "stdout.txt", err_file = dir_ / "stderr.txt";
    const std::string command = shell_quote(CLOTHSIM_BINARY) + " " + shell_quote(scene.string()) + " --out " +
                                shell_quote(out().string()) + " " + extra + " >" + shell_quote(out_file.string()) +
                                " 2>" + shell_quote(err_file.string());
    const int status = std::system(command.c_str());
    RunResult r;
    r.exit_code = (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
    r.out = clothsim::testing::read_file_bytes(out_file);
    r.err = clothsim::testing::read_file_bytes(err_file);
    return r;
  }
  fs::path out() const { return dir_ / "out"; }
};

TEST_F(ContactKeysCli, BadContactKeysWriteNothing) {
  write("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  const std::string grid = R"("mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]})";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {dynamic_scene(R"(, "collision": {"self": true, "thickness": 0})"), "collision.thickness: must be > 0 [m] (got 0)"},
      {dynamic_scene(R"(, "collision": {"friction": -0.1})"), "collision.friction: must be >= 0 [-] (got -0.1)"},
      {with_obstacles(R"([{"primitive": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]},
                          {"primitive": "sphere", "center": [0, 0, 0], "radius": 0}])"),
       "obstacles[1].radius: must be > 0 [m] (got 0)"},
      {with_obstacles(R"([{"obj": "missing.obj"}])"), "obstacles[0].obj: "},
      {with_obstacles(R"([{"obj": "bad_index.obj"}])"), "obstacles[0].obj: "},
      {with_obstacles(R"([{"primitive": "cone"}])"), "obstacles[0].primitive: unknown primitive \"cone\""},
      {dynamic_scene(R"(, "output": {"obj": true, "obj_level": 5})"), "output.obj_level: must be an integer from 0 to 4"},
      {"{" + grid + R"(, "collision": {"self": true}})", "collision: needs \"analysis\": \"dynamic\""},
      {R"({"analysis": "dynamic", "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4],
          "rotate": {"axis": [0, 0, 0], "angle_deg": 90}}})",
       "mesh.rotate.axis: must be a non-zero vector"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const fs::path scene = write("bad" + std::to_string(i) + ".json", cases[i].first);
    const RunResult r = run_scene(scene, "--no-render");
    EXPECT_EQ(r.exit_code, 1) << cases[i].second << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, "clothsim: error: " + scene.string() + ": " + cases[i].second))
        << "expected \"" << cases[i].second << "\" in: " << r.err;
    EXPECT_FALSE(fs::exists(out())) << "output root created for " << cases[i].second;
  }
}

// The implicit response's figures in summary.json are the sums of their stats.csv columns, on a
// run whose response refactorises its Newton matrix (a sheet pressed onto the ground with
// friction and self-collision on, proximity as constraints of the response); and the barrier's
// Newton iterations likewise, on the same run with the default method.
TEST_F(ContactKeysCli, ResponseFiguresSumTheirColumns) {
  auto press = [&](const std::string& name, const std::string& method) {
    return write(name + ".json", R"({"name": ")" + name + R"(", "analysis": "dynamic",
      "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [8, 8],
               "rotate": {"axis": [1, 0, 0], "angle_deg": -90}, "translate": [0, 0.0015, 0]},
      "material": {"preset": "cotton"},
      "loads": {"gravity": [0, -9.81, 0]},
      "time": {"dt": 0.001, "end": 0.004, "output_fps": 500},
      "collision": {"thickness": 0.002, "friction": 0.5, "self": true, "method": ")" + method + R"("},
      "obstacles": [{"name": "ground", "primitive": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}]})");
  };
  // (stats.csv column, summary.json "contact" key)
  auto expect_sums = [&](const std::string& name, const std::vector<std::pair<std::string, std::string>>& columns) {
    std::istringstream in(clothsim::testing::read_file_bytes(out() / name / "stats.csv"));
    std::string field;
    std::getline(in, field);
    std::vector<std::string> names;
    for (std::istringstream header(field); std::getline(header, field, ',');) names.push_back(field);
    std::map<std::string, long long> sums;
    int rows = 0;
    for (std::string row; std::getline(in, row); ++rows) {
      std::istringstream fields(row);
      for (std::size_t k = 0; k < names.size() && std::getline(fields, field, ','); ++k)
        for (const auto& entry : columns)
          if (entry.first == names[k]) sums[names[k]] += std::stoll(field);
    }
    EXPECT_EQ(rows, 4);
    const nlohmann::json summary = nlohmann::json::parse(clothsim::testing::read_file_bytes(out() / name / "summary.json"));
    for (const auto& [column, key] : columns) {
      EXPECT_EQ(sums.count(column), 1u) << column << " is not a column of stats.csv";
      EXPECT_EQ(sums[column], summary["contact"][key].get<long long>()) << column;
      EXPECT_GT(sums[column], 0) << column;  // the cloth is pressed onto the ground: the method works
    }
  };
  const RunResult r = run_scene(press("press", "constraints"), "--no-render");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_sums("press", {{"response_iterations", "response_iterations"},
                        {"response_cg_iterations", "response_cg_iterations"},
                        {"response_factorizations", "response_factorizations"}});
  const RunResult b = run_scene(press("press_barrier", "barrier"), "--no-render");
  ASSERT_EQ(b.exit_code, 0) << b.err;
  expect_sums("press_barrier", {{"contact_newton_iterations", "newton_iterations"}});
}

// A cloth that starts behind a plane (a ground turned into a wall through the sheet, as fuzzing
// found it: the first step ran for minutes and grew to 2 GB) stops at the first step with an error
// naming the obstacle and how deep the cloth is behind it; the run's summary says it failed.
TEST_F(ContactKeysCli, ClothStartingBehindAPlaneIsAnError) {
  const fs::path scene = write("behind.json", R"({"name": "behind", "analysis": "dynamic",
      "mesh": {"primitive": "grid", "size": [0.6, 0.6], "divisions": [12, 12],
               "rotate": {"axis": [1, 0, 0], "angle_deg": -90}, "translate": [0, 0.25, 0]},
      "material": {"preset": "cotton"},
      "loads": {"gravity": [0, -9.81, 0]},
      "time": {"dt": 0.002, "end": 0.1},
      "collision": {"self": true, "thickness": 0.002},
      "obstacles": [{"name": "ground", "primitive": "plane", "point": [0, 0, 0], "normal": [0, 1, 1e6]}]})");
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = run_scene(scene, "--no-render");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(r.exit_code, 0);
  EXPECT_LT(seconds, 30.0);
  EXPECT_TRUE(contains(r.err, "obstacles[0] \"ground\": the cloth starts behind this plane, up to 0.3")) << r.err;
  EXPECT_TRUE(contains(r.err, "step 1 ")) << r.err;
  const nlohmann::json summary = nlohmann::json::parse(clothsim::testing::read_file_bytes(out() / "behind" / "summary.json"));
  EXPECT_EQ(summary["status"], "failed") << summary.dump();
}

// Where a step's time goes is booked apart (issue 44): per stats.csv row the parts (the first
// solve, Newton's further solves, the barrier, the CCD line search, the candidate search, the
// fail-safe) are not negative and add up to at most the whole step; Newton's further solves take
// time exactly in the rows with more than one Newton solve; summary.json's steps with and without
// contact count every step and their times add up to the rows' step times.
TEST_F(ContactKeysCli, StepTimesAreBookedApart) {
  const fs::path scene = write("booked.json", R"({"name": "booked", "analysis": "dynamic",
      "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [8, 8],
               "rotate": {"axis": [1, 0, 0], "angle_deg": -90}, "translate": [0, 0.004, 0]},
      "material": {"preset": "cotton"},
      "loads": {"gravity": [0, -9.81, 0]},
      "initial": {"velocity": [0, -0.5, 0]},
      "time": {"dt": 0.002, "end": 0.02, "output_fps": 50},
      "collision": {"thickness": 0.002, "friction": 0.5, "self": true},
      "obstacles": [{"name": "ground", "primitive": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}]})");
  const RunResult r = run_scene(scene, "--no-render");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream in(clothsim::testing::read_file_bytes(out() / "booked" / "stats.csv"));
  std::string field;
  std::getline(in, field);
  std::map<std::string, std::size_t> column;
  {
    std::istringstream header(field);
    for (std::size_t k = 0; std::getline(header, field, ','); ++k) column[field] = k;
  }
  const std::vector<std::string> parts = {"first_solve_ms", "newton_solve_ms", "barrier_ms", "line_search_ms", "candidates_ms",
                                          "failsafe_ms"};
  for (const std::string& c : parts) ASSERT_EQ(column.count(c), 1u) << c;
  ASSERT_EQ(column.count("step_ms"), 1u);
  double step_sum = 0.0;
  int rows = 0, multi_newton = 0, free_rows = 0;
  for (std::string row; std::getline(in, row); ++rows) {
    std::vector<std::string> f;
    for (std::istringstream fields(row); std::getline(fields, field, ',');) f.push_back(field);
    auto value = [&](const std::string& c) { return std::stod(f.at(column.at(c))); };
    double sum = 0.0;
    for (const std::string& c : parts) {
      EXPECT_GE(value(c), 0.0) << c << " in " << row;
      sum += value(c);
    }
    EXPECT_LE(sum, value("step_ms") * (1 + 1e-6) + 1e-6) << row;
    const int newton = static_cast<int>(value("contact_newton_iterations"));
    if (newton > 1) ++multi_newton;
    if (newton == 0) ++free_rows;
    EXPECT_EQ(value("newton_solve_ms") > 0, newton > 1) << row;
    step_sum += value("step_ms");
  }
  EXPECT_EQ(rows, 10);
  EXPECT_GT(multi_newton, 0);  // the sheet lands within the run: Newton works in some steps
  const nlohmann::json c = nlohmann::json::parse(clothsim::testing::read_file_bytes(out() / "booked" / "summary.json"))["contact"];
  EXPECT_EQ(c["contact_steps"].get<long long>() + c["free_steps"].get<long long>(), rows);
  EXPECT_GT(c["contact_steps"].get<long long>(), 0);
  EXPECT_GE(c["free_steps"].get<long long>(), free_rows);  // (a step without Newton saw no contact)
  EXPECT_NEAR(c["contact_step_seconds"].get<double>() + c["free_step_seconds"].get<double>(), step_sum / 1000.0,
              1e-6 * step_sum / 1000.0 + 1e-9);
  EXPECT_TRUE(contains(r.out, "steps with contact")) << r.out;
}

// A short run: the contact figures appear in stats.csv and summary.json only with contact, and
// OBJ frames at obj_level 1 hold the refined surface with vertex normals.
TEST_F(ContactKeysCli, ContactOutputsOnlyWithContact) {
  const std::string common = R"("analysis": "dynamic",
      "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4],
               "rotate": {"axis": [1, 0, 0], "angle_deg": -90}, "translate": [0, 0.0015, 0]},
      "material": {"preset": "cotton"},
      "loads": {"gravity": [0, -9.81, 0]},
      "time": {"dt": 0.001, "end": 0.004, "output_fps": 500},
      "probes": [{"name": "c", "at": [0, 0.0015, 0]}])";
  const fs::path with = write("touch.json", R"({"name": "touch", )" + common + R"(,
      "collision": {"thickness": 0.002},
      "obstacles": [{"name": "ground", "primitive": "plane", "point": [0, 0, 0], "normal": [0, 1, 0]}],
      "output": {"obj": true, "obj_level": 1}})");
  const fs::path without = write("free.json", R"({"name": "free", )" + common + R"(, "output": {"obj": true}})");

  const RunResult a = run_scene(with, "--no-render");
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const RunResult b = run_scene(without, "--no-render");
  ASSERT_EQ(b.exit_code, 0) << b.err;

  auto first_line = [](const fs::path& file) {
    std::istringstream in(clothsim::testing::read_file_bytes(file));
    std::string line;
    std::getline(in, line);
    return line;
  };
  const std::string contact_columns =
      ",contact_pairs,contact_impulses,impact_zones,contact_unresolved,contact_ms,response_iterations,response_cg_iterations,"
      "response_factorizations,contact_newton_iterations,contact_active_pairs,contact_energy,contact_relinearisations,"
      "step_ms,first_solve_ms,newton_solve_ms,barrier_ms,line_search_ms,candidates_ms,failsafe_ms";
  const std::string header_with = first_line(out() / "touch" / "stats.csv");
  const std::string header_without = first_line(out() / "free" / "stats.csv");
  EXPECT_EQ(header_with.size() >= contact_columns.size() &&
                header_with.compare(header_with.size() - contact_columns.size(), contact_columns.size(),
                                    contact_columns) == 0,
            true)
      << header_with;
  EXPECT_FALSE(contains(header_without, "contact")) << header_without;

  const nlohmann::json sa = nlohmann::json::parse(clothsim::testing::read_file_bytes(out() / "touch" / "summary.json"));
  const nlohmann::json sb = nlohmann::json::parse(clothsim::testing::read_file_bytes(out() / "free" / "summary.json"));
  ASSERT_TRUE(sa.contains("contact")) << sa.dump();
  for (const char* key : {"pairs_tested", "impulses", "impact_zones", "unresolved_pairs", "seconds",
                          "broad_phase_seconds", "narrow_phase_seconds", "response_seconds", "response_iterations",
                          "response_cg_iterations", "response_factorizations", "barrier_evaluation_seconds", "first_solve_seconds", "newton_solve_seconds",
                          "line_search_seconds", "candidates_seconds", "failsafe_seconds", "contact_steps",
                          "contact_step_seconds", "free_steps", "free_step_seconds"})
    EXPECT_TRUE(sa["contact"].contains(key)) << key << ": " << sa.dump();
  EXPECT_GT(sa["contact"]["pairs_tested"].get<long long>(), 0);  // the cloth starts within the thickness
  EXPECT_FALSE(sb.contains("contact")) << sb.dump();

  // obj_level 1: more vertices than control vertices, one `vn` per `v`, faces `f a//a b//b c//c`.
  auto count_prefix = [](const std::string& text, const std::string& prefix) {
    std::istringstream in(text);
    int n = 0;
    for (std::string line; std::getline(in, line);) n += line.rfind(prefix, 0) == 0 ? 1 : 0;
    return n;
  };
  const std::string refined = clothsim::testing::read_file_bytes(out() / "touch" / "frames" / "mesh_0000.obj");
  const std::string plain = clothsim::testing::read_file_bytes(out() / "free" / "frames" / "mesh_0000.obj");
  const int v_refined = count_prefix(refined, "v "), v_plain = count_prefix(plain, "v ");
  EXPECT_EQ(v_plain, 25);
  EXPECT_GT(v_refined, v_plain);
  EXPECT_EQ(count_prefix(refined, "vn "), v_refined);
  EXPECT_EQ(count_prefix(plain, "vn "), 0);
  EXPECT_GT(count_prefix(refined, "f "), 0);
  std::istringstream lines(refined);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("f ", 0) == 0) {
      std::istringstream f(line.substr(2));
      for (std::string corner; f >> corner;) {
        const auto slashes = corner.find("//");
        ASSERT_NE(slashes, std::string::npos) << line;
        ASSERT_EQ(corner.substr(0, slashes), corner.substr(slashes + 2)) << line;
      }
    }
}

}  // namespace
}  // namespace clothsim

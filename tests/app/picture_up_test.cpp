// The automatic camera's up (render.up; scenes/README.md): opposite to gravity by default, so a
// z-up scene is drawn upright; +y without gravity; the scene's own render.up wins; a y-up scene's
// camera is the one it always had. Built through the scene loader and the drawer directly.
#include "app/limit_surface_drawer.hpp"

#include "sim/dynamics/simulator.hpp"
#include "sim/scene/scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace clothsim {
namespace {

render::Camera auto_camera(const std::string& extra) {
  const std::string text = R"({"name": "up", "analysis": "dynamic",
    "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4]},
    "time": {"dt": 0.01, "end": 0.02})" + extra + "}";
  const Scene scene = load_scene_text(text, "up.json", LogFn());
  const Simulator sim(scene.problem);
  const LimitSurfaceDrawer drawer(sim.discretization(), scene.render, 160, 120);
  const SurfaceSnapshot s = drawer.snapshot(sim.state().x);
  render::Vec3f lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  LimitSurfaceDrawer::extend_bounds(s, lo, hi);
  return drawer.camera(lo, hi);
}

// Upright: the picture's up is `up` made perpendicular to the view (the camera's up, as
// frame_bounds makes it), and the eye looks a little down along `up`.
void expect_upright(const render::Camera& c, const Eigen::Vector3d& up) {
  const Eigen::Vector3d eye(c.eye[0], c.eye[1], c.eye[2]), target(c.target[0], c.target[1], c.target[2]);
  const Eigen::Vector3d view = (target - eye).normalized();
  const Eigen::Vector3d cam_up = Eigen::Vector3d(c.up[0], c.up[1], c.up[2]).normalized();
  const Eigen::Vector3d picture_up = (cam_up - cam_up.dot(view) * view).normalized();
  EXPECT_NEAR((picture_up - (up - up.dot(view) * view).normalized()).norm(), 0.0, 1e-5);
  // Looking a little down: the view has a negative component along up (0.35 / |(0.35, -0.35, -1)|).
  EXPECT_NEAR(view.dot(up), -0.35 / std::sqrt(0.35 * 0.35 * 2 + 1), 1e-5);
}

TEST(PictureUp, OppositeToGravityByDefault) {
  expect_upright(auto_camera(R"(, "loads": {"gravity": [0, 0, -9.81]})"), Eigen::Vector3d::UnitZ());
  expect_upright(auto_camera(R"(, "loads": {"gravity": [0, -9.81, 0]})"), Eigen::Vector3d::UnitY());
  expect_upright(auto_camera(""), Eigen::Vector3d::UnitY());  // no gravity: +y
  expect_upright(auto_camera(R"(, "loads": {"gravity": [0, 0, -9.81]}, "render": {"up": [1, 0, 0]})"),
                 Eigen::Vector3d::UnitX());
  // With a ground (the x–z plane below the cloth) +y stays up, or the ground would hide the cloth.
  expect_upright(auto_camera(R"(, "loads": {"gravity": [0, 0, -9.81]}, "render": {"ground": true})"),
                 Eigen::Vector3d::UnitY());
}

TEST(PictureUp, AYUpSceneKeepsItsCamera) {
  // Exactly the view of before: along (0.35, -0.35, -1), +y up.
  const render::Camera c = auto_camera(R"(, "loads": {"gravity": [0, -9.81, 0]})");
  const Eigen::Vector3d eye(c.eye[0], c.eye[1], c.eye[2]), target(c.target[0], c.target[1], c.target[2]);
  const Eigen::Vector3d view = (target - eye).normalized();
  EXPECT_NEAR((view - Eigen::Vector3d(0.35, -0.35, -1.0).normalized()).norm(), 0.0, 1e-6);
  expect_upright(c, Eigen::Vector3d::UnitY());
}

TEST(PictureUp, ZeroUpIsAnError) {
  EXPECT_THROW(auto_camera(R"(, "render": {"up": [0, 0, 0]})"), SceneError);
}

}  // namespace
}  // namespace clothsim

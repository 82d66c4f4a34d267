// The automatic camera's up (render.up; scenes/README.md): opposite to gravity by default, so a
// z-up scene is drawn upright; +y without gravity; the scene's own render.up wins; a y-up scene's
// camera is the one it always had. The ground lies normal to it: a z-up scene's default picture
// is the y-up picture of the same scene turned, ground and shadow included. Built through the
// scene loader, the drawer and the renderer directly.
#include "app/limit_surface_drawer.hpp"

#include "render/renderer.hpp"
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
  // The ground (on by default with gravity) lies normal to up, so it no longer holds +y.
  expect_upright(auto_camera(R"(, "loads": {"gravity": [0, 0, -9.81]}, "render": {"ground": true})"),
                 Eigen::Vector3d::UnitZ());
}

TEST(PictureUp, AYUpSceneKeepsItsCamera) {
  // Exactly the view of before: along (0.35, -0.35, -1), +y up.
  const render::Camera c = auto_camera(R"(, "loads": {"gravity": [0, -9.81, 0]})");
  const Eigen::Vector3d eye(c.eye[0], c.eye[1], c.eye[2]), target(c.target[0], c.target[1], c.target[2]);
  const Eigen::Vector3d view = (target - eye).normalized();
  EXPECT_NEAR((view - Eigen::Vector3d(0.35, -0.35, -1.0).normalized()).norm(), 0.0, 1e-6);
  expect_upright(c, Eigen::Vector3d::UnitY());
}

// The default picture of a sheet held flat 0.1 m above the ground (the framed box reaches that
// far below it), with gravity along `gravity` and the mesh turned by `mesh_placement`.
render::Image default_picture(const std::string& gravity, const std::string& mesh_placement, int down_axis,
                              bool shadow) {
  const std::string text = R"({"name": "up", "analysis": "dynamic",
    "mesh": {"primitive": "grid", "size": [0.2, 0.2], "divisions": [4, 4])" + mesh_placement + R"(},
    "time": {"dt": 0.01, "end": 0.02}, "loads": {"gravity": )" + gravity + R"(},
    "render": {"shadow": )" + (shadow ? "true" : "false") + "}}";
  const Scene scene = load_scene_text(text, "up.json", LogFn());
  EXPECT_TRUE(scene.render.ground);  // on by default with gravity
  const Simulator sim(scene.problem);
  const LimitSurfaceDrawer drawer(sim.discretization(), scene.render, 160, 120);
  const SurfaceSnapshot s = drawer.snapshot(sim.state().x);
  render::Vec3f lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  LimitSurfaceDrawer::extend_bounds(s, lo, hi);
  lo[static_cast<std::size_t>(down_axis)] -= 0.1f;
  render::Renderer renderer(160, 120);
  return renderer.render(drawer.frame(s, drawer.camera(lo, hi), lo, hi));
}

TEST(PictureUp, AZUpSceneStandsOnItsGroundWithItsShadow) {
  // The grid lies in z = 0: flat in a z-up world; turned by −90° about x it is the x–z plane of
  // a y-up world, and the whole scene is the z-up one turned the same way.
  const render::Image z_up = default_picture("[0, 0, -9.81]", "", 2, true);
  const render::Image y_up =
      default_picture("[0, -9.81, 0]", R"(, "rotate": {"axis": [1, 0, 0], "angle_deg": -90})", 1, true);
  ASSERT_EQ(z_up.rgb.size(), y_up.rgb.size());
  // The same picture: only round-off (the shadow map's texels lie differently) tells them apart.
  std::size_t differ = 0;
  for (std::size_t i = 0; i < z_up.rgb.size(); ++i) differ += std::abs(int(z_up.rgb[i]) - int(y_up.rgb[i])) > 16;
  EXPECT_LT(differ, z_up.rgb.size() / 200) << differ << " of " << z_up.rgb.size() << " channels differ by more than 16";
  // The ground is there (light grey, not the white background, at the bottom centre) and the
  // shadow darkens part of it: pixels much darker than without the shadow, all of them grey.
  const render::Image plain = default_picture("[0, 0, -9.81]", "", 2, false);
  auto at = [](const render::Image& image, int x, int y, int c) {
    return int(image.rgb[3 * (static_cast<std::size_t>(y) * 160 + static_cast<std::size_t>(x)) + static_cast<std::size_t>(c)]);
  };
  EXPECT_LT(at(plain, 80, 118, 0), 250);
  EXPECT_EQ(at(plain, 80, 118, 0), at(plain, 80, 118, 2));  // grey
  auto grey = [&](int x, int y) {
    return at(plain, x, y, 0) == at(plain, x, y, 1) && at(plain, x, y, 1) == at(plain, x, y, 2);
  };
  int shadowed = 0, cloth = 0, cloth_changed = 0;
  for (int y = 1; y + 1 < 120; ++y) {
    for (int x = 1; x + 1 < 160; ++x) {
      shadowed += grey(x, y) && at(z_up, x, y, 1) < at(plain, x, y, 1) - 30;
      // The cloth's own pixels (none of the 3 × 3 around them grey: no edge blended with the
      // ground) are untouched.
      bool inside = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) inside = inside && !grey(x + dx, y + dy);
      cloth += inside;
      cloth_changed += inside && (at(z_up, x, y, 0) != at(plain, x, y, 0) || at(z_up, x, y, 1) != at(plain, x, y, 1));
    }
  }
  EXPECT_GT(shadowed, 160 * 120 / 50) << "the shadow covers too little of the ground";
  EXPECT_GT(cloth, 160 * 120 / 20);
  EXPECT_EQ(cloth_changed, 0) << "the shadow falls on the ground only";
}

TEST(PictureUp, ZeroUpIsAnError) {
  EXPECT_THROW(auto_camera(R"(, "render": {"up": [0, 0, 0]})"), SceneError);
}

}  // namespace
}  // namespace clothsim

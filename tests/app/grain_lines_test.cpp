// render.texture "grain" (app/limit_surface_drawer.hpp): a line along the warp across every
// control triangle, moving with the triangle's affine map; none without the key.
#include "app/limit_surface_drawer.hpp"

#include "sim/loop_shell/loop_shell.hpp"
#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace clothsim {
namespace {

TEST(GrainLines, RunAlongTheWarpAndFollowTheDeformation) {
  TriMesh mesh = make_grid(0.2, 0.1, 4, 2);
  const double angle = 30.0 * M_PI / 180.0;
  mesh.warp.assign(mesh.triangles.size(), Eigen::Vector3d(std::cos(angle), std::sin(angle), 0));
  const LoopShellDiscretization d(mesh, {}, ShellMaterial{}, Quadrature::one_point);
  RenderSettings settings;
  settings.refine = 0;
  EXPECT_TRUE(LimitSurfaceDrawer(d, settings, 64, 48).snapshot(d.rest()).grain.empty());  // texture "none"
  settings.texture = "grain";
  const LimitSurfaceDrawer drawer(d, settings, 64, 48);
  // At rest: one segment per triangle along (cos 30°, sin 30°, 0), through the centroid.
  const SurfaceSnapshot rest = drawer.snapshot(d.rest());
  ASSERT_EQ(rest.grain.size(), 6 * mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3f a(rest.grain[6 * t], rest.grain[6 * t + 1], rest.grain[6 * t + 2]);
    const Eigen::Vector3f b(rest.grain[6 * t + 3], rest.grain[6 * t + 4], rest.grain[6 * t + 5]);
    const Eigen::Vector3f dir = (b - a).normalized();
    EXPECT_NEAR(dir.x(), std::cos(angle), 1e-5) << t;
    EXPECT_NEAR(dir.y(), std::sin(angle), 1e-5) << t;
    const Triangle& tri = mesh.triangles[t];
    const Eigen::Vector3d centroid = (mesh.vertices.row(tri[0]) + mesh.vertices.row(tri[1]) + mesh.vertices.row(tri[2])).transpose() / 3;
    EXPECT_LT((((a + b) / 2).cast<double>() - centroid).norm(), 1e-6) << t;
  }
  // Stretched by 2 along x: the lines turn to (2 cos 30°, sin 30°, 0).
  Eigen::VectorXd x = d.rest();
  for (Eigen::Index i = 0; i < x.size(); i += 3) x(i) *= 2;
  const SurfaceSnapshot stretched = drawer.snapshot(x);
  const Eigen::Vector3f a(stretched.grain[0], stretched.grain[1], stretched.grain[2]);
  const Eigen::Vector3f b(stretched.grain[3], stretched.grain[4], stretched.grain[5]);
  const Eigen::Vector3f expected = Eigen::Vector3d(2 * std::cos(angle), std::sin(angle), 0).normalized().cast<float>();
  EXPECT_LT(((b - a).normalized() - expected).norm(), 1e-5);
  // The frame carries them as a line overlay.
  const render::Frame f = drawer.frame(rest, render::Camera{}, {0, 0, 0}, {0, 0, 0});
  ASSERT_EQ(f.lines.size(), 1u);
  EXPECT_EQ(f.lines[0].segments.size(), 2 * mesh.triangles.size());
}

}  // namespace
}  // namespace clothsim

namespace clothsim {
namespace {

// render.texture "checker": squares of RenderSettings::kCheckerCell on the texture coordinates,
// the darker ones drawn as a second mesh over the same points.
TEST(CheckerTexture, SplitsTheFineTrianglesBySquare) {
  // A 0.2 m x 0.1 m grid whose texture coordinates are its own x, y in metres: 4 x 2 squares of
  // 5 cm, every other one dark, so half of the surface's area is dark.
  TriMesh mesh = make_grid(0.2, 0.1, 8, 4);
  for (const Triangle& t : mesh.triangles) {
    std::array<Eigen::Vector2d, 3> c;
    for (int k = 0; k < 3; ++k) c[static_cast<size_t>(k)] = mesh.vertices.row(t[static_cast<size_t>(k)]).head<2>().transpose();
    mesh.uv.push_back(c);
  }
  const LoopShellDiscretization d(mesh, {}, ShellMaterial{}, Quadrature::one_point);
  RenderSettings settings;
  settings.refine = 1;
  settings.texture = "checker";
  const LimitSurfaceDrawer drawer(d, settings, 64, 48);
  const render::Frame f = drawer.frame(drawer.snapshot(d.rest()), render::Camera{}, {0, 0, 0}, {0, 0, 0});
  ASSERT_EQ(f.meshes.size(), 2u);
  const std::size_t light = f.meshes[0].triangles.size() / 3, dark = f.meshes[1].triangles.size() / 3;
  EXPECT_EQ(light + dark, 4 * mesh.triangles.size());
  EXPECT_EQ(light, dark);  // the grid's cells never straddle a square: exactly half each
  EXPECT_LT(f.meshes[1].color[0], f.meshes[0].color[0]);
  // Without texture coordinates the checker is not drawn (the scene loader refuses it before).
  TriMesh bare = mesh;
  bare.uv.clear();
  const LoopShellDiscretization plain(bare, {}, ShellMaterial{}, Quadrature::one_point);
  const LimitSurfaceDrawer no_uv(plain, settings, 64, 48);
  EXPECT_EQ(no_uv.frame(no_uv.snapshot(plain.rest()), render::Camera{}, {0, 0, 0}, {0, 0, 0}).meshes.size(), 1u);
}

}  // namespace
}  // namespace clothsim

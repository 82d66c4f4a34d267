// The adapter between the simulation and the renderer: turns node positions into plain
// render::Frame data — the surface refined `render.refine` times (positions and normals from the
// discretisation's display operator, built once), the control mesh as an optional wireframe, the
// scene's colours and a camera (given, or framed once on a box: a whole sequence's bounds, or the
// box known before a run, see app/frame_images.hpp).
#pragma once

#include "render/frame.hpp"
#include "sim/scene/scene.hpp"
#include "sim/discretization/discretization.hpp"

#include <Eigen/Core>

namespace clothsim {

// One frame's geometry, kept in single precision until it is drawn.
struct SurfaceSnapshot {
  std::vector<float> positions;  // limit surface, 3 per fine vertex [m]
  std::vector<float> normals;    // unit normals, 3 per fine vertex
  std::vector<float> control;    // control mesh vertices (wireframe), 3 per vertex [m]
};

class LimitSurfaceDrawer {
 public:
  // `discretization` must outlive the drawer.
  LimitSurfaceDrawer(const Discretization& discretization, const RenderSettings& settings, int width, int height);

  // `x`: node positions (3·#nodes, flat) [m].
  SurfaceSnapshot snapshot(const Eigen::VectorXd& x) const;
  // Grows the box [lo, hi] to hold the snapshot.
  static void extend_bounds(const SurfaceSnapshot& s, render::Vec3f& lo, render::Vec3f& hi);
  // The scene's camera, or one that frames the box [lo, hi] (viewed slightly from above).
  render::Camera camera(const render::Vec3f& lo, const render::Vec3f& hi) const;
  // `ground_height`: y of the ground plane (when render.ground), e.g. the sequence's lowest y.
  render::Frame frame(const SurfaceSnapshot& s, const render::Camera& camera, float ground_height) const;

  int fine_triangles() const { return static_cast<int>(triangles_.size() / 3); }

 private:
  const Discretization& discretization_;
  SurfaceOperator display_;
  std::vector<unsigned> triangles_;  // fine triangles
  std::vector<unsigned> edges_;      // edges of the mesh's triangles (wireframe over the nodes)
  RenderSettings settings_;
  int width_, height_;
};

}  // namespace clothsim

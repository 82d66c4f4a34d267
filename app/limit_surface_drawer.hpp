// The adapter between the simulation and the renderer: turns node positions into plain
// render::Frame data — the surface chosen by `render.surface` refined `render.refine` times
// (positions and normals from the discretisation's operator for it, Discretization::drawn_display,
// built once; by default the method's own surface), the control mesh as an optional wireframe, the
// scene's colours, with render.texture "grain" a line along the warp across each control triangle,
// and a camera (given, or framed once on a box: a whole sequence's bounds, or the
// box known before a run, see app/frame_images.hpp).
#pragma once

#include "render/frame.hpp"
#include "sim/scene/scene.hpp"
#include "sim/discretization/discretization.hpp"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <string>

namespace clothsim {

// What a picture shows, for summary.json and result.json: {"surface": "loop_limit" or "flat"
// (render.surface resolved for the method), "refine": k, "description": "Loop limit surface
// refined 2x"} (sim/discretization/drawn_surface.hpp).
nlohmann::ordered_json drawn_surface_json(const std::string& method, const RenderSettings& settings);

// One frame's geometry, kept in single precision until it is drawn.
struct SurfaceSnapshot {
  std::vector<float> positions;  // the drawn surface, 3 per fine vertex [m]
  std::vector<float> normals;    // unit normals, 3 per fine vertex
  std::vector<float> control;    // control mesh vertices (wireframe), 3 per vertex [m]
  std::vector<float> obstacles;  // the obstacles' mesh vertices at the frame's time, 3 per vertex [m]
  float plane_height = 0.0f;     // height along render.up of the ground plane obstacle at the frame's time [m]
  std::vector<float> grain;      // render.texture "grain": two end points per control triangle [m]
};

class LimitSurfaceDrawer {
 public:
  // `discretization` must outlive the drawer.
  LimitSurfaceDrawer(const Discretization& discretization, const RenderSettings& settings, int width, int height);

  // Obstacles drawn with the cloth: the meshes of every non-plane obstacle (the geometry that
  // collides), and a plane whose normal is ± the pictures' up (render.up, by default opposite
  // to gravity) as the ground; other planes are not drawn.
  void set_obstacles(const std::vector<Obstacle>& obstacles);
  // `x`: node positions (3·#nodes, flat) [m] at time `t` [s] (where the obstacles are).
  SurfaceSnapshot snapshot(const Eigen::VectorXd& x, double t = 0.0) const;
  // Grows the box [lo, hi] to hold the snapshot's cloth.
  static void extend_bounds(const SurfaceSnapshot& s, render::Vec3f& lo, render::Vec3f& hi);
  // The scene's camera, or one that frames the box [lo, hi] (viewed slightly from above).
  render::Camera camera(const render::Vec3f& lo, const render::Vec3f& hi) const;
  // With render.ground the ground is the plane normal to render.up through the lowest corner
  // of the box [lo, hi] (the framed box: the sequence's, or the one known before a run) or the
  // lowest obstacle vertex of the snapshot if that lies lower (so no obstacle pierces it), with
  // the cloth's and the obstacles' shadow unless render.shadow is false; a plane obstacle normal
  // to render.up is drawn as the ground at its own height instead (with or without
  // render.ground).
  render::Frame frame(const SurfaceSnapshot& s, const render::Camera& camera, const render::Vec3f& lo,
                      const render::Vec3f& hi) const;

  int fine_triangles() const { return static_cast<int>(triangles_.size() / 3); }

 private:
  const Discretization& discretization_;
  SurfaceOperator display_;
  std::vector<unsigned> triangles_;  // fine triangles
  std::vector<unsigned> edges_;      // edges of the mesh's triangles (wireframe over the nodes)
  // render.texture "grain": per control triangle, the two end points of its rest warp line as
  // coefficients (b₁, b₂) on its rest edges (P = X₀ + b₁ (X₁ − X₀) + b₂ (X₂ − X₀)), 4 per
  // triangle; the line's end points move with the triangle's affine map. Empty without grain.
  std::vector<double> grain_coefficients_;
  std::vector<unsigned> grain_segments_;
  // render.texture "checker": the fine triangles of the darker squares (drawn as a second mesh;
  // triangles_ then holds the others).
  std::vector<unsigned> checker_triangles_;
  RenderSettings settings_;
  int width_, height_;
  std::vector<Obstacle> obstacles_;    // drawn meshes (no planes)
  std::vector<unsigned> obstacle_triangles_;
  int ground_plane_ = -1;              // index into planes_ of the plane drawn as the ground
  std::vector<Obstacle> planes_;
};

}  // namespace clothsim

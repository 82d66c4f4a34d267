// The adapter between the simulation and the renderer: turns control-mesh positions into plain
// render::Frame data — the limit surface refined `render.refine` times (positions and normals
// from a sparse operator built once), the control mesh as an optional wireframe, the scene's
// colours and a camera (given, or framed once on a box: a whole sequence's bounds, or the box
// known before a run, see app/frame_images.hpp).
#pragma once

#include "render/frame.hpp"
#include "sim/scene/scene.hpp"
#include "sim/shell/ghost_layer.hpp"
#include "sim/subdivision/limit_refinement.hpp"

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
  LimitSurfaceDrawer(const ExtendedMesh& mesh, const RenderSettings& settings, int width, int height);

  // `extended_positions`: #ext × 3 positions of the control mesh with its ghost layer.
  SurfaceSnapshot snapshot(const Eigen::MatrixX3d& extended_positions) const;
  // Grows the box [lo, hi] to hold the snapshot.
  static void extend_bounds(const SurfaceSnapshot& s, render::Vec3f& lo, render::Vec3f& hi);
  // The scene's camera, or one that frames the box [lo, hi] (viewed slightly from above).
  render::Camera camera(const render::Vec3f& lo, const render::Vec3f& hi) const;
  // `ground_height`: y of the ground plane (when render.ground), e.g. the sequence's lowest y.
  render::Frame frame(const SurfaceSnapshot& s, const render::Camera& camera, float ground_height) const;

  int fine_triangles() const { return static_cast<int>(triangles_.size() / 3); }

 private:
  LimitRefinement refinement_;
  std::vector<unsigned> triangles_;  // fine triangles
  std::vector<unsigned> edges_;      // control-mesh edges of the real triangles (wireframe)
  int num_real_ = 0;
  RenderSettings settings_;
  int width_, height_;
};

}  // namespace clothsim

// Camera geometry shared by the renderer and its callers: view and projection matrices
// (column-major, as GL expects), projecting a world point to pixel coordinates, and framing an
// axis-aligned box with a camera.
#pragma once

#include <array>

#include "render/frame.hpp"

namespace clothsim::render {

using Mat4f = std::array<float, 16>;  // column-major: element (row r, column c) is [4 c + r]

// Rigid world-to-camera transform: the camera sits at the origin looking down −z with +y up.
// Throws std::invalid_argument if eye == target or any coordinate is not finite. If camera.up
// is (nearly) parallel to the viewing direction another up vector is used.
Mat4f view_matrix(const Camera& camera);

// OpenGL perspective projection; fov_deg is the vertical field of view.
Mat4f projection_matrix(float fov_deg, float aspect, float near_plane, float far_plane);

struct PixelPosition {
  float x = 0;      // pixels from the left image edge (pixel centres at 0.5, 1.5, ...)
  float y = 0;      // pixels from the top image edge
  float depth = 0;  // distance in front of the camera along the viewing direction
};

// Where `point` lands in a width × height image taken with `camera` (as Renderer::render draws
// it). The point is in front of the camera iff depth > 0; x, y are meaningless otherwise.
PixelPosition project_to_pixel(const Camera& camera, int width, int height, const Vec3f& point);

// A camera looking along `view_direction` (from the eye towards the scene) that frames the
// axis-aligned box [lo, hi]: the camera comes as close as the box's eight corners allow while
// they stay inside both the vertical field of view `fov_deg` and the horizontal one for the
// image aspect ratio `aspect` (= width / height), with a 5 % margin, and the projected box is
// centred (so the box fills the image in the direction that binds). Use it to fix one camera for a whole animation. If `up` is parallel to the
// view direction another up vector is chosen. Throws std::invalid_argument for a zero or
// non-finite view direction, non-finite bounds, fov_deg outside (0, 180) or a non-positive
// aspect.
Camera frame_bounds(const Vec3f& lo, const Vec3f& hi, float fov_deg, Vec3f view_direction, Vec3f up,
                    float aspect = 4.0f / 3.0f);

}  // namespace clothsim::render

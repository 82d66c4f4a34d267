// Camera geometry: look-at and perspective matrices, point projection, box framing.
#include "render/camera_math.hpp"

#include "render/vec3d.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace clothsim::render {
namespace {

using namespace detail;

// Unit right, up and backward (−forward) axes of a camera looking along `forward`.
struct Basis {
  Vec3d right, up, back;
};

Basis camera_basis(const Vec3d& forward, const Vec3d& up_hint) {
  const Vec3d f = (1.0 / norm(forward)) * forward;
  Vec3d r = cross(f, up_hint);
  // An up hint (nearly) parallel to the viewing direction: use the world axis least aligned
  // with it instead.
  if (norm(r) < 1e-6 * std::max(norm(up_hint), 1e-300)) {
    const Vec3d candidates[3] = {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}};
    const Vec3d* best = &candidates[0];
    for (const Vec3d& c : candidates) {
      if (std::abs(dot(c, f)) < std::abs(dot(*best, f))) best = &c;
    }
    r = cross(f, *best);
  }
  r = (1.0 / norm(r)) * r;
  return {r, cross(r, f), -1.0 * f};
}

Mat4f to_float(const double (&m)[16]) {
  Mat4f out{};
  for (std::size_t i = 0; i < 16; ++i) out[i] = static_cast<float>(m[i]);
  return out;
}

}  // namespace

Mat4f view_matrix(const Camera& camera) {
  const Vec3d eye = to_d(camera.eye);
  const Vec3d target = to_d(camera.target);
  const Vec3d up = to_d(camera.up);
  if (!finite(eye) || !finite(target) || !finite(up)) {
    throw std::invalid_argument("render camera: eye, target and up must be finite");
  }
  const Vec3d forward = target - eye;
  if (!(norm(forward) > 0)) {
    throw std::invalid_argument("render camera: eye and target coincide");
  }
  const Basis b = camera_basis(forward, up);
  // Rows of the rotation are the camera axes; translation moves the eye to the origin.
  const double m[16] = {b.right.x,          b.up.x,          b.back.x,          0,  //
                        b.right.y,          b.up.y,          b.back.y,          0,  //
                        b.right.z,          b.up.z,          b.back.z,          0,  //
                        -dot(b.right, eye), -dot(b.up, eye), -dot(b.back, eye), 1};
  return to_float(m);
}

Mat4f projection_matrix(float fov_deg, float aspect, float near_plane, float far_plane) {
  const double f = 1.0 / std::tan(0.5 * static_cast<double>(fov_deg) * std::numbers::pi / 180.0);
  const double n = near_plane;
  const double fa = far_plane;
  const double m[16] = {f / static_cast<double>(aspect),
                        0,
                        0,
                        0,  //
                        0,
                        f,
                        0,
                        0,  //
                        0,
                        0,
                        (fa + n) / (n - fa),
                        -1,  //
                        0,
                        0,
                        2 * fa * n / (n - fa),
                        0};
  return to_float(m);
}

PixelPosition project_to_pixel(const Camera& camera, int width, int height, const Vec3f& point) {
  const Mat4f v = view_matrix(camera);
  const double x = v[0] * point[0] + v[4] * point[1] + v[8] * point[2] + v[12];
  const double y = v[1] * point[0] + v[5] * point[1] + v[9] * point[2] + v[13];
  const double z = v[2] * point[0] + v[6] * point[1] + v[10] * point[2] + v[14];
  const double depth = -z;
  const double f =
      1.0 / std::tan(0.5 * static_cast<double>(camera.fov_deg) * std::numbers::pi / 180.0);
  const double aspect = static_cast<double>(width) / static_cast<double>(height);
  PixelPosition p;
  p.depth = static_cast<float>(depth);
  if (depth > 0) {
    const double ndc_x = f / aspect * x / depth;
    const double ndc_y = f * y / depth;
    p.x = static_cast<float>(0.5 * (ndc_x + 1.0) * width);
    p.y = static_cast<float>(0.5 * (1.0 - ndc_y) * height);
  }
  return p;
}

Camera frame_bounds(const Vec3f& lo, const Vec3f& hi, float fov_deg, Vec3f view_direction, Vec3f up,
                    float aspect) {
  const Vec3d l = to_d(lo);
  const Vec3d h = to_d(hi);
  const Vec3d dir = to_d(view_direction);
  if (!finite(l) || !finite(h)) throw std::invalid_argument("frame_bounds: bounds not finite");
  if (!finite(dir) || !(norm(dir) > 0)) {
    throw std::invalid_argument("frame_bounds: view direction must be finite and non-zero");
  }
  if (!(fov_deg > 0 && fov_deg < 180)) {
    throw std::invalid_argument("frame_bounds: fov_deg must lie in (0, 180), got " +
                                std::to_string(fov_deg));
  }
  if (!(aspect > 0) || !std::isfinite(aspect)) {
    throw std::invalid_argument("frame_bounds: aspect must be positive");
  }
  // The tightest eye position along the viewing direction that keeps all eight corners inside
  // the frustum whose half-angle tangents are shrunk by the margin, the projected box centred in
  // the binding direction. In camera coordinates (r, u, f: right, up, forward) a corner c is
  // inside iff |c_r − e_r| ≤ t_h (c_f − e_f) and |c_u − e_u| ≤ t_v (c_f − e_f); for the
  // horizontal pair that reads e_r − t_h e_f ≥ A = max(c_r − t_h c_f) and
  // −e_r − t_h e_f ≥ B = max(−c_r − t_h c_f), so the eye can come forward to
  // e_f = −(A + B) / (2 t_h), centred at e_r = (A − B) / 2 (likewise vertically); the smaller of
  // the two e_f binds, and the other direction keeps its centre.
  Vec3d lo_box = l, hi_box = h;
  if (!(norm(h - l) > 0)) {  // a point: frame a tiny box around it
    lo_box = l - 1e-3 * Vec3d{1, 1, 1};
    hi_box = h + 1e-3 * Vec3d{1, 1, 1};
  }
  const Vec3d centre = 0.5 * (lo_box + hi_box);
  const double half_v = 0.5 * static_cast<double>(fov_deg) * std::numbers::pi / 180.0;
  const double margin = 1.05;
  const double t_v = std::tan(half_v) / margin;
  const double t_h = std::tan(half_v) * static_cast<double>(aspect) / margin;
  const Basis b = camera_basis(dir, to_d(up));
  const Vec3d f = -1.0 * b.back;
  const double inf = std::numeric_limits<double>::infinity();
  double a_h = -inf, b_h = -inf, a_v = -inf, b_v = -inf;
  for (int i = 0; i < 8; ++i) {
    const Vec3d c{(i & 1) != 0 ? hi_box.x : lo_box.x, (i & 2) != 0 ? hi_box.y : lo_box.y,
                  (i & 4) != 0 ? hi_box.z : lo_box.z};
    const double cr = dot(c, b.right), cu = dot(c, b.up), cf = dot(c, f);
    a_h = std::max(a_h, cr - t_h * cf);
    b_h = std::max(b_h, -cr - t_h * cf);
    a_v = std::max(a_v, cu - t_v * cf);
    b_v = std::max(b_v, -cu - t_v * cf);
  }
  const double e_f = std::min(-(a_h + b_h) / (2 * t_h), -(a_v + b_v) / (2 * t_v));
  const Vec3d eye = 0.5 * (a_h - b_h) * b.right + 0.5 * (a_v - b_v) * b.up + e_f * f;
  // The target: on the axis, as deep as the box centre.
  const Vec3d target = eye + (dot(centre, f) - e_f) * f;
  Camera camera;
  camera.eye = {static_cast<float>(eye.x), static_cast<float>(eye.y), static_cast<float>(eye.z)};
  camera.target = {static_cast<float>(target.x), static_cast<float>(target.y),
                   static_cast<float>(target.z)};
  camera.up = {static_cast<float>(b.up.x), static_cast<float>(b.up.y), static_cast<float>(b.up.z)};
  camera.fov_deg = fov_deg;
  return camera;
}

}  // namespace clothsim::render

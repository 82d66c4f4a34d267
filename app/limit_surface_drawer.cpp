#include "app/limit_surface_drawer.hpp"

#include "sim/subdivision/loop.hpp"

#include "render/camera_math.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace clothsim {

namespace {
render::Vec3f to_vec3f(const Eigen::Vector3d& v) {
  return {static_cast<float>(v(0)), static_cast<float>(v(1)), static_cast<float>(v(2))};
}
}  // namespace

nlohmann::ordered_json drawn_surface_json(const std::string& method, const RenderSettings& settings) {
  return {{"surface", drawn_surface_key(resolve_drawn_surface(method, settings.surface))},
          {"refine", settings.refine},
          {"description", drawn_surface_description(method, settings.surface, settings.refine)}};
}

LimitSurfaceDrawer::LimitSurfaceDrawer(const Discretization& discretization, const RenderSettings& settings, int width,
                                       int height)
    : discretization_(discretization),
      display_(discretization.drawn_display(settings.refine, settings.surface)),
      settings_(settings),
      width_(width),
      height_(height) {
  triangles_.reserve(3 * display_.triangles.size());
  for (const Triangle& t : display_.triangles)
    for (int v : t) triangles_.push_back(static_cast<unsigned>(v));
  std::vector<std::pair<int, int>> edges;
  for (const Triangle& t : discretization.mesh().triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& [a, b] : edges) {
    edges_.push_back(static_cast<unsigned>(a));
    edges_.push_back(static_cast<unsigned>(b));
  }
  // The checker: each fine triangle takes the square of its centroid's texture coordinates (its
  // control triangle's, split as the triangle is).
  const TriMesh& control = discretization.mesh();
  if (settings.texture == "checker" && control.uv.size() == control.triangles.size() &&
      display_.triangles.size() == control.uv.size() << (2 * display_.levels)) {
    const std::vector<std::array<Eigen::Vector2d, 3>> uv = refine_corner_uv(control.uv, display_.levels);
    std::vector<unsigned> light;
    for (std::size_t t = 0; t < uv.size(); ++t) {
      const Eigen::Vector2d c = (uv[t][0] + uv[t][1] + uv[t][2]) / (3.0 * RenderSettings::kCheckerCell);
      const bool dark = ((static_cast<long long>(std::floor(c.x())) + static_cast<long long>(std::floor(c.y()))) & 1) != 0;
      std::vector<unsigned>& into = dark ? checker_triangles_ : light;
      into.insert(into.end(), triangles_.begin() + static_cast<std::ptrdiff_t>(3 * t),
                  triangles_.begin() + static_cast<std::ptrdiff_t>(3 * t + 3));
    }
    triangles_ = std::move(light);
  }
  // The grain lines: through each triangle's centroid along its warp (projected into its plane),
  // 0.6 √(2 area) long.
  const TriMesh& mesh = discretization.mesh();
  if (settings.texture == "grain" && mesh.warp.size() == mesh.triangles.size()) {
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const Triangle& tri = mesh.triangles[t];
      const Eigen::Vector3d x0 = mesh.vertices.row(tri[0]), x1 = mesh.vertices.row(tri[1]), x2 = mesh.vertices.row(tri[2]);
      Eigen::Matrix<double, 3, 2> e;
      e << x1 - x0, x2 - x0;
      const Eigen::Vector3d n = e.col(0).cross(e.col(1));
      const Eigen::Vector3d w = mesh.warp[t] - mesh.warp[t].dot(n.normalized()) * n.normalized();
      if (!(w.norm() > 0) || !(n.norm() > 0)) continue;
      const double half = 0.3 * std::sqrt(n.norm());
      const Eigen::Matrix2d gram = e.transpose() * e;
      const Eigen::Vector2d centre(1.0 / 3, 1.0 / 3), step = gram.inverse() * (e.transpose() * (half * w.normalized()));
      for (const Eigen::Vector2d& b : {Eigen::Vector2d(centre - step), Eigen::Vector2d(centre + step)}) {
        grain_coefficients_.push_back(static_cast<double>(t));
        grain_coefficients_.push_back(b(0));
        grain_coefficients_.push_back(b(1));
        grain_segments_.push_back(static_cast<unsigned>(grain_segments_.size()));
      }
    }
  }
}

void LimitSurfaceDrawer::set_obstacles(const std::vector<Obstacle>& obstacles) {
  obstacles_.clear();
  obstacle_triangles_.clear();
  planes_.clear();
  ground_plane_ = -1;
  unsigned offset = 0;
  for (const Obstacle& o : obstacles) {
    if (o.shape == Obstacle::Shape::plane) {
      planes_.push_back(o);
      if (ground_plane_ < 0 && std::abs(o.normal.normalized().dot(settings_.world_up.normalized())) > 0.999)
        ground_plane_ = static_cast<int>(planes_.size()) - 1;
      continue;
    }
    for (const Triangle& t : o.mesh.triangles)
      for (int v : t) obstacle_triangles_.push_back(offset + static_cast<unsigned>(v));
    offset += static_cast<unsigned>(o.mesh.num_vertices());
    obstacles_.push_back(o);
  }
}

SurfaceSnapshot LimitSurfaceDrawer::snapshot(const Eigen::VectorXd& x, double t) const {
  Eigen::MatrixX3d p, n;
  display_.evaluate(discretization_.control_net(x), p, n);
  SurfaceSnapshot s;
  s.positions.resize(static_cast<std::size_t>(3 * p.rows()));
  s.normals.resize(static_cast<std::size_t>(3 * p.rows()));
  for (Eigen::Index i = 0; i < p.rows(); ++i)
    for (int k = 0; k < 3; ++k) {
      s.positions[static_cast<std::size_t>(3 * i + k)] = static_cast<float>(p(i, k));
      s.normals[static_cast<std::size_t>(3 * i + k)] = static_cast<float>(n(i, k));
    }
  if (settings_.wireframe) {
    s.control.resize(static_cast<std::size_t>(x.size()));
    for (Eigen::Index i = 0; i < x.size(); ++i) s.control[static_cast<std::size_t>(i)] = static_cast<float>(x(i));
  }
  const std::vector<Triangle>& triangles = discretization_.mesh().triangles;
  for (std::size_t k = 0; k + 2 < grain_coefficients_.size(); k += 3) {
    const Triangle& tri = triangles[static_cast<std::size_t>(grain_coefficients_[k])];
    const Eigen::Vector3d x0 = x.segment<3>(3 * tri[0]), x1 = x.segment<3>(3 * tri[1]), x2 = x.segment<3>(3 * tri[2]);
    const Eigen::Vector3d end = x0 + grain_coefficients_[k + 1] * (x1 - x0) + grain_coefficients_[k + 2] * (x2 - x0);
    for (int c = 0; c < 3; ++c) s.grain.push_back(static_cast<float>(end(c)));
  }
  for (const Obstacle& o : obstacles_) {
    const Eigen::MatrixX3d v = mesh_at(o, t);
    for (Eigen::Index i = 0; i < v.rows(); ++i)
      for (int k = 0; k < 3; ++k) s.obstacles.push_back(static_cast<float>(v(i, k)));
  }
  if (ground_plane_ >= 0) {
    Eigen::Vector3d point, normal;
    plane_at(planes_[static_cast<std::size_t>(ground_plane_)], t, point, normal);
    s.plane_height = static_cast<float>(point.dot(settings_.world_up.normalized()));
  }
  return s;
}

void LimitSurfaceDrawer::extend_bounds(const SurfaceSnapshot& s, render::Vec3f& lo, render::Vec3f& hi) {
  for (std::size_t i = 0; i + 2 < s.positions.size(); i += 3)
    for (std::size_t k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], s.positions[i + k]);
      hi[k] = std::max(hi[k], s.positions[i + k]);
    }
}

render::Camera LimitSurfaceDrawer::camera(const render::Vec3f& lo, const render::Vec3f& hi) const {
  if (settings_.has_camera) {
    render::Camera c;
    c.eye = to_vec3f(settings_.eye);
    c.target = to_vec3f(settings_.target);
    c.up = to_vec3f(settings_.up);
    c.fov_deg = static_cast<float>(settings_.fov_deg);
    return c;
  }
  // With +y up: looking along −z, a little from above. Another up (render.up, by default opposite
  // to gravity) turns that view with it, by the shortest rotation taking +y to it.
  const Eigen::Vector3d up = settings_.world_up.normalized();
  const Eigen::Vector3d view =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitY(), up) * Eigen::Vector3d(0.35, -0.35, -1.0);
  return render::frame_bounds(lo, hi, static_cast<float>(settings_.fov_deg), to_vec3f(view), to_vec3f(up),
                              static_cast<float>(width_) / static_cast<float>(height_));
}

render::Frame LimitSurfaceDrawer::frame(const SurfaceSnapshot& s, const render::Camera& camera,
                                        const render::Vec3f& lo, const render::Vec3f& hi) const {
  render::Frame f;
  f.width = width_;
  f.height = height_;
  f.camera = camera;
  f.background = to_vec3f(settings_.background);
  render::Mesh mesh;
  mesh.positions = s.positions;
  mesh.normals = s.normals;
  mesh.triangles = triangles_;
  mesh.color = to_vec3f(settings_.color);
  mesh.back_color = to_vec3f(settings_.back_color);
  f.meshes.push_back(std::move(mesh));
  if (!checker_triangles_.empty()) {  // the darker squares: the same surface, 55 % of the colours
    render::Mesh dark;
    dark.positions = s.positions;
    dark.normals = s.normals;
    dark.triangles = checker_triangles_;
    dark.color = to_vec3f(0.55 * settings_.color);
    dark.back_color = to_vec3f(0.55 * settings_.back_color);
    f.meshes.push_back(std::move(dark));
  }
  if (settings_.wireframe && !s.control.empty()) {
    render::Lines lines;
    lines.positions = s.control;
    lines.segments = edges_;
    lines.color = {0.15f, 0.15f, 0.15f};
    f.lines.push_back(std::move(lines));
  }
  if (!s.grain.empty()) {
    render::Lines lines;
    lines.positions = s.grain;
    lines.segments = grain_segments_;
    lines.color = {0.95f, 0.9f, 0.7f};  // a light thread colour over the cloth
    f.lines.push_back(std::move(lines));
  }
  if (!s.obstacles.empty()) {
    render::Mesh obstacles;
    obstacles.positions = s.obstacles;  // flat-shaded primitives get smooth normals from the renderer
    obstacles.triangles = obstacle_triangles_;
    obstacles.color = {0.55f, 0.6f, 0.7f};
    obstacles.back_color = {0.35f, 0.38f, 0.45f};
    f.meshes.push_back(std::move(obstacles));
  }
  const Eigen::Vector3d up = settings_.world_up.normalized();
  double lowest = std::numeric_limits<double>::infinity();  // the box's lowest corner along up
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner((c & 1) != 0 ? hi[0] : lo[0], (c & 2) != 0 ? hi[1] : lo[1], (c & 4) != 0 ? hi[2] : lo[2]);
    lowest = std::min(lowest, corner.dot(up));
  }
  // Nothing drawn pierces it: an obstacle reaching below the box (the sequence framing's box
  // holds the cloth only) takes the ground down with it.
  for (std::size_t i = 0; i + 2 < s.obstacles.size(); i += 3)
    lowest = std::min(lowest, up.x() * s.obstacles[i] + up.y() * s.obstacles[i + 1] + up.z() * s.obstacles[i + 2]);
  f.ground = settings_.ground || ground_plane_ >= 0;
  f.ground_height = ground_plane_ >= 0 ? s.plane_height : static_cast<float>(lowest);
  f.up = to_vec3f(up);
  f.shadow = settings_.shadow;
  return f;
}

}  // namespace clothsim

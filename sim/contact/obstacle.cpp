#include "sim/contact/obstacle.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace clothsim {

namespace {

// Segments around a circle of radius r: 72 (5°), so that a chord's sagitta r (1 − cos(π/n)) is
// 0.095 % of r, and on a capsule's caps (latitude steps of 5°) the diagonals of the quads
// (7.1°) sag by at most 0.19 % of r.
constexpr int kSegments = 72;

// A unit vector perpendicular to `a` (unit), and a third completing a right-handed frame.
void frame_of(const Eigen::Vector3d& a, Eigen::Vector3d& e1, Eigen::Vector3d& e2) {
  const Eigen::Vector3d helper = std::abs(a.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  e1 = a.cross(helper).normalized();
  e2 = a.cross(e1);
}

class Builder {
 public:
  int add(const Eigen::Vector3d& p) {
    points_.push_back(p);
    return static_cast<int>(points_.size()) - 1;
  }
  void triangle(int a, int b, int c) { triangles_.push_back({a, b, c}); }
  // Two triangles over the quad a b c d (counter-clockwise).
  void quad(int a, int b, int c, int d) {
    triangle(a, b, c);
    triangle(a, c, d);
  }
  TriMesh mesh() const {
    TriMesh m;
    m.vertices.resize(static_cast<Eigen::Index>(points_.size()), 3);
    for (size_t i = 0; i < points_.size(); ++i) m.vertices.row(static_cast<Eigen::Index>(i)) = points_[i].transpose();
    m.triangles = triangles_;
    return m;
  }

 private:
  std::vector<Eigen::Vector3d> points_;
  std::vector<Triangle> triangles_;
};

// A sphere: an icosahedron subdivided 4 times (5120 triangles), vertices projected onto the sphere;
// its longest chord subtends 4.4°, a sagitta of 0.07 % of r.
TriMesh sphere_mesh(const Eigen::Vector3d& c, double r) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> p = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                                    {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (auto& q : p) q.normalize();
  std::vector<Triangle> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                             {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                             {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < 4; ++level) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      p.push_back((p[static_cast<size_t>(a)] + p[static_cast<size_t>(b)]).normalized());
      const int id = static_cast<int>(p.size()) - 1;
      mid.emplace(key, id);
      return id;
    };
    std::vector<Triangle> next;
    for (const Triangle& tri : t) {
      const int ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]), ca = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], ab, ca});
      next.push_back({tri[1], bc, ab});
      next.push_back({tri[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    t = std::move(next);
  }
  TriMesh m;
  m.vertices.resize(static_cast<Eigen::Index>(p.size()), 3);
  for (size_t i = 0; i < p.size(); ++i) m.vertices.row(static_cast<Eigen::Index>(i)) = (c + r * p[i]).transpose();
  m.triangles = std::move(t);
  return m;
}

// A capsule (hemispherical caps) or a closed cylinder (flat caps) around the axis from → to.
TriMesh round_mesh(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double r, bool caps_round) {
  const Eigen::Vector3d axis = (to - from).normalized();
  Eigen::Vector3d e1, e2;
  frame_of(axis, e1, e2);
  const int n = kSegments;
  Builder b;
  auto ring = [&](const Eigen::Vector3d& centre, double radius) {
    const int first = b.add(centre + radius * e1);
    for (int i = 1; i < n; ++i) {
      const double a = 2.0 * M_PI * i / n;
      b.add(centre + radius * (std::cos(a) * e1 + std::sin(a) * e2));
    }
    return first;
  };
  // Rings from the `from` end to the `to` end; consecutive rings are joined by quads.
  std::vector<int> rings;
  const int cap_rings = caps_round ? 18 : 0;  // latitude steps of π/(2·18) = 5°
  for (int k = cap_rings - 1; k >= 1; --k) {  // latitudes between the pole and the equator
    const double phi = 0.5 * M_PI * k / cap_rings;
    rings.push_back(ring(from - r * std::sin(phi) * axis, r * std::cos(phi)));
  }
  rings.push_back(ring(from, r));
  // The side: straight, so the rings along it do not change the surface, only the triangles'
  // shape. They are at most four segment lengths apart: fewer, longer triangles give each cloth
  // point resting on the side fewer contact candidates (sleeve_on_arm: rings one segment length
  // apart took 9.0 s of contact, four 6.3 s, with the same run to 1e-9 in its energies), while a
  // triangle's bounding box stays short whatever the axis (a box of a long triangle on an oblique
  // axis would hold many points far from it).
  const double length = (to - from).norm();
  // (At most 200 rings along a long, thin body. Clamped before the conversion: the count for a
  // 1e120 m capsule does not fit an int.)
  const double wanted = std::ceil(length / (4.0 * 2.0 * M_PI * r / n));
  const int along = wanted >= 200.0 ? 200 : wanted >= 1.0 ? static_cast<int>(wanted) : 1;
  for (int k = 1; k <= along; ++k) rings.push_back(ring(from + (length * k / along) * axis, r));
  for (int k = 1; k < cap_rings; ++k) {
    const double phi = 0.5 * M_PI * k / cap_rings;
    rings.push_back(ring(to + r * std::sin(phi) * axis, r * std::cos(phi)));
  }
  // Ring i runs counter-clockwise about +axis; outward quads go (i, j) → (i, j+1) → (i+1, j+1).
  for (size_t k = 0; k + 1 < rings.size(); ++k)
    for (int i = 0; i < n; ++i) {
      const int j = (i + 1) % n;
      b.quad(rings[k] + i, rings[k] + j, rings[k + 1] + j, rings[k + 1] + i);
    }
  // Poles (round caps) or cap centres (flat caps), fanned.
  const int bottom = b.add(caps_round ? Eigen::Vector3d(from - r * axis) : from);
  const int top = b.add(caps_round ? Eigen::Vector3d(to + r * axis) : to);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    b.triangle(bottom, rings.front() + j, rings.front() + i);
    b.triangle(top, rings.back() + i, rings.back() + j);
  }
  return b.mesh();
}

TriMesh box_mesh(const Eigen::Vector3d& c, const Eigen::Vector3d& size) {
  Builder b;
  const Eigen::Vector3d h = 0.5 * size;
  int v[8];
  for (int i = 0; i < 8; ++i)
    v[i] = b.add(c + Eigen::Vector3d((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z()));
  b.quad(v[0], v[4], v[6], v[2]);  // −x
  b.quad(v[1], v[3], v[7], v[5]);  // +x
  b.quad(v[0], v[1], v[5], v[4]);  // −y
  b.quad(v[2], v[6], v[7], v[3]);  // +y
  b.quad(v[0], v[2], v[3], v[1]);  // −z
  b.quad(v[4], v[5], v[7], v[6]);  // +z
  return b.mesh();
}

}  // namespace

const char* to_string(Obstacle::Shape shape) {
  switch (shape) {
    case Obstacle::Shape::plane: return "plane";
    case Obstacle::Shape::sphere: return "sphere";
    case Obstacle::Shape::capsule: return "capsule";
    case Obstacle::Shape::box: return "box";
    case Obstacle::Shape::cylinder: return "cylinder";
    case Obstacle::Shape::mesh: return "mesh";
  }
  return "?";
}

TriMesh tessellate(const Obstacle& o) {
  switch (o.shape) {
    case Obstacle::Shape::sphere:
      if (!(o.radius > 0)) throw std::invalid_argument("sphere: the radius must be > 0");
      return sphere_mesh(o.center, o.radius);
    case Obstacle::Shape::capsule:
    case Obstacle::Shape::cylinder:
      if (!(o.radius > 0)) throw std::invalid_argument(std::string(to_string(o.shape)) + ": the radius must be > 0");
      if (!((o.to - o.from).norm() > 0))
        throw std::invalid_argument(std::string(to_string(o.shape)) + ": \"from\" and \"to\" must differ");
      return round_mesh(o.from, o.to, o.radius, o.shape == Obstacle::Shape::capsule);
    case Obstacle::Shape::box:
      if (!(o.size.minCoeff() > 0)) throw std::invalid_argument("box: every edge length must be > 0");
      return box_mesh(o.center, o.size);
    case Obstacle::Shape::plane:
    case Obstacle::Shape::mesh:
      break;
  }
  throw std::invalid_argument(std::string("tessellate: a ") + to_string(o.shape) + " is not a primitive with a tessellation");
}

void plane_at(const Obstacle& o, double t, Eigen::Vector3d& point, Eigen::Vector3d& normal) {
  point = obstacle_point(o, o.point, t);
  normal = (obstacle_point(o, o.point + o.normal, t) - point).normalized();
}

Eigen::MatrixX3d mesh_at(const Obstacle& o, double t) {
  if (o.motion.empty()) return o.mesh.vertices;
  Eigen::MatrixX3d out(o.mesh.vertices.rows(), 3);
  for (Eigen::Index v = 0; v < out.rows(); ++v)
    out.row(v) = obstacle_point(o, o.mesh.vertices.row(v).transpose(), t).transpose();
  return out;
}

}  // namespace clothsim

#include "sim/contact/pair_geometry.hpp"

#include "sim/contact/narrow_phase.hpp"

#include <algorithm>

namespace clothsim::contact {

double box_gap(const Corners& x, bool point_triangle) {
  Eigen::Vector3d lo_a = x[0], hi_a = x[0], lo_b, hi_b;
  if (point_triangle) {
    lo_b = x[1].cwiseMin(x[2]).cwiseMin(x[3]);
    hi_b = x[1].cwiseMax(x[2]).cwiseMax(x[3]);
  } else {
    lo_a = x[0].cwiseMin(x[1]);
    hi_a = x[0].cwiseMax(x[1]);
    lo_b = x[2].cwiseMin(x[3]);
    hi_b = x[2].cwiseMax(x[3]);
  }
  return std::max(0.0, std::max((lo_b - hi_a).maxCoeff(), (lo_a - hi_b).maxCoeff()));
}

void sign_by_start(const PairGeometry& start, PairGeometry& end, bool point_triangle) {
  if (!(end.normal.dot(start.normal) < 0)) return;
  auto interior = [point_triangle](const PairGeometry& g) {
    if (point_triangle) return -g.coef[1] > 0 && -g.coef[2] > 0 && -g.coef[3] > 0;
    return g.coef[0] > 0 && g.coef[1] > 0 && g.coef[2] < 0 && g.coef[3] < 0;
  };
  if (!interior(start) || !interior(end)) return;
  end.distance = -end.distance;
  end.normal = -end.normal;
}

RigidMap obstacle_step_map(const Obstacle& o, double t, double h) {
  auto pose = [&](double time) {
    RigidMap m;
    m.c = obstacle_point(o, Eigen::Vector3d::Zero(), time);
    for (int k = 0; k < 3; ++k) m.r.col(k) = obstacle_point(o, Eigen::Vector3d::Unit(k), time) - m.c;
    return m;
  };
  const RigidMap a = pose(t), b = pose(t + h);
  RigidMap m;
  m.r = b.r * a.r.transpose();
  m.c = b.c - m.r * a.c;
  return m;
}

Corners PairPrimitives::corners(const Candidate& c, const Eigen::MatrixX3d& p, const Eigen::MatrixX3d& o) const {
  auto cp = [&](int i) -> Eigen::Vector3d { return p.row(i).transpose(); };
  auto op = [&](int i) -> Eigen::Vector3d { return o.row(i).transpose(); };
  switch (c.kind) {
    case Kind::cloth_point_cloth_triangle: {
      const auto& t = triangles_[static_cast<size_t>(c.b)];
      return {cp(c.a), cp(t[0]), cp(t[1]), cp(t[2])};
    }
    case Kind::cloth_edge_cloth_edge: {
      const auto& ea = edges_[static_cast<size_t>(c.a)];
      const auto& eb = edges_[static_cast<size_t>(c.b)];
      return {cp(ea[0]), cp(ea[1]), cp(eb[0]), cp(eb[1])};
    }
    case Kind::cloth_point_obstacle_triangle: {
      const auto& t = obs_.triangles[static_cast<size_t>(c.b)];
      return {cp(c.a), op(t[0]), op(t[1]), op(t[2])};
    }
    case Kind::obstacle_point_cloth_triangle: {
      const auto& t = triangles_[static_cast<size_t>(c.b)];
      return {op(c.a), cp(t[0]), cp(t[1]), cp(t[2])};
    }
    case Kind::cloth_edge_obstacle_edge: {
      const auto& ea = edges_[static_cast<size_t>(c.a)];
      const auto& eb = obs_.edges[static_cast<size_t>(c.b)];
      return {cp(ea[0]), cp(ea[1]), op(eb[0]), op(eb[1])};
    }
  }
  return {};
}

PairGeometry PairPrimitives::geometry(const Candidate& c, const Corners& x) const {
  PairGeometry g;
  g.num = 4;
  std::array<int, 4> ids{};
  std::array<bool, 4> obstacle{};
  switch (c.kind) {
    case Kind::cloth_point_cloth_triangle: {
      const auto& t = triangles_[static_cast<size_t>(c.b)];
      ids = {c.a, t[0], t[1], t[2]};
      break;
    }
    case Kind::cloth_edge_cloth_edge: {
      const auto& ea = edges_[static_cast<size_t>(c.a)];
      const auto& eb = edges_[static_cast<size_t>(c.b)];
      ids = {ea[0], ea[1], eb[0], eb[1]};
      break;
    }
    case Kind::cloth_point_obstacle_triangle: {
      const auto& t = obs_.triangles[static_cast<size_t>(c.b)];
      ids = {c.a, t[0], t[1], t[2]};
      obstacle = {false, true, true, true};
      break;
    }
    case Kind::obstacle_point_cloth_triangle: {
      const auto& t = triangles_[static_cast<size_t>(c.b)];
      ids = {c.a, t[0], t[1], t[2]};
      obstacle = {true, false, false, false};
      break;
    }
    case Kind::cloth_edge_obstacle_edge: {
      const auto& ea = edges_[static_cast<size_t>(c.a)];
      const auto& eb = obs_.edges[static_cast<size_t>(c.b)];
      ids = {ea[0], ea[1], eb[0], eb[1]};
      obstacle = {false, false, true, true};
      break;
    }
  }
  g.point = ids;
  g.obstacle = obstacle;
  if (is_point_triangle(c.kind)) {
    const PointTriangleProximity q = point_triangle(x[0], x[1], x[2], x[3]);
    g.coef = {1.0, -q.weights[0], -q.weights[1], -q.weights[2]};
    g.normal = q.normal;
    g.distance = q.distance;
  } else {
    const EdgeEdgeProximity q = edge_edge(x[0], x[1], x[2], x[3]);
    g.coef = {1.0 - q.s, q.s, -(1.0 - q.t), -q.t};
    g.normal = q.normal;
    g.distance = q.distance;
  }
  return g;
}

std::array<int, 4> PairPrimitives::cloth_points(const Candidate& c) const {
  switch (c.kind) {
    case Kind::cloth_point_cloth_triangle: {
      const auto& t = triangles_[static_cast<size_t>(c.b)];
      return {c.a, t[0], t[1], t[2]};
    }
    case Kind::cloth_edge_cloth_edge: {
      const auto& ea = edges_[static_cast<size_t>(c.a)];
      const auto& eb = edges_[static_cast<size_t>(c.b)];
      return {ea[0], ea[1], eb[0], eb[1]};
    }
    case Kind::cloth_point_obstacle_triangle: return {c.a, -1, -1, -1};
    case Kind::obstacle_point_cloth_triangle: {
      const auto& t = triangles_[static_cast<size_t>(c.b)];
      return {t[0], t[1], t[2], -1};
    }
    case Kind::cloth_edge_obstacle_edge: {
      const auto& ea = edges_[static_cast<size_t>(c.a)];
      return {ea[0], ea[1], -1, -1};
    }
  }
  return {-1, -1, -1, -1};
}

int PairPrimitives::obstacle_of(const PairGeometry& g) const {
  for (int k = 0; k < g.num; ++k)
    if (g.obstacle[static_cast<size_t>(k)]) return obs_.obstacle_of_vertex[static_cast<size_t>(g.point[static_cast<size_t>(k)])];
  return -1;
}

bool PairPrimitives::redundant_on_flat_face(const Candidate& c, const PairGeometry& g, const Corners& x) const {
  return c.kind == Kind::cloth_point_obstacle_triangle &&
         obs_.redundant_on_flat_face(c.b, {-g.coef[1], -g.coef[2], -g.coef[3]}, g.normal, x[1], x[2], x[3]);
}

double PairPrimitives::motion(const Candidate& c, const Eigen::VectorXd& move, double obstacle) const {
  const std::array<int, 4> q = cloth_points(c);
  if (c.kind == Kind::cloth_point_cloth_triangle || c.kind == Kind::cloth_edge_cloth_edge) {
    const size_t split = c.kind == Kind::cloth_point_cloth_triangle ? 1 : 2;
    double a = 0.0, b = 0.0;
    for (size_t k = 0; k < split; ++k) a = std::max(a, move(q[k]));
    for (size_t k = split; k < 4; ++k) b = std::max(b, move(q[k]));
    return a + b;
  }
  double largest = 0.0;
  for (int p : q)
    if (p >= 0) largest = std::max(largest, move(p));
  return largest + obstacle;
}

}  // namespace clothsim::contact

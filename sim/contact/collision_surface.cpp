#include "sim/contact/collision_surface.hpp"

#include "sim/contact/broad_phase.hpp"
#include "sim/contact/candidates.hpp"
#include "sim/contact/narrow_phase.hpp"
#include "sim/contact/obstacle_set.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace clothsim::contact {

void parallel_product(const Eigen::SparseMatrix<double, Eigen::RowMajor>& a, const double* x, Eigen::Index x_rows, int cols,
                      double* y) {
  if (!a.isCompressed()) throw std::logic_error("parallel_product: the matrix must be compressed");
  const Eigen::Index rows = a.rows();
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* value = a.valuePtr();
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, rows, 2048), [&](const tbb::blocked_range<Eigen::Index>& range) {
    for (Eigen::Index r = range.begin(); r != range.end(); ++r)
      for (int c = 0; c < cols; ++c) {
        double sum = 0.0;
        for (int k = outer[r]; k < outer[r + 1]; ++k) sum += value[k] * x[c * x_rows + inner[k]];
        y[c * rows + r] = sum;
      }
  });
}

double triangle_distance(const Eigen::MatrixX3d& p, const std::array<int, 3>& a, const std::array<int, 3>& b) {
  double dist = std::numeric_limits<double>::infinity();
  auto pt = [&](int i) -> Eigen::Vector3d { return p.row(i).transpose(); };
  for (size_t k = 0; k < 3; ++k) {
    dist = std::min(dist, point_triangle(pt(a[k]), pt(b[0]), pt(b[1]), pt(b[2])).distance);
    dist = std::min(dist, point_triangle(pt(b[k]), pt(a[0]), pt(a[1]), pt(a[2])).distance);
    for (size_t l = 0; l < 3; ++l)
      dist = std::min(dist, edge_edge(pt(a[k]), pt(a[(k + 1) % 3]), pt(b[l]), pt(b[(l + 1) % 3])).distance);
  }
  return dist;
}

CollisionSurface::CollisionSurface(const Discretization& d, int level) : d_(d) {
  op_ = d.display(level);
  op_.position.makeCompressed();
  jacobian_ = d.point_jacobian(op_);
  jacobian_.makeCompressed();
  rest_ = d.surface_positions(op_, d.rest());
  slot_.assign(static_cast<size_t>(3 * d.num_nodes()), -1);
  build_edges(op_.triangles, edges_, triangle_edges_);
  build_ownership(op_.triangles, static_cast<int>(rest_.rows()), triangle_edges_, static_cast<int>(edges_.size()), owned_points_,
                  owned_edges_);
  fine_per_patch_ = 1 << (2 * op_.levels);
}

Eigen::MatrixX3d CollisionSurface::points(const Eigen::VectorXd& x) const {
  const Eigen::MatrixX3d net = d_.control_net(x);
  Eigen::MatrixX3d p(op_.position.rows(), 3);
  parallel_product(op_.position, net.data(), net.rows(), 3, p.data());
  return p;
}

Eigen::MatrixX3d CollisionSurface::points_through_rows(const Eigen::VectorXd& x) const {
  if (!in_node_form_) return points(x);
  return end_points(rest_, 1.0, x - d_.rest());
}

Eigen::MatrixX3d CollisionSurface::end_points(const Eigen::MatrixX3d& p0, double h, const Eigen::VectorXd& v) const {
  Eigen::MatrixX3d out(p0.rows(), 3);
  if (in_node_form_) {
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, p0.rows(), 2048), [&](const tbb::blocked_range<Eigen::Index>& range) {
      for (Eigen::Index p = range.begin(); p != range.end(); ++p) {
        double x = 0.0, y = 0.0, z = 0.0;
        for (int k = point_map_.offsets[static_cast<size_t>(p)]; k < point_map_.offsets[static_cast<size_t>(p) + 1]; ++k) {
          const double w = point_map_.weights[static_cast<size_t>(k)];
          const double* vn = v.data() + 3 * static_cast<Eigen::Index>(point_map_.nodes[static_cast<size_t>(k)]);
          x += w * vn[0];
          y += w * vn[1];
          z += w * vn[2];
        }
        out(p, 0) = p0(p, 0) + h * x;
        out(p, 1) = p0(p, 1) + h * y;
        out(p, 2) = p0(p, 2) + h * z;
      }
    });
    return out;
  }
  Eigen::VectorXd pv(jacobian_.rows());  // surface point velocities, flat
  parallel_product(jacobian_, v.data(), v.size(), 1, pv.data());
  return p0 + h * Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(pv.data(), p0.rows(), 3);
}

CollisionSurface::DofRow CollisionSurface::rows(const PairGeometry& g) {
  DofRow b;
  for (int k = 0; k < g.num; ++k) {
    const double coef = g.coef[static_cast<size_t>(k)];
    const int p = g.point[static_cast<size_t>(k)];
    if (coef == 0.0 || g.obstacle[static_cast<size_t>(k)]) continue;
    for (int comp = 0; comp < 3; ++comp)
      for (Jacobian::InnerIterator it(jacobian_, 3 * p + comp); it; ++it) {
        const int dof = static_cast<int>(it.col());
        int& s = slot_[static_cast<size_t>(dof)];
        if (s < 0) {
          s = static_cast<int>(b.size());
          b.emplace_back(dof, Eigen::Vector3d::Zero());
        }
        b[static_cast<size_t>(s)].second[comp] += coef * it.value();
      }
  }
  for (const auto& entry : b) slot_[static_cast<size_t>(entry.first)] = -1;
  return b;
}

void CollisionSurface::to_node_form(DofRow& b, std::vector<std::pair<int, double>>& nodes) {
  nodes.clear();
  if (b.size() % 3 != 0) return;
  for (size_t i = 0; i < b.size(); ++i) slot_[static_cast<size_t>(b[i].first)] = static_cast<int>(i);
  bool ok = true;
  for (const auto& [dof, vec] : b) {
    const int c = dof % 3;
    const double w = vec[c];
    for (int k = 0; k < 3 && ok; ++k) {
      const int at = slot_[static_cast<size_t>(dof - c + k)];
      ok = at >= 0 && b[static_cast<size_t>(at)].second == w * Eigen::Vector3d::Unit(k);
    }
    if (!ok) break;
    if (c == 0) nodes.emplace_back(dof / 3, w);
  }
  for (const auto& entry : b) slot_[static_cast<size_t>(entry.first)] = -1;
  if (ok) {
    b.clear();
  } else {
    nodes.clear();
  }
}

NodeRow CollisionSurface::node_row(const DofRow& b) {
  NodeRow row;
  row.dofs = b;
  to_node_form(row.dofs, row.nodes);
  return row;
}

namespace {
// A pair of one surface point p with coefficient 1.
PairGeometry one_point(int p) {
  PairGeometry g;
  g.num = 1;
  g.point[0] = p;
  g.coef[0] = 1.0;
  return g;
}
}  // namespace

void CollisionSurface::make_point_rows() {
  point_map_ = PointMap{};
  in_node_form_ = true;
  for (Eigen::Index p = 0; p < rest_.rows(); ++p) {
    NodeRow row = node_row(rows(one_point(static_cast<int>(p))));
    if (!row.dofs.empty()) {
      in_node_form_ = false;
      point_map_ = PointMap{};
      return;
    }
    std::sort(row.nodes.begin(), row.nodes.end());
    for (const auto& [node, w] : row.nodes) {
      point_map_.nodes.push_back(node);
      point_map_.weights.push_back(w);
    }
    point_map_.offsets.push_back(static_cast<int>(point_map_.nodes.size()));
  }
}

PointRow CollisionSurface::pair_points(const PairGeometry& g) const {
  PointRow row;
  for (int k = 0; k < g.num; ++k) {
    const double coef = g.coef[static_cast<size_t>(k)];
    if (g.obstacle[static_cast<size_t>(k)] || coef == 0.0) continue;
    row.points[static_cast<size_t>(row.count)] = g.point[static_cast<size_t>(k)];
    row.coefs[static_cast<size_t>(row.count)] = coef;
    ++row.count;
  }
  return row;
}

PointRow CollisionSurface::point_alone(int p) const {
  PointRow row;
  row.points[0] = p;
  row.coefs[0] = 1.0;
  row.count = 1;
  return row;
}

NodeRow CollisionSurface::point_row(int p) {
  if (in_node_form_) return point_alone(p).node_row(point_map_);
  return node_row(rows(one_point(p)));
}

NodeRow CollisionSurface::pair_row(const PairGeometry& g) {
  if (in_node_form_) return pair_points(g).node_row(point_map_);
  return node_row(rows(g));
}

bool CollisionSurface::near_pair(const std::array<int, 3>& a, const std::array<int, 3>& b, double near) const {
  if (shares_vertex(a, b)) return true;
  const double near2 = near * near;
  for (int x : a)
    for (int y : b)
      if ((rest_.row(x) - rest_.row(y)).squaredNorm() < near2) return true;
  // Bounding spheres about the centroids bound the distance from below (they only skip the exact
  // test where it could not differ).
  auto sphere = [&](const std::array<int, 3>& t, Eigen::RowVector3d& centre) {
    centre = (rest_.row(t[0]) + rest_.row(t[1]) + rest_.row(t[2])) / 3.0;
    double radius = 0.0;
    for (int x : t) radius = std::max(radius, (rest_.row(x) - centre).norm());
    return radius;
  };
  Eigen::RowVector3d ca, cb;
  const double ra = sphere(a, ca), rb = sphere(b, cb);
  if ((ca - cb).norm() - ra - rb > near * (1.0 + 1e-12)) return false;
  return triangle_distance(rest_, a, b) < near;
}

long long CollisionSurface::find_near_at_rest(double near, double joined, const std::vector<Triangle>& patch_corners,
                                              std::vector<std::vector<int>>& near_at_rest,
                                              std::vector<std::vector<int>>& joined_at_rest) const {
  const std::vector<Triangle>& triangles = op_.triangles;
  near_at_rest.assign(triangles.size(), {});
  std::vector<Box> boxes(triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) boxes[t] = swept_box(rest_, rest_, triangles[t], 0.5 * near);
  BroadPhase rest_broad;
  const std::vector<std::pair<int, int>> pairs = rest_broad.self_pairs(boxes);
  // The predicate in parallel (one flag per pair), the lists in the pairs' order: the same lists
  // as a serial pass.
  std::vector<char> is_near(pairs.size(), 0), is_joined(pairs.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pairs.size(), 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const auto& a = triangles[static_cast<size_t>(pairs[i].first)];
      const auto& b = triangles[static_cast<size_t>(pairs[i].second)];
      is_near[i] = near_pair(a, b, near);
      if (!is_near[i]) continue;
      const auto& pa = patch_corners[static_cast<size_t>(pairs[i].first / fine_per_patch_)];
      const auto& pb = patch_corners[static_cast<size_t>(pairs[i].second / fine_per_patch_)];
      is_joined[i] = !shares_vertex(pa, pb) && triangle_distance(rest_, a, b) < joined;
    }
  });
  joined_at_rest.assign(triangles.size(), {});
  long long count = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (is_near[i]) near_at_rest[static_cast<size_t>(pairs[i].first)].push_back(pairs[i].second);
    if (is_joined[i]) {
      joined_at_rest[static_cast<size_t>(pairs[i].first)].push_back(pairs[i].second);
      ++count;
    }
  }
  return count;  // (the lists are sorted: the pairs come sorted)
}

}  // namespace clothsim::contact

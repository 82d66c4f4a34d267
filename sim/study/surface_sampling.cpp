#include "sim/study/surface_sampling.hpp"


#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {

// Barycentric parameters (v, w) of `p` in the chart triangle (a, b, c); false if degenerate.
bool barycentric(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                 const Eigen::Vector2d& p, double& v, double& w) {
  const Eigen::Vector2d e1 = b - a, e2 = c - a, d = p - a;
  const double det = e1.x() * e2.y() - e1.y() * e2.x();
  if (det == 0.0) return false;
  v = (d.x() * e2.y() - d.y() * e2.x()) / det;
  w = (e1.x() * d.y() - e1.y() * d.x()) / det;
  return true;
}

}  // namespace

std::vector<SurfaceSample> locate_points(const std::vector<Triangle>& triangles, const Eigen::MatrixX2d& chart,
                                        const Eigen::MatrixX2d& targets, double period) {
  constexpr double kTolerance = 1e-10;
  // Chart triangles, unwrapped across the seam of a periodic first coordinate.
  std::vector<std::array<Eigen::Vector2d, 3>> corners(triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector2d q = chart.row(triangles[t][k]).transpose();
      if (period > 0 && k > 0) q.x() -= period * std::round((q.x() - corners[t][0].x()) / period);
      corners[t][k] = q;
    }
  std::vector<SurfaceSample> out;
  out.reserve(static_cast<size_t>(targets.rows()));
  for (Eigen::Index i = 0; i < targets.rows(); ++i) {
    const Eigen::Vector2d target = targets.row(i).transpose();
    bool found = false;
    for (size_t t = 0; t < triangles.size() && !found; ++t) {
      for (int shift : {0, -1, 1}) {
        if (shift != 0 && period <= 0) continue;
        const Eigen::Vector2d p = target + Eigen::Vector2d(shift * period, 0.0);
        double v = 0, w = 0;
        if (!barycentric(corners[t][0], corners[t][1], corners[t][2], p, v, w)) continue;
        if (v < -kTolerance || w < -kTolerance || v + w > 1 + kTolerance) continue;
        v = std::clamp(v, 0.0, 1.0);
        w = std::clamp(w, 0.0, 1.0 - v);
        out.push_back({static_cast<int>(t), v, w});
        found = true;
        break;
      }
    }
    if (!found)
      throw std::invalid_argument("locate_points: chart point " + std::to_string(i) + " (" +
                                  std::to_string(target.x()) + ", " + std::to_string(target.y()) +
                                  ") lies in no triangle of the mesh");
  }
  return out;
}

Eigen::MatrixX2d cylinder_chart(const Eigen::MatrixX3d& vertices) {
  Eigen::MatrixX2d chart(vertices.rows(), 2);
  if (vertices.rows() == 0) return chart;
  const double y0 = vertices.col(1).minCoeff(), y1 = vertices.col(1).maxCoeff();
  if (!(y1 > y0)) throw std::invalid_argument("cylinder_chart: the mesh has no extent along y");
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    double theta = std::atan2(-vertices(v, 2), vertices(v, 0));
    if (theta < 0) theta += 2 * std::numbers::pi;
    chart(v, 0) = theta;
    chart(v, 1) = (vertices(v, 1) - y0) / (y1 - y0);
  }
  return chart;
}

Eigen::MatrixX2d cylinder_parameter_grid(int n_theta, int n_s) {
  if (n_theta < 1 || n_s < 1) throw std::invalid_argument("cylinder_parameter_grid: need at least one point per direction");
  Eigen::MatrixX2d grid(static_cast<Eigen::Index>(n_theta) * n_s, 2);
  for (int j = 0; j < n_s; ++j)
    for (int i = 0; i < n_theta; ++i) {
      const Eigen::Index row = static_cast<Eigen::Index>(j) * n_theta + i;
      grid(row, 0) = 2 * std::numbers::pi * (i + 0.5) / n_theta;
      grid(row, 1) = (j + 0.5) / n_s;
    }
  return grid;
}

namespace {

void check_shapes(const std::vector<Eigen::MatrixX3d>& u, const std::vector<Eigen::MatrixX3d>& u_ref) {
  if (u.size() != u_ref.size())
    throw std::invalid_argument("relative_rms_difference: " + std::to_string(u.size()) + " sample times against " +
                                std::to_string(u_ref.size()) + " in the reference");
  for (size_t k = 0; k < u.size(); ++k)
    if (u[k].rows() != u_ref[k].rows())
      throw std::invalid_argument("relative_rms_difference: sample time " + std::to_string(k) + " has " +
                                  std::to_string(u[k].rows()) + " points against " +
                                  std::to_string(u_ref[k].rows()) + " in the reference");
}

}  // namespace

double relative_rms_difference(const std::vector<Eigen::MatrixX3d>& u, const std::vector<Eigen::MatrixX3d>& u_ref) {
  check_shapes(u, u_ref);
  double diff = 0.0, ref = 0.0;
  for (size_t k = 0; k < u.size(); ++k) {
    diff += (u[k] - u_ref[k]).squaredNorm();
    ref += u_ref[k].squaredNorm();
  }
  if (!(ref > 0.0)) throw std::invalid_argument("relative_rms_difference: the reference displacement is zero");
  return std::sqrt(diff / ref);
}

double rms_norm(const std::vector<Eigen::MatrixX3d>& u) {
  double sum = 0.0;
  Eigen::Index count = 0;
  for (const Eigen::MatrixX3d& m : u) {
    sum += m.squaredNorm();
    count += m.rows();
  }
  return count > 0 ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
}

}  // namespace clothsim

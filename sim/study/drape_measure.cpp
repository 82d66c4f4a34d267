#include "sim/study/drape_measure.hpp"

#include "sim/study/fold_count.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace clothsim {

DrapeMeasure measure_drape(const Eigen::MatrixX3d& vertices, const std::vector<std::array<int, 3>>& triangles,
                           const DrapeMeasureSettings& s) {
  if (vertices.rows() == 0 || triangles.empty()) throw std::invalid_argument("measure_drape: the surface is empty");
  if (!(s.cell > 0) || !(s.support_radius > 0) || !(s.specimen_radius > s.support_radius) || !(s.prominence >= 0) ||
      s.smoothing < 1 || s.angles < 8 || !(s.up.norm() > 0))
    throw std::invalid_argument("measure_drape: need cell > 0, 0 < support radius < specimen radius, prominence >= 0, "
                                "smoothing >= 1, angles >= 8 and a non-zero up direction");
  // An orthonormal frame (e1, e2) of the plane normal to up; the shadow lives in its coordinates.
  const Eigen::Vector3d up = s.up.normalized();
  const Eigen::Vector3d e1 = up.unitOrthogonal();
  const Eigen::Vector3d e2 = up.cross(e1);
  const Eigen::Index nv = vertices.rows();
  Eigen::MatrixX2d p(nv, 2);
  for (Eigen::Index i = 0; i < nv; ++i) {
    const Eigen::Vector3d x = vertices.row(i).transpose();
    if (!x.allFinite()) throw std::invalid_argument("measure_drape: vertex " + std::to_string(i) + " is not finite");
    p(i, 0) = x.dot(e1);
    p(i, 1) = x.dot(e2);
  }
  if (!s.support_center.allFinite()) throw std::invalid_argument("measure_drape: the support's centre is not finite");
  const Eigen::Vector2d axis(s.support_center.dot(e1), s.support_center.dot(e2));
  const double h = s.cell, r0 = s.support_radius;
  const double x0 = std::min(p.col(0).minCoeff(), axis.x() - r0) - 2 * h;
  const double y0 = std::min(p.col(1).minCoeff(), axis.y() - r0) - 2 * h;
  // The cell counts, checked as doubles before they become integers.
  const double cells_x = std::ceil((std::max(p.col(0).maxCoeff(), axis.x() + r0) - x0) / h) + 2;
  const double cells_y = std::ceil((std::max(p.col(1).maxCoeff(), axis.y() + r0) - y0) / h) + 2;
  if (!(cells_x * cells_y <= 1e8))
    throw std::invalid_argument("measure_drape: the shadow needs " + std::to_string(cells_x * cells_y) +
                                " raster cells (more than 1e8): use a larger cell");
  const long long nx = static_cast<long long>(cells_x), ny = static_cast<long long>(cells_y);
  std::vector<std::uint8_t> grid(static_cast<size_t>(nx * ny), 0);
  // A cell is in the shadow when its centre lies in (or on) a projected triangle.
  for (const auto& t : triangles) {
    for (const int v : t)
      if (v < 0 || v >= nv) throw std::invalid_argument("measure_drape: a triangle names vertex " + std::to_string(v));
    const Eigen::Vector2d a = p.row(t[0]), b = p.row(t[1]), c = p.row(t[2]);
    const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (det == 0.0) continue;
    const auto first = [&](double lo, double o) { return std::max(0LL, static_cast<long long>(std::floor((lo - o) / h - 0.5))); };
    const auto last = [&](double hi, double o, long long n) {
      return std::min(n - 1, static_cast<long long>(std::ceil((hi - o) / h - 0.5)));
    };
    const long long i0 = first(std::min({a.x(), b.x(), c.x()}), x0), i1 = last(std::max({a.x(), b.x(), c.x()}), x0, nx);
    const long long j0 = first(std::min({a.y(), b.y(), c.y()}), y0), j1 = last(std::max({a.y(), b.y(), c.y()}), y0, ny);
    constexpr double tol = 1e-12;
    for (long long j = j0; j <= j1; ++j) {
      const double py = y0 + (static_cast<double>(j) + 0.5) * h;
      for (long long i = i0; i <= i1; ++i) {
        std::uint8_t& cell = grid[static_cast<size_t>(j * nx + i)];
        if (cell) continue;
        const double px = x0 + (static_cast<double>(i) + 0.5) * h;
        const double l1 = ((px - a.x()) * (c.y() - a.y()) - (py - a.y()) * (c.x() - a.x())) / det;
        const double l2 = ((b.x() - a.x()) * (py - a.y()) - (b.y() - a.y()) * (px - a.x())) / det;
        if (l1 >= -tol && l2 >= -tol && l1 + l2 <= 1 + tol) cell = 1;
      }
    }
  }
  // The support disc: a cell whose centre lies in it.
  for (long long j = 0; j < ny; ++j)
    for (long long i = 0; i < nx; ++i) {
      const double dx = x0 + (static_cast<double>(i) + 0.5) * h - axis.x();
      const double dy = y0 + (static_cast<double>(j) + 0.5) * h - axis.y();
      if (dx * dx + dy * dy <= r0 * r0) grid[static_cast<size_t>(j * nx + i)] = 1;
    }
  DrapeMeasure m;
  long long filled = 0, boundary = 0;
  double cx = 0, cy = 0;
  for (long long j = 0; j < ny; ++j)
    for (long long i = 0; i < nx; ++i) {
      if (!grid[static_cast<size_t>(j * nx + i)]) continue;
      ++filled;
      cx += x0 + (static_cast<double>(i) + 0.5) * h;
      cy += y0 + (static_cast<double>(j) + 0.5) * h;
      const auto at = [&](long long a, long long b) { return grid[static_cast<size_t>(b * nx + a)] != 0; };
      if (i == 0 || j == 0 || i == nx - 1 || j == ny - 1 || !at(i - 1, j) || !at(i + 1, j) || !at(i, j - 1) || !at(i, j + 1))
        ++boundary;
    }
  if (filled == 0) throw std::invalid_argument("measure_drape: the shadow covers no raster cell (use a smaller cell)");
  cx /= static_cast<double>(filled);
  cy /= static_cast<double>(filled);
  m.shadow_area = static_cast<double>(filled) * h * h;
  m.area_bound = 0.5 * static_cast<double>(boundary) * h * h;
  const double support = M_PI * s.support_radius * s.support_radius;
  const double specimen = M_PI * s.specimen_radius * s.specimen_radius;
  m.drape_coefficient = (m.shadow_area - support) / (specimen - support);
  // The outline: per angular bin about the centroid, the farthest occupied cell (its far side).
  std::vector<double> r(static_cast<size_t>(s.angles), 0.0);
  for (long long j = 0; j < ny; ++j)
    for (long long i = 0; i < nx; ++i) {
      if (!grid[static_cast<size_t>(j * nx + i)]) continue;
      const double dx = x0 + (static_cast<double>(i) + 0.5) * h - cx, dy = y0 + (static_cast<double>(j) + 0.5) * h - cy;
      const double radius = std::hypot(dx, dy) + 0.5 * h;
      const int k = static_cast<int>((std::atan2(dy, dx) + M_PI) / (2 * M_PI) * s.angles) % s.angles;
      r[static_cast<size_t>(k)] = std::max(r[static_cast<size_t>(k)], radius);
    }
  const int n = s.angles, w = s.smoothing, half = w / 2;
  m.outline.assign(static_cast<size_t>(n), 0.0);
  for (int k = 0; k < n; ++k) {
    double sum = 0;
    for (int d = -half; d < w - half; ++d) sum += r[static_cast<size_t>(((k + d) % n + n) % n)];
    m.outline[static_cast<size_t>(k)] = sum / w;
  }
  // The nodes: the outline's maxima by topographic prominence, as the sleeves' folds are counted.
  for (const SignalPeak& peak : find_profile_peaks(m.outline, true))
    if (peak.prominence >= s.prominence) m.node_bins.push_back(peak.index);
  m.nodes = static_cast<int>(m.node_bins.size());
  return m;
}

}  // namespace clothsim

#include "sim/study/fold_count.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

namespace clothsim {

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr double kEmpty = -std::numeric_limits<double>::infinity();  // a bin no section point reached

std::string vector_text(const Eigen::Vector3d& v) {
  std::ostringstream out;
  out << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return out.str();
}

void check_surface(const Eigen::MatrixX3d& points, const std::vector<std::array<int, 3>>& triangles) {
  for (Eigen::Index p = 0; p < points.rows(); ++p)
    if (!points.row(p).allFinite())
      throw std::invalid_argument("fold count: point " + std::to_string(p) + " has a non-finite coordinate " +
                                  vector_text(points.row(p).transpose()));
  for (size_t t = 0; t < triangles.size(); ++t)
    for (int v : triangles[t])
      if (v < 0 || v >= points.rows())
        throw std::invalid_argument("fold count: triangle " + std::to_string(t) + " has vertex index " +
                                    std::to_string(v) + " outside [0, " + std::to_string(points.rows()) + ")");
}

void check_window(const char* bins_name, int bins, const char* window_name, int window) {
  if (bins < 8)
    throw std::invalid_argument(std::string("fold count: ") + bins_name + " must be at least 8 (got " +
                                std::to_string(bins) + ")");
  if (window < 1 || window > bins || window % 2 == 0)
    throw std::invalid_argument(std::string("fold count: ") + window_name + " must be odd and in [1, " + bins_name +
                                "] (got " + std::to_string(window) + ")");
}

void check_options(const FoldCountOptions& o) {
  check_window("angular_bins", o.angular_bins, "angular_window", o.angular_window);
  check_window("axial_bins", o.axial_bins, "axial_window", o.axial_window);
  if (!(std::isfinite(o.prominence) && o.prominence >= 0))
    throw std::invalid_argument("fold count: prominence must be finite and >= 0 (got " + std::to_string(o.prominence) +
                                ")");
  if (o.prominence == 0 && !(std::isfinite(o.relative_prominence) && o.relative_prominence > 0))
    throw std::invalid_argument("fold count: relative_prominence must be finite and > 0 (got " +
                                std::to_string(o.relative_prominence) + ")");
  if (o.heights < 1) throw std::invalid_argument("fold count: heights must be at least 1");
  if (!(o.height_from >= 0 && o.height_from <= o.height_to && o.height_to <= 1))
    throw std::invalid_argument("fold count: need 0 <= height_from <= height_to <= 1 (got " +
                                std::to_string(o.height_from) + ", " + std::to_string(o.height_to) + ")");
  if (o.axial_angles < 1) throw std::invalid_argument("fold count: axial_angles must be at least 1");
}

// Local coordinates of every point: (a, b, s) = ((x − c)·e1, (x − c)·e2, (x − c)·d).
Eigen::MatrixX3d local_coordinates(const Eigen::MatrixX3d& points, const FoldFrame& f) {
  Eigen::MatrixX3d q(points.rows(), 3);
  for (Eigen::Index p = 0; p < points.rows(); ++p) {
    const Eigen::Vector3d x = points.row(p).transpose() - f.origin;
    q.row(p) << x.dot(f.e1), x.dot(f.e2), x.dot(f.d);
  }
  return q;
}

// Extent of the triangles' vertices along the axis (third local coordinate); {0, 0} without triangles.
std::pair<double, double> axial_extent(const Eigen::MatrixX3d& q, const std::vector<std::array<int, 3>>& triangles) {
  if (triangles.empty()) return {0.0, 0.0};
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& t : triangles)
    for (int v : t) {
      lo = std::min(lo, q(v, 2));
      hi = std::max(hi, q(v, 2));
    }
  return {lo, hi};
}

struct Segment {
  Eigen::Vector3d p, q;  // local coordinates; p == q for a single point
};

// The exact section of the triangles with the plane f = 0, f given per point (`f`, linear in
// space): per triangle, the vertices with f exactly 0 and the crossings of the edges whose ends
// have strictly opposite signs. Two such points make a segment, one a single point, three (a
// triangle lying in the plane) its three edges. A crossing is interpolated from the edge's lower
// vertex index, so that both triangles of an edge give the same point.
std::vector<Segment> plane_section(const Eigen::MatrixX3d& q, const std::vector<std::array<int, 3>>& triangles,
                                   const Eigen::VectorXd& f) {
  std::vector<Segment> out;
  auto sign = [&](int v) { return f[v] > 0 ? 1 : (f[v] < 0 ? -1 : 0); };
  for (const auto& t : triangles) {
    const int s0 = sign(t[0]), s1 = sign(t[1]), s2 = sign(t[2]);
    if ((s0 > 0 && s1 > 0 && s2 > 0) || (s0 < 0 && s1 < 0 && s2 < 0)) continue;
    std::array<Eigen::Vector3d, 3> pts;
    int k = 0;
    const int signs[3] = {s0, s1, s2};
    for (int i = 0; i < 3; ++i)
      if (signs[i] == 0) pts[k++] = q.row(t[i]).transpose();
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3;
      if (signs[i] * signs[j] >= 0) continue;
      const int a = std::min(t[i], t[j]), b = std::max(t[i], t[j]);
      const double u = f[a] / (f[a] - f[b]);
      pts[k++] = q.row(a).transpose() + u * (q.row(b) - q.row(a)).transpose();
    }
    if (k == 1) out.push_back({pts[0], pts[0]});
    if (k == 2) out.push_back({pts[0], pts[1]});
    if (k == 3)
      for (int i = 0; i < 3; ++i) out.push_back({pts[i], pts[(i + 1) % 3]});
  }
  return out;
}

void raise(std::vector<double>& bins, long j, double r) {
  const long n = static_cast<long>(bins.size());
  j = ((j % n) + n) % n;
  bins[j] = std::max(bins[j], r);
}

long angular_bin(const Eigen::Vector2d& x, double width, int n) {
  double theta = std::atan2(x.y(), x.x());
  if (theta < 0) theta += kTwoPi;
  return std::min(static_cast<long>(std::floor(theta / width)), static_cast<long>(n - 1));
}

// Raises the angular bins (bin j: θ ∈ [j w, (j + 1) w], w = 2π / n) that the segment p–q (plane
// coordinates (a, b)) passes through to the largest radius of its points in them. The radius is
// convex along a straight segment, so its maximum over the part inside a bin is at an end of that
// part: an end of the segment or its crossing with a bin's edge ray, all computed exactly.
void add_angular(Eigen::Vector2d p, Eigen::Vector2d q, std::vector<double>& bins) {
  const int n = static_cast<int>(bins.size());
  const double width = kTwoPi / n;
  const double rp = p.norm(), rq = q.norm();
  if (rp == 0 && rq == 0) return;  // a point on the axis has no angle
  const double cross = p.x() * q.y() - p.y() * q.x();
  if (rp == 0 || rq == 0 || cross == 0) {  // on one ray, or on two opposite rays through the axis
    if (rp > 0) raise(bins, angular_bin(p, width, n), rp);
    if (rq > 0) raise(bins, angular_bin(q, width, n), rq);
    return;
  }
  if (cross < 0) std::swap(p, q);  // sweep counter-clockwise from p to q
  const double r_start = p.norm(), r_end = q.norm();
  const double sweep = std::atan2(std::abs(cross), p.dot(q));  // (0, π)
  double theta = std::atan2(p.y(), p.x());
  if (theta < 0) theta += kTwoPi;
  const double x = theta / width, y = (theta + sweep) / width;
  long bin = std::min(static_cast<long>(std::floor(x)), static_cast<long>(n - 1));
  double r_prev = r_start;
  const Eigen::Vector2d e = q - p;
  for (long k = bin + 1; static_cast<double>(k) < y; ++k) {
    const double phi = static_cast<double>(k) * width;
    const Eigen::Vector2d u(std::cos(phi), std::sin(phi));
    const double denom = u.x() * e.y() - u.y() * e.x();
    const double t = denom == 0 ? 0.0 : std::clamp(-(u.x() * p.y() - u.y() * p.x()) / denom, 0.0, 1.0);
    const double r = (p + t * e).norm();
    raise(bins, bin, std::max(r_prev, r));
    bin = k;
    r_prev = r;
  }
  raise(bins, bin, std::max(r_prev, r_end));
}

// Raises the axial bins (bin j: s ∈ [s_min + j h, s_min + (j + 1) h]) that the segment
// (s0, r0)–(s1, r1) passes through; r is linear along it, so the maximum in a bin is at an end of
// the part inside it.
void add_axial(double s0, double r0, double s1, double r1, double s_min, double h, std::vector<double>& bins) {
  const long n = static_cast<long>(bins.size());
  auto bin_of = [&](double s) {
    if (!(h > 0)) return 0L;
    return std::clamp(static_cast<long>(std::floor((s - s_min) / h)), 0L, n - 1);
  };
  if (s0 > s1) {
    std::swap(s0, s1);
    std::swap(r0, r1);
  }
  const long j0 = bin_of(s0), j1 = bin_of(s1);
  if (j0 == j1) {
    raise(bins, j0, std::max(r0, r1));
    return;
  }
  double r_prev = r0;
  for (long k = j0 + 1; k <= j1; ++k) {
    const double edge = s_min + static_cast<double>(k) * h;
    const double t = std::clamp((edge - s0) / (s1 - s0), 0.0, 1.0);
    const double r = r0 + t * (r1 - r0);
    raise(bins, k - 1, std::max(r_prev, r));
    r_prev = r;
  }
  raise(bins, j1, std::max(r_prev, r1));
}

std::vector<double> raw_angular_profile(const Eigen::MatrixX3d& q, const std::vector<std::array<int, 3>>& triangles,
                                        double height, int n) {
  const Eigen::VectorXd f = q.col(2).array() - height;
  std::vector<double> bins(static_cast<size_t>(n), kEmpty);
  for (const Segment& seg : plane_section(q, triangles, f)) add_angular(seg.p.head<2>(), seg.q.head<2>(), bins);
  return bins;
}

std::vector<double> raw_axial_profile(const Eigen::MatrixX3d& q, const std::vector<std::array<int, 3>>& triangles,
                                      double angle, double s_min, double s_max, int n) {
  const double c = std::cos(angle), s = std::sin(angle);
  const Eigen::VectorXd f = -s * q.col(0).array() + c * q.col(1).array();
  std::vector<double> bins(static_cast<size_t>(n), kEmpty);
  const double h = (s_max - s_min) / n;
  for (const Segment& seg : plane_section(q, triangles, f)) {
    double s0 = seg.p.z(), s1 = seg.q.z();
    double r0 = c * seg.p.x() + s * seg.p.y(), r1 = c * seg.q.x() + s * seg.q.y();
    if (r0 < 0 && r1 < 0) continue;  // the other half of the plane
    if (r0 < 0 || r1 < 0) {          // clip at the axis
      const double t = r0 / (r0 - r1);
      const double s_axis = s0 + t * (s1 - s0);
      if (r0 < 0) {
        s0 = s_axis;
        r0 = 0;
      } else {
        s1 = s_axis;
        r1 = 0;
      }
    }
    add_axial(s0, r0, s1, r1, s_min, h, bins);
  }
  return bins;
}

// Empty bins of a circular profile filled by linear interpolation between the nearest reached bins
// on either side; false if no bin was reached.
bool fill_circular(std::vector<double>& x) {
  const long n = static_cast<long>(x.size());
  std::vector<long> hit;
  for (long j = 0; j < n; ++j)
    if (x[j] != kEmpty) hit.push_back(j);
  if (hit.empty()) return false;
  for (size_t i = 0; i < hit.size(); ++i) {
    const long a = hit[i], b = i + 1 < hit.size() ? hit[i + 1] : hit[0] + n;
    for (long j = a + 1; j < b; ++j) {
      const double t = static_cast<double>(j - a) / static_cast<double>(b - a);
      x[j % n] = (1 - t) * x[a] + t * x[b % n];
    }
  }
  return true;
}

std::vector<double> smooth_circular(const std::vector<double>& x, int window) {
  const long n = static_cast<long>(x.size()), h = window / 2;
  std::vector<double> y(x.size());
  for (long j = 0; j < n; ++j) {
    double sum = 0;
    for (long k = -h; k <= h; ++k) sum += x[((j + k) % n + n) % n];
    y[j] = sum / window;
  }
  return y;
}

// A moving average whose window shrinks symmetrically near the ends (the end samples stay as they are).
std::vector<double> smooth_linear(const std::vector<double>& x, int window) {
  const long n = static_cast<long>(x.size());
  std::vector<double> y(x.size());
  for (long j = 0; j < n; ++j) {
    const long h = std::min({static_cast<long>(window / 2), j, n - 1 - j});
    double sum = 0;
    for (long k = j - h; k <= j + h; ++k) sum += x[k];
    y[j] = sum / static_cast<double>(2 * h + 1);
  }
  return y;
}

double mean(const std::vector<double>& x) {
  double sum = 0;
  for (double v : x) sum += v;
  return x.empty() ? 0.0 : sum / static_cast<double>(x.size());
}

Eigen::VectorXd to_eigen(const std::vector<double>& x) {
  return Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
}

// A height section before counting: the filled, unsmoothed profile and its mean.
struct PreparedSection {
  double height = 0.0;
  bool has_section = false;
  std::vector<double> filled;
  double coverage = 0.0, mean_radius = 0.0;
};

PreparedSection prepare_section(const Eigen::MatrixX3d& q, const std::vector<std::array<int, 3>>& triangles,
                                double height, int bins) {
  PreparedSection p;
  p.height = height;
  p.filled = raw_angular_profile(q, triangles, height, bins);
  const auto reached = std::count_if(p.filled.begin(), p.filled.end(), [](double v) { return v != kEmpty; });
  p.coverage = static_cast<double>(reached) / bins;
  p.has_section = fill_circular(p.filled);
  if (p.has_section) p.mean_radius = mean(p.filled);
  return p;
}

CircumferentialFolds count_section(const PreparedSection& p, const FoldCountOptions& o, double threshold) {
  CircumferentialFolds out;
  out.height = p.height;
  out.has_section = p.has_section;
  if (!p.has_section) return out;
  out.coverage = p.coverage;
  out.mean_radius = p.mean_radius;
  out.prominence_threshold = threshold;
  const std::vector<double> smooth = smooth_circular(p.filled, o.angular_window);
  for (const SignalPeak& peak : find_profile_peaks(smooth, true)) {
    if (peak.prominence >= threshold)
      out.peaks.push_back({kTwoPi * (peak.index + 0.5) / o.angular_bins, smooth[peak.index], peak.prominence});
    else
      out.largest_uncounted_prominence = std::max(out.largest_uncounted_prominence, peak.prominence);
  }
  out.count = static_cast<int>(out.peaks.size());
  out.profile = to_eigen(smooth);
  return out;
}

// An axial profile before counting: the reached range of bins [first, last], gaps filled.
struct PreparedProfile {
  double angle = 0.0;
  bool has_section = false;
  long first = 0;
  std::vector<double> filled;
  double mean_radius = 0.0;
};

PreparedProfile prepare_profile(const Eigen::MatrixX3d& q, const std::vector<std::array<int, 3>>& triangles,
                                double angle, double s_min, double s_max, int bins) {
  PreparedProfile p;
  p.angle = angle;
  const std::vector<double> raw = raw_axial_profile(q, triangles, angle, s_min, s_max, bins);
  std::vector<long> hit;
  for (long j = 0; j < static_cast<long>(raw.size()); ++j)
    if (raw[j] != kEmpty) hit.push_back(j);
  if (hit.empty()) return p;
  p.has_section = true;
  p.first = hit.front();
  p.filled.assign(raw.begin() + hit.front(), raw.begin() + hit.back() + 1);
  for (size_t i = 0; i + 1 < hit.size(); ++i)
    for (long j = hit[i] + 1; j < hit[i + 1]; ++j) {
      const double t = static_cast<double>(j - hit[i]) / static_cast<double>(hit[i + 1] - hit[i]);
      p.filled[j - p.first] = (1 - t) * raw[hit[i]] + t * raw[hit[i + 1]];
    }
  p.mean_radius = mean(p.filled);
  return p;
}

AxialProfileFolds count_profile(const PreparedProfile& p, const FoldCountOptions& o, double s_min, double s_max,
                                double threshold) {
  AxialProfileFolds out;
  out.angle = p.angle;
  out.has_section = p.has_section;
  if (!p.has_section) return out;
  const double h = (s_max - s_min) / o.axial_bins;
  auto centre = [&](long j) { return s_min + (static_cast<double>(j) + 0.5) * h; };
  out.s_from = centre(p.first);
  out.s_to = centre(p.first + static_cast<long>(p.filled.size()) - 1);
  out.mean_radius = p.mean_radius;
  const std::vector<double> smooth = smooth_linear(p.filled, o.axial_window);
  for (const SignalPeak& peak : find_profile_peaks(smooth, false)) {
    if (peak.prominence >= threshold)
      out.peaks.push_back({centre(p.first + peak.index), smooth[peak.index], peak.prominence});
    else
      out.largest_uncounted_prominence = std::max(out.largest_uncounted_prominence, peak.prominence);
  }
  out.count = static_cast<int>(out.peaks.size());
  out.profile = to_eigen(smooth);
  return out;
}

std::optional<double> median_count(const std::vector<int>& counts) {
  std::vector<double> v(counts.begin(), counts.end());
  return median_of(std::move(v));
}

AxialFolds count_profiles(const std::vector<PreparedProfile>& prepared, const FoldCountOptions& o, double s_min,
                          double s_max, double threshold) {
  AxialFolds out;
  out.s_min = s_min;
  out.s_max = s_max;
  out.prominence_threshold = threshold;
  std::vector<int> counts;
  for (const PreparedProfile& p : prepared) {
    out.profiles.push_back(count_profile(p, o, s_min, s_max, threshold));
    if (p.has_section) counts.push_back(out.profiles.back().count);
  }
  out.median_count = median_count(counts);
  return out;
}

}  // namespace

FoldFrame fold_frame(const FoldAxis& axis) {
  if (!axis.point.allFinite()) throw std::invalid_argument("fold count: the axis point " + vector_text(axis.point) + " is not finite");
  const double norm = axis.direction.norm();
  if (!(std::isfinite(norm) && norm > 0))
    throw std::invalid_argument("fold count: the axis direction " + vector_text(axis.direction) +
                                " is zero or not finite");
  FoldFrame f;
  f.origin = axis.point;
  f.d = axis.direction / norm;
  Eigen::Vector3d ref = axis.reference;
  if (!ref.allFinite())
    throw std::invalid_argument("fold count: the reference direction " + vector_text(ref) + " is not finite");
  if (ref.isZero(0.0)) {
    int least = 0;
    for (int i = 1; i < 3; ++i)
      if (std::abs(f.d[i]) < std::abs(f.d[least])) least = i;
    ref = Eigen::Vector3d::Unit(least);
  }
  const Eigen::Vector3d perp = ref - ref.dot(f.d) * f.d;
  if (!(perp.norm() > 1e-9 * ref.norm()))
    throw std::invalid_argument("fold count: the reference direction " + vector_text(axis.reference) +
                                " is parallel to the axis");
  f.e1 = perp.normalized();
  f.e2 = f.d.cross(f.e1);
  return f;
}

Eigen::VectorXd section_radius_profile(const Eigen::MatrixX3d& points, const std::vector<std::array<int, 3>>& triangles,
                                       const FoldAxis& axis, double height, int angular_bins) {
  check_surface(points, triangles);
  if (angular_bins < 8) throw std::invalid_argument("fold count: angular_bins must be at least 8");
  if (!std::isfinite(height)) throw std::invalid_argument("fold count: the height is not finite");
  const FoldFrame frame = fold_frame(axis);
  std::vector<double> raw = raw_angular_profile(local_coordinates(points, frame), triangles, height, angular_bins);
  for (double& v : raw)
    if (v == kEmpty) v = std::numeric_limits<double>::quiet_NaN();
  return to_eigen(raw);
}

CircumferentialFolds count_circumferential_folds(const Eigen::MatrixX3d& points,
                                                 const std::vector<std::array<int, 3>>& triangles,
                                                 const FoldAxis& axis, double height,
                                                 const FoldCountOptions& options) {
  check_surface(points, triangles);
  check_options(options);
  if (!std::isfinite(height)) throw std::invalid_argument("fold count: the height is not finite");
  const FoldFrame frame = fold_frame(axis);
  const PreparedSection p = prepare_section(local_coordinates(points, frame), triangles, height, options.angular_bins);
  const double threshold =
      options.prominence > 0 ? options.prominence : options.relative_prominence * p.mean_radius;
  return count_section(p, options, threshold);
}

AxialFolds count_axial_folds(const Eigen::MatrixX3d& points, const std::vector<std::array<int, 3>>& triangles,
                             const FoldAxis& axis, const std::vector<double>& angles,
                             const FoldCountOptions& options) {
  check_surface(points, triangles);
  check_options(options);
  for (size_t k = 0; k < angles.size(); ++k)
    if (!std::isfinite(angles[k]))
      throw std::invalid_argument("fold count: angle " + std::to_string(k) + " is not finite");
  const FoldFrame frame = fold_frame(axis);
  const Eigen::MatrixX3d q = local_coordinates(points, frame);
  const auto [s_min, s_max] = axial_extent(q, triangles);
  std::vector<PreparedProfile> prepared;
  std::vector<double> means;
  for (double angle : angles) {
    prepared.push_back(prepare_profile(q, triangles, angle, s_min, s_max, options.axial_bins));
    if (prepared.back().has_section) means.push_back(prepared.back().mean_radius);
  }
  const double threshold = options.prominence > 0 ? options.prominence : options.relative_prominence * mean(means);
  return count_profiles(prepared, options, s_min, s_max, threshold);
}

SleeveFolds count_sleeve_folds(const Eigen::MatrixX3d& points, const std::vector<std::array<int, 3>>& triangles,
                               const FoldAxis& axis, const FoldCountOptions& options) {
  check_surface(points, triangles);
  check_options(options);
  const FoldFrame frame = fold_frame(axis);
  SleeveFolds out;
  if (triangles.empty()) {
    out.prominence_threshold = options.prominence;
    out.axial.prominence_threshold = options.prominence;
    return out;
  }
  const Eigen::MatrixX3d q = local_coordinates(points, frame);
  std::tie(out.s_min, out.s_max) = axial_extent(q, triangles);
  const double length = out.s_max - out.s_min;

  std::vector<PreparedSection> sections;
  std::vector<double> section_means;
  for (int i = 0; i < options.heights; ++i) {
    const double fraction =
        options.heights == 1 ? 0.5 * (options.height_from + options.height_to)
                             : options.height_from + (options.height_to - options.height_from) * i / (options.heights - 1);
    sections.push_back(prepare_section(q, triangles, out.s_min + fraction * length, options.angular_bins));
    if (sections.back().has_section) section_means.push_back(sections.back().mean_radius);
  }
  std::vector<PreparedProfile> profiles;
  std::vector<double> profile_means;
  for (int k = 0; k < options.axial_angles; ++k) {
    profiles.push_back(prepare_profile(q, triangles, kTwoPi * (k + 0.5) / options.axial_angles, out.s_min, out.s_max,
                                       options.axial_bins));
    if (profiles.back().has_section) profile_means.push_back(profiles.back().mean_radius);
  }
  out.mean_radius = !section_means.empty() ? mean(section_means) : mean(profile_means);
  out.prominence_threshold = options.prominence > 0 ? options.prominence : options.relative_prominence * out.mean_radius;

  std::vector<int> counts;
  for (const PreparedSection& p : sections) {
    out.heights.push_back(count_section(p, options, out.prominence_threshold));
    if (p.has_section) counts.push_back(out.heights.back().count);
  }
  out.circumferential_median = median_count(counts);
  out.axial = count_profiles(profiles, options, out.s_min, out.s_max, out.prominence_threshold);
  return out;
}

std::vector<SignalPeak> find_profile_peaks(const std::vector<double>& x, bool circular) {
  const long n = static_cast<long>(x.size());
  for (long j = 0; j < n; ++j)
    if (!std::isfinite(x[j])) throw std::invalid_argument("find_profile_peaks: sample " + std::to_string(j) + " is not finite");
  std::vector<SignalPeak> peaks;
  if (n < 3) return peaks;
  auto at = [&](long j) { return x[((j % n) + n) % n]; };

  // The prominence of the flat top [a, b] (b ≥ a, unwrapped indices) of height h. Exact ties are
  // broken by index: a sample of height h is higher ground if its index (in [0, n)) is below the
  // flat top's lowest one, as if every sample were lowered by an infinitesimal multiple of its
  // index; so of two equally high crests only the first one walks past the other.
  auto prominence = [&](long a, long b, double h) {
    const long rank = b >= n ? 0 : a % n;  // the flat top's lowest index
    auto higher = [&](long j) {
      const long i = ((j % n) + n) % n;
      return x[i] > h || (x[i] == h && i < rank);
    };
    double left = h, right = h;
    if (circular) {
      const long others = n - (b - a + 1);
      for (long k = 1; k <= others && !higher(a - k); ++k) left = std::min(left, at(a - k));
      for (long k = 1; k <= others && !higher(b + k); ++k) right = std::min(right, at(b + k));
    } else {
      for (long j = a - 1; j >= 0 && !higher(j); --j) left = std::min(left, x[j]);
      for (long j = b + 1; j < n && !higher(j); ++j) right = std::min(right, x[j]);
    }
    return h - std::max(left, right);
  };

  if (circular) {
    // Start at the beginning of a run of equal samples; none: a constant signal.
    long start = -1;
    for (long j = 0; j < n && start < 0; ++j)
      if (at(j) != at(j - 1)) start = j;
    if (start < 0) return peaks;
    for (long a = start; a < start + n;) {
      long b = a;
      while (b + 1 < start + n && at(b + 1) == at(a)) ++b;
      if (at(a - 1) < at(a) && at(b + 1) < at(a))
        peaks.push_back({static_cast<int>(((a + b) / 2) % n), prominence(a, b, at(a))});
      a = b + 1;
    }
    std::sort(peaks.begin(), peaks.end(), [](const SignalPeak& l, const SignalPeak& r) { return l.index < r.index; });
  } else {
    for (long a = 1; a < n - 1;) {
      long b = a;
      while (b + 1 < n - 1 && x[b + 1] == x[a]) ++b;
      if (x[a - 1] < x[a] && x[b + 1] < x[a]) peaks.push_back({static_cast<int>((a + b) / 2), prominence(a, b, x[a])});
      a = b + 1;
    }
  }
  return peaks;
}

std::optional<double> median_of(std::vector<double> values) {
  if (values.empty()) return std::nullopt;
  std::sort(values.begin(), values.end());
  const size_t m = values.size() / 2;
  return values.size() % 2 == 1 ? values[m] : 0.5 * (values[m - 1] + values[m]);
}

}  // namespace clothsim

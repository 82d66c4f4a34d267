// The fold counter (sim/study/fold_count.hpp, docs/fold_count.md) on synthetic sleeves with a known
// number of folds: cosine lobes around the axis, twisted (helical) lobes, bellows rings, diamonds,
// radial noise and a single bump, each built as a triangle mesh whose vertices lie on the analytic
// surface, at several resolutions and with three triangulations (structured with the quads'
// diagonals one way, the other way, and a randomly jittered one), about an axis along z and about a
// tilted one. The expected counts come from the analytic surfaces (where a fold's prominence lies
// within ±30 % of the threshold the expectation is called ambiguous and not checked); the peak
// finder's prominences are checked against hand-computed values.
#include "sim/study/fold_count.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2 * kPi;
constexpr double kRadius = 0.05;     // R [m]
constexpr double kLength = 0.2;      // L [m]
constexpr double kAmplitude = 0.005; // a [m]: fold prominence 2a = 10 mm
// The default threshold: 2 % of the mean radius, which is R for every surface below up to the
// few-percent effect of the bellows' rings on the mean of the sampled heights.
constexpr double kThreshold = 0.02 * kRadius;

using RadiusFn = std::function<double(double theta, double s)>;
using Triangles = std::vector<std::array<int, 3>>;

enum class Triangulation { kDiagonalsUp, kDiagonalsDown, kJittered };

const char* name(Triangulation t) {
  switch (t) {
    case Triangulation::kDiagonalsUp: return "diagonals up";
    case Triangulation::kDiagonalsDown: return "diagonals down";
    case Triangulation::kJittered: return "jittered";
  }
  return "?";
}

// An orthonormal right-handed frame (e1, e2, d) at c, built here (not by fold_frame).
struct Frame {
  Eigen::Vector3d c, e1, e2, d;
  bool tilted = false;
};

Frame aligned_frame() {
  return {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), false};
}

Frame tilted_frame() {
  Frame f;
  f.c = Eigen::Vector3d(0.3, -0.1, 0.7);
  f.d = Eigen::Vector3d(1, 2, -0.5).normalized();
  f.e1 = Eigen::Vector3d(2, -1, 0).normalized();  // ⊥ (1, 2, −0.5)
  f.e2 = f.d.cross(f.e1);
  f.tilted = true;
  return f;
}

// The aligned frame relies on fold_frame's default reference (x for an axis along z, checked in
// FoldFrame.DefaultReferenceIsTheLeastAlignedCoordinateAxis); the tilted one passes e1.
FoldAxis axis_of(const Frame& f) {
  FoldAxis axis;
  axis.point = f.c;
  axis.direction = f.tilted ? Eigen::Vector3d(f.d * 3.0) : f.d;  // any length
  axis.reference = f.tilted ? f.e1 : Eigen::Vector3d::Zero();
  return axis;
}

struct Sleeve {
  Eigen::MatrixX3d points;
  Triangles triangles;
  std::string label;
};

// The surface x = c + r(θ, s) (cos θ e1 + sin θ e2) + s d, θ ∈ [0, 2π), s ∈ [0, L], sampled at
// n_theta × (n_s + 1) vertices (ring j at s = L j / n_s) and split into triangles. Jittered: every
// vertex's θ and every inner ring vertex's s moved by up to ±0.3 of a spacing, and each quad's
// diagonal chosen at random.
Sleeve make_sleeve(const RadiusFn& r, int n_theta, int n_s, Triangulation kind, const Frame& f, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::bernoulli_distribution coin(0.5);
  const bool jittered = kind == Triangulation::kJittered;
  Sleeve out;
  out.points.resize((n_s + 1) * n_theta, 3);
  for (int j = 0; j <= n_s; ++j)
    for (int i = 0; i < n_theta; ++i) {
      const double theta = kTwoPi * (i + (jittered ? jitter(rng) : 0.0)) / n_theta;
      const double s = kLength * (j + (jittered && j > 0 && j < n_s ? jitter(rng) : 0.0)) / n_s;
      const double radius = r(theta, s);
      const Eigen::Vector3d x =
          f.c + radius * std::cos(theta) * f.e1 + radius * std::sin(theta) * f.e2 + s * f.d;
      out.points.row(j * n_theta + i) = x.transpose();
    }
  for (int j = 0; j < n_s; ++j)
    for (int i = 0; i < n_theta; ++i) {
      const int i1 = (i + 1) % n_theta;
      const int a = j * n_theta + i, b = j * n_theta + i1, c = (j + 1) * n_theta + i1, d = (j + 1) * n_theta + i;
      const bool up = kind == Triangulation::kDiagonalsUp || (jittered && coin(rng));
      if (up) {
        out.triangles.push_back({a, b, c});
        out.triangles.push_back({a, c, d});
      } else {
        out.triangles.push_back({a, b, d});
        out.triangles.push_back({b, c, d});
      }
    }
  std::ostringstream label;
  label << n_theta << "x" << n_s << " " << name(kind) << (f.tilted ? ", tilted axis" : ", axis z");
  out.label = label.str();
  return out;
}

// The meshes most tests run on: three triangulations at two resolutions, about both axes.
struct MeshSpec {
  int n_theta, n_s;
  Triangulation kind;
  bool tilted;
};
std::vector<MeshSpec> standard_meshes(int n_theta, int n_s) {
  std::vector<MeshSpec> out;
  for (int scale : {1, 2})
    for (Triangulation kind : {Triangulation::kDiagonalsUp, Triangulation::kDiagonalsDown, Triangulation::kJittered})
      out.push_back({n_theta * scale, n_s * scale, kind, kind != Triangulation::kDiagonalsUp});
  return out;
}

// The expected count of a circular profile R + amp cos(n θ + φ): n peaks of prominence 2 amp, all
// counted or none; none (ambiguous) within ±30 % of the threshold.
std::optional<int> expected_circular(int n, double amp, double threshold = kThreshold) {
  const double prominence = 2 * std::abs(amp);
  if (prominence >= 1.3 * threshold) return n;
  if (prominence <= 0.7 * threshold) return 0;
  return std::nullopt;
}

// The expected count of a linear profile R + amp cos φ, φ from phi0 to phi1 > phi0, under the
// header's prominence definition: the maxima φ = 2πj strictly inside; a maximum's base on a side
// is −amp if a trough lies between it and that end, else amp cos(end phase) (no higher sample
// than a crest exists). None (ambiguous) if a prominence lies within ±30 % of the threshold.
std::optional<int> expected_linear(double phi0, double phi1, double amp, double threshold = kThreshold) {
  int count = 0;
  for (long j = static_cast<long>(std::ceil(phi0 / kTwoPi)); j <= static_cast<long>(std::floor(phi1 / kTwoPi)); ++j) {
    const double crest = kTwoPi * static_cast<double>(j);
    if (crest <= phi0 || crest >= phi1) continue;
    const double left = crest - kPi > phi0 ? -amp : amp * std::cos(phi0);
    const double right = crest + kPi < phi1 ? -amp : amp * std::cos(phi1);
    const double prominence = amp - std::max(left, right);
    if (prominence >= 1.3 * threshold)
      ++count;
    else if (prominence > 0.7 * threshold)
      return std::nullopt;
  }
  return count;
}

// Distance [rad] from θ to the nearest angle offset + 2πj/n.
double lattice_distance(double theta, double offset, int n) {
  return std::abs(std::remainder(theta - offset, kTwoPi / n));
}

std::string optional_text(const std::optional<double>& v) {
  if (!v) return "none";
  std::ostringstream out;
  out << *v;
  return out.str();
}

std::string summary_text(const SleeveFolds& f) {
  std::ostringstream out;
  out << "heights:";
  for (const CircumferentialFolds& h : f.heights) out << " " << (h.has_section ? std::to_string(h.count) : "-");
  out << " (median " << optional_text(f.circumferential_median) << "); axial:";
  for (const AxialProfileFolds& p : f.axial.profiles) out << " " << (p.has_section ? std::to_string(p.count) : "-");
  out << " (median " << optional_text(f.axial.median_count) << "); P = " << f.prominence_threshold * 1e3 << " mm";
  return out.str();
}

// The largest prominence among counted peaks is at most ~2a; the smallest counted one and the
// largest uncounted one show the margins.
std::string margins_text(const SleeveFolds& f) {
  double smallest = std::numeric_limits<double>::infinity(), uncounted = 0;
  for (const CircumferentialFolds& h : f.heights) {
    for (const FoldPeak& p : h.peaks) smallest = std::min(smallest, p.prominence);
    uncounted = std::max(uncounted, h.largest_uncounted_prominence);
  }
  for (const AxialProfileFolds& a : f.axial.profiles) {
    for (const FoldPeak& p : a.peaks) smallest = std::min(smallest, p.prominence);
    uncounted = std::max(uncounted, a.largest_uncounted_prominence);
  }
  std::ostringstream out;
  out << "smallest counted prominence ";
  if (std::isfinite(smallest))
    out << smallest * 1e3 << " mm";
  else
    out << "(none counted)";
  out << ", largest uncounted " << uncounted * 1e3 << " mm";
  return out.str();
}

// The heights of count_sleeve_folds with the default options: 9 from 20 % to 80 % of [0, L].
std::vector<double> default_heights() {
  std::vector<double> s;
  for (int i = 0; i < 9; ++i) s.push_back(kLength * (0.2 + 0.6 * i / 8));
  return s;
}

// ---------------------------------------------------------------------------------------------
// The peak finder and the median.

TEST(FoldPeaks, LinearProminenceFollowsTheStandardDefinition) {
  // Hand-computed: peak 1 (2) is bounded on the right by 3 (base max(0, 1) = 1); peak 3 (3) is the
  // highest (bases 0 and 0); peak 5 (1) is bounded on the left by 3 (bases 0 and 0).
  std::vector<SignalPeak> p = find_profile_peaks({0, 2, 1, 3, 0, 1, 0}, false);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[0].index, 1);
  EXPECT_DOUBLE_EQ(p[0].prominence, 1.0);
  EXPECT_EQ(p[1].index, 3);
  EXPECT_DOUBLE_EQ(p[1].prominence, 3.0);
  EXPECT_EQ(p[2].index, 5);
  EXPECT_DOUBLE_EQ(p[2].prominence, 1.0);
  // The end samples are never peaks, however high.
  p = find_profile_peaks({5, 1, 2, 1, 5}, false);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].index, 2);
  EXPECT_DOUBLE_EQ(p[0].prominence, 1.0);
  // Flat tops: one peak at the middle (the lower of two middle samples); a flat top that reaches
  // an end is no peak.
  p = find_profile_peaks({0, 2, 2, 2, 0}, false);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].index, 2);
  EXPECT_DOUBLE_EQ(p[0].prominence, 2.0);
  p = find_profile_peaks({0, 2, 2, 0}, false);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].index, 1);
  EXPECT_TRUE(find_profile_peaks({0, 1, 2, 2}, false).empty());
  EXPECT_TRUE(find_profile_peaks({1, 1, 1}, false).empty());
  // Two exactly equal crests: the first one's right walk passes the second (base 0); the
  // second's left walk stops at the first (base 1).
  p = find_profile_peaks({0, 2, 1, 2, 0}, false);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_DOUBLE_EQ(p[0].prominence, 2.0);
  EXPECT_DOUBLE_EQ(p[1].prominence, 1.0);
  // The same signal as circular and as linear: the first sample is a peak only when it wraps.
  p = find_profile_peaks({3, 0, 1, 0}, false);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].index, 2);
  EXPECT_DOUBLE_EQ(p[0].prominence, 1.0);
  std::cout << "[fold peaks] linear cases as computed by hand\n";
}

TEST(FoldPeaks, CircularProminenceWrapsAround) {
  // {0, 2, 1, 3}: peak 1 (2) is bounded by 3 on both sides after wrapping (bases 0 and 1);
  // peak 3 (3) is the highest: its prominence is the drop to the global minimum.
  std::vector<SignalPeak> p = find_profile_peaks({0, 2, 1, 3}, true);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0].index, 1);
  EXPECT_DOUBLE_EQ(p[0].prominence, 1.0);
  EXPECT_EQ(p[1].index, 3);
  EXPECT_DOUBLE_EQ(p[1].prominence, 3.0);
  p = find_profile_peaks({3, 0, 1, 0}, true);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0].index, 0);
  EXPECT_DOUBLE_EQ(p[0].prominence, 3.0);
  EXPECT_EQ(p[1].index, 2);
  EXPECT_DOUBLE_EQ(p[1].prominence, 1.0);
  // A flat top across the wrap (samples 3 and 0) is one peak.
  p = find_profile_peaks({1, 0, 0, 1}, true);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].index, 3);
  EXPECT_DOUBLE_EQ(p[0].prominence, 1.0);
  EXPECT_TRUE(find_profile_peaks({2, 2, 2, 2}, true).empty());
  // Two exactly equal crests: the tie goes to the lower index, so only the first one walks past
  // the other (to the global minimum 0); the second stops at the first (bases 1 and 0).
  p = find_profile_peaks({0, 2, 1, 2, 0.5}, true);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_DOUBLE_EQ(p[0].prominence, 2.0);
  EXPECT_DOUBLE_EQ(p[1].prominence, 1.0);
  EXPECT_THROW(find_profile_peaks({0, std::nan(""), 1}, true), std::invalid_argument);
  std::cout << "[fold peaks] circular cases as computed by hand\n";
}

TEST(FoldPeaks, Median) {
  EXPECT_FALSE(median_of({}).has_value());
  EXPECT_DOUBLE_EQ(*median_of({5}), 5.0);
  EXPECT_DOUBLE_EQ(*median_of({9, 1, 5}), 5.0);
  EXPECT_DOUBLE_EQ(*median_of({4, 1, 3, 9}), 3.5);
  std::cout << "[median] {}, {5}, {9, 1, 5}, {4, 1, 3, 9}: none, " << *median_of({5}) << ", " << *median_of({9, 1, 5})
            << ", " << *median_of({4, 1, 3, 9}) << "\n";
}

TEST(FoldFrame, DefaultReferenceIsTheLeastAlignedCoordinateAxis) {
  FoldAxis axis;
  axis.direction = Eigen::Vector3d(0, 0, 2);
  FoldFrame f = fold_frame(axis);
  EXPECT_TRUE(f.d.isApprox(Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE(f.e1.isApprox(Eigen::Vector3d::UnitX()));  // x and y tie: x
  EXPECT_TRUE(f.e2.isApprox(Eigen::Vector3d::UnitY()));
  axis.direction = Eigen::Vector3d(1, 0, 0);
  f = fold_frame(axis);
  EXPECT_TRUE(f.e1.isApprox(Eigen::Vector3d::UnitY()));  // y and z tie: y
  EXPECT_TRUE(f.e2.isApprox(Eigen::Vector3d::UnitZ()));  // x × y
  axis.direction = Eigen::Vector3d(0, 1, 0);
  axis.reference = Eigen::Vector3d(0, 5, 1);  // its part ⊥ y is z
  f = fold_frame(axis);
  EXPECT_TRUE(f.e1.isApprox(Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE(f.e2.isApprox(Eigen::Vector3d::UnitX()));  // y × z
  std::cout << "[fold frame] d = y, reference (0, 5, 1): e1 = " << f.e1.transpose() << ", e2 = " << f.e2.transpose()
            << "\n";
}

// ---------------------------------------------------------------------------------------------
// The exact section profile.

// A square tube |x|, |y| ≤ h for 0 ≤ z ≤ 1 (four faces of two triangles each) and its lid at
// z = 1 (two triangles lying in the plane z = 1). Its section's radius is h / max(|cos θ|,
// |sin θ|), largest at the corners θ = π/4 + kπ/2, so the largest radius in bin [θa, θb] is at
// one of its edges or at a corner inside it.
TEST(FoldSection, SquareTubeProfileIsExactInEveryBin) {
  const double h = 0.05;
  Eigen::MatrixX3d points(8, 3);
  points << h, h, 0, -h, h, 0, -h, -h, 0, h, -h, 0, h, h, 1, -h, h, 1, -h, -h, 1, h, -h, 1;
  Triangles triangles;
  for (int k = 0; k < 4; ++k) {
    const int k1 = (k + 1) % 4;
    triangles.push_back({k, k1, 4 + k1});
    triangles.push_back({k, 4 + k1, 4 + k});
  }
  triangles.push_back({4, 5, 6});  // the lid
  triangles.push_back({4, 6, 7});
  auto radius = [&](double theta) { return h / std::max(std::abs(std::cos(theta)), std::abs(std::sin(theta))); };
  FoldAxis axis;
  axis.direction = Eigen::Vector3d::UnitZ();
  for (int bins : {720, 701, 8})
    for (double z : {0.5, 0.0, 1.0}) {  // the middle; the bottom rim's vertices; the top rim with the lid
      const Eigen::VectorXd profile = section_radius_profile(points, triangles, axis, z, bins);
      ASSERT_EQ(profile.size(), bins);
      double worst = 0;
      for (int j = 0; j < bins; ++j) {
        const double a = kTwoPi * j / bins, b = kTwoPi * (j + 1) / bins;
        double expected = std::max(radius(a), radius(b));
        for (int k = 0; k < 4; ++k) {
          const double corner = kPi / 4 + k * kPi / 2;
          if (corner >= a && corner <= b) expected = h * std::sqrt(2.0);
        }
        ASSERT_TRUE(std::isfinite(profile[j])) << "bin " << j << " of " << bins << " at z = " << z;
        worst = std::max(worst, std::abs(profile[j] - expected));
      }
      std::cout << "[square tube] " << bins << " bins, z = " << z << ": largest error " << worst << " m\n";
      EXPECT_LT(worst, 1e-14);
    }
}

TEST(FoldSection, VerticesExactlyOnThePlaneGiveACompleteSection) {
  const int n = 5;
  auto r = [&](double theta, double) { return kRadius + kAmplitude * std::cos(n * theta); };
  for (Triangulation kind : {Triangulation::kDiagonalsUp, Triangulation::kDiagonalsDown}) {
    const Sleeve sleeve = make_sleeve(r, 60, 20, kind, aligned_frame());
    for (int ring : {0, 7, 20}) {
      const double s = kLength * ring / 20;
      ASSERT_EQ(sleeve.points(ring * 60, 2), s);  // the ring's vertices lie exactly on the plane
      const CircumferentialFolds folds = count_circumferential_folds(sleeve.points, sleeve.triangles, {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()}, s);
      std::cout << "[on the plane] " << sleeve.label << ", ring " << ring << ": coverage " << folds.coverage
                << ", " << folds.count << " folds\n";
      EXPECT_TRUE(folds.has_section);
      EXPECT_DOUBLE_EQ(folds.coverage, 1.0);
      EXPECT_EQ(folds.count, n);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Analytic sleeves and what the counter must report on them.

struct Shape {
  std::string name;
  RadiusFn r;
  std::function<std::optional<int>(double s)> circumferential;  // expected count at height s [m]
  std::function<std::optional<int>(double theta)> axial;        // expected count along θ [rad]
};

// r = R + a cos(n θ): n lobes at every height, a constant r along the axis.
Shape cosine_shape(int n) {
  return {"cosine n=" + std::to_string(n),
          [n](double theta, double) { return kRadius + kAmplitude * std::cos(n * theta); },
          [n](double) { return expected_circular(n, kAmplitude); }, [](double) { return std::optional<int>(0); }};
}

// r = R + a cos(n (θ + β s)): n lobes at every height, turning by −β s; along θ the phase runs
// from n θ to n θ + n β L.
Shape twisted_shape(int n, double beta) {
  return {"twisted n=" + std::to_string(n),
          [n, beta](double theta, double s) { return kRadius + kAmplitude * std::cos(n * (theta + beta * s)); },
          [n](double) { return expected_circular(n, kAmplitude); },
          [n, beta](double theta) { return expected_linear(n * theta, n * theta + n * beta * kLength, kAmplitude); }};
}

// r = R + sign · amp cos(2π m s / L): circles at every height; along the axis m crests inside
// (sign −1: troughs at the ends) or m − 1 (sign +1: the crests at the ends are not folds).
Shape bellows_shape(int m, double amp, double sign) {
  return {"bellows m=" + std::to_string(m) + (sign < 0 ? " (troughs at the ends)" : " (crests at the ends)"),
          [m, amp, sign](double, double s) { return kRadius + sign * amp * std::cos(kTwoPi * m * s / kLength); },
          [](double) { return std::optional<int>(0); },
          [m, amp, sign](double) {
            const double phase = sign < 0 ? kPi : 0.0;
            return expected_linear(phase, phase + kTwoPi * m, amp);
          }};
}

// Diamonds r = R + a cos(n θ) cos(2π m s / L). At a height s the section is R + A cos(n θ) with
// A = a cos(2π m s / L): n lobes where 2|A| ≥ P (their crests at the crests of cos(n θ) where
// A > 0, at its troughs where A < 0), none at a nodal height. Along θ the profile is
// R + a c cos(2π m s / L), c = cos(n θ): where c > 0 its crests lie at s = j L / m and the two at
// the ends are not folds: m − 1; where c < 0 they lie at s = (j + ½) L / m: m; where 2 a |c| < P
// none. The axial median is the median of these over the angles.
Shape diamond_shape(int n, int m) {
  return {"diamonds n=" + std::to_string(n) + " m=" + std::to_string(m),
          [n, m](double theta, double s) {
            return kRadius + kAmplitude * std::cos(n * theta) * std::cos(kTwoPi * m * s / kLength);
          },
          [n, m](double s) { return expected_circular(n, kAmplitude * std::cos(kTwoPi * m * s / kLength)); },
          [n, m](double theta) {
            const double c = std::cos(n * theta);
            const double phase = c > 0 ? 0.0 : kPi;
            return expected_linear(phase, phase + kTwoPi * m, kAmplitude * std::abs(c));
          }};
}

Shape cylinder_shape() {
  return {"cylinder", [](double, double) { return kRadius; }, [](double) { return std::optional<int>(0); },
          [](double) { return std::optional<int>(0); }};
}

// Checks every height's and every angle's count and both medians against the shape's analytic
// expectations (ambiguous ones skipped; a median only when all its entries are unambiguous) and
// prints how many were checked.
void expect_counts(const SleeveFolds& folds, const Shape& shape, const std::string& label) {
  std::vector<double> heights, angles;
  size_t skipped = 0;
  for (const CircumferentialFolds& h : folds.heights) {
    EXPECT_TRUE(h.has_section) << label;
    const std::optional<int> expected = shape.circumferential(h.height);
    if (!expected) {
      ++skipped;
      continue;
    }
    heights.push_back(*expected);
    EXPECT_EQ(h.count, *expected) << shape.name << ", " << label << ", at s = " << h.height;
  }
  for (const AxialProfileFolds& p : folds.axial.profiles) {
    EXPECT_TRUE(p.has_section) << label;
    const std::optional<int> expected = shape.axial(p.angle);
    if (!expected) {
      ++skipped;
      continue;
    }
    angles.push_back(*expected);
    EXPECT_EQ(p.count, *expected) << shape.name << ", " << label << ", at θ = " << p.angle;
  }
  if (heights.size() == folds.heights.size()) {
    EXPECT_EQ(folds.circumferential_median, median_of(heights)) << label;
  }
  if (angles.size() == folds.axial.profiles.size()) {
    EXPECT_EQ(folds.axial.median_count, median_of(angles)) << label;
  }
  std::cout << "  checked " << heights.size() + angles.size() << " counts against the analytic surface"
            << (skipped ? ", " + std::to_string(skipped) + " ambiguous (a fold's prominence within ±30 % of P)" : "")
            << "\n";
}

// ---------------------------------------------------------------------------------------------
// Circumferential folds.

TEST(CircumferentialFolds, CosineLobesAreCountedAtEveryHeightOnEveryMesh) {
  for (int n : {3, 5, 8, 13}) {
    const Shape shape = cosine_shape(n);
    // At least 12 vertices per lobe around (72 for n ≤ 6): on a jittered 72 × 24 mesh with n = 13
    // (5.5 vertices per lobe) the height counts are still 13, but along the axis the facets of
    // neighbouring rings differ by up to ~1.5 mm (measured) and show as spurious axial folds.
    for (const MeshSpec& spec : standard_meshes(std::max(72, 12 * n), 24)) {
      const Frame frame = spec.tilted ? tilted_frame() : aligned_frame();
      const Sleeve sleeve = make_sleeve(shape.r, spec.n_theta, spec.n_s, spec.kind, frame);
      const SleeveFolds folds = count_sleeve_folds(sleeve.points, sleeve.triangles, axis_of(frame));
      std::cout << "[" << shape.name << "] " << sleeve.label << ": " << summary_text(folds) << "; "
                << margins_text(folds) << "\n";
      expect_counts(folds, shape, sleeve.label);
      EXPECT_EQ(folds.circumferential_median, std::optional<double>(n));
      EXPECT_NEAR(folds.prominence_threshold, kThreshold, 0.02 * kThreshold);
      ASSERT_EQ(folds.heights.size(), 9u);
      // Crests at θ = 2πj/n, found within a vertex spacing (the section's polygon peaks at a vertex).
      const double tolerance = kTwoPi / spec.n_theta;
      for (size_t i = 0; i < folds.heights.size(); ++i) {
        const CircumferentialFolds& h = folds.heights[i];
        EXPECT_NEAR(h.height, default_heights()[i], 1e-12);
        EXPECT_DOUBLE_EQ(h.coverage, 1.0);
        for (const FoldPeak& p : h.peaks) EXPECT_LT(lattice_distance(p.position, 0.0, n), tolerance) << p.position;
      }
    }
  }
}

TEST(CircumferentialFolds, TwistedFoldsAreCountedAtEveryHeight) {
  const double beta = kPi / kLength;  // half a turn over the sleeve
  for (int n : {3, 5, 8, 13}) {
    const Shape shape = twisted_shape(n, beta);
    // At least 12 vertices per fold wavelength around and 6 along the axis (n/2 waves over L): on
    // coarser jittered meshes the facets' deviation from the surface reaches P (measured: 72 × 30
    // for n = 13, 5.5 and 4.6 vertices per wave, shows spurious axial peaks).
    for (const MeshSpec& spec : standard_meshes(std::max(72, 12 * n), std::max(30, 6 * n))) {
      const Frame frame = spec.tilted ? tilted_frame() : aligned_frame();
      const Sleeve sleeve = make_sleeve(shape.r, spec.n_theta, spec.n_s, spec.kind, frame);
      const SleeveFolds folds = count_sleeve_folds(sleeve.points, sleeve.triangles, axis_of(frame));
      std::cout << "[" << shape.name << "] " << sleeve.label << ": " << summary_text(folds) << "; "
                << margins_text(folds) << "\n";
      expect_counts(folds, shape, sleeve.label);
      EXPECT_EQ(folds.circumferential_median, std::optional<double>(n));
      // The crests turn with the height: θ = 2πj/n − β s.
      const double tolerance = kTwoPi / spec.n_theta;
      for (const CircumferentialFolds& h : folds.heights)
        for (const FoldPeak& p : h.peaks)
          EXPECT_LT(lattice_distance(p.position, -beta * h.height, n), tolerance) << "s = " << h.height;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Folds along the axis.

TEST(AxialFolds, BellowsRingsAreCountedAtEveryAngle) {
  for (int m : {4, 9, 20}) {
    for (double sign : {-1.0, 1.0}) {
      const double amp = m == 20 ? 0.6 * kAmplitude : kAmplitude;
      const Shape shape = bellows_shape(m, amp, sign);
      const int expected = sign < 0 ? m : m - 1;  // by hand: crests strictly inside [0, L]
      EXPECT_EQ(shape.axial(0.0), std::optional<int>(expected));
      for (const MeshSpec& spec : standard_meshes(48, 10 * m)) {
        const Frame frame = spec.tilted ? tilted_frame() : aligned_frame();
        const Sleeve sleeve = make_sleeve(shape.r, spec.n_theta, spec.n_s, spec.kind, frame);
        const SleeveFolds folds = count_sleeve_folds(sleeve.points, sleeve.triangles, axis_of(frame));
        std::cout << "[" << shape.name << "] " << sleeve.label << ": " << summary_text(folds) << "; "
                  << margins_text(folds) << "\n";
        expect_counts(folds, shape, sleeve.label);
        EXPECT_EQ(folds.axial.median_count, std::optional<double>(expected));
        EXPECT_EQ(folds.circumferential_median, std::optional<double>(0));
        EXPECT_NEAR(folds.axial.s_min, 0.0, 1e-12);
        EXPECT_NEAR(folds.axial.s_max, kLength, 1e-12);
        ASSERT_EQ(folds.axial.profiles.size(), 16u);
        // Crests at s = (j + ½) L / m (troughs at the ends) or j L / m, within 1 % of L.
        const double offset = sign < 0 ? 0.5 * kLength / m : 0.0;
        for (const AxialProfileFolds& p : folds.axial.profiles)
          for (const FoldPeak& peak : p.peaks)
            EXPECT_LT(std::abs(std::remainder(peak.position - offset, kLength / m)), 0.01 * kLength) << peak.position;
      }
    }
  }
}

TEST(AxialFolds, DiamondsReportLobesPerHeightAndMOrMMinusOnePerAngle) {
  struct Case {
    int n, m;
    double axial_median;  // by hand over θ_k = 2π (k + ½) / 16: the signs of cos(n θ_k)
  };
  // n = 4: cos(n θ_k) = ±0.71, 8 positive (m − 1) and 8 negative (m): median m − ½. n = 3: 8 and 8
  // (the smallest |cos| 0.195 still gives 2a|c| = 1.95 mm ≥ 1.3 P). n = 6: 8 and 8 (|c| = 0.38, 0.92).
  for (const Case c : {Case{4, 4, 3.5}, Case{3, 5, 4.5}, Case{6, 3, 2.5}}) {
    const Shape shape = diamond_shape(c.n, c.m);
    for (const MeshSpec& spec : standard_meshes(72, 12 * c.m)) {
      const Frame frame = spec.tilted ? tilted_frame() : aligned_frame();
      const Sleeve sleeve = make_sleeve(shape.r, spec.n_theta, spec.n_s, spec.kind, frame);
      const SleeveFolds folds = count_sleeve_folds(sleeve.points, sleeve.triangles, axis_of(frame));
      std::cout << "[" << shape.name << "] " << sleeve.label << ": " << summary_text(folds) << "; "
                << margins_text(folds) << "\n";
      expect_counts(folds, shape, sleeve.label);
      EXPECT_EQ(folds.axial.median_count, std::optional<double>(c.axial_median));
      for (const CircumferentialFolds& h : folds.heights) {
        const double offset = std::cos(kTwoPi * c.m * h.height / kLength) > 0 ? 0.0 : kPi / c.n;
        for (const FoldPeak& p : h.peaks) EXPECT_LT(lattice_distance(p.position, offset, c.n), kTwoPi / spec.n_theta);
      }
    }
    // Explicit heights: a crest row and a trough row give n lobes, a nodal height none.
    const Sleeve sleeve = make_sleeve(shape.r, 96, 12 * c.m, Triangulation::kJittered, tilted_frame());
    const double row = kLength / c.m;
    for (double s : {row, 1.5 * row, 1.25 * row}) {
      const CircumferentialFolds h = count_circumferential_folds(sleeve.points, sleeve.triangles, axis_of(tilted_frame()), s);
      const int expected = std::abs(s - 1.25 * row) < 1e-12 ? 0 : c.n;
      std::cout << "[" << shape.name << "] s = " << s << ": " << h.count << " lobes (largest uncounted prominence "
                << h.largest_uncounted_prominence * 1e3 << " mm)\n";
      EXPECT_EQ(h.count, expected) << "s = " << s;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Noise and a single bump.

// Adds uniform radial noise of ±amplitude to every vertex (the radius about the frame's axis).
void add_radial_noise(Sleeve& sleeve, const Frame& f, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> noise(-amplitude, amplitude);
  for (Eigen::Index v = 0; v < sleeve.points.rows(); ++v) {
    const Eigen::Vector3d x = sleeve.points.row(v).transpose() - f.c;
    Eigen::Vector3d radial = x - x.dot(f.d) * f.d;
    radial.normalize();
    sleeve.points.row(v) += noise(rng) * radial.transpose();
  }
}

TEST(FoldCount, RadialNoiseWellBelowTheThresholdLeavesTheCountsUnchanged) {
  const double noise = 0.1 * kThreshold;  // ±0.1 mm
  struct Case {
    Shape shape;
    int n_s;
  };
  const std::vector<Case> cases = {{cosine_shape(5), 30},
                                   {twisted_shape(8, kPi / kLength), 40},
                                   {bellows_shape(9, kAmplitude, -1), 90},
                                   {diamond_shape(4, 4), 48},
                                   {cylinder_shape(), 30}};
  for (const Case& c : cases)
    for (Triangulation kind : {Triangulation::kDiagonalsUp, Triangulation::kJittered}) {
      const Frame frame = kind == Triangulation::kJittered ? tilted_frame() : aligned_frame();
      const Sleeve clean = make_sleeve(c.shape.r, 96, c.n_s, kind, frame);
      Sleeve noisy = clean;
      add_radial_noise(noisy, frame, noise, 11);
      const SleeveFolds a = count_sleeve_folds(clean.points, clean.triangles, axis_of(frame));
      const SleeveFolds b = count_sleeve_folds(noisy.points, noisy.triangles, axis_of(frame));
      std::cout << "[noise ±" << noise * 1e3 << " mm] " << c.shape.name << ", " << clean.label << "\n  clean: "
                << summary_text(a) << "\n  noisy: " << summary_text(b) << "; " << margins_text(b) << "\n";
      expect_counts(b, c.shape, noisy.label + " with noise");
      ASSERT_EQ(a.heights.size(), b.heights.size());
      for (size_t i = 0; i < a.heights.size(); ++i) EXPECT_EQ(b.heights[i].count, a.heights[i].count) << i;
      for (size_t k = 0; k < a.axial.profiles.size(); ++k)
        EXPECT_EQ(b.axial.profiles[k].count, a.axial.profiles[k].count) << k;
    }
}

TEST(FoldCount, ASingleBumpAboveTheThresholdIsCounted) {
  const double theta_b = 1.0, s_b = 0.5 * kLength;  // the bump's centre
  const double sigma_theta = 0.15, sigma_s = 0.015;
  auto bump = [&](double height) {
    return [=](double theta, double s) {
      const double dt = std::remainder(theta - theta_b, kTwoPi), ds = s - s_b;
      return kRadius + height * std::exp(-0.5 * (dt * dt / (sigma_theta * sigma_theta) + ds * ds / (sigma_s * sigma_s)));
    };
  };
  const Frame frame = tilted_frame();
  const FoldAxis axis = axis_of(frame);
  for (double height : {3 * kThreshold, 0.4 * kThreshold})
    for (Triangulation kind : {Triangulation::kDiagonalsDown, Triangulation::kJittered}) {
      Sleeve sleeve = make_sleeve(bump(height), 120, 80, kind, frame);
      add_radial_noise(sleeve, frame, 0.1 * kThreshold, 5);
      const bool counted = height > kThreshold;
      const CircumferentialFolds at_bump = count_circumferential_folds(sleeve.points, sleeve.triangles, axis, s_b);
      const CircumferentialFolds away = count_circumferential_folds(sleeve.points, sleeve.triangles, axis, 0.2 * kLength);
      const AxialFolds along = count_axial_folds(sleeve.points, sleeve.triangles, axis, {theta_b, theta_b + kPi});
      std::cout << "[bump " << height * 1e3 << " mm + noise] " << sleeve.label << ": at its height " << at_bump.count
                << " (" << (at_bump.peaks.empty() ? 0.0 : at_bump.peaks[0].prominence * 1e3) << " mm at θ = "
                << (at_bump.peaks.empty() ? 0.0 : at_bump.peaks[0].position) << "), away " << away.count
                << "; along the axis through it " << along.profiles[0].count << ", opposite "
                << along.profiles[1].count << "\n";
      EXPECT_EQ(at_bump.count, counted ? 1 : 0);
      EXPECT_EQ(away.count, 0);
      EXPECT_EQ(along.profiles[0].count, counted ? 1 : 0);
      EXPECT_EQ(along.profiles[1].count, 0);
      if (counted) {
        EXPECT_LT(lattice_distance(at_bump.peaks[0].position, theta_b, 1), 0.02);
        EXPECT_NEAR(along.profiles[0].peaks[0].position, s_b, 0.01 * kLength);
        EXPECT_NEAR(at_bump.peaks[0].prominence, height, 0.2 * height);
      }
    }
}

// ---------------------------------------------------------------------------------------------
// Resolution independence.

TEST(FoldCount, TheSameSurfaceAtThreeResolutionsGivesIdenticalCounts) {
  for (const Shape& shape : {twisted_shape(8, kPi / kLength), diamond_shape(4, 4), bellows_shape(9, kAmplitude, -1)})
    for (Triangulation kind : {Triangulation::kDiagonalsUp, Triangulation::kJittered}) {
      std::vector<SleeveFolds> results;
      // From 8 to 24 vertices per fold wavelength around and 10 to 30 rings per bellows ring (on a
      // jittered 48 × 60 mesh, 6.7 rings per bellows ring, the facets deviate ~1 mm ≈ P from the
      // surface and one section shows a spurious fold).
      for (int scale : {1, 2, 3}) {
        const Frame frame = kind == Triangulation::kJittered ? tilted_frame() : aligned_frame();
        const Sleeve sleeve = make_sleeve(shape.r, 64 * scale, 90 * scale, kind, frame, 100 + scale);
        results.push_back(count_sleeve_folds(sleeve.points, sleeve.triangles, axis_of(frame)));
        std::cout << "[resolution] " << shape.name << ", " << sleeve.label << ": " << summary_text(results.back())
                  << "\n";
        expect_counts(results.back(), shape, sleeve.label);
      }
      for (size_t k = 1; k < results.size(); ++k) {
        for (size_t i = 0; i < results[0].heights.size(); ++i)
          EXPECT_EQ(results[k].heights[i].count, results[0].heights[i].count) << shape.name << " height " << i;
        for (size_t a = 0; a < results[0].axial.profiles.size(); ++a)
          EXPECT_EQ(results[k].axial.profiles[a].count, results[0].axial.profiles[a].count) << shape.name << " angle " << a;
        EXPECT_EQ(results[k].circumferential_median, results[0].circumferential_median);
        EXPECT_EQ(results[k].axial.median_count, results[0].axial.median_count);
      }
    }
}

// ---------------------------------------------------------------------------------------------
// Degenerate and bad input.

TEST(FoldCount, DegenerateSectionsReportNoCount) {
  auto r = [](double theta, double) { return kRadius + kAmplitude * std::cos(5 * theta); };
  const Frame frame = tilted_frame();
  const FoldAxis axis = axis_of(frame);
  const Sleeve sleeve = make_sleeve(r, 60, 20, Triangulation::kJittered, frame);
  // Heights beyond the ends: no section, no count, no crash.
  for (double s : {-0.01, kLength + 1e-6, 5.0}) {
    const CircumferentialFolds h = count_circumferential_folds(sleeve.points, sleeve.triangles, axis, s);
    std::cout << "[degenerate] height " << s << ": has_section " << h.has_section << ", count " << h.count << "\n";
    EXPECT_FALSE(h.has_section);
    EXPECT_EQ(h.count, 0);
    EXPECT_TRUE(h.peaks.empty());
  }
  // Half a sleeve (0 ≤ θ ≤ π): the sections reach half of the bins, the half-planes on the other
  // side miss it.
  Sleeve half;
  half.points = sleeve.points;
  for (const auto& t : sleeve.triangles) {
    bool keep = true;
    for (int v : t) {
      const Eigen::Vector3d x = sleeve.points.row(v).transpose() - frame.c;
      keep = keep && x.dot(frame.e2) >= 0;
    }
    if (keep) half.triangles.push_back(t);
  }
  const SleeveFolds folds = count_sleeve_folds(half.points, half.triangles, axis);
  std::cout << "[degenerate] half sleeve: " << summary_text(folds) << ", coverage " << folds.heights[4].coverage << "\n";
  for (const CircumferentialFolds& h : folds.heights) {
    EXPECT_TRUE(h.has_section);
    EXPECT_GT(h.coverage, 0.4);
    EXPECT_LT(h.coverage, 0.5);
  }
  int missing = 0;
  for (const AxialProfileFolds& p : folds.axial.profiles) missing += p.has_section ? 0 : 1;
  EXPECT_EQ(missing, 8);  // θ_k in (π, 2π)
  // No triangles at all: nothing to count.
  const SleeveFolds none = count_sleeve_folds(sleeve.points, {}, axis);
  EXPECT_TRUE(none.heights.empty());
  EXPECT_FALSE(none.circumferential_median.has_value());
  EXPECT_FALSE(none.axial.median_count.has_value());
  const AxialFolds no_profiles = count_axial_folds(sleeve.points, {}, axis, {0.0, 1.0});
  ASSERT_EQ(no_profiles.profiles.size(), 2u);
  EXPECT_FALSE(no_profiles.profiles[0].has_section);
  EXPECT_FALSE(no_profiles.median_count.has_value());
}

TEST(FoldCount, ProminenceGivenInMetres) {
  auto r = [](double theta, double) { return kRadius + kAmplitude * std::cos(5 * theta); };
  const Sleeve sleeve = make_sleeve(r, 96, 20, Triangulation::kJittered, aligned_frame());
  FoldCountOptions options;
  for (double p : {0.008, 0.012}) {  // below and above the lobes' prominence 2a = 10 mm
    options.prominence = p;
    const SleeveFolds folds = count_sleeve_folds(sleeve.points, sleeve.triangles, axis_of(aligned_frame()), options);
    std::cout << "[P in metres] P = " << p << ": " << summary_text(folds) << "\n";
    EXPECT_EQ(folds.prominence_threshold, p);
    EXPECT_EQ(*folds.circumferential_median, p < 2 * kAmplitude ? 5.0 : 0.0);
  }
}

TEST(FoldCount, BadInputIsRejected) {
  auto r = [](double theta, double) { return kRadius + kAmplitude * std::cos(3 * theta); };
  const Sleeve sleeve = make_sleeve(r, 24, 6, Triangulation::kDiagonalsUp, aligned_frame());
  const FoldAxis axis{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()};
  auto message = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(no exception)");
  };
  Eigen::MatrixX3d bad = sleeve.points;
  bad(17, 1) = std::nan("");
  std::string m = message([&] { count_sleeve_folds(bad, sleeve.triangles, axis); });
  std::cout << "[bad input] " << m << "\n";
  EXPECT_NE(m.find("point 17"), std::string::npos) << m;
  bad(17, 1) = 0;
  bad(3, 2) = std::numeric_limits<double>::infinity();
  m = message([&] { count_circumferential_folds(bad, sleeve.triangles, axis, 0.1); });
  EXPECT_NE(m.find("point 3"), std::string::npos) << m;
  m = message([&] { count_axial_folds(bad, sleeve.triangles, axis, {0.0}); });
  EXPECT_NE(m.find("point 3"), std::string::npos) << m;
  m = message([&] { section_radius_profile(bad, sleeve.triangles, axis, 0.1, 720); });
  EXPECT_NE(m.find("point 3"), std::string::npos) << m;

  Triangles tris = sleeve.triangles;
  tris[5][2] = static_cast<int>(sleeve.points.rows());
  m = message([&] { count_sleeve_folds(sleeve.points, tris, axis); });
  std::cout << "[bad input] " << m << "\n";
  EXPECT_NE(m.find("triangle 5"), std::string::npos) << m;
  tris[5][2] = -1;
  EXPECT_THROW(count_sleeve_folds(sleeve.points, tris, axis), std::invalid_argument);

  m = message([&] { count_sleeve_folds(sleeve.points, sleeve.triangles, {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}); });
  std::cout << "[bad input] " << m << "\n";
  EXPECT_NE(m.find("direction"), std::string::npos) << m;
  FoldAxis parallel = axis;
  parallel.reference = Eigen::Vector3d(0, 0, -2);
  EXPECT_THROW(count_sleeve_folds(sleeve.points, sleeve.triangles, parallel), std::invalid_argument);
  FoldAxis nan_point = axis;
  nan_point.point.x() = std::nan("");
  EXPECT_THROW(count_sleeve_folds(sleeve.points, sleeve.triangles, nan_point), std::invalid_argument);

  EXPECT_THROW(count_circumferential_folds(sleeve.points, sleeve.triangles, axis, std::nan("")), std::invalid_argument);
  EXPECT_THROW(count_axial_folds(sleeve.points, sleeve.triangles, axis, {0.0, INFINITY}), std::invalid_argument);

  auto rejects = [&](const std::function<void(FoldCountOptions&)>& change) {
    FoldCountOptions o;
    change(o);
    const std::string what = message([&] { count_sleeve_folds(sleeve.points, sleeve.triangles, axis, o); });
    std::cout << "[bad options] " << what << "\n";
    return what != "(no exception)";
  };
  EXPECT_TRUE(rejects([](FoldCountOptions& o) { o.angular_window = 8; }));  // even
  EXPECT_TRUE(rejects([](FoldCountOptions& o) { o.angular_window = 0; }));
  EXPECT_TRUE(rejects([](FoldCountOptions& o) { o.angular_bins = 4; }));
  EXPECT_TRUE(rejects([](FoldCountOptions& o) { o.axial_window = 601; }));
  EXPECT_TRUE(rejects([](FoldCountOptions& o) { o.prominence = -1e-3; }));
  EXPECT_TRUE(rejects([](FoldCountOptions& o) { o.relative_prominence = 0; }));
  EXPECT_TRUE(rejects([](FoldCountOptions& o) { o.heights = 0; }));
  EXPECT_TRUE(rejects([](FoldCountOptions& o) { o.height_from = 0.9; }));
  EXPECT_TRUE(rejects([](FoldCountOptions& o) { o.axial_angles = 0; }));
  EXPECT_FALSE(rejects([](FoldCountOptions& o) { o.relative_prominence = 0, o.prominence = 1e-3; }));
}

}  // namespace
}  // namespace clothsim

// Counting the folds of a sleeve from its drawn surface (docs/fold_count.md), for comparing runs
// of different methods and resolutions: every figure depends on the surface's shape, not on how it
// is triangulated.
//
// The sleeve is roughly a cylinder around an axis (a point c and a direction d). Local coordinates
// of a point x: the height s = (x − c)·d [m] along the axis, and the angle θ ∈ [0, 2π) [rad] about
// it, measured from the reference direction e1 towards e2 = d × e1 (fold_frame()); the radius is
// the distance from the axis [m].
//
//  - Circumferential folds at a height s (twisted sleeves, the lobes of a compressed one): the
//    surface's exact section with the plane ⊥ d at s, as a radius profile r(θ) in N angular bins
//    (per bin the largest radius of the section's points whose angle lies in the bin, computed
//    exactly along every section segment; bins the section does not reach are filled by circular
//    linear interpolation), smoothed by a circular moving average of W bins; the folds are the
//    local maxima whose prominence (circular definition, below) is at least P.
//  - Folds along the axis (bellows rings, diamonds): for angles θ_k, the section with the
//    half-plane that contains the axis and points at θ_k, as a profile r(s) in bins of height over
//    the surface's extent along d (again exact per-bin maxima along the section segments), smoothed
//    by a moving average of W_s bins; the folds are its interior local maxima with prominence ≥ P.
//    The first and last bins of a profile are never peaks: a maximum at an end of the sleeve is
//    not a fold.
//
// Prominence of a local maximum of height h (the topographic one, as scipy.signal's
// peak_prominences for a linear signal): walk from the peak in each direction until a sample
// strictly higher than h or the end of the signal; the base on that side is the lowest sample
// passed; prominence = h − max(left base, right base). On a circular signal the walks wrap around
// and stop at a strictly higher sample or after a full turn, so the highest peak's prominence is
// h − (global minimum). A flat top (equal neighbouring samples) is one peak at its middle sample.
// Exact ties between separate samples are broken by index (a sample as high as the peak counts as
// higher if its index is lower, as if every sample were lowered by an infinitesimal multiple of its
// index): of two exactly equal crests — a symmetric mesh can make them — only the first gets the
// drop to the global minimum, the second the drop to the col between them. (scipy lets both walk
// past each other; it is otherwise the same definition.)
//
// Taking the largest radius per bin reads the outer envelope of a section: a fold that overhangs
// (a section that is not a function r(θ) or r(s)) is seen as its outermost layer.
#pragma once

#include <Eigen/Core>

#include <array>
#include <optional>
#include <vector>

namespace clothsim {

struct FoldAxis {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();       // [m] c: heights are measured from it
  Eigen::Vector3d direction = Eigen::Vector3d::UnitY();  // d: nonzero and finite; normalised here
  // The direction of θ = 0 (its component ⊥ d is used). Zero (the default): the coordinate axis
  // x, y or z least aligned with d (the first of them on a tie), made ⊥ d.
  Eigen::Vector3d reference = Eigen::Vector3d::Zero();
};

// The axis's orthonormal right-handed frame (e1, e2, d), e2 = d × e1, and its origin c.
struct FoldFrame {
  Eigen::Vector3d origin, e1, e2, d;
};

// Throws std::invalid_argument for a zero or non-finite direction, or a reference that is not
// finite or is parallel to d.
FoldFrame fold_frame(const FoldAxis& axis);

// Defaults (docs/fold_count.md, "Defaults"). Bins are fixed fractions of a turn or of the sleeve's
// length, never of the mesh, so that the counts do not depend on the triangulation.
struct FoldCountOptions {
  int angular_bins = 720;  // N: bins of 0.5° around the axis (≥ 8)
  int angular_window = 9;  // W: circular moving average over 9 bins (4.5°); odd, 1 ≤ W ≤ N
  int axial_bins = 600;    // bins along the sleeve's extent along d (≥ 8)
  int axial_window = 7;    // moving average along the axis over 7 bins (1.2 % of the length); odd,
                           // 1 ≤ W_s ≤ axial_bins; shrunk symmetrically at the ends of a profile
  // P [m], the least prominence of a fold. 0 (the default): relative_prominence × the mean radius
  // (docs: per call, the mean of the unsmoothed profiles it computes; for count_sleeve_folds one P
  // for the whole sleeve from its height sections). Must be ≥ 0.
  double prominence = 0.0;
  double relative_prominence = 0.02;  // [-] used when prominence == 0; > 0
  // count_sleeve_folds: `heights` equally spaced heights from height_from to height_to (fractions of
  // the extent along d, 0 ≤ from ≤ to ≤ 1; one height: the middle of the range) and
  // `axial_angles` angles θ_k = 2π (k + ½) / axial_angles (≥ 1).
  int heights = 9;
  double height_from = 0.2;
  double height_to = 0.8;
  int axial_angles = 16;
};

// One counted fold.
struct FoldPeak {
  double position = 0.0;    // circumferential: θ [rad] in [0, 2π), the bin's centre; axial: s [m]
  double radius = 0.0;      // [m] the smoothed profile at the peak
  double prominence = 0.0;  // [m]
};

// The folds of one height section.
struct CircumferentialFolds {
  double height = 0.0;        // s [m]
  bool has_section = false;   // false: the plane misses the surface (count 0, nothing else set)
  int count = 0;              // folds: peaks with prominence ≥ prominence_threshold
  std::vector<FoldPeak> peaks;  // the counted peaks, by increasing θ
  double largest_uncounted_prominence = 0.0;  // [m] the highest prominence below the threshold (0: none)
  double coverage = 0.0;      // fraction of the N bins the section reaches (the rest interpolated)
  double mean_radius = 0.0;   // [m] mean of the filled, unsmoothed profile over the bins
  double prominence_threshold = 0.0;  // [m] P used
  Eigen::VectorXd profile;    // [m] the smoothed r(θ); bin j is centred at θ = 2π (j + ½) / N
};

// The folds along one half-plane θ = angle.
struct AxialProfileFolds {
  double angle = 0.0;         // θ [rad] as given
  bool has_section = false;   // false: the half-plane misses the surface (count 0, nothing else set)
  int count = 0;
  std::vector<FoldPeak> peaks;  // the counted peaks, by increasing s
  double largest_uncounted_prominence = 0.0;  // [m]
  // The profile covers the bins from the first to the last one the section reaches (gaps between
  // them interpolated linearly): centres s_from … s_to [m].
  double s_from = 0.0, s_to = 0.0;
  double mean_radius = 0.0;   // [m] mean of the unsmoothed profile over its bins
  Eigen::VectorXd profile;    // [m] the smoothed r(s) over those bins
};

struct AxialFolds {
  double s_min = 0.0, s_max = 0.0;   // [m] the extent along d over which the bins are laid
  double prominence_threshold = 0.0;  // [m] P used
  std::vector<AxialProfileFolds> profiles;  // one per angle, in the given order
  std::optional<double> median_count;  // median of the counts of the profiles that have a section
                                       // (mean of the middle two for an even number); none if no
                                       // profile has one
};

struct SleeveFolds {
  double s_min = 0.0, s_max = 0.0;  // [m] extent of the triangles' vertices along d
  double mean_radius = 0.0;         // [m] mean of the height sections' mean radii (no section:
                                    // of the axial profiles'; nothing at all: 0)
  double prominence_threshold = 0.0;  // [m] P used for every count below
  std::vector<CircumferentialFolds> heights;  // at the options' heights, bottom to top
  std::optional<double> circumferential_median;  // over the heights that have a section
  AxialFolds axial;  // at the options' axial_angles
};

// The inputs of all functions below: `points` #P × 3 [m] and `triangles` (indices into points; the
// drawn surface, any orientation, need not be manifold). They throw std::invalid_argument naming
// the first point with a non-finite coordinate, the first triangle with an index out of range, an
// invalid axis (fold_frame) or invalid options. A section that misses the surface is not an error.

// The raw section profile at height s: N values [m], bin j (θ ∈ [2πj/N, 2π(j+1)/N]) holding the
// largest radius of the section's points in it, NaN where the section does not reach;
// angular_bins ≥ 8.
Eigen::VectorXd section_radius_profile(const Eigen::MatrixX3d& points, const std::vector<std::array<int, 3>>& triangles,
                                       const FoldAxis& axis, double height, int angular_bins);

// With the relative prominence, P = relative_prominence × this section's mean_radius.
CircumferentialFolds count_circumferential_folds(const Eigen::MatrixX3d& points,
                                                 const std::vector<std::array<int, 3>>& triangles,
                                                 const FoldAxis& axis, double height,
                                                 const FoldCountOptions& options = {});

// `angles` [rad], any finite values (the half-plane at θ points along cos θ e1 + sin θ e2). With
// the relative prominence, P = relative_prominence × the mean of the profiles' mean radii.
AxialFolds count_axial_folds(const Eigen::MatrixX3d& points, const std::vector<std::array<int, 3>>& triangles,
                             const FoldAxis& axis, const std::vector<double>& angles,
                             const FoldCountOptions& options = {});

// The summary of a sleeve: the height sections and the axial profiles of the options, all counted
// with one P (the options' prominence, or relative_prominence × mean_radius). No triangles: no
// heights, no profiles, no medians, s_min = s_max = mean_radius = 0 and P = options.prominence.
SleeveFolds count_sleeve_folds(const Eigen::MatrixX3d& points, const std::vector<std::array<int, 3>>& triangles,
                               const FoldAxis& axis, const FoldCountOptions& options = {});

// The peak finder on its own: every local maximum of `signal` (a flat top: its middle sample, the
// lower index of the two middle ones) with its prominence (header comment), by increasing index.
// circular: the signal wraps around; otherwise the first and last samples are never peaks. A
// constant signal has no peaks. Throws std::invalid_argument for a non-finite sample.
struct SignalPeak {
  int index = 0;
  double prominence = 0.0;
};
std::vector<SignalPeak> find_profile_peaks(const std::vector<double>& signal, bool circular);

// The median of `values` (mean of the middle two for an even count); none for an empty list.
std::optional<double> median_of(std::vector<double> values);

}  // namespace clothsim

// The fold study (`clothsim study folds`, docs/fold_study.md): the number of folds of a twisted
// and of an axially compressed sleeve against mesh resolution, for each discretisation method and
// several seeds of a geometric imperfection, next to the band the shell-buckling theory allows.
//
// A run is a shipped sleeve scene (scenes/sleeve_twist.json or scenes/sleeve_compress.json) with
// its mesh (segments × rings of the cylinder primitive), "method", material preset, time step and
// "imperfection" replaced, self-collision switched off and PCG preconditioned by a Cholesky factor
// ("preconditioner": "cholesky"), simulated to the plan's end time (default 1 s, the end of the
// scenes' motion). At the end the drawn surface (Discretization::display(2): two refinement steps of the method —
// Loop subdivision for loop_kl, midpoint refinement of the flat triangles for the others) is
// handed to count_sleeve_folds (sim/study/fold_count.hpp, default options): the median over 9
// heights of the r(θ) peak count (circumferential) and the median over 16 half-planes of the r(s)
// peak count (axial).
//
// Theory (docs/fold_study.md derives it). t_eff = sqrt(12 B / (E·t)) is the thickness of a solid
// plate with the material's stretch modulus E·t [N/m] and bending rigidity B [N·m].
//  - Twist (torsion buckling, Donnell's moderate-length regime): circumferential waves
//    n = c (R/L)^½ (R/t_eff)^¼ with c ∈ [2.9, 3.8].
//  - Axial compression: classical axisymmetric wavelength λ = 2π sqrt(R t_eff) / (12 (1 − ν²))^¼;
//    the critical modes lie on Koiter's circle k_x² + k_y² = k_c k_x (k_c = 2π/λ). The band is
//    its branch from the axisymmetric ring (k_x = k_c, n = 0, L/λ rings) to the square diamond
//    (k_x = k_y = k_c/2, n = πR/λ, L/(2λ) waves along a meridian): axial count ∈ [L/(2λ), L/λ],
//    circumferential count ∈ [0, πR/λ].
#pragma once

#include "sim/core/log.hpp"
#include "sim/discretization/discretization.hpp"
#include "sim/shell/material.hpp"

#include <Eigen/Core>

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace clothsim {

// --- Theory -------------------------------------------------------------------------------------

// sqrt(12 B / (E·t)) [m]: the bending-equivalent thickness. Throws std::invalid_argument for a
// non-positive stretch modulus or a negative bending rigidity.
double effective_thickness(const ShellMaterial& material);

// λ = 2π sqrt(R t) / (12 (1 − ν²))^¼ [m], R and t [m], 0 ≤ ν < 1.
double axisymmetric_buckling_wavelength(double radius, double thickness, double poisson_ratio);

// A range of fold counts (lo ≤ hi); both NaN when the theory says nothing.
struct FoldBand {
  double lo = 0.0;
  double hi = 0.0;
  bool known() const { return lo == lo && hi == hi; }
};

constexpr double kTwistPrefactorLow = 2.9;
constexpr double kTwistPrefactorHigh = 3.8;

// c (R/L)^½ (R/t)^¼ for c from kTwistPrefactorLow to kTwistPrefactorHigh.
FoldBand twist_circumferential_band(double radius, double length, double thickness);
// [L/(2λ), L/λ] and [0, πR/λ] (header comment).
FoldBand compression_axial_band(double radius, double length, double thickness, double poisson_ratio);
FoldBand compression_circumferential_band(double radius, double thickness, double poisson_ratio);

// --- Counting -----------------------------------------------------------------------------------

struct FoldCounts {
  std::optional<double> circumferential_median;  // none when no height section hits the surface
  std::optional<double> axial_median;
  double prominence_threshold = 0.0;  // [m] P used
};

// The display levels the study counts on (the drawn surface).
constexpr int kFoldStudyDisplayLevels = 2;

// Counts the folds of the surface `discretization` draws for node positions x (3·#nodes) [m],
// refined `levels` times, about the axis through `axis_point` along `axis_direction`, with
// count_sleeve_folds' default options.
FoldCounts count_drawn_folds(const Discretization& discretization, const Eigen::VectorXd& x,
                             const Eigen::Vector3d& axis_point, const Eigen::Vector3d& axis_direction,
                             int levels = kFoldStudyDisplayLevels);

// --- The plan -----------------------------------------------------------------------------------

struct FoldMesh {
  int segments = 0;  // vertices around the cylinder
  int rings = 0;     // vertex rings along the axis
  int vertices() const { return segments * rings; }
};

struct FoldStudyPlan {
  std::filesystem::path scenes_dir;  // holds sleeve_twist.json and sleeve_compress.json
  std::vector<std::string> cases;    // "twist", "compress"
  std::vector<std::string> methods;  // "loop_kl", "linear_fe", "mass_spring"
  std::vector<FoldMesh> meshes;      // coarse to fine
  std::vector<int> seeds;            // imperfection seeds (≥ 0)
  std::string preset = "cotton";     // material preset (sim/shell/material_presets.hpp)
  // Imperfection amplitude [m]; none: kDefaultAmplitudeFactor × t_eff of the preset.
  std::optional<double> amplitude;
  // Imperfection wavelengths [m] (the scene key's [shortest, longest]); none: the scene format's
  // default. The default plans use [0.5 λ, 2πR] of the preset (λ the axisymmetric wavelength).
  std::optional<std::pair<double, double>> wavelength;
  double dt = 0.005;                 // [s]
  std::optional<double> end;         // [s]; none: the scene's time.end
  bool self_collision = false;       // off: it would dominate the cost
};

constexpr double kDefaultAmplitudeFactor = 0.5;  // amplitude = 0.5 t_eff by default

// The default study: both cases, the three methods, meshes 26×19, 38×27, 54×39, 76×55 (494 to
// 4180 vertices, 8.5×, the shipped aspect), seeds 1, 2, 3, dt = 5 ms, to 1 s (the end of the
// scenes' motion).
FoldStudyPlan full_fold_plan(const std::filesystem::path& scenes_dir);
// For the tests: both cases, the three methods, meshes 13×9 and 18×13, seed 1, to 0.1 s.
FoldStudyPlan quick_fold_plan(const std::filesystem::path& scenes_dir);

// Option parsing for the command line; each throws std::invalid_argument with a message naming
// the option and the bad item.
std::vector<FoldMesh> parse_fold_meshes(const std::string& text);       // "26x19,38x27"
std::vector<int> parse_fold_seeds(const std::string& text);             // "1,2,3"
std::vector<std::string> parse_fold_methods(const std::string& text);   // "loop_kl,linear_fe"
std::vector<std::string> parse_fold_cases(const std::string& text);     // "twist,compress"
// Checks the whole plan (known cases, methods and preset, meshes ≥ 3 × 2, positive dt, ...).
void validate_fold_plan(const FoldStudyPlan& plan);

// --- Results ------------------------------------------------------------------------------------

struct FoldRow {
  std::string case_name;  // "twist" or "compress"
  std::string method;
  int segments = 0, rings = 0, vertices = 0;
  int seed = 0;
  double amplitude = 0.0;  // [m]
  double dt = 0.0;         // [s]
  int steps = 0;           // steps taken
  double end_time = 0.0;   // [s] simulated time reached
  double wall_seconds = 0.0;  // building the Simulator, stepping and counting
  double circumferential_median = 0.0;  // NaN when the run failed or there is no section
  double axial_median = 0.0;
  FoldBand circumferential_theory;  // NaN when the theory says nothing (the twist's axial count)
  FoldBand axial_theory;
  double t_eff = 0.0;        // [m]
  std::string preset;
  std::string status;        // "ok" or "failed"
  std::string note;          // the failure, or empty
};

// One run of a plan: a case, method, mesh and seed.
struct FoldRun {
  std::string case_name;
  std::string method;
  FoldMesh mesh;
  int seed = 0;
  // Its stable name, "<case>-<method>-<segments>x<rings>-seed<seed>" (e.g. "twist-loop_kl-13x9-seed1"):
  // the same run has the same id in every plan (the plan's other settings are shared by all runs).
  std::string id() const;
};

// The plan's runs in the order run_fold_study runs them (cases, then methods, meshes, seeds).
// Throws std::invalid_argument for an invalid plan.
std::vector<FoldRun> fold_study_runs(const FoldStudyPlan& plan);

// Runs one run of the plan (as run_fold_study does) and returns its row; a failed run is a row
// with status "failed". Throws std::invalid_argument for an invalid plan and SceneError for an
// unreadable scene.
FoldRow run_fold_case(const FoldStudyPlan& plan, const FoldRun& run);

// Runs the plan (cases, then methods, meshes, seeds); progress lines to `log`. A failed run
// (SimulationError, a non-finite state) is a row with status "failed", NaN counts and a note;
// the study goes on. Throws std::invalid_argument for an invalid plan and SceneError for an
// unreadable scene.
std::vector<FoldRow> run_fold_study(const FoldStudyPlan& plan, const LogFn& log);

// CSV columns, in order: case, method, segments, rings, vertices, seed, amplitude, dt, steps,
// end_time, wall_seconds, circumferential_median, axial_median, circumferential_theory_lo,
// circumferential_theory_hi, axial_theory_lo, axial_theory_hi, t_eff, preset, status, note.
const std::vector<std::string>& fold_csv_columns();
void write_fold_csv(std::ostream& out, const std::vector<FoldRow>& rows);
// The rows of a CSV written by write_fold_csv (the header must be fold_csv_columns()); writing
// them again gives the same text. Throws std::invalid_argument naming the line and column of a
// malformed field.
std::vector<FoldRow> read_fold_csv(const std::string& text);
// Markdown: per case, method and mesh the seeds' counts (min–max and each), the theory band and
// the mean wall time per run.
void write_fold_markdown(std::ostream& out, const std::vector<FoldRow>& rows);

}  // namespace clothsim

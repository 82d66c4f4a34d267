// The convergence study (`clothsim study convergence`, docs/convergence.md): error against run
// time for several ways of solving the same problems.
//
// A *case* is a problem with a reference solution: the four square plates of sim/study/plates.hpp
// (reference: the analytic centre deflection) and the dynamic sleeve scenes (reference: the finest
// run of the same scene, a designated method on the finest mesh at the finest time step). A
// *method* is a named way to discretise and solve a case (the Loop subdivision element with one-
// or three-point quadrature, and the baselines linear_fe and mass_spring on the flat triangles;
// each is one Method in convergence_methods()). A *setting* is the resolution (and time
// step) of one run. Every run of a method on a case at a setting gives one row of results.csv
// (a sleeve run one row per error window).
//
// Errors:
//  - plates: |w − w_ref| / |w_ref| with w the downward deflection of the surface at the plate's
//    centre (the parameter point (x, y) = (0, 0)) and w_ref the series solution.
//  - sleeves: at a fixed grid of parameter points (θ, s) of the rest cylinder (θ around the axis,
//    s = y / L along it) and at the sample times of a window, the surface displacement u
//    (deformed surface point minus rest surface point at the same parameter) of the run and u_ref
//    of the reference: error = sqrt(Σ |u − u_ref|²) / sqrt(Σ |u_ref|²), sums over all points and
//    the window's times, i.e. RMS(|u − u_ref|) / RMS(|u_ref|) (surface_sampling.hpp). The full
//    plan has an "early" window that ends before the sleeves' first buckling bifurcation and a
//    "long" one to 0.2 s, after it (docs/convergence.md explains why both).
//  - sleeves after buckling (pointwise displacement is no measure there): at the end of each run
//    (its last sample time), the elastic energy E (Simulator::elastic_energy) and the fold counts of
//    the drawn surface (count_sleeve_folds, sim/study/fold_count.hpp: circumferential median over
//    the heights, axial median over the meridians), each against the reference run's:
//    |E − E_ref| / |E_ref| and count − count_ref.
// Wall time: std::chrono::steady_clock around the solve only — static: solve_static (assembly,
// factorisation, solve); dynamic: constructing the Simulator plus all its steps. Building the
// problem (mesh, scene) and evaluating the error are not included. Static solves that take
// milliseconds are repeated (up to 5 runs within 0.25 s) and the shortest time is reported (the
// solves are deterministic, so the error does not change), after one untimed warm-up solve per
// method.
#pragma once

#include "sim/core/log.hpp"
#include "sim/problem/problem.hpp"
#include "sim/shell/quadrature.hpp"
#include "sim/static/static_solve.hpp"
#include "sim/study/fold_count.hpp"
#include "sim/study/plates.hpp"
#include "sim/study/surface_sampling.hpp"

#include <Eigen/Core>

#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <ostream>
#include <map>
#include <string>
#include <vector>

namespace clothsim {

// What a method reports about one run.
struct MethodRun {
  int vertices = 0;                 // nodes / control vertices of the discretisation
  int dofs = 0;                     // free degrees of freedom (after boundary conditions)
  int steps = 0;                    // time steps taken (0 for a static solve)
  long long solver_iterations = 0;  // static: 1 per direct solve; dynamic: linear-solver iterations
                                    // summed over all steps (PCG iterations, 1 per direct solve)
  double wall_seconds = 0.0;        // [s], see the header comment
  // Surface displacement [m] at the requested points: one #P × 3 matrix per requested sample time
  // (a static solve: one matrix).
  std::vector<Eigen::MatrixX3d> displacements;
  // Dynamic runs, at the last sample time (the end of the run); left empty / NaN by a method that
  // does not report them (its rows then have empty post-buckling columns):
  double final_elastic_energy = std::numeric_limits<double>::quiet_NaN();  // [J]
  // [m] points of the surface whose folds are counted (kFoldSurfaceLevels) and its triangles
  Eigen::MatrixX3d final_surface;
  std::vector<Triangle> final_surface_triangles;
};

// Refinement levels of the surface whose folds are counted, the same for every method: the Loop
// limit surface over the nodes (Discretization::loop_limit_display: loop_kl's drawn surface; for
// a flat method the smooth surface its nodes span, since its own facets' corners on a coarse
// sleeve would count as folds). docs/convergence.md, "Post-buckling measures".
inline constexpr int kFoldSurfaceLevels = 2;

// A named way to discretise and solve a case. `points` are parameter points of the problem's
// control mesh (its triangles and barycentric coordinates); `times` [s] are increasing sample
// times, the last one the end of the run, each a multiple of problem.time.dt. Either function may
// be empty: the method then does not take part in the static (or dynamic) cases. Both may throw
// (std::runtime_error, SimulationError); the study records the failure in the row.
struct Method {
  std::string name;         // the CSV's "method" column, e.g. "loop_one_point"
  std::string description;  // one line for logs and docs
  // The discretisation (Problem::method, sim/setup/setup.hpp) the study builds the problem for:
  // a sleeve's scene is loaded with this "method", so its mesh is prepared for it and the
  // parameter points lie on that mesh; a plate's Problem gets it.
  std::string discretization = "loop_kl";
  // Optional: the reason the method cannot take a case's problem (e.g. clamped borders), or ""
  // when it can. A case it cannot take is skipped (no rows; a log line says why).
  std::function<std::string(const Problem& problem)> unsupported;
  std::function<MethodRun(const Problem& problem, const std::vector<SurfaceSample>& points)> solve_static;
  std::function<MethodRun(const Problem& problem, const std::vector<SurfaceSample>& points,
                          const std::vector<double>& times)>
      run_dynamic;
};

// The Loop subdivision element (paper §4) with the given quadrature rule: solve_static and
// Simulator, the displacement evaluated on the limit surface.
Method loop_subdivision_method(const std::string& name, Quadrature rule);

// A piecewise-flat baseline (sim/flat_fe/): "linear_fe" (corotated membrane triangles with hinge
// bending; static and dynamic; not for clamped or symmetry borders) or "mass_spring" (edge and
// bending springs; dynamic only). The displacement at a parameter point is the barycentric
// interpolation of the nodal displacements (the flat surface's samples operator).
Method flat_baseline_method(const std::string& discretization);

// The registered methods, in plotting order: "loop_one_point", "loop_three_point", "linear_fe",
// "mass_spring".
std::vector<Method> convergence_methods();

// Resolution of a sleeve's cylinder primitive: vertices around × rings along the axis.
struct SleeveMesh {
  int segments = 0;
  int rings = 0;
};

struct PlateStudyCase {
  AnalyticPlate plate;
  std::vector<int> divisions;  // grids of n × n cells, coarse to fine
};

// A set of sample times over which a sleeve's error is measured; each window gives its own row.
struct ErrorWindow {
  std::string name;           // the CSV's "window" column, e.g. "early"
  std::vector<double> times;  // [s], positive and increasing
};

// One setting of a sleeve's tolerance series: a method on a mesh at a time step.
struct ToleranceSetting {
  std::string method;  // Method::name; a setting whose method is not in the study is skipped
  SleeveMesh mesh;
  double dt = 1e-3;    // [s]
  // The case's windows (by name) this setting is measured in; empty: all of them. Its runs sample
  // only these windows' times, which must be multiples of dt (a setting at a large time step, such
  // as a scene's own 0.01 s, can thus skip a window of short times).
  std::vector<std::string> windows;
};

struct SleeveStudyCase {
  std::string name;              // the CSV's "case" column
  std::filesystem::path scene;   // a dynamic scene whose mesh is a full "cylinder" primitive
  // Every run simulates to the last of all windows' times and samples at each of them (each a
  // multiple of every time step of the case).
  std::vector<ErrorWindow> windows;
  int grid_theta = 32;           // parameter points around the axis
  int grid_s = 16;               // parameter points along the axis
  std::vector<SleeveMesh> meshes;  // mesh series, coarse to fine, at time step mesh_dt
  double mesh_dt = 1e-3;           // [s]
  SleeveMesh dt_mesh;              // time-step series on this mesh, time steps `dts`
  std::vector<double> dts;         // [s], large to small
  // Methods that also run the time-step series (the others run the mesh series only); empty: all.
  std::vector<std::string> dt_series_methods;
  // Tolerance series (the linear solver's relative-residual tolerance, the scene's
  // solver.tolerance): each of tolerance_settings (a method on a mesh at a time step), once with
  // every tolerance of `tolerances` and once with tight_tolerance, the solver reference of that
  // setting (its solver error is 0 by definition). Each run's error is reported against the
  // study's reference (total error), against the tight run of its setting (solver error), and the
  // tight run's against the reference (discretisation error). Empty `tolerances`: no tolerance
  // series.
  std::vector<double> tolerances;  // loose to tight, each > tight_tolerance
  double tight_tolerance = 1e-12;
  std::vector<ToleranceSetting> tolerance_settings;
  SleeveMesh reference_mesh;       // the reference run: this mesh, reference_dt, reference_method
  double reference_dt = 5e-4;      // [s]
  std::string reference_method = "loop_three_point";
  // The rest cylinder's axis, for the fold counts (the scenes' cylinder primitive: the y axis from
  // the origin; θ = 0 along x).
  FoldAxis fold_axis;
};

struct ConvergencePlan {
  std::vector<PlateStudyCase> plates;
  std::vector<SleeveStudyCase> sleeves;
};

// The full study (docs/convergence.md: about 20 minutes on 2 cores, Release) and a tiny one for
// the tests (a few seconds). `scenes_dir` is the folder holding sleeve_*.json.
ConvergencePlan full_convergence_plan(const std::filesystem::path& scenes_dir);
ConvergencePlan quick_convergence_plan(const std::filesystem::path& scenes_dir);

// One row of results.csv (columns in results_csv_columns() order).
struct ConvergenceRow {
  std::string case_name;  // "plate_ss_uniform", "sleeve_gravity", ...
  std::string method;     // Method::name
  std::string series;     // "mesh" (refining the mesh), "dt" (refining the time step),
                          // "tolerance" (loosening the linear solver's tolerance) or
                          // "reference" (the run the sleeve's errors are measured against)
  std::string window;     // sleeves: the ErrorWindow's name; plates: "static"
  std::string setting;    // "16x16" (plate cells), "26x19 dt=0.001" (sleeve segments x rings,
                          // time step) or "26x19 dt=0.001 tol=1e-05" (tolerance series)
  int vertices = 0;
  int dofs = 0;
  double h = 0.0;          // [m] mesh size sqrt(2 · area / #triangles) of the rest control mesh
  double dt = 0.0;         // [s] time step; 0 for static cases
  int steps = 0;           // time steps; 0 for static cases
  double wall_seconds = 0.0;
  long long solver_iterations = 0;
  double error = 0.0;      // relative error (see the header comment); NaN if the run failed
  std::optional<double> order;  // observed order against the previous row of the same case,
                                // method, series and window: log(e_prev / e) / log(x_prev / x), x = h
                                // (mesh series) or dt (dt series)
  std::string quantity;    // what `value` is
  double value = 0.0;      // plates: centre deflection [m]; sleeves: RMS |u| [m]
  double reference_value = 0.0;  // the same for the reference
  double reference_precision = 0.0;  // relative uncertainty of reference_value (plates: rounding
                                     // of the published coefficient; sleeves: 0)
  std::string reference;   // what the reference is
  std::string note;        // empty, or e.g. the reason a run failed
  // Post-buckling measures (sleeves; empty for plates and failed runs): at the end of the run.
  std::optional<double> elastic_energy;            // [J] E
  std::optional<double> reference_elastic_energy;  // [J] E_ref
  std::optional<double> energy_error;              // |E − E_ref| / |E_ref| [-]
  std::optional<double> folds_circumferential;     // median fold count over the height sections
  std::optional<double> folds_axial;               // median fold count over the meridians
  std::optional<double> reference_folds_circumferential;
  std::optional<double> reference_folds_axial;
  std::optional<double> fold_difference_circumferential;  // folds − reference folds
  std::optional<double> fold_difference_axial;
  // The linear solver's relative-residual tolerance of the run (dynamic runs solved by PCG; empty
  // for static solves and direct solvers).
  std::optional<double> tolerance;
  // Tolerance series only (empty in the other series): the run against the tight-tolerance run of
  // its method, mesh and time step (the solver reference) — the window's norm (relative to the
  // solver reference's RMS |u|) and its end energy, and that run's fold counts — and the solver
  // reference against the study's reference (the discretisation error of the setting).
  std::optional<double> solver_error;
  std::optional<double> discretization_error;
  std::optional<double> solver_energy_error;          // |E − E_tight| / |E_tight|
  std::optional<double> discretization_energy_error;  // |E_tight − E_ref| / |E_ref|
  std::optional<double> solver_reference_folds_circumferential;
  std::optional<double> solver_reference_folds_axial;
};

// Progress lines ("case ... method ... setting ... error ... (x s)") go to `log` (may be empty).
// Throws std::invalid_argument for an inconsistent plan (unknown reference method, sample times
// that are not multiples of a time step, a scene that is not a dynamic cylinder) and SceneError
// for an unreadable scene. A failed run (or failed reference run) does not stop the study: its
// rows get error NaN and a note.
std::vector<ConvergenceRow> run_convergence(const ConvergencePlan& plan, const std::vector<Method>& methods,
                                            const LogFn& log);

// The study as independent runs (docs/cluster.md): every simulation of a sleeve (a method on a
// mesh at a time step and solver tolerance, sampled at the times its windows need; the reference
// run included) and every static solve of a plate (a method on a grid) has a stable id made of
// those parameters, e.g. "sleeve_gravity.loop_three_point.26x19.dt0.001.tol1e-08". Each can run
// anywhere; the rows are then built from the stored results as run_convergence builds them (the
// same numbers but wall times, which are each run's own).
//
// The runs of `plan` in the order the study first needs them.
std::vector<std::string> convergence_run_ids(const ConvergencePlan& plan, const std::vector<Method>& methods);
// Runs run `id` and returns its result as text (JSON: the sampled displacements, end energy, fold
// counts, counts and time; exact doubles). A run that fails returns its failure in the result.
// Throws std::invalid_argument for an id that is not in the plan.
std::string run_convergence_run(const ConvergencePlan& plan, const std::vector<Method>& methods, const std::string& id,
                                const LogFn& log);
// The rows from stored results (id → the text run_convergence_run returned); a run without a
// result marks its rows failed ("run ID did not finish"). Throws std::runtime_error naming a run
// whose result cannot be read.
std::vector<ConvergenceRow> gather_convergence(const ConvergencePlan& plan, const std::vector<Method>& methods,
                                               const std::map<std::string, std::string>& results, const LogFn& log);

// The CSV columns, in order: case, method, series, window, setting, vertices, dofs, h, dt, steps,
// wall_seconds, solver_iterations, error, order, quantity, value, reference_value,
// reference_precision, reference, note, elastic_energy, reference_elastic_energy, energy_error,
// folds_circumferential, folds_axial, reference_folds_circumferential, reference_folds_axial,
// fold_difference_circumferential, fold_difference_axial, tolerance, solver_error,
// discretization_error, solver_energy_error, discretization_energy_error,
// solver_reference_folds_circumferential, solver_reference_folds_axial.
const std::vector<std::string>& results_csv_columns();

// Writes the header line and one line per row (RFC 4180 quoting where needed; numbers in the
// shortest form that reads back exactly, wall_seconds to the microsecond, empty order for the
// first row of a series, "nan" for a failed run's error, empty post-buckling columns where a row
// has none).
void write_results_csv(std::ostream& out, const std::vector<ConvergenceRow>& rows);

// A Markdown table of the rows (case, method, series, window, setting, vertices, dofs, dt, wall time,
// iterations, error, order, energy error, folds, tolerance, solver error, discretisation error).
void write_results_markdown(std::ostream& out, const std::vector<ConvergenceRow>& rows);

// The rule that chooses the linear solver's tolerance from the tolerance series
// (docs/convergence.md, "Solver tolerance"). Of a setting's (case, method, mesh and time step)
// tolerance runs, those at tolerances >= baseline other than the tight run are the *candidates*
// (loose to tight); those at tolerances <= baseline, the tight run included, are the *baseline
// runs*: the study's other series' tolerance (kSeriesTolerance, the scenes' default before this
// rule chose 1e-5) and tighter, they differ from the tight run only by perturbations far below
// any discretisation error, which after a buckling bifurcation are amplified and decide the end
// state — their differences are the run-to-run spread of that state.
//  - A window is *resolved* when no baseline run (other than the tight one) has a solver error
//    above max_amplification × its tolerance. Before a bifurcation the solver error is at most a
//    few dozen times the tolerance (measured up to 61); after one, perturbations grow by many
//    orders of magnitude and the window's norm measures that growth, not the solver's accuracy.
//    Unresolved windows do not enter the rule.
//  - In a resolved window, the loosest candidate whose solver error, and that of every tighter
//    candidate, is at most ratio × the discretisation error (the tight run against the reference).
//  - The end state (elastic energy and fold counts at the end of the run) of every candidate looser
//    than the baseline is compared with the range the baseline runs span (the energy also with
//    ratio × its discretisation error).
struct ToleranceRule {
  double ratio = 0.1;               // solver error at most ratio × the discretisation error
  double baseline = 1e-8;           // [-] the tolerance of the study's other series
  double max_amplification = 1e3;   // largest solver error / tolerance of a resolved window's baseline runs
};

// One error window of one setting.
struct ToleranceWindowCheck {
  std::string window;
  double discretization_error = 0.0;  // the tight run against the study's reference
  // Of the baseline runs other than the tight one: the largest solver error, and the largest
  // solver error / tolerance (0 if there are none).
  double baseline_solver_error = 0.0;
  double amplification = 0.0;
  bool resolved = true;  // amplification <= max_amplification
  // The loosest candidate whose solver error, and that of every tighter candidate, is at most
  // ratio × discretization_error; none if the tightest candidate already fails.
  std::optional<double> loosest;
};

// One setting (case, method, mesh and time step) of the tolerance series: its windows, and its end
// state against the spread.
struct ToleranceSettingCheck {
  std::string case_name;
  std::string method;
  std::string setting;             // the rows' setting without its tolerance: "26x19 dt=0.001"
  double dt = 0.0;                 // [s]
  double tight_tolerance = 0.0;
  std::vector<double> candidates;  // loose to tight
  std::vector<ToleranceWindowCheck> windows;
  // The end state's spread over the baseline runs: the largest relative energy difference from the
  // tight run (|E − E_tight| / |E_tight|), and the range of fold counts (the tight run included);
  // NaN when the runs report none.
  double energy_spread = std::numeric_limits<double>::quiet_NaN();
  double folds_circumferential_min = std::numeric_limits<double>::quiet_NaN();
  double folds_circumferential_max = std::numeric_limits<double>::quiet_NaN();
  double folds_axial_min = std::numeric_limits<double>::quiet_NaN();
  double folds_axial_max = std::numeric_limits<double>::quiet_NaN();
  // Candidates looser than the baseline whose fold counts lie outside that range, or whose energy
  // differs from the tight run's by more than both energy_spread and ratio × the setting's
  // discretisation error of the energy (|E_tight − E_ref| / |E_ref|; the bound for an end state
  // before buckling, where the spread is round-off), or that failed.
  std::vector<double> outside_spread;
};

struct ToleranceSummary {
  ToleranceRule rule;
  std::vector<ToleranceSettingCheck> settings;  // in the order of the rows
  // The recommendation: the tightest of the resolved windows' loosest candidates over every
  // setting; none when there is no tolerance series, no resolved window, or a resolved window in
  // which no candidate passes.
  std::optional<double> recommended;
};

// Applies `rule` to the rows of series "tolerance" (grouped by case, method and setting — mesh and
// time step, the part of `setting` before " tol=").
ToleranceSummary summarize_tolerance_series(const std::vector<ConvergenceRow>& rows, const ToleranceRule& rule = {});

// The summary as Markdown: one table row per setting and window, the end-state check and the
// recommendation (nothing when there is no tolerance series).
void write_tolerance_summary_markdown(std::ostream& out, const ToleranceSummary& summary);

}  // namespace clothsim

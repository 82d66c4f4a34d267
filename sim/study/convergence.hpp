// The convergence study (`clothsim study convergence`, docs/convergence.md): error against run
// time for several ways of solving the same problems.
//
// A *case* is a problem with a reference solution: the four square plates of sim/study/plates.hpp
// (reference: the analytic centre deflection) and the dynamic sleeve scenes (reference: the finest
// run of the same scene, a designated method on the finest mesh at the finest time step). A
// *method* is a named way to discretise and solve a case (now the Loop subdivision element with
// one- or three-point quadrature; baselines such as a linear FE or hinge bending are added by
// registering one more Method in convergence_methods()). A *setting* is the resolution (and time
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
#include "sim/study/plates.hpp"
#include "sim/study/surface_sampling.hpp"

#include <Eigen/Core>

#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
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
};

// A named way to discretise and solve a case. `points` are parameter points of the problem's
// control mesh (its triangles and barycentric coordinates); `times` [s] are increasing sample
// times, the last one the end of the run, each a multiple of problem.time.dt. Either function may
// be empty: the method then does not take part in the static (or dynamic) cases. Both may throw
// (std::runtime_error, SimulationError); the study records the failure in the row.
struct Method {
  std::string name;         // the CSV's "method" column, e.g. "loop_one_point"
  std::string description;  // one line for logs and docs
  std::function<MethodRun(const Problem& problem, const std::vector<SurfaceSample>& points)> solve_static;
  std::function<MethodRun(const Problem& problem, const std::vector<SurfaceSample>& points,
                          const std::vector<double>& times)>
      run_dynamic;
};

// The Loop subdivision element (paper §4) with the given quadrature rule: solve_static and
// Simulator, the displacement evaluated on the limit surface.
Method loop_subdivision_method(const std::string& name, Quadrature rule);

// The registered methods, in plotting order: "loop_one_point", "loop_three_point". Later
// baselines ("linear_fe", "hinge_bending") are added here, one line each.
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
  SleeveMesh reference_mesh;       // the reference run: this mesh, reference_dt, reference_method
  double reference_dt = 5e-4;      // [s]
  std::string reference_method = "loop_three_point";
};

struct ConvergencePlan {
  std::vector<PlateStudyCase> plates;
  std::vector<SleeveStudyCase> sleeves;
};

// The full study (docs/convergence.md: ~10 minutes on 2 cores, Release) and a tiny one for the
// tests (a few seconds). `scenes_dir` is the folder holding sleeve_*.json.
ConvergencePlan full_convergence_plan(const std::filesystem::path& scenes_dir);
ConvergencePlan quick_convergence_plan(const std::filesystem::path& scenes_dir);

// One row of results.csv (columns in results_csv_columns() order).
struct ConvergenceRow {
  std::string case_name;  // "plate_ss_uniform", "sleeve_gravity", ...
  std::string method;     // Method::name
  std::string series;     // "mesh" (refining the mesh), "dt" (refining the time step) or
                          // "reference" (the run the sleeve's errors are measured against)
  std::string window;     // sleeves: the ErrorWindow's name; plates: "static"
  std::string setting;    // "16x16" (plate cells) or "26x19 dt=0.001" (sleeve segments x rings)
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
};

// Progress lines ("case ... method ... setting ... error ... (x s)") go to `log` (may be empty).
// Throws std::invalid_argument for an inconsistent plan (unknown reference method, sample times
// that are not multiples of a time step, a scene that is not a dynamic cylinder) and SceneError
// for an unreadable scene. A failed run (or failed reference run) does not stop the study: its
// rows get error NaN and a note.
std::vector<ConvergenceRow> run_convergence(const ConvergencePlan& plan, const std::vector<Method>& methods,
                                            const LogFn& log);

// The CSV columns, in order: case, method, series, window, setting, vertices, dofs, h, dt, steps,
// wall_seconds, solver_iterations, error, order, quantity, value, reference_value,
// reference_precision, reference, note.
const std::vector<std::string>& results_csv_columns();

// Writes the header line and one line per row (RFC 4180 quoting where needed; numbers in the
// shortest form that reads back exactly, wall_seconds to the microsecond, empty order for the
// first row of a series, "nan" for a failed run's error).
void write_results_csv(std::ostream& out, const std::vector<ConvergenceRow>& rows);

// A Markdown table of the rows (case, method, series, window, setting, vertices, dofs, dt, wall time,
// iterations, error, order).
void write_results_markdown(std::ostream& out, const std::vector<ConvergenceRow>& rows);

}  // namespace clothsim

#include "sim/study/convergence.hpp"

#include "sim/dynamics/simulator.hpp"
#include "sim/scene/scene.hpp"
#include "sim/shell/dof_map.hpp"
#include "sim/solver/linear_solver.hpp"
#include "sim/study/report_format.hpp"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace clothsim {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A static solve of `problem` as given (its method and quadrature set by the caller).
MethodRun solve_static_run(const Problem& problem, const std::vector<SurfaceSample>& points) {
  MethodRun run;
  const Clock::time_point start = Clock::now();
  const StaticResult result = solve_static(problem);
  run.wall_seconds = seconds_since(start);
  run.vertices = problem.mesh.num_vertices();
  run.dofs = result.dofs;
  run.solver_iterations = 1;
  const Discretization& d = *result.discretization;
  const SurfaceOperator sampling = d.samples(points);
  run.displacements = {d.surface_positions(sampling, result.positions()) - d.surface_positions(sampling, d.rest())};
  return run;
}

// The surface whose folds are counted, for node positions x [m]: the Loop limit surface over the
// nodes at kFoldSurfaceLevels (Discretization::loop_limit_display) for every method — loop_kl's
// own drawn surface; for a flat method the smooth surface its nodes span, since its own drawing is
// its facets, whose corners on a coarse sleeve (a 14-gon's stand 1.3 mm off the circle) exceed
// the fold counter's 1 mm prominence.
void fold_surface(const Discretization& d, const Eigen::VectorXd& x, Eigen::MatrixX3d& points,
                  std::vector<Triangle>& triangles) {
  const SurfaceOperator drawn = d.loop_limit_display(kFoldSurfaceLevels);
  points = d.surface_positions(drawn, x);
  triangles = drawn.triangles;
}

// A dynamic run of `problem` as given (its method and quadrature set by the caller) to the last
// sample time; also reports the elastic energy and the drawn surface there.
MethodRun run_dynamic_simulation(Problem problem, const std::vector<SurfaceSample>& points,
                                 const std::vector<double>& times) {
  if (times.empty()) throw std::invalid_argument("run_dynamic_simulation: no sample times");
  problem.time.end = times.back();
  const double slack = 1e-9 * problem.time.dt;
  MethodRun run;
  std::vector<Eigen::VectorXd> snapshots;  // node positions at the sample times [m]
  const Clock::time_point start = Clock::now();
  Simulator sim(problem);
  size_t next = 0;
  auto take_due_samples = [&] {
    for (; next < times.size() && sim.state().t >= times[next] - slack; ++next)
      snapshots.push_back(sim.state().x);
  };
  for (take_due_samples(); next < times.size(); take_due_samples()) {
    const StepStats stats = sim.step();
    run.solver_iterations += stats.solver_iterations;
    ++run.steps;
  }
  run.wall_seconds = seconds_since(start);
  const Discretization& d = sim.discretization();
  run.vertices = sim.num_vertices();
  run.dofs = 0;
  for (int dof = 0; dof < 3 * d.num_nodes(); ++dof) run.dofs += d.status(dof) == DofStatus::free;
  const SurfaceOperator sampling = d.samples(points);
  const Eigen::MatrixX3d rest = d.surface_positions(sampling, d.rest());
  for (const Eigen::VectorXd& x : snapshots) run.displacements.push_back(d.surface_positions(sampling, x) - rest);
  // The loop ends at the step that reaches the last sample time: the state is the run's end.
  run.final_elastic_energy = sim.elastic_energy();
  fold_surface(d, sim.state().x, run.final_surface, run.final_surface_triangles);
  return run;
}

std::string flat_baseline_unsupported(const std::string& discretization, const Problem& problem) {
  for (const BoundaryCondition& bc : problem.boundary)
    if (bc.clamped || bc.symmetric)
      return discretization + " has no rotational degrees of freedom: \"" + (bc.clamped ? "clamped" : "symmetry") +
             "\" borders are not supported";
  return "";
}

// sqrt(2 · area / #triangles) of the rest mesh [m]: the edge length of a uniform right-triangle
// grid (side / n for an n × n plate grid).
double mesh_size(const TriMesh& mesh) {
  double area = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices.row(t[0]), b = mesh.vertices.row(t[1]), c = mesh.vertices.row(t[2]);
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return mesh.triangles.empty() ? 0.0 : std::sqrt(2.0 * area / static_cast<double>(mesh.num_triangles()));
}

// The linear solver's tolerance of every sleeve run outside the tolerance series.
constexpr double kSeriesTolerance = 1e-8;

std::string sleeve_setting(const SleeveMesh& m, double dt) {
  return std::to_string(m.segments) + "x" + std::to_string(m.rings) + " dt=" + format_shortest(dt);
}

// The relative-residual tolerance a problem's linear solver works to, or none for a direct solver.
std::optional<double> solver_tolerance(const Problem& problem) {
  if (problem.solver.type == LinearSolverType::cholmod) return std::nullopt;
  return problem.solver.tolerance;
}

// Each window's times must be positive, increasing and whole numbers of steps of `dt`.
void check_sample_times(const std::string& case_name, const std::vector<ErrorWindow>& windows, double dt) {
  for (const ErrorWindow& w : windows) {
    if (w.times.empty()) throw std::invalid_argument(case_name + ": window \"" + w.name + "\" has no sample times");
    double previous = 0.0;
    for (double t : w.times) {
      const double steps = t / dt;
      if (!(t > previous) || std::abs(steps - std::round(steps)) > 1e-6 * steps)
        throw std::invalid_argument(case_name + ": window \"" + w.name + "\": sample time " + format_shortest(t) +
                                    " s: sample times must be positive, increasing and multiples of dt = " +
                                    format_shortest(dt) + " s");
      previous = t;
    }
  }
}

void check_sample_times(const SleeveStudyCase& c, double dt) { check_sample_times(c.name, c.windows, dt); }

// The windows a tolerance setting is measured in (ToleranceSetting::windows; empty: the case's).
std::vector<ErrorWindow> setting_windows(const SleeveStudyCase& c, const ToleranceSetting& setting) {
  if (setting.windows.empty()) return c.windows;
  std::vector<ErrorWindow> out;
  for (const std::string& name : setting.windows) {
    const auto it = std::find_if(c.windows.begin(), c.windows.end(), [&](const ErrorWindow& w) { return w.name == name; });
    if (it == c.windows.end())
      throw std::invalid_argument(c.name + ": tolerance setting " + setting.method + " " + std::to_string(setting.mesh.segments) +
                                  "x" + std::to_string(setting.mesh.rings) + ": no window \"" + name + "\"");
    out.push_back(*it);
  }
  return out;
}

// The union of the windows' sample times, ascending [s].
std::vector<double> all_sample_times(const std::vector<ErrorWindow>& windows) {
  std::vector<double> times;
  for (const ErrorWindow& w : windows) times.insert(times.end(), w.times.begin(), w.times.end());
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  return times;
}

std::vector<double> all_sample_times(const SleeveStudyCase& c) { return all_sample_times(c.windows); }

// The samples of `run` (taken at `all_times`) that belong to `window`.
std::vector<Eigen::MatrixX3d> window_samples(const std::vector<Eigen::MatrixX3d>& samples,
                                             const std::vector<double>& all_times, const ErrorWindow& window) {
  std::vector<Eigen::MatrixX3d> out;
  for (double t : window.times) {
    const auto it = std::lower_bound(all_times.begin(), all_times.end(), t);
    out.push_back(samples.at(static_cast<size_t>(it - all_times.begin())));
  }
  return out;
}

std::string join_times(const std::vector<double>& times) {
  std::string out;
  for (double t : times) {
    if (!out.empty()) out += ' ';
    out += format_shortest(t);
  }
  return out;
}

// A sleeve case's scene file with the mesh resolution and time step replaced, loaded through the
// normal scene loader.
class SleeveScene {
 public:
  explicit SleeveScene(const SleeveStudyCase& c) : case_(c) {
    std::ifstream in(c.scene);
    if (!in) throw SceneError(c.scene.string() + ": cannot read the scene file");
    std::ostringstream text;
    text << in.rdbuf();
    try {
      json_ = nlohmann::json::parse(text.str());
    } catch (const nlohmann::json::exception& e) {
      throw SceneError(c.scene.string() + ": malformed JSON: " + e.what());
    }
    const nlohmann::json& mesh = json_.at("mesh");
    if (json_.value("analysis", "static") != "dynamic" || mesh.value("primitive", "") != "cylinder" ||
        mesh.value("angle_deg", 360.0) != 360.0)
      throw std::invalid_argument(c.scene.string() + ": the convergence study needs a dynamic scene whose mesh is a "
                                                     "full \"cylinder\" primitive");
  }

  // The scene with the given mesh, time step and discretisation (its mesh prepared for it), and
  // with the linear solver's tolerance (solver.tolerance) replaced if one is given.
  Problem problem(const SleeveMesh& m, double dt, const std::string& discretization,
                  std::optional<double> tolerance = std::nullopt) const {
    nlohmann::json j = json_;
    j["method"] = discretization;
    j["mesh"]["segments"] = m.segments;
    j["mesh"]["rings"] = m.rings;
    j["time"]["dt"] = dt;
    j["time"]["end"] = all_sample_times(case_).back();
    // The perfect sleeve: the study's windows lie around its first buckling (docs/convergence.md),
    // which a shipped scene's seeded imperfection moves (the compressed sleeve then buckles at
    // once), so the imperfection is left out.
    j.erase("imperfection");
    // The mesh and time-step series solve to 1e-8 (kSeriesTolerance), whatever the scene's default:
    // their differences go down to 1e-4 (neighbouring settings), which the solver error must not touch.
    j["solver"]["tolerance"] = tolerance ? *tolerance : kSeriesTolerance;
    return load_scene_text(j.dump(2), case_.scene, LogFn()).problem;
  }

 private:
  const SleeveStudyCase& case_;
  nlohmann::json json_;
};

// The outcome of one run: the method's report or the reason it failed.
struct Outcome {
  MethodRun run;
  double h = 0.0;
  std::string failure;  // empty on success
  // The post-buckling measures at the end of the run (none if the method did not report them).
  std::optional<double> energy;                          // [J]
  std::optional<double> folds_circumferential, folds_axial;  // medians (count_sleeve_folds)
  std::optional<double> tolerance;  // the linear solver's relative-residual tolerance (none: direct)
};

// Where the runner's runs come from (docs/cluster.md, the convergence study as tasks): computed
// here (the usual way); only listed, with one of them computed (planning, and running one task);
// or read back from the results of tasks that ran elsewhere (the gather).
struct RunSource {
  enum class Mode { compute, collect, stored };
  Mode mode = Mode::compute;
  std::string target;                                        // collect: the run to compute
  std::optional<std::string> target_result;                  // collect: its result (run_json)
  std::vector<std::string> ids;                              // collect: every run, in order of first need
  const std::map<std::string, std::string>* stored = nullptr;  // stored: id → result text
};

// A run's id in a plan: letters, digits and . _ - only (the sweep's ids), from its parameters.
std::string run_id(const std::string& text) {
  std::string id;
  for (const char ch : text) {
    const bool plain = std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '_' || ch == '-';
    id += plain ? ch : '_';
  }
  return id;
}

nlohmann::json optional_json(const std::optional<double>& x) { return x ? nlohmann::json(*x) : nlohmann::json(); }
std::optional<double> optional_of(const nlohmann::json& j) {
  return j.is_null() ? std::nullopt : std::optional<double>(j.get<double>());
}

// An outcome as the text a task leaves (exact doubles: nlohmann writes the shortest form that
// reads back to the same double) and back. The fold surface is not kept (only its counts are).
std::string run_json(const Outcome& o) {
  nlohmann::json j;
  j["failure"] = o.failure;
  j["h"] = o.h;
  j["energy"] = optional_json(o.energy);
  j["folds_circumferential"] = optional_json(o.folds_circumferential);
  j["folds_axial"] = optional_json(o.folds_axial);
  j["tolerance"] = optional_json(o.tolerance);
  j["vertices"] = o.run.vertices;
  j["dofs"] = o.run.dofs;
  j["steps"] = o.run.steps;
  j["solver_iterations"] = o.run.solver_iterations;
  j["wall_seconds"] = o.run.wall_seconds;
  j["final_elastic_energy"] = std::isfinite(o.run.final_elastic_energy) ? nlohmann::json(o.run.final_elastic_energy)
                                                                         : nlohmann::json();
  nlohmann::json samples = nlohmann::json::array();
  for (const Eigen::MatrixX3d& u : o.run.displacements) {
    nlohmann::json rows = nlohmann::json::array();
    for (Eigen::Index i = 0; i < u.rows(); ++i) rows.push_back({u(i, 0), u(i, 1), u(i, 2)});
    samples.push_back(rows);
  }
  j["displacements"] = samples;
  return j.dump() + "\n";
}

Outcome outcome_of(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(text);
  Outcome o;
  o.failure = j.at("failure").get<std::string>();
  o.h = j.at("h").get<double>();
  o.energy = optional_of(j.at("energy"));
  o.folds_circumferential = optional_of(j.at("folds_circumferential"));
  o.folds_axial = optional_of(j.at("folds_axial"));
  o.tolerance = optional_of(j.at("tolerance"));
  o.run.vertices = j.at("vertices").get<int>();
  o.run.dofs = j.at("dofs").get<int>();
  o.run.steps = j.at("steps").get<int>();
  o.run.solver_iterations = j.at("solver_iterations").get<long long>();
  o.run.wall_seconds = j.at("wall_seconds").get<double>();
  if (!j.at("final_elastic_energy").is_null()) o.run.final_elastic_energy = j.at("final_elastic_energy").get<double>();
  for (const nlohmann::json& rows : j.at("displacements")) {
    Eigen::MatrixX3d u(static_cast<Eigen::Index>(rows.size()), 3);
    for (std::size_t i = 0; i < rows.size(); ++i)
      for (int k = 0; k < 3; ++k) u(static_cast<Eigen::Index>(i), k) = rows.at(i).at(static_cast<std::size_t>(k)).get<double>();
    o.run.displacements.push_back(u);
  }
  return o;
}

const Method& find_method(const std::vector<Method>& methods, const std::vector<Method>& registered,
                          const std::string& name) {
  for (const std::vector<Method>* list : {&methods, &registered})
    for (const Method& m : *list)
      if (m.name == name) return m;
  throw std::invalid_argument("unknown method \"" + name + "\"");
}

// A static solve, repeated while it is short (up to kStaticRepeats runs while their total stays
// under kStaticRepeatSeconds) so that millisecond timings are not dominated by noise; reports the
// last run with the shortest wall time of all.
constexpr int kStaticRepeats = 5;
constexpr double kStaticRepeatSeconds = 0.25;

MethodRun solve_static_timed(const Method& method, const Problem& problem,
                             const std::vector<SurfaceSample>& points) {
  MethodRun run = method.solve_static(problem, points);
  double total = run.wall_seconds, best = run.wall_seconds;
  for (int k = 1; k < kStaticRepeats && total + best < kStaticRepeatSeconds; ++k) {
    run = method.solve_static(problem, points);
    total += run.wall_seconds;
    best = std::min(best, run.wall_seconds);
  }
  run.wall_seconds = best;
  return run;
}

class StudyRunner {
 public:
  StudyRunner(const std::vector<Method>& methods, const LogFn& log, RunSource& source)
      : methods_(methods), log_(log), source_(source) {}

  void run_plate(const PlateStudyCase& c, std::vector<ConvergenceRow>& rows) {
    for (const Method& method : methods_) {
      if (!method.solve_static) continue;
      if (const std::string why = unsupported(method, plate_problem(c.plate, c.divisions.front(), Quadrature::one_point));
          !why.empty()) {
        skip(c.plate.id, method, why);
        continue;
      }
      for (int n : c.divisions) {
        // The method sets its own quadrature; the problem carries the default.
        Problem problem = plate_problem(c.plate, n, Quadrature::one_point);
        problem.method = method.discretization;
        const Eigen::MatrixX2d chart = problem.mesh.vertices.leftCols<2>();  // (x, y) [m]
        const std::vector<SurfaceSample> centre =
            locate_points(problem.mesh.triangles, chart, Eigen::MatrixX2d::Zero(1, 2));
        const Outcome o = get(run_id(std::string(c.plate.id) + "." + method.name + "." + std::to_string(n) + "x" + std::to_string(n)), [&] {
          Outcome computed;
          warm_up(method, problem, centre);
          try {
            computed.run = solve_static_timed(method, problem, centre);
          } catch (const std::exception& e) {
            computed.failure = e.what();
          }
          return computed;
        });
        ConvergenceRow row;
        row.case_name = c.plate.id;
        row.method = method.name;
        row.series = "mesh";
        row.window = "static";
        row.setting = std::to_string(n) + "x" + std::to_string(n);
        row.h = mesh_size(problem.mesh);
        row.quantity = "centre deflection [m]";
        row.reference_value = plate_reference_deflection(c.plate, problem);
        row.reference_precision = c.plate.relative_precision();
        std::ostringstream ref;
        ref << "analytic (Timoshenko & Woinowsky-Krieger): w = " << c.plate.coefficient
            << (c.plate.point_load ? " P a^2 / D" : " q a^4 / D");
        row.reference = ref.str();
        if (o.failure.empty()) {
          fill_run(row, o.run);
          row.value = -o.run.displacements.at(0)(0, 2);
          row.error = std::abs(row.value - row.reference_value) / std::abs(row.reference_value);
        } else {
          mark_failed(row, o.failure);
        }
        report(row);
        rows.push_back(row);
      }
    }
  }

  void run_sleeve(const SleeveStudyCase& c, std::vector<ConvergenceRow>& rows) {
    if (c.windows.empty()) throw std::invalid_argument(c.name + ": no error windows");
    for (double dt : c.dts) check_sample_times(c, dt);
    if (!c.tolerances.empty()) {
      for (const ToleranceSetting& setting : c.tolerance_settings)
        check_sample_times(c.name, setting_windows(c, setting), setting.dt);
      for (double tolerance : c.tolerances)
        if (!(tolerance > c.tight_tolerance && tolerance < 1))
          throw std::invalid_argument(c.name + ": tolerance " + format_shortest(tolerance) +
                                      ": the tolerance series' tolerances must lie between its tight tolerance " +
                                      format_shortest(c.tight_tolerance) + " and 1");
    }
    check_sample_times(c, c.mesh_dt);
    check_sample_times(c, c.reference_dt);
    const Method& reference_method = find_method(methods_, registered_, c.reference_method);
    const SleeveScene scene(c);
    const std::vector<double> times = all_sample_times(c);
    cache_.clear();

    const Outcome& reference = outcome(c, scene, times, reference_method, c.reference_mesh, c.reference_dt);
    if (!reference.failure.empty() || !reference.energy)
      log_line("case " + c.name + ": the reference run " +
               (reference.failure.empty() ? std::string("reported no end state") : "failed: " + reference.failure));
    const std::string reference_text =
        "finest run: " + reference_method.name + " " + sleeve_setting(c.reference_mesh, c.reference_dt);

    // One run's rows, one per window of `windows` (sampled at `run_times`, their union). A
    // tolerance-series run passes its tolerance and its solver reference (the tight-tolerance run
    // of the same method, mesh and time step, sampled at the same times).
    auto add_in = [&](const std::vector<ErrorWindow>& windows, const std::vector<double>& run_times,
                      const Method& method, const std::string& series, const SleeveMesh& m, double dt,
                      std::optional<double> tolerance = std::nullopt, const Outcome* solver_reference = nullptr) {
      const Outcome& o = outcome(c, scene, run_times, method, m, dt, tolerance);
      for (const ErrorWindow& window : windows) {
        ConvergenceRow row;
        row.case_name = c.name;
        row.method = method.name;
        row.series = series;
        row.window = window.name;
        row.setting = sleeve_setting(m, dt) + (tolerance ? " tol=" + format_shortest(*tolerance) : "");
        row.tolerance = o.tolerance;
        row.h = o.h;
        row.dt = dt;
        row.quantity = "RMS surface displacement [m] at " + std::to_string(c.grid_theta) + "x" +
                       std::to_string(c.grid_s) + " (theta s) points; t = " + join_times(window.times) + " s";
        row.reference = reference_text;
        fill_run(row, o.run);
        if (!reference.failure.empty()) {
          mark_failed(row, "the reference run failed: " + reference.failure);
        } else {
          const std::vector<Eigen::MatrixX3d> u_ref = window_samples(reference.run.displacements, times, window);
          row.reference_value = rms_norm(u_ref);
          if (!o.failure.empty()) {
            mark_failed(row, o.failure);
          } else {
            const std::vector<Eigen::MatrixX3d> u = window_samples(o.run.displacements, run_times, window);
            row.value = rms_norm(u);
            row.error = relative_rms_difference(u, u_ref);
            if (&o == &reference) row.note = "the reference run itself (error 0 by definition)";
            fill_post_buckling(row, o, reference);
          }
        }
        if (solver_reference) fill_solver_error(row, o, *solver_reference, reference, run_times, times, window);
        report(row);
        rows.push_back(row);
      }
    };
    auto add = [&](const Method& method, const std::string& series, const SleeveMesh& m, double dt) {
      add_in(c.windows, times, method, series, m, dt);
    };

    add(reference_method, "reference", c.reference_mesh, c.reference_dt);
    for (const Method& method : methods_) {
      if (!method.run_dynamic) continue;
      if (const std::string why = unsupported(method, scene.problem(c.reference_mesh, c.reference_dt, method.discretization));
          !why.empty()) {
        skip(c.name, method, why);
        continue;
      }
      for (const SleeveMesh& m : c.meshes) add(method, "mesh", m, c.mesh_dt);
      const bool dt_series = listed(c.dt_series_methods, method.name);
      if (dt_series)
        for (double dt : c.dts) add(method, "dt", c.dt_mesh, dt);
    }
    // The tolerance series, after the others (its runs at their tolerance, 1e-8, may be theirs).
    for (const ToleranceSetting& setting : c.tolerance_settings) {
      if (c.tolerances.empty()) break;
      const auto it = std::find_if(methods_.begin(), methods_.end(),
                                   [&](const Method& m) { return m.name == setting.method; });
      if (it == methods_.end() || !it->run_dynamic ||
          !unsupported(*it, scene.problem(c.reference_mesh, c.reference_dt, it->discretization)).empty())
        continue;
      const std::vector<ErrorWindow> windows = setting_windows(c, setting);
      const std::vector<double> run_times = all_sample_times(windows);
      const Outcome& tight = outcome(c, scene, run_times, *it, setting.mesh, setting.dt, c.tight_tolerance);
      for (double tolerance : c.tolerances)
        add_in(windows, run_times, *it, "tolerance", setting.mesh, setting.dt, tolerance, &tight);
      add_in(windows, run_times, *it, "tolerance", setting.mesh, setting.dt, c.tight_tolerance, &tight);
    }
  }

 private:
  // One untimed solve before a method's first timed static run, so that one-time start-up
  // (thread pools, allocator growth) is not charged to the first row.
  void warm_up(const Method& method, const Problem& problem, const std::vector<SurfaceSample>& points) {
    if (!warmed_up_.insert(method.name).second) return;
    try {
      method.solve_static(problem, points);
    } catch (const std::exception&) {
      // the timed run reports the failure
    }
  }

  static void fill_run(ConvergenceRow& row, const MethodRun& run) {
    row.vertices = run.vertices;
    row.dofs = run.dofs;
    row.steps = run.steps;
    row.wall_seconds = run.wall_seconds;
    row.solver_iterations = run.solver_iterations;
  }

  static std::string unsupported(const Method& method, const Problem& problem) {
    return method.unsupported ? method.unsupported(problem) : std::string();
  }

  void skip(const std::string& case_name, const Method& method, const std::string& why) const {
    log_line("case " + case_name + " method " + method.name + " skipped: " + why);
  }

  void log_line(const std::string& line) const {
    if (log_) log_(line);
  }

  // The post-buckling columns of a sleeve row: the run's end state against the reference's.
  static void fill_post_buckling(ConvergenceRow& row, const Outcome& o, const Outcome& reference) {
    row.elastic_energy = o.energy;
    row.reference_elastic_energy = reference.energy;
    if (o.energy && reference.energy)
      row.energy_error = std::abs(*o.energy - *reference.energy) / std::abs(*reference.energy);
    row.folds_circumferential = o.folds_circumferential;
    row.folds_axial = o.folds_axial;
    row.reference_folds_circumferential = reference.folds_circumferential;
    row.reference_folds_axial = reference.folds_axial;
    if (o.folds_circumferential && reference.folds_circumferential)
      row.fold_difference_circumferential = *o.folds_circumferential - *reference.folds_circumferential;
    if (o.folds_axial && reference.folds_axial)
      row.fold_difference_axial = *o.folds_axial - *reference.folds_axial;
  }

  // The tolerance-series columns of a row of run `o`: against its solver reference `tight` and
  // `tight` against the study's reference, in the row's window (`o` and `tight` sampled at
  // `times`, the reference at `reference_times`).
  static void fill_solver_error(ConvergenceRow& row, const Outcome& o, const Outcome& tight, const Outcome& reference,
                                const std::vector<double>& times, const std::vector<double>& reference_times,
                                const ErrorWindow& window) {
    if (!tight.failure.empty()) {
      if (row.note.empty()) row.note = "failed: the solver reference (tight tolerance) failed: " + tight.failure;
      return;
    }
    if (&o == &tight && row.note.empty())
      row.note = "the solver reference of this setting (solver error 0 by definition)";
    const std::vector<Eigen::MatrixX3d> u_tight = window_samples(tight.run.displacements, times, window);
    if (reference.failure.empty())
      row.discretization_error =
          relative_rms_difference(u_tight, window_samples(reference.run.displacements, reference_times, window));
    if (tight.energy && reference.energy)
      row.discretization_energy_error = std::abs(*tight.energy - *reference.energy) / std::abs(*reference.energy);
    row.solver_reference_folds_circumferential = tight.folds_circumferential;
    row.solver_reference_folds_axial = tight.folds_axial;
    if (!o.failure.empty()) return;
    row.solver_error = relative_rms_difference(window_samples(o.run.displacements, times, window), u_tight);
    if (o.energy && tight.energy)
      row.solver_energy_error = std::abs(*o.energy - *tight.energy) / std::abs(*tight.energy);
  }

  static bool listed(const std::vector<std::string>& names, const std::string& name) {
    return names.empty() || std::find(names.begin(), names.end(), name) != names.end();
  }

  static void mark_failed(ConvergenceRow& row, const std::string& why) {
    row.error = std::numeric_limits<double>::quiet_NaN();
    row.note = "failed: " + why;
  }

  void report(const ConvergenceRow& row) const {
    if (!log_) return;
    log_("case " + row.case_name + " method " + row.method + " setting " + row.setting +
         (row.window.empty() || row.window == "static" ? "" : " window " + row.window) + " error " +
         format_significant(row.error, 4) +
         (row.solver_error ? " solver error " + format_significant(*row.solver_error, 4) : std::string()) + " (" +
         format_fixed(row.wall_seconds, 2) + " s)" +
         (row.note.empty() ? "" : " [" + row.note + "]"));
  }

  // The run of `method` on mesh m at time step dt (with the linear solver's tolerance replaced if
  // one is given), computed once per case: runs with the same effective settings are one run.
  const Outcome& outcome(const SleeveStudyCase& c, const SleeveScene& scene, const std::vector<double>& times,
                         const Method& method, const SleeveMesh& m, double dt,
                         std::optional<double> tolerance = std::nullopt) {
    const Problem problem = scene.problem(m, dt, method.discretization, tolerance);
    const std::optional<double> effective = solver_tolerance(problem);
    const std::string key = method.name + " " + sleeve_setting(m, dt) + " tol=" +
                            (effective ? format_shortest(*effective) : std::string("direct")) + " t=" + join_times(times);
    if (auto it = cache_.find(key); it != cache_.end()) return it->second;
    const std::string id =
        run_id(c.name + "." + method.name + "." + std::to_string(m.segments) + "x" + std::to_string(m.rings) + ".dt" +
               format_shortest(dt) + ".tol" + (effective ? format_shortest(*effective) : std::string("direct")) +
               (times == all_sample_times(c) ? std::string() : ".t" + join_times(times)));
    return cache_.emplace(key, get(id, [&] { return compute(c, problem, times, method, effective); })).first->second;
  }

  // The outcome of run `id`: computed by `compute`, or as the source says.
  template <class Compute>
  Outcome get(const std::string& id, const Compute& compute) {
    switch (source_.mode) {
      case RunSource::Mode::compute:
        return compute();
      case RunSource::Mode::collect: {
        if (std::find(source_.ids.begin(), source_.ids.end(), id) == source_.ids.end()) source_.ids.push_back(id);
        Outcome o;
        if (id == source_.target && !source_.target_result) {
          o = compute();
          source_.target_result = run_json(o);
        } else {
          o.failure = "planned";
        }
        return o;
      }
      case RunSource::Mode::stored: {
        const auto it = source_.stored->find(id);
        if (it == source_.stored->end()) {
          Outcome missing;
          missing.failure = "run " + id + " did not finish";
          return missing;
        }
        try {
          return outcome_of(it->second);
        } catch (const std::exception& e) {
          throw std::runtime_error("the result of run " + id + ": " + e.what());
        }
      }
    }
    return compute();
  }

  Outcome compute(const SleeveStudyCase& c, const Problem& problem, const std::vector<double>& times,
                  const Method& method, std::optional<double> effective) {
    Outcome o;
    o.tolerance = effective;
    o.h = mesh_size(problem.mesh);
    const std::vector<SurfaceSample> points =
        locate_points(problem.mesh.triangles, cylinder_chart(problem.mesh.vertices),
                      cylinder_parameter_grid(c.grid_theta, c.grid_s), 2 * std::numbers::pi);
    try {
      o.run = method.run_dynamic(problem, points, times);
      if (std::isfinite(o.run.final_elastic_energy)) o.energy = o.run.final_elastic_energy;
      if (o.run.final_surface_triangles.size() > 0) {
        const SleeveFolds folds = count_sleeve_folds(o.run.final_surface, o.run.final_surface_triangles, c.fold_axis);
        o.folds_circumferential = folds.circumferential_median;
        o.folds_axial = folds.axial.median_count;
      }
      // The surfaces are large (kFoldSurfaceLevels); only the counts are kept.
      o.run.final_surface.resize(0, 3);
      o.run.final_surface_triangles.clear();
    } catch (const std::exception& e) {
      o.failure = e.what();
    }
    return o;
  }

  const std::vector<Method>& methods_;
  const std::vector<Method> registered_ = convergence_methods();
  const LogFn& log_;
  RunSource& source_;
  std::map<std::string, Outcome> cache_;
  std::set<std::string> warmed_up_;  // methods that have had their untimed static solve
};

// Observed orders between consecutive rows of the same case, method and series.
void fill_orders(std::vector<ConvergenceRow>& rows) {
  std::map<std::string, const ConvergenceRow*> previous;
  for (ConvergenceRow& row : rows) {
    if (row.series != "mesh" && row.series != "dt") continue;
    const std::string key = row.case_name + "\n" + row.method + "\n" + row.series + "\n" + row.window;
    if (auto it = previous.find(key); it != previous.end()) {
      const ConvergenceRow& p = *it->second;
      const double x0 = row.series == "dt" ? p.dt : p.h, x1 = row.series == "dt" ? row.dt : row.h;
      if (p.error > 0 && row.error > 0 && std::isfinite(p.error) && std::isfinite(row.error) && x0 > 0 && x1 > 0 &&
          x0 != x1)
        row.order = std::log(p.error / row.error) / std::log(x0 / x1);
    }
    previous[key] = &row;
  }
}

}  // namespace

Method loop_subdivision_method(const std::string& name, Quadrature rule) {
  Method m;
  m.name = name;
  m.description = std::string("Loop subdivision shell element, ") + to_string(rule) + " quadrature";
  m.discretization = "loop_kl";
  m.solve_static = [rule](Problem problem, const std::vector<SurfaceSample>& points) {
    problem.method = "loop_kl";
    problem.quadrature = rule;
    return solve_static_run(problem, points);
  };
  m.run_dynamic = [rule](Problem problem, const std::vector<SurfaceSample>& points, const std::vector<double>& times) {
    problem.method = "loop_kl";
    problem.quadrature = rule;
    return run_dynamic_simulation(std::move(problem), points, times);
  };
  return m;
}

Method flat_baseline_method(const std::string& discretization) {
  if (discretization != "linear_fe" && discretization != "mass_spring")
    throw std::invalid_argument("flat_baseline_method: unknown baseline \"" + discretization +
                                "\" (known: linear_fe, mass_spring)");
  Method m;
  m.name = discretization;
  m.discretization = discretization;
  m.description = discretization == "linear_fe"
                      ? "flat corotated membrane triangles with dihedral-angle hinge bending (docs/linear_fe.md)"
                      : "edge and bending springs on the flat triangles, dynamic only (docs/mass_spring.md)";
  m.unsupported = [discretization](const Problem& problem) { return flat_baseline_unsupported(discretization, problem); };
  if (discretization == "linear_fe")
    m.solve_static = [discretization](Problem problem, const std::vector<SurfaceSample>& points) {
      problem.method = discretization;
      return solve_static_run(problem, points);
    };
  m.run_dynamic = [discretization](Problem problem, const std::vector<SurfaceSample>& points,
                                   const std::vector<double>& times) {
    problem.method = discretization;
    return run_dynamic_simulation(std::move(problem), points, times);
  };
  return m;
}

std::vector<Method> convergence_methods() {
  return {
      loop_subdivision_method("loop_one_point", Quadrature::one_point),
      loop_subdivision_method("loop_three_point", Quadrature::three_point),
      flat_baseline_method("linear_fe"),
      flat_baseline_method("mass_spring"),
  };
}

ConvergencePlan full_convergence_plan(const std::filesystem::path& scenes_dir) {
  ConvergencePlan plan;
  for (const AnalyticPlate& plate : kAnalyticPlates) plan.plates.push_back({plate, {8, 16, 32, 64, 128}});
  // Segments × rings keep the shipped sleeve's aspect (26 × 19: rings − 1 ≈ 0.69 · segments);
  // segments are even so that the gravity sleeve's pegs at θ = 0 and π are vertices. The mesh
  // series runs at the reference time step and the time-step series on the reference mesh, so
  // each isolates one source of error (the reference run itself shows up in both with error 0).
  const std::vector<SleeveMesh> meshes = {{14, 11}, {20, 15}, {26, 19}, {40, 29}, {52, 37}};
  // "early" ends before the first buckling bifurcation of each scene (measured at 52 × 37:
  // docs/convergence.md); "long" runs well past it. Times are multiples of every time step.
  const std::vector<double> long_window = {0.04, 0.08, 0.12, 0.16, 0.2};
  const std::pair<const char*, std::vector<double>> scenes[] = {
      {"sleeve_gravity", {0.008, 0.016, 0.024, 0.032}},
      {"sleeve_twist", {0.008, 0.016, 0.024}},
      {"sleeve_compress", {0.004, 0.008}},
  };
  for (const auto& [name, early] : scenes) {
    SleeveStudyCase c;
    c.name = name;
    c.scene = scenes_dir / (std::string(name) + ".json");
    c.windows = {{"early", early}, {"long", long_window}};
    c.meshes = meshes;
    c.mesh_dt = 5e-4;
    c.dt_mesh = meshes.back();
    c.dts = {4e-3, 2e-3, 1e-3, 5e-4};
    // The baselines run the mesh series only (their 52 × 37 runs are the study's most expensive:
    // docs/convergence.md, "Run times").
    c.dt_series_methods = {"loop_one_point", "loop_three_point"};
    c.reference_mesh = meshes.back();
    c.reference_dt = 5e-4;
    // The tolerance series with the scenes' own rule (one-point) at their own time step (1 ms): on
    // the shipped mesh (what users run) and on the reference mesh (a finer mesh has a smaller
    // discretisation error and a worse-conditioned system; there the 1e-8 run is the time-step
    // series'). The candidates 1e-2 … 1e-8 (the other series' tolerance), one more baseline run at
    // 1e-10 and the tight run (ToleranceRule, docs/convergence.md "Solver tolerance").
    c.tolerances = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10};
    c.tight_tolerance = 1e-12;
    c.tolerance_settings = {{"loop_one_point", {26, 19}, 1e-3, {}}, {"loop_one_point", meshes.back(), 1e-3, {}}};
    // The timing scene sleeve_compress_2542 is this compression on 62 × 41 at 0.01 s: finer than
    // the reference mesh and at ten times its time step, where the relative-residual tolerance
    // was not yet measured. Its step divides only the long window's times.
    if (std::string(name) == "sleeve_compress")
      c.tolerance_settings.push_back({"loop_one_point", {62, 41}, 1e-2, {"long"}});
    plan.sleeves.push_back(c);
  }
  return plan;
}

ConvergencePlan quick_convergence_plan(const std::filesystem::path& scenes_dir) {
  ConvergencePlan plan;
  plan.plates.push_back({kAnalyticPlates[0], {4, 8, 16}});
  SleeveStudyCase c;
  c.name = "sleeve_twist";
  c.scene = scenes_dir / "sleeve_twist.json";
  c.windows = {{"early", {0.01, 0.02}}};
  c.grid_theta = 16;
  c.grid_s = 8;
  c.meshes = {{8, 6}, {12, 9}};
  c.mesh_dt = 2e-3;
  c.dt_mesh = {12, 9};
  c.dts = {1e-2, 5e-3, 2e-3};
  c.dt_series_methods = {"loop_one_point", "loop_three_point"};  // as the full plan
  c.reference_mesh = {16, 11};
  c.reference_dt = 1e-3;
  // Candidates 1e-2, 1e-3, 1e-5, 1e-8 (the last the other series': its run is the mesh series'), one
  // more baseline run and the tight run, with both Loop rules at the mesh series' time step.
  c.tolerances = {1e-2, 1e-3, 1e-5, 1e-8, 1e-10};
  c.tight_tolerance = 1e-12;
  c.tolerance_settings = {{"loop_one_point", {12, 9}, 2e-3, {}}, {"loop_three_point", {12, 9}, 2e-3, {}}};
  plan.sleeves.push_back(c);
  return plan;
}

namespace {

std::vector<ConvergenceRow> run_with(const ConvergencePlan& plan, const std::vector<Method>& methods, const LogFn& log,
                                     RunSource& source) {
  std::vector<ConvergenceRow> rows;
  StudyRunner runner(methods, log, source);
  for (const PlateStudyCase& c : plan.plates) runner.run_plate(c, rows);
  for (const SleeveStudyCase& c : plan.sleeves) runner.run_sleeve(c, rows);
  fill_orders(rows);
  return rows;
}

}  // namespace

std::vector<ConvergenceRow> run_convergence(const ConvergencePlan& plan, const std::vector<Method>& methods,
                                            const LogFn& log) {
  RunSource source;
  return run_with(plan, methods, log, source);
}

std::vector<std::string> convergence_run_ids(const ConvergencePlan& plan, const std::vector<Method>& methods) {
  RunSource source;
  source.mode = RunSource::Mode::collect;
  run_with(plan, methods, LogFn(), source);
  return source.ids;
}

std::string run_convergence_run(const ConvergencePlan& plan, const std::vector<Method>& methods, const std::string& id,
                                const LogFn& log) {
  RunSource source;
  source.mode = RunSource::Mode::collect;
  source.target = id;
  run_with(plan, methods, LogFn(), source);
  if (!source.target_result) throw std::invalid_argument("the convergence study's plan has no run \"" + id + "\"");
  if (log) {
    const Outcome o = outcome_of(*source.target_result);
    log(id + ": " + (o.failure.empty() ? "done" : "failed: " + o.failure) + " (" + format_fixed(o.run.wall_seconds, 2) +
        " s)");
  }
  return *source.target_result;
}

std::vector<ConvergenceRow> gather_convergence(const ConvergencePlan& plan, const std::vector<Method>& methods,
                                               const std::map<std::string, std::string>& results, const LogFn& log) {
  RunSource source;
  source.mode = RunSource::Mode::stored;
  source.stored = &results;
  return run_with(plan, methods, log, source);
}

const std::vector<std::string>& results_csv_columns() {
  static const std::vector<std::string> columns = {
      "case",     "method", "series",          "window",              "setting",   "vertices", "dofs",
      "h",        "dt",     "steps",           "wall_seconds",        "solver_iterations",     "error",
      "order",    "quantity", "value",         "reference_value",     "reference_precision",   "reference",
      "note",     "elastic_energy", "reference_elastic_energy", "energy_error", "folds_circumferential", "folds_axial",
      "reference_folds_circumferential", "reference_folds_axial", "fold_difference_circumferential",
      "fold_difference_axial", "tolerance", "solver_error", "discretization_error", "solver_energy_error",
      "discretization_energy_error", "solver_reference_folds_circumferential", "solver_reference_folds_axial"};
  return columns;
}

namespace {

// An optional number: empty when absent, else the shortest exact form ("nan" for NaN).
std::string optional_number(const std::optional<double>& x) { return x ? format_shortest(*x) : std::string(); }

}  // namespace

void write_results_csv(std::ostream& out, const std::vector<ConvergenceRow>& rows) {
  const std::vector<std::string>& columns = results_csv_columns();
  for (size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << columns[i];
  out << '\n';
  for (const ConvergenceRow& r : rows)
    out << csv_field(r.case_name) << ',' << csv_field(r.method) << ',' << csv_field(r.series) << ','
        << csv_field(r.window) << ',' << csv_field(r.setting) << ',' << r.vertices << ',' << r.dofs << ',' << format_shortest(r.h) << ','
        << format_shortest(r.dt) << ',' << r.steps << ',' << format_fixed(r.wall_seconds, 6) << ','
        << r.solver_iterations << ',' << format_shortest(r.error) << ','
        << (r.order ? format_shortest(*r.order) : "") << ',' << csv_field(r.quantity) << ','
        << format_shortest(r.value) << ',' << format_shortest(r.reference_value) << ','
        << format_shortest(r.reference_precision) << ',' << csv_field(r.reference)
        << ',' << csv_field(r.note) << ',' << optional_number(r.elastic_energy) << ','
        << optional_number(r.reference_elastic_energy) << ',' << optional_number(r.energy_error) << ','
        << optional_number(r.folds_circumferential) << ',' << optional_number(r.folds_axial) << ','
        << optional_number(r.reference_folds_circumferential) << ',' << optional_number(r.reference_folds_axial) << ','
        << optional_number(r.fold_difference_circumferential) << ',' << optional_number(r.fold_difference_axial)
        << ',' << optional_number(r.tolerance) << ',' << optional_number(r.solver_error) << ','
        << optional_number(r.discretization_error) << ',' << optional_number(r.solver_energy_error) << ','
        << optional_number(r.discretization_energy_error) << ','
        << optional_number(r.solver_reference_folds_circumferential) << ','
        << optional_number(r.solver_reference_folds_axial) << '\n';
}

void write_results_markdown(std::ostream& out, const std::vector<ConvergenceRow>& rows) {
  out << "| case | method | series | window | setting | vertices | dofs | dt [s] | wall [s] | solver iterations | "
         "error | order | energy error | folds circ. / axial (ref.) | tolerance | solver error | "
         "discretisation error |\n"
         "|---|---|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n";
  auto folds = [](const ConvergenceRow& r) -> std::string {
    if (!r.folds_circumferential && !r.folds_axial) return "";
    auto count = [](const std::optional<double>& x) { return x ? format_shortest(*x) : std::string("–"); };
    return count(r.folds_circumferential) + " / " + count(r.folds_axial) + " (" +
           count(r.reference_folds_circumferential) + " / " + count(r.reference_folds_axial) + ")";
  };
  auto significant = [](const std::optional<double>& x) { return x ? format_significant(*x, 3) : std::string(); };
  for (const ConvergenceRow& r : rows)
    out << "| " << markdown_cell(r.case_name) << " | " << markdown_cell(r.method) << " | " << r.series << " | "
        << markdown_cell(r.window) << " | " << markdown_cell(r.setting) << " | " << r.vertices << " | " << r.dofs << " | "
        << (r.dt > 0 ? format_shortest(r.dt) : "–") << " | " << format_fixed(r.wall_seconds, 3) << " | "
        << r.solver_iterations << " | " << format_significant(r.error, 3) << " | "
        << (r.order ? format_fixed(*r.order, 2) : "") << " | "
        << (r.energy_error ? format_significant(*r.energy_error, 3) : "") << " | " << folds(r) << " | "
        << (r.tolerance ? format_shortest(*r.tolerance) : "") << " | " << significant(r.solver_error) << " | "
        << significant(r.discretization_error) << " |\n";
}

}  // namespace clothsim

namespace clothsim {

ToleranceSummary summarize_tolerance_series(const std::vector<ConvergenceRow>& rows, const ToleranceRule& rule) {
  ToleranceSummary summary;
  summary.rule = rule;
  // The tolerance rows of each setting, in the order of the rows.
  std::vector<std::vector<const ConvergenceRow*>> groups;
  std::map<std::string, size_t> group_of;
  for (const ConvergenceRow& r : rows) {
    if (r.series != "tolerance" || !r.tolerance) continue;
    const std::string key = r.case_name + "\n" + r.method + "\n" + r.setting.substr(0, r.setting.find(" tol="));
    const auto [it, added] = group_of.emplace(key, groups.size());
    if (added) groups.emplace_back();
    groups[it->second].push_back(&r);
  }
  bool complete = !groups.empty(), any_resolved = false;
  double recommended = std::numeric_limits<double>::infinity();
  for (const std::vector<const ConvergenceRow*>& group : groups) {
    ToleranceSettingCheck check;
    check.case_name = group.front()->case_name;
    check.method = group.front()->method;
    check.setting = group.front()->setting.substr(0, group.front()->setting.find(" tol="));
    check.dt = group.front()->dt;
    std::vector<std::string> windows;
    std::set<double> tolerances;
    for (const ConvergenceRow* r : group) {
      tolerances.insert(*r->tolerance);
      if (std::find(windows.begin(), windows.end(), r->window) == windows.end()) windows.push_back(r->window);
    }
    check.tight_tolerance = *tolerances.begin();
    for (auto it = tolerances.rbegin(); it != tolerances.rend(); ++it)
      if (*it >= rule.baseline && *it != check.tight_tolerance) check.candidates.push_back(*it);
    auto is_baseline = [&](double t) { return t <= rule.baseline || t == check.tight_tolerance; };
    auto row_at = [&](double t, const std::string& window) -> const ConvergenceRow* {
      for (const ConvergenceRow* r : group)
        if (*r->tolerance == t && r->window == window) return r;
      return nullptr;
    };
    for (const std::string& window : windows) {
      ToleranceWindowCheck w;
      w.window = window;
      const ConvergenceRow* tight = row_at(check.tight_tolerance, window);
      w.discretization_error = tight && tight->discretization_error ? *tight->discretization_error
                                                                    : std::numeric_limits<double>::quiet_NaN();
      for (double t : tolerances) {
        if (!is_baseline(t) || t == check.tight_tolerance) continue;
        const ConvergenceRow* r = row_at(t, window);
        const double e = r && r->solver_error ? *r->solver_error : std::numeric_limits<double>::infinity();
        w.baseline_solver_error = std::max(w.baseline_solver_error, e);
        w.amplification = std::max(w.amplification, e / t);
      }
      const double limit = rule.ratio * w.discretization_error;  // NaN: no candidate passes
      w.resolved = w.amplification <= rule.max_amplification;
      // Tight to loose: the loosest candidate before the first that fails.
      for (auto it = check.candidates.rbegin(); it != check.candidates.rend(); ++it) {
        const ConvergenceRow* r = row_at(*it, window);
        if (!r || !r->solver_error || !(*r->solver_error <= limit)) break;
        w.loosest = *it;
      }
      if (w.resolved) {
        any_resolved = true;
        if (w.loosest) recommended = std::min(recommended, *w.loosest);
        else complete = false;
      }
      check.windows.push_back(w);
    }
    // The end state (the same in every window's rows: take the first window's).
    auto widen = [](double& lo, double& hi, const std::optional<double>& x) {
      if (!x) return;
      lo = std::isnan(lo) ? *x : std::min(lo, *x);
      hi = std::isnan(hi) ? *x : std::max(hi, *x);
    };
    for (double t : tolerances) {
      if (!is_baseline(t)) continue;
      const ConvergenceRow* r = row_at(t, windows.front());
      if (!r) continue;
      if (t != check.tight_tolerance && r->solver_energy_error)
        check.energy_spread = std::isnan(check.energy_spread) ? *r->solver_energy_error
                                                              : std::max(check.energy_spread, *r->solver_energy_error);
      widen(check.folds_circumferential_min, check.folds_circumferential_max, r->folds_circumferential);
      widen(check.folds_axial_min, check.folds_axial_max, r->folds_axial);
    }
    auto inside = [](const std::optional<double>& x, double lo, double hi) {
      return std::isnan(lo) || (x && *x >= lo && *x <= hi);
    };
    for (double t : check.candidates) {
      if (t <= rule.baseline) continue;
      const ConvergenceRow* r = row_at(t, windows.front());
      // The energy may differ from the tight run's by the spread, or (an end state before buckling,
      // where the spread is round-off) by ratio × the setting's discretisation error of the energy.
      double energy_bound = check.energy_spread;
      if (r && r->discretization_energy_error)
        energy_bound = std::max(energy_bound, rule.ratio * *r->discretization_energy_error);
      const bool energy_ok =
          std::isnan(energy_bound) || (r && r->solver_energy_error && *r->solver_energy_error <= energy_bound);
      if (!r || !std::isfinite(r->error) || !energy_ok ||
          !inside(r->folds_circumferential, check.folds_circumferential_min, check.folds_circumferential_max) ||
          !inside(r->folds_axial, check.folds_axial_min, check.folds_axial_max))
        check.outside_spread.push_back(t);
    }
    summary.settings.push_back(std::move(check));
  }
  if (complete && any_resolved) summary.recommended = recommended;
  return summary;
}

void write_tolerance_summary_markdown(std::ostream& out, const ToleranceSummary& summary) {
  if (summary.settings.empty()) return;
  const ToleranceRule& rule = summary.rule;
  auto range = [](double lo, double hi) {
    if (std::isnan(lo)) return std::string("–");
    return lo == hi ? format_shortest(lo) : format_shortest(lo) + "–" + format_shortest(hi);
  };
  auto list = [](const std::vector<double>& xs) {
    std::string s;
    for (double x : xs) s += (s.empty() ? "" : ", ") + format_shortest(x);
    return s.empty() ? std::string("none") : s;
  };
  out << "\n## Solver tolerance\n\n"
         "Rule (docs/convergence.md, \"Solver tolerance\"): the loosest tolerance whose solver error (against the "
         "setting's tight run), and that of every tighter candidate, is at most "
      << format_shortest(rule.ratio)
      << " × the discretisation error (the tight run against the reference), in every resolved window. Baseline "
         "runs: tolerances up to "
      << format_shortest(rule.baseline) << " and the tight run; a window is resolved when none of them has a solver "
      << "error above " << format_shortest(rule.max_amplification)
      << " × its tolerance (after buckling, perturbations grow by orders of magnitude).\n\n"
         "| case | method | setting | window | discretisation error | baseline runs' solver error | "
         "largest solver error / tolerance | resolved | loosest passing |\n|---|---|---|---|--:|--:|--:|---|--:|\n";
  for (const ToleranceSettingCheck& s : summary.settings)
    for (const ToleranceWindowCheck& w : s.windows)
      out << "| " << markdown_cell(s.case_name) << " | " << markdown_cell(s.method) << " | " << markdown_cell(s.setting)
          << " | " << markdown_cell(w.window) << " | " << format_significant(w.discretization_error, 3) << " | "
          << format_significant(w.baseline_solver_error, 3) << " | " << format_significant(w.amplification, 2) << " | "
          << (w.resolved ? "yes" : "no") << " | "
          << (w.loosest ? format_shortest(*w.loosest) : std::string("none")) << " |\n";
  out << "\nEnd state (post-buckling measures) of the candidates looser than the baseline against the spread of "
         "the baseline runs:\n\n"
         "| case | method | setting | energy spread | folds circ. | folds axial | candidates outside the spread |\n"
         "|---|---|---|--:|--:|--:|---|\n";
  for (const ToleranceSettingCheck& s : summary.settings)
    out << "| " << markdown_cell(s.case_name) << " | " << markdown_cell(s.method) << " | " << markdown_cell(s.setting)
        << " | " << format_significant(s.energy_spread, 3) << " | "
        << range(s.folds_circumferential_min, s.folds_circumferential_max) << " | "
        << range(s.folds_axial_min, s.folds_axial_max) << " | " << list(s.outside_spread) << " |\n";
  out << "\nRecommended tolerance by the rule: "
      << (summary.recommended ? format_shortest(*summary.recommended)
                              : std::string("none (no resolved window, or one in which no candidate passes)"))
      << "\n";
}

}  // namespace clothsim

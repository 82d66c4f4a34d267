#include "sim/study/stability.hpp"

#include "sim/dynamics/simulator.hpp"
#include "sim/scene/scene.hpp"
#include "sim/study/report_format.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace clothsim {

namespace {

using Json = nlohmann::ordered_json;

constexpr double kRadius = 0.05;  // [m]
constexpr double kLength = 0.2;   // [m]

// ---------------------------------------------------------------------------------------------
// The base sleeve and its variants.

Json vec3(double x, double y, double z) { return Json::array({x, y, z}); }

// Vertices within 0.1 mm of the plane y = `y` (a rim of the sleeve).
Json rim(double y) {
  return Json{{"box", Json::array({vec3(-1, y - 1e-4, -1), vec3(1, y + 1e-4, 1)})}};
}

Json twist_motion(double angle_deg, double duration) {
  return Json::array({Json{{"type", "rotate"}, {"axis", vec3(0, 1, 0)}, {"center", vec3(0, 0, 0)},
                           {"angle_deg", angle_deg}, {"start", 0.0}, {"end", duration}}});
}

// The base: a cotton sleeve (R = 5 cm, L = 20 cm, 26 × 19 = 494 vertices) hanging from its top
// rim (held in x, y, z) under gravity; its bottom rim is held in x and z but free to slide along
// the axis, and turns by 90° about the axis in 0.5 s, then stays. 0.6 s at dt = 1 ms, stiffness
// damping 1e-3 s, PCG (block Jacobi) to 1e-8, one linear solve per step.
Json base_scene() {
  Json s;
  s["name"] = "base";
  s["description"] = "";
  s["analysis"] = "dynamic";
  s["mesh"] = Json{{"primitive", "cylinder"}, {"radius", kRadius}, {"length", kLength}, {"segments", 26}, {"rings", 19}};
  s["material"] = Json{{"preset", "cotton"}};
  s["boundary"] = Json::array({
      Json{{"select", rim(kLength)}, {"fix", Json::array({"x", "y", "z"})}},
      Json{{"select", rim(0.0)}, {"fix", Json::array({"x", "z"})}, {"motion", twist_motion(90.0, 0.5)}},
  });
  s["loads"] = Json{{"gravity", vec3(0, -9.81, 0)}};
  s["time"] = Json{{"dt", 1e-3}, {"end", 0.6}, {"output_fps", 30}};
  s["damping"] = Json{{"stiffness", 1e-3}, {"mass", 0.0}};
  s["solver"] = Json{{"type", "pcg"},
                     {"tolerance", 1e-8},
                     {"max_iterations", 2000},
                     {"newton_iterations", 1},
                     {"preconditioner", "block_jacobi"}};
  s["corotational"] = true;
  s["probes"] = Json::array({Json{{"name", "middle"}, {"at", vec3(kRadius, kLength / 2, 0)}},
                             Json{{"name", "bottom_rim"}, {"at", vec3(kRadius, 0, 0)}}});
  return s;
}

// Modifiers, each changing one kind of parameter of a scene.
void set_stretch_modulus(Json& s, double et) { s["material"]["stretch_modulus"] = et; }
void set_metal(Json& s) { s["material"] = Json{{"preset", "metal"}}; }
// A solid sheet of Young's modulus 1e7 Pa and density 250 kg/m³ (cotton's E·t and ρ_A at its
// measured 0.5 mm), so E·t, B = E t³/12 and ρ_A all follow the thickness.
void set_thickness(Json& s, double t) {
  s["material"] = Json{{"youngs_modulus", 1e7}, {"poisson_ratio", 0.25}, {"thickness", t}, {"density", 250.0}};
}
void set_poisson(Json& s, double nu) { s["material"]["poisson_ratio"] = nu; }
void set_dt(Json& s, double dt) { s["time"]["dt"] = dt; }
void set_end(Json& s, double end) { s["time"]["end"] = end; }
void set_twist(Json& s, double angle_deg, double duration) {
  s["boundary"][1]["motion"] = twist_motion(angle_deg, duration);
  set_end(s, duration + 0.1);
}
// The bottom rim held in x, y, z and pushed up along the axis by `fraction` of the length.
void set_compression(Json& s, double fraction, double duration) {
  s["boundary"][1]["fix"] = Json::array({"x", "y", "z"});
  s["boundary"][1]["motion"] = Json::array({Json{{"type", "translate"},
                                                 {"displacement", vec3(0, fraction * kLength, 0)},
                                                 {"start", 0.0},
                                                 {"end", duration}}});
  set_end(s, duration + 0.1);
}
// No supports and no gravity: a free sleeve set spinning rigidly about `axis` through its centre.
void set_spin(Json& s, const Json& omega) {
  s["boundary"] = Json::array();
  s["loads"] = Json{{"gravity", vec3(0, 0, 0)}};
  s["initial"] = Json{{"angular_velocity", omega}, {"center", vec3(0, kLength / 2, 0)}};
}
void set_gravity_factor(Json& s, double factor) { s["loads"]["gravity"] = vec3(0, -9.81 * factor, 0); }
void set_mesh(Json& s, int segments, int rings) {
  s["mesh"]["segments"] = segments;
  s["mesh"]["rings"] = rings;
}
void set_cholesky(Json& s) { s["solver"]["preconditioner"] = "cholesky"; }
void set_newton(Json& s, int iterations) { s["solver"]["newton_iterations"] = iterations; }

// Solver settings a case needs beyond the base's, and why.
struct Remedy {
  std::string text;                  // e.g. "newton_iterations = 2 (...)"
  std::function<void(Json&)> apply;  // sets them in a scene
  bool needed = true;                // needed to pass (the case also runs without it), or speed only
  bool systematic = true;            // without it the case fails whatever the round-off
};

struct Builder {
  std::vector<StabilityCase> cases;
  void add(const std::string& name, const std::string& group, const std::string& description, bool quick,
           const std::function<void(Json&)>& modify, const Remedy& remedy = {}) {
    Json s = base_scene();
    modify(s);
    s["name"] = name;
    s["description"] = "Stability study case " + name + " (docs/stability.md): " + description +
                       ". Base: cotton sleeve R = 5 cm, L = 20 cm, 26 x 19 = 494 vertices hanging from its top rim "
                       "under gravity, bottom rim held in x and z (free along the axis) and turned 90 deg about the "
                       "axis in 0.5 s; 0.6 s at dt = 1 ms, stiffness damping 1e-3 s, PCG (block Jacobi) to 1e-8, one "
                       "linear solve per step.";
    StabilityCase c{name, group, description, "", remedy.text, "", quick};
    if (remedy.apply) {
      if (remedy.needed) c.without_remedy_json = s.dump(2) + "\n";
      c.fails_without_remedy = remedy.needed && remedy.systematic;
      remedy.apply(s);
      s["description"] = s["description"].get<std::string>() + " Solver settings beyond the base: " + remedy.text + ".";
    }
    c.scene_json = s.dump(2) + "\n";
    cases.push_back(std::move(c));
  }
};

}  // namespace

std::vector<StabilityCase> stability_cases(bool quick_only) {
  // Why each remedy is needed: docs/stability.md, "Remedies".
  const Remedy spin_newton{
      "newton_iterations = 2 (fast rigid rotation: with one solve the vertices move along chords and the sleeve "
      "is stretched by (omega dt)^2 / 2 each step); preconditioner = cholesky (speed)",
      [](Json& s) { set_newton(s, 2); set_cholesky(s); }};
  const Remedy snap_newton{
      "newton_iterations = 2 (the stiff sleeve snaps into folds within one 10 ms step; one solve with the "
      "rotations frozen overshoots by an amount that depends on round-off)",
      [](Json& s) { set_newton(s, 2); }, true, false};
  const Remedy twist_newton{
      "newton_iterations = 8 (the rim turns 36 deg per step: with the rotations frozen the elements next to it "
      "are torn to a strain of 2.3; the iteration converges slowly)",
      [](Json& s) { set_newton(s, 8); }};
  const Remedy fine_speed{"preconditioner = cholesky (speed: block Jacobi needs hundreds of iterations on 10k vertices)",
                          [](Json& s) { set_cholesky(s); }, false};

  Builder b;
  b.add("base", "base", "the base sleeve: cotton, E t = 5000 N/m, nu = 0.25, dt = 1 ms", false, [](Json&) {});
  // Materials: E·t from cotton through the paper's metal to 1e7 N/m (cotton's B, ν, ρ_A).
  b.add("material_Et_1e5", "material", "E t = 1e5 N/m (the paper's metal stretch modulus), cotton bending and mass",
        false, [](Json& s) { set_stretch_modulus(s, 1e5); });
  b.add("material_Et_1e7", "material", "E t = 1e7 N/m, cotton bending and mass", false,
        [](Json& s) { set_stretch_modulus(s, 1e7); });
  b.add("material_metal", "material", "the paper's metal preset: E t = 1e5 N/m, nu = 0.05, B = 8.3e-3 N m, 0.5 kg/m2",
        false, [](Json& s) { set_metal(s); });
  // Thickness of a solid sheet (E = 1e7 Pa, 250 kg/m³).
  b.add("thickness_0.1mm", "thickness", "solid sheet 0.1 mm thick (E = 1e7 Pa, 250 kg/m3: E t = 1000 N/m)", false,
        [](Json& s) { set_thickness(s, 1e-4); });
  b.add("thickness_1mm", "thickness", "solid sheet 1 mm thick (E t = 1e4 N/m, B = 8.3e-4 N m)", false,
        [](Json& s) { set_thickness(s, 1e-3); });
  b.add("thickness_5mm", "thickness", "solid sheet 5 mm thick (E t = 5e4 N/m, B = 0.10 N m, 1.25 kg/m2)", false,
        [](Json& s) { set_thickness(s, 5e-3); });
  // Poisson ratio.
  b.add("nu_0", "poisson", "nu = 0", false, [](Json& s) { set_poisson(s, 0.0); });
  b.add("nu_0.49", "poisson", "nu = 0.49", false, [](Json& s) { set_poisson(s, 0.49); });
  // Time step.
  b.add("dt_1e-4", "time step", "dt = 0.1 ms", false, [](Json& s) { set_dt(s, 1e-4); });
  b.add("dt_1e-2", "time step", "dt = 10 ms", true, [](Json& s) { set_dt(s, 1e-2); }, snap_newton);
  b.add("dt_5e-2", "time step", "dt = 50 ms", true, [](Json& s) { set_dt(s, 5e-2); });
  // Twist of the bottom rim (over 1 s).
  b.add("twist_180", "twist", "bottom rim turned 180 deg in 1 s", false, [](Json& s) { set_twist(s, 180, 1.0); });
  b.add("twist_360", "twist", "bottom rim turned 360 deg in 1 s", false, [](Json& s) { set_twist(s, 360, 1.0); });
  b.add("twist_720", "twist", "bottom rim turned 720 deg in 1 s", false, [](Json& s) { set_twist(s, 720, 1.0); });
  // Axial compression (bottom rim held in x, y, z and pushed towards the top rim in 0.5 s).
  b.add("compress_30", "compression", "bottom rim held and pushed up by 30 % of the length in 0.5 s", false,
        [](Json& s) { set_compression(s, 0.3, 0.5); });
  b.add("compress_60", "compression", "bottom rim held and pushed up by 60 % of the length in 0.5 s", false,
        [](Json& s) { set_compression(s, 0.6, 0.5); });
  // Rigid spin.
  b.add("spin_50", "spin", "free sleeve (no supports, no gravity) spinning at 50 rad/s about a transverse axis", false,
        [](Json& s) { set_spin(s, vec3(50, 0, 0)); });
  b.add("spin_50_axial", "spin", "free sleeve (no supports, no gravity) spinning at 50 rad/s about its axis", false,
        [](Json& s) { set_spin(s, vec3(0, 50, 0)); }, spin_newton);
  // Gravity.
  b.add("gravity_x10", "gravity", "gravity x 10 (98.1 m/s2)", false, [](Json& s) { set_gravity_factor(s, 10); });
  // Meshes.
  b.add("mesh_coarse_90", "mesh", "coarse mesh: 10 x 9 = 90 vertices", true, [](Json& s) { set_mesh(s, 10, 9); });
  b.add("mesh_fine_10k", "mesh", "fine mesh: 126 x 80 = 10080 vertices; the first 0.1 s (rim turned 18 deg)", false,
        [](Json& s) { set_mesh(s, 126, 80); set_end(s, 0.1); }, fine_speed);
  // Combinations of extremes.
  b.add("material_Et_1e7_dt_5e-2", "combination", "E t = 1e7 N/m with dt = 50 ms", true,
        [](Json& s) { set_stretch_modulus(s, 1e7); set_dt(s, 5e-2); });
  b.add("twist_720_dt_5e-2", "combination", "bottom rim turned 720 deg in 1 s with dt = 50 ms", true,
        [](Json& s) { set_twist(s, 720, 1.0); set_dt(s, 5e-2); }, twist_newton);
  b.add("compress_60_dt_5e-2", "combination", "pushed up by 60 % in 0.5 s with dt = 50 ms", true,
        [](Json& s) { set_compression(s, 0.6, 0.5); set_dt(s, 5e-2); });
  b.add("compress_60_metal", "combination", "the metal preset pushed up by 60 % in 0.5 s", false,
        [](Json& s) { set_metal(s); set_compression(s, 0.6, 0.5); });
  b.add("spin_50_dt_1e-2", "combination", "free sleeve spinning at 50 rad/s (transverse) with dt = 10 ms", true,
        [](Json& s) { set_spin(s, vec3(50, 0, 0)); set_dt(s, 1e-2); }, spin_newton);
  b.add("gravity_x10_thickness_0.1mm", "combination", "gravity x 10 on the 0.1 mm sheet", false,
        [](Json& s) { set_thickness(s, 1e-4); set_gravity_factor(s, 10); });
  b.add("mesh_coarse_90_dt_5e-2", "combination", "coarse mesh (90 vertices) with dt = 50 ms", true,
        [](Json& s) { set_mesh(s, 10, 9); set_dt(s, 5e-2); });
  b.add("material_Et_1e5_dt_1e-2", "combination", "E t = 1e5 N/m with dt = 10 ms", true,
        [](Json& s) { set_stretch_modulus(s, 1e5); set_dt(s, 1e-2); }, snap_newton);
  b.add("nu_0.49_material_Et_1e7_dt_1e-2", "combination", "nu = 0.49 and E t = 1e7 N/m with dt = 10 ms", false,
        [](Json& s) { set_poisson(s, 0.49); set_stretch_modulus(s, 1e7); set_dt(s, 1e-2); }, snap_newton);
  if (!quick_only) return b.cases;
  std::vector<StabilityCase> quick;
  for (const StabilityCase& c : b.cases)
    if (c.quick) quick.push_back(c);
  return quick;
}

// ---------------------------------------------------------------------------------------------
// Running and judging a case.

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
std::string short_number(double v) { return format_significant(v, 3); }

// Runs the scene `json` of case `name` to its end or its failure, recording the figures into r;
// progress lines are prefixed with `label`.
void simulate(const std::string& json, const std::string& name, const std::string& label, const StabilityLog& log,
              StabilityResult& r) {
  const auto t0 = std::chrono::steady_clock::now();
  const Scene scene = load_scene_text(json, name + ".json", LogFn());
  if (scene.analysis != "dynamic") throw std::runtime_error(name + ": the case is not a dynamic scene");
  const Problem& problem = scene.problem;
  Simulator sim(problem);
  r.vertices = sim.num_vertices();
  r.dt = problem.time.dt;
  r.planned_steps = sim.num_steps();
  r.tolerance = problem.solver.tolerance;
  r.iteration_limit = problem.solver.max_iterations * problem.solver.newton_iterations;

  const double e0 = sim.kinetic_energy() + sim.elastic_energy();
  double scale = e0, work_in = 0.0;
  double lowest = 0.0, rise = 0.0;  // min of U(t) so far, largest rise of U [J]
  r.max_strain = sim.max_membrane_strain();
  int next_report = 1;
  try {
    for (int k = 1; k <= r.planned_steps; ++k) {
      const StepStats s = sim.step();
      r.steps = k;
      const double e = s.kinetic_energy + s.elastic_energy;
      const double w = s.external_work + s.boundary_work;
      work_in += std::max(w, 0.0);
      const double unexplained = e - e0 - (sim.external_work() + sim.boundary_work());  // U(t)
      rise = std::max(rise, unexplained - lowest);
      lowest = std::min(lowest, unexplained);
      scale = std::max({scale, e, work_in});
      r.max_iterations = std::max(r.max_iterations, s.solver_iterations);
      r.residual = std::max(r.residual, s.residual);
      const double strain = sim.max_membrane_strain();
      r.max_strain = std::isfinite(strain) ? std::max(r.max_strain, strain) : strain;
      if (!std::isfinite(e) || !std::isfinite(w) || !std::isfinite(strain) || !std::isfinite(s.residual)) {
        r.nan = true;
        r.error = "step " + std::to_string(k) + ": a recorded figure became NaN or infinite";
        break;
      }
      if (log && k * 10 >= next_report * r.planned_steps && k < r.planned_steps) {
        log(label + ": step " + std::to_string(k) + "/" + std::to_string(r.planned_steps) + ", t = " + short_number(s.t) +
            " s, wall " + short_number(seconds_since(t0)) + " s");
        while (k * 10 >= next_report * r.planned_steps) ++next_report;
      }
    }
  } catch (const SimulationError& e) {
    r.error = e.what();
    r.nan = e.kind() == SimulationError::Kind::nan;
  } catch (const std::exception& e) {  // anything else a step throws ends this case, not the study
    r.error = "step " + std::to_string(r.steps + 1) + ": " + e.what();
  }
  r.finished = r.steps == r.planned_steps && r.error.empty();
  r.energy_scale = scale;
  r.energy_rise = scale > 0 ? rise / scale : 0.0;
  r.wall_seconds = seconds_since(t0);
}

}  // namespace

StabilityResult run_stability_case(const StabilityCase& c, const StabilityLog& log, const StabilityLimits& limits) {
  StabilityResult r;
  r.name = c.name;
  r.group = c.group;
  r.description = c.description;
  r.remedy = c.remedy;
  r.limits = limits;
  if (!c.without_remedy_json.empty()) {
    StabilityResult plain = r;
    simulate(c.without_remedy_json, c.name, c.name + " without the remedy", log, plain);
    judge(plain);
    r.without_remedy = plain.pass ? "pass" : "fail: " + plain.failures.front();
    if (log) log(c.name + " without the remedy: " + r.without_remedy);
  }
  simulate(c.scene_json, c.name, c.name, log, r);
  judge(r);
  return r;
}

void judge(StabilityResult& r) {
  r.failures.clear();
  if (!r.finished) r.failures.push_back("did not finish" + (r.error.empty() ? std::string() : ": " + r.error));
  if (r.nan) r.failures.push_back("NaN");
  if (!(r.energy_rise <= r.limits.energy_rise))
    r.failures.push_back("energy rise " + short_number(r.energy_rise) + " > " + short_number(r.limits.energy_rise));
  if (!(r.residual <= 1.01 * r.tolerance))
    r.failures.push_back("residual " + short_number(r.residual) + " > tolerance " + short_number(r.tolerance));
  if (!(r.max_strain <= r.limits.strain))
    r.failures.push_back("strain " + short_number(r.max_strain) + " > " + short_number(r.limits.strain));
  r.pass = r.failures.empty();
}

// ---------------------------------------------------------------------------------------------
// Report contents.

namespace {

std::string number(double v) { return format_shortest(v); }

std::string join(const std::vector<std::string>& parts, const std::string& separator) {
  std::string out;
  for (size_t i = 0; i < parts.size(); ++i) out += (i ? separator : "") + parts[i];
  return out;
}

std::string scientific(double v) {
  if (!std::isfinite(v)) return number(v);
  if (v == 0) return "0";
  std::ostringstream s;
  s << std::scientific << std::setprecision(1) << v;
  return s.str();
}

}  // namespace

std::string stability_csv(const std::vector<StabilityResult>& results) {
  std::ostringstream out;
  out << "case,finished,nan,energy_rise,max_strain,max_iterations,residual,verdict,group,vertices,dt,steps,"
         "planned_steps,energy_scale,energy_rise_limit,strain_limit,tolerance,iteration_limit,wall_seconds,failed,"
         "remedy,without_remedy,error\n";
  for (const StabilityResult& r : results) {
    out << csv_field(r.name) << ',' << (r.finished ? "true" : "false") << ',' << (r.nan ? "true" : "false") << ','
        << number(r.energy_rise) << ',' << number(r.max_strain) << ',' << r.max_iterations << ',' << number(r.residual)
        << ',' << r.verdict() << ',' << csv_field(r.group) << ',' << r.vertices << ',' << number(r.dt) << ','
        << r.steps << ',' << r.planned_steps << ',' << number(r.energy_scale) << ',' << number(r.limits.energy_rise)
        << ',' << number(r.limits.strain) << ',' << number(r.tolerance) << ',' << r.iteration_limit << ','
        << format_fixed(r.wall_seconds, 2) << ',' << csv_field(join(r.failures, "; ")) << ',' << csv_field(r.remedy) << ','
        << csv_field(r.without_remedy) << ',' << csv_field(r.error) << '\n';
  }
  return out.str();
}

std::string stability_markdown(const std::vector<StabilityResult>& results, double total_wall_seconds) {
  std::ostringstream out;
  int passed = 0;
  for (const StabilityResult& r : results) passed += r.pass ? 1 : 0;
  const StabilityLimits limits = results.empty() ? StabilityLimits() : results.front().limits;
  out << "# Stability study\n\n"
      << passed << " of " << results.size() << " cases pass; total wall time " << format_fixed(total_wall_seconds, 1)
      << " s. The cases, the figures and the criteria are described in docs/stability.md; each case's scene is in "
         "scenes/<case>.json.\n\n"
      << "| case | verdict | vertices | dt [s] | steps | energy rise | max strain | max iterations | residual | wall [s] "
         "| settings beyond the base | without them |\n"
      << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const StabilityResult& r : results) {
    out << "| `" << r.name << "` | " << (r.pass ? "pass" : "**fail**: " + markdown_cell(join(r.failures, "; "))) << " | "
        << r.vertices << " | " << number(r.dt) << " | " << r.steps << "/" << r.planned_steps << " | "
        << scientific(r.energy_rise) << " | " << scientific(r.max_strain) << " | " << r.max_iterations << " | "
        << scientific(r.residual) << " | " << format_fixed(r.wall_seconds, 1) << " | "
        << markdown_cell(r.remedy.empty() ? "–" : r.remedy) << " | "
        << markdown_cell(r.without_remedy.empty() ? "–" : r.without_remedy) << " |\n";
  }
  out << "\nVerdict: a case passes when it finishes every step without NaN; the largest rise of total energy "
         "(kinetic + elastic) not explained by the work of the loads and the supports stays within "
      << number(limits.energy_rise)
      << " of the energy scale (the largest total energy or cumulative work put in); every step's linear solve "
         "reaches the solver tolerance; and the largest principal membrane (Green–Lagrange) strain stays at or below "
      << number(limits.strain) << ". Energy rise, max strain and residual are shown to two digits.\n";
  return out.str();
}

}  // namespace clothsim

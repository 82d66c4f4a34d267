// The stability study (`clothsim study stability`, docs/stability.md): a matrix of stiff and
// extreme dynamic cases built from one base sleeve — materials (E·t from 5000 to 1e7 N/m),
// thickness, Poisson ratio, time step, twist, compression, rigid spin, gravity, coarse and fine
// meshes, and combinations of extremes — each run to its end while recording whether it finished,
// NaN, the largest rise of total energy not explained by the work put in, the largest membrane
// strain, the solver's iterations and residual, and a pass/fail verdict.
//
// Every case is a complete dynamic scene (scenes/README.md) given as JSON text and loaded through
// the normal strict scene loader, so `clothsim <case>.json` reruns it. This file writes no files:
// the application (app/study_stability.cpp) writes the CSV, the Markdown table and the heat map.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace clothsim {

struct StabilityCase {
  std::string name;         // e.g. "twist_720", "material_Et_1e7_dt_5e-2"
  std::string group;        // "base", "material", "thickness", "poisson", "time step", "twist",
                            // "compression", "spin", "gravity", "mesh" or "combination"
  std::string description;  // what differs from the base sleeve
  std::string scene_json;   // the complete dynamic scene (pretty-printed JSON)
  // Settings beyond the base's solver defaults, with the reason (empty: none); they are already
  // in scene_json. docs/stability.md explains each.
  std::string remedy;
  // When the remedy is needed to pass (not just for speed): the same scene with the base's
  // solver settings, run too so that the report shows what the remedy fixes; otherwise empty.
  std::string without_remedy_json;
  bool quick = false;  // in the fast subset (`--quick`, ctest)
  // Whether the case fails without the remedy whatever the round-off: true for systematic
  // errors (a fast spin is stretched by (ω dt)²/2 every step); false where the sleeve buckles
  // within one step and the energy rise without the remedy depends on round-off (measured:
  // scaling each matrix entry by 1 ± 1 ulp moves it between below 1 % and 11 %).
  bool fails_without_remedy = true;
};

// The cases, in table order: all of them, or only the fast subset (a few seconds each).
std::vector<StabilityCase> stability_cases(bool quick_only);

// Pass/fail thresholds (docs/stability.md, "Verdict").
struct StabilityLimits {
  double energy_rise = 0.01;  // largest unexplained rise of E, as a fraction of the energy scale
  double strain = 1.0;        // sanity bound on |principal Green–Lagrange membrane strain|: a
                              // stretch of √3 (73 %), beyond any fabric
};

struct StabilityResult {
  std::string name, group, description, remedy;
  int vertices = 0;
  double dt = 0.0;            // [s]
  int planned_steps = 0;
  int steps = 0;              // steps completed
  bool finished = false;      // all planned steps completed
  bool nan = false;           // the state or a recorded figure became NaN or infinite
  std::string error;          // why it stopped early (SimulationError message), or empty
  // Largest rise of U(t) = E(t) − E(0) − W_ext(0, t) − W_boundary(0, t) over any interval
  // t₁ < t₂ of the run (E = kinetic + elastic energy), divided by `energy_scale`.
  double energy_rise = 0.0;   // [-]
  double energy_scale = 0.0;  // [J] max over the run of E(t) and the cumulative positive work put in
  double max_strain = 0.0;    // largest |principal membrane strain| over the states [-]
  int max_iterations = 0;     // largest solver iterations of a step (PCG; 1 per direct solve)
  int iteration_limit = 0;    // the scene's solver.max_iterations (× newton_iterations)
  double residual = 0.0;      // largest final relative residual of a step's linear system
  double tolerance = 0.0;     // the scene's solver.tolerance
  double wall_seconds = 0.0;  // [s]
  StabilityLimits limits;
  bool pass = false;
  std::vector<std::string> failures;  // the verdict's failed criteria, in words
  // The verdict with the base's solver settings when the case has a needed remedy ("fail: ..."
  // or "pass"), else empty.
  std::string without_remedy;
  std::string verdict() const { return pass ? "pass" : "fail"; }
};

// Progress lines (case started, every ~10 % of its steps, case done); may be empty.
using StabilityLog = std::function<void(const std::string&)>;

// Runs one case to its end (or its failure) and judges it. Throws only for an invalid case
// (a scene the loader or the Simulator rejects); a failing simulation is a result.
StabilityResult run_stability_case(const StabilityCase& c, const StabilityLog& log = {},
                                   const StabilityLimits& limits = {});

// Applies the verdict criteria to the recorded figures (sets pass and failures): finished, no
// NaN, energy_rise <= limits.energy_rise, residual <= tolerance (with 1 % slack for rounding of
// the reported value), max_strain finite and <= limits.strain.
void judge(StabilityResult& r);

// The report files' contents. CSV columns (header line first):
//   case,finished,nan,energy_rise,max_strain,max_iterations,residual,verdict,group,vertices,dt,
//   steps,planned_steps,energy_scale,energy_rise_limit,strain_limit,tolerance,iteration_limit,
//   wall_seconds,failed,remedy,without_remedy,error
// Numbers in shortest round-trip form; text fields quoted as in RFC 4180 when needed.
std::string stability_csv(const std::vector<StabilityResult>& results);
// A Markdown table of every case with its verdict and figures, followed by the criteria.
std::string stability_markdown(const std::vector<StabilityResult>& results, double total_wall_seconds);

}  // namespace clothsim

// `clothsim study stability [--out DIR] [--quick] [--no-plot]`: runs the stability matrix of
// sim/study/stability.hpp and writes DIR/study_stability/ — results.csv, table.md, heatmap.png
// (scripts/plot_stability.py) and scenes/<case>.json (each case as a scene file, so
// `clothsim DIR/study_stability/scenes/<case>.json` reruns it). The folder is built under a
// temporary sibling name and renamed into place at the end. Exit code 1 on an error or when any
// case fails (the report is written all the same).
// Each case is a task of app/sweep.hpp (id: the case's name, result: result.json, every field of
// its StabilityResult): without a sweep option they all run in this process one after another;
// with --plan, --executor, -j or --retry-failed as `clothsim task` processes (docs/cluster.md).
// A gathered report's total wall time is the sum of the cases' own times.
#include "app/output_folders.hpp"
#include "app/plotting.hpp"
#include "app/study.hpp"

#include "sim/study/report_format.hpp"
#include "sim/study/stability.hpp"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

void log_line(const std::string& line) { std::cerr << "clothsim: " << line << std::endl; }

std::string short_number(double v) { return format_significant(v, 3); }

// Doubles as JSON numbers, or "nan" / "inf" / "-inf" (JSON has no such numbers).
Json number_json(double v) { return std::isfinite(v) ? Json(v) : Json(format_shortest(v)); }
double number_of(const Json& j) {
  if (j.is_number()) return j.get<double>();
  const std::string s = j.get<std::string>();
  if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
  if (s == "inf") return std::numeric_limits<double>::infinity();
  if (s == "-inf") return -std::numeric_limits<double>::infinity();
  throw std::invalid_argument("\"" + s + "\" is not a number");
}

Json result_json(const StabilityResult& r) {
  return Json{{"name", r.name},
              {"group", r.group},
              {"description", r.description},
              {"remedy", r.remedy},
              {"vertices", r.vertices},
              {"dt", number_json(r.dt)},
              {"planned_steps", r.planned_steps},
              {"steps", r.steps},
              {"finished", r.finished},
              {"nan", r.nan},
              {"error", r.error},
              {"energy_rise", number_json(r.energy_rise)},
              {"energy_scale", number_json(r.energy_scale)},
              {"max_strain", number_json(r.max_strain)},
              {"max_iterations", r.max_iterations},
              {"iteration_limit", r.iteration_limit},
              {"residual", number_json(r.residual)},
              {"tolerance", number_json(r.tolerance)},
              {"wall_seconds", number_json(r.wall_seconds)},
              {"limits", {{"energy_rise", number_json(r.limits.energy_rise)}, {"strain", number_json(r.limits.strain)}}},
              {"pass", r.pass},
              {"failures", r.failures},
              {"without_remedy", r.without_remedy}};
}

StabilityResult result_of(const Json& j) {
  StabilityResult r;
  r.name = j.at("name").get<std::string>();
  r.group = j.at("group").get<std::string>();
  r.description = j.at("description").get<std::string>();
  r.remedy = j.at("remedy").get<std::string>();
  r.vertices = j.at("vertices").get<int>();
  r.dt = number_of(j.at("dt"));
  r.planned_steps = j.at("planned_steps").get<int>();
  r.steps = j.at("steps").get<int>();
  r.finished = j.at("finished").get<bool>();
  r.nan = j.at("nan").get<bool>();
  r.error = j.at("error").get<std::string>();
  r.energy_rise = number_of(j.at("energy_rise"));
  r.energy_scale = number_of(j.at("energy_scale"));
  r.max_strain = number_of(j.at("max_strain"));
  r.max_iterations = j.at("max_iterations").get<int>();
  r.iteration_limit = j.at("iteration_limit").get<int>();
  r.residual = number_of(j.at("residual"));
  r.tolerance = number_of(j.at("tolerance"));
  r.wall_seconds = number_of(j.at("wall_seconds"));
  r.limits.energy_rise = number_of(j.at("limits").at("energy_rise"));
  r.limits.strain = number_of(j.at("limits").at("strain"));
  r.pass = j.at("pass").get<bool>();
  r.failures = j.at("failures").get<std::vector<std::string>>();
  r.without_remedy = j.at("without_remedy").get<std::string>();
  return r;
}

std::vector<StabilityCase> planned_cases(const Json& settings) { return stability_cases(settings.at("quick").get<bool>()); }

// One task: the case named `id`, its result as JSON.
std::string run_stability_task(const Json& settings, const std::string& id, const LogFn& log) {
  for (const StabilityCase& c : planned_cases(settings)) {
    if (c.name != id) continue;
    if (log) log(c.description);
    const StabilityResult r = run_stability_case(c, [&](const std::string& line) {
      if (log) log(line);
    });
    if (log)
      log(r.verdict() + " (" + std::to_string(r.steps) + "/" + std::to_string(r.planned_steps) + " steps, energy rise " +
          short_number(r.energy_rise) + ", max strain " + short_number(r.max_strain) + ", max iterations " +
          std::to_string(r.max_iterations) + ", residual " + short_number(r.residual) + ", " +
          short_number(r.wall_seconds) + " s)" + (r.pass ? "" : ": " + r.failures.front()));
    return result_json(r).dump(2) + "\n";
  }
  throw std::invalid_argument("the stability study's plan has no case \"" + id + "\"");
}

int gather_stability_report(const Json& settings, const GatherInput& input) {
  const fs::path final_dir = input.out_root / "study_stability";
  const std::vector<StabilityCase> cases = planned_cases(settings);
  std::vector<StabilityResult> results;
  double task_seconds = 0.0;
  for (const std::string& id : input.ids)
    if (const auto found = input.results.find(id); found != input.results.end()) {
      try {
        results.push_back(result_of(Json::parse(found->second)));
      } catch (const std::exception& e) {
        throw std::runtime_error("the result of task " + id + ": " + e.what());
      }
      task_seconds += results.back().wall_seconds;
    }
  const double wall = input.seconds.value_or(task_seconds);
  std::string table = stability_markdown(results, wall);
  if (!input.problems.empty()) {
    table += "\n## Cases that did not finish\n\n" + std::to_string(input.problems.size()) + " of " +
             std::to_string(input.ids.size()) +
             " cases are missing from the table (`clothsim study stability --plan DIR --retry-failed` runs them):\n\n";
    for (const std::string& p : input.problems) table += "- " + markdown_cell(p) + "\n";
  }
  // Built under a temporary sibling and renamed into place (an older report replaced only then).
  const fs::path tmp = input.out_root / (".study_stability.tmp-" + std::to_string(static_cast<long>(::getpid())));
  const std::vector<fs::path> created = missing_folders(input.out_root);  // removed again on failure
  std::string plot_error;
  try {
    fs::create_directories(input.out_root);
    fs::remove_all(tmp);
    fs::create_directories(tmp / "scenes");
    for (const StabilityCase& c : cases) write_text_file(tmp / "scenes" / (c.name + ".json"), c.scene_json);
    write_text_file(tmp / "results.csv", stability_csv(results));
    write_text_file(tmp / "table.md", table);
    if (input.plot) {
      log_line("drawing the heat map (scripts/plot_stability.py)");
      plot_error = run_plot_script("plot_stability.py", {(tmp / "results.csv").string(), (tmp / "heatmap.png").string()});
    }
    if (const std::string warning = replace_folder(tmp, final_dir); !warning.empty()) log_line("warning: " + warning);
  } catch (...) {
    std::error_code ec;
    fs::remove_all(tmp, ec);
    for (const fs::path& dir : created) fs::remove(dir, ec);  // deepest first; only if empty
    throw;
  }

  std::vector<std::string> failed;
  for (const StabilityResult& r : results)
    if (!r.pass) failed.push_back(r.name);
  std::cout << "stability study: " << results.size() - failed.size() << " of " << results.size()
            << " cases pass (wall " << short_number(wall) << " s)\n"
            << "  wrote " << (final_dir / "results.csv").string() << ", table.md"
            << (input.plot && plot_error.empty() ? ", heatmap.png" : "") << " and scenes/\n";
  int code = 0;
  if (!plot_error.empty()) {
    std::cerr << "clothsim: error: heat map: " << plot_error << " (the data were written; --no-plot skips the PNG)\n";
    code = 1;
  }
  if (!failed.empty()) {
    std::string names;
    for (const std::string& n : failed) names += (names.empty() ? "" : ", ") + n;
    std::cerr << "clothsim: error: stability study: " << failed.size() << " of " << results.size()
              << " cases failed (" << names << "); see " << (final_dir / "table.md").string() << "\n";
    code = 1;
  }
  return code;
}

}  // namespace

SweepStudy stability_study_sweep(bool quick) {
  SweepStudy study;
  study.name = "stability";
  study.settings = Json{{"quick", quick}};
  for (const StabilityCase& c : stability_cases(quick)) study.ids.push_back(c.name);
  return study;
}

const SweepHooks& stability_sweep_hooks() {
  static const SweepHooks hooks{"result.json", run_stability_task, gather_stability_report};
  return hooks;
}

int run_stability_study(const StudyOptions& options, SweepCommand sweep) {
  sweep.out_root = options.out_root;
  sweep.plot = options.plot;
  if ((sweep.gather || sweep.retry_failed) && options.quick) {
    std::cerr << "clothsim: error: study stability: " << (sweep.gather ? "--gather" : "--retry-failed")
              << " uses the plan in its folder; --quick cannot be given with it\n";
    return 1;
  }
  try {
    if (!sweep_requested(sweep)) {
      const std::vector<StabilityCase> cases = stability_cases(options.quick);
      log_line("stability study: " + std::to_string(cases.size()) + " cases" + (options.quick ? " (quick subset)" : "") +
               ", writing " + (options.out_root / "study_stability").string());
    }
    return run_study_command("stability", [&] { return stability_study_sweep(options.quick); }, sweep);
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: stability study: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace clothsim

// `clothsim study folds [--out DIR] [--quick] [--no-plot] [--meshes ...] [--seeds ...] [--methods ...]
// [--cases ...] [--preset NAME] [--amplitude M] [--dt S] [--end S]`: runs the fold study
// (sim/study/fold_study.hpp, docs/fold_study.md) and writes DIR/study_folds/:
//   results.csv           one row per run (columns: fold_csv_columns())
//   results.md            the seeds of each case, method and mesh as a Markdown table (and the
//                         runs that did not finish, when gathered from a sweep that lacks some)
//   folds_vs_vertices.png counts against vertices per method with the theory band
//                         (scripts/plot_folds.py, matplotlib)
// The folder is built as DIR/.study_folds.tmp-<pid> and renamed into place at the end; an older
// report is replaced only then. A run that fails is a row with a note, not the end of the study.
// If only the plot fails, the folder (with the CSV) is still published and the command exits 1.
// Each run is a task of app/sweep.hpp (id FoldRun::id(), result a one-row CSV, row.csv): without
// a sweep option they all run in this process one after another and are gathered in memory; with
// --plan, --executor, -j or --retry-failed they run as `clothsim task` processes (docs/cluster.md).
#include "app/output_folders.hpp"
#include "app/resources.hpp"
#include "app/study.hpp"
#include "sim/study/fold_study.hpp"
#include "sim/study/report_format.hpp"

#include <nlohmann/json.hpp>


#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// The plan as plan.json's settings, and back (doubles round-trip exactly through JSON).
Json fold_plan_settings(const FoldStudyPlan& plan) {
  Json meshes = Json::array();
  for (const FoldMesh& m : plan.meshes) meshes.push_back({m.segments, m.rings});
  return Json{{"scenes", fs::absolute(plan.scenes_dir).lexically_normal().string()},
              {"cases", plan.cases},
              {"methods", plan.methods},
              {"meshes", meshes},
              {"seeds", plan.seeds},
              {"preset", plan.preset},
              {"amplitude", plan.amplitude ? Json(*plan.amplitude) : Json(nullptr)},
              {"wavelength", plan.wavelength ? Json{plan.wavelength->first, plan.wavelength->second} : Json(nullptr)},
              {"dt", plan.dt},
              {"end", plan.end ? Json(*plan.end) : Json(nullptr)},
              {"self_collision", plan.self_collision}};
}

FoldStudyPlan fold_plan_from_settings(const Json& j) {
  FoldStudyPlan plan;
  try {
    plan.scenes_dir = j.at("scenes").get<std::string>();
    plan.cases = j.at("cases").get<std::vector<std::string>>();
    plan.methods = j.at("methods").get<std::vector<std::string>>();
    for (const Json& m : j.at("meshes")) plan.meshes.push_back({m.at(0).get<int>(), m.at(1).get<int>()});
    plan.seeds = j.at("seeds").get<std::vector<int>>();
    plan.preset = j.at("preset").get<std::string>();
    if (!j.at("amplitude").is_null()) plan.amplitude = j.at("amplitude").get<double>();
    if (!j.at("wavelength").is_null())
      plan.wavelength = std::make_pair(j.at("wavelength").at(0).get<double>(), j.at("wavelength").at(1).get<double>());
    plan.dt = j.at("dt").get<double>();
    if (!j.at("end").is_null()) plan.end = j.at("end").get<double>();
    plan.self_collision = j.at("self_collision").get<bool>();
  } catch (const Json::exception& e) {
    throw std::invalid_argument(std::string("the fold study's settings: ") + e.what());
  }
  validate_fold_plan(plan);
  return plan;
}

std::string count_text(double v) { return std::isfinite(v) ? format_shortest(v) : "-"; }

// One task: the run with this id, as a one-row CSV (write_fold_csv).
std::string run_fold_task(const Json& settings, const std::string& id, const LogFn& log) {
  const FoldStudyPlan plan = fold_plan_from_settings(settings);
  for (const FoldRun& run : fold_study_runs(plan)) {
    if (run.id() != id) continue;
    const FoldRow row = run_fold_case(plan, run);
    if (log)
      log("circumferential " + count_text(row.circumferential_median) + ", axial " + count_text(row.axial_median) +
          " (" + format_fixed(row.wall_seconds, 1) + " s" + (row.status == "ok" ? "" : ", " + row.status + ": " + row.note) +
          ")");
    std::ostringstream csv;
    write_fold_csv(csv, {row});
    return csv.str();
  }
  throw std::invalid_argument("the fold study's plan has no run \"" + id + "\"");
}

// The report from the finished runs, in the plan's order.
int gather_fold_report(const Json&, const GatherInput& input) {
  const fs::path target = input.out_root / "study_folds";
  std::vector<FoldRow> rows;
  for (const std::string& id : input.ids)
    if (const auto found = input.results.find(id); found != input.results.end()) {
      std::vector<FoldRow> task_rows;
      try {
        task_rows = read_fold_csv(found->second);
      } catch (const std::exception& e) {
        throw std::runtime_error("the result of task " + id + ": " + e.what());
      }
      rows.insert(rows.end(), task_rows.begin(), task_rows.end());
    }
  std::ostringstream csv_text, md_text;
  write_fold_csv(csv_text, rows);
  write_fold_markdown(md_text, rows);
  if (!input.problems.empty()) {
    md_text << "\n## Runs that did not finish\n\n"
            << input.problems.size() << " of " << input.ids.size()
            << " runs are missing from the table (`clothsim study folds --plan DIR --retry-failed` runs them):\n\n";
    for (const std::string& p : input.problems) md_text << "- " << markdown_cell(p) << '\n';
  }
  const std::string plot_error =
      publish_report(input.out_root, "study_folds", {{"results.csv", csv_text.str()}, {"results.md", md_text.str()}},
                     input.plot, "plot_folds.py", "folds_vs_vertices.png");
  int failed = 0;
  double task_seconds = 0.0;
  for (const FoldRow& r : rows) {
    failed += r.status != "ok";
    task_seconds += r.wall_seconds;
  }
  std::cout << "fold study: " << rows.size() << " runs (" << failed << " failed or unstable) "
            << (input.seconds ? "in " + format_fixed(*input.seconds, 1) + " s"
                              : "of " + format_fixed(task_seconds, 1) + " s together")
            << "; wrote " << (target / "results.csv").string()
            << (input.plot && plot_error.empty() ? " and folds_vs_vertices.png" : "") << '\n';
  if (!plot_error.empty()) {
    std::cerr << "clothsim: error: folds_vs_vertices.png: " << plot_error << " (results.csv was written to "
              << target.string() << ")\n";
    return 1;
  }
  return 0;
}

}  // namespace

SweepStudy fold_study_sweep(const FoldStudyPlan& plan) {
  SweepStudy study;
  study.name = "folds";
  study.settings = fold_plan_settings(plan);
  for (const FoldRun& run : fold_study_runs(plan)) study.ids.push_back(run.id());
  return study;
}

const SweepHooks& fold_sweep_hooks() {
  static const SweepHooks hooks{"row.csv", run_fold_task, gather_fold_report};
  return hooks;
}

int run_fold_study_report(const StudyOptions& options, const FoldStudyArgs& args, SweepCommand sweep) {
  sweep.out_root = options.out_root;
  sweep.plot = options.plot;
  const bool from_folder = sweep.gather || sweep.retry_failed;
  const bool plan_options = !args.meshes.empty() || !args.seeds.empty() || !args.methods.empty() || !args.cases.empty() ||
                            !args.preset.empty() || args.amplitude || args.dt || args.end || options.quick;
  if (from_folder && plan_options) {
    std::cerr << "clothsim: error: study folds: " << (sweep.gather ? "--gather" : "--retry-failed")
              << " uses the plan in its folder; --quick and the options that change the plan cannot be given with it\n";
    return 1;
  }
  FoldStudyPlan plan;
  if (!from_folder) {
    try {
      // The plan and its options: a bad option is reported before anything runs or is written.
      const fs::path scenes = resource_dir("scenes");
      plan = options.quick ? quick_fold_plan(scenes) : full_fold_plan(scenes);
      if (!args.meshes.empty()) plan.meshes = parse_fold_meshes(args.meshes);
      if (!args.seeds.empty()) plan.seeds = parse_fold_seeds(args.seeds);
      if (!args.methods.empty()) plan.methods = parse_fold_methods(args.methods);
      if (!args.cases.empty()) plan.cases = parse_fold_cases(args.cases);
      if (!args.preset.empty()) plan.preset = args.preset;
      if (args.amplitude) plan.amplitude = *args.amplitude;
      if (args.dt) plan.dt = *args.dt;
      if (args.end) plan.end = *args.end;
      validate_fold_plan(plan);
    } catch (const std::exception& e) {
      std::cerr << "clothsim: error: study folds: " << e.what() << '\n';
      return 1;
    }
  }
  try {
    return run_study_command("folds", [&] { return fold_study_sweep(plan); }, sweep);
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: fold study: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace clothsim

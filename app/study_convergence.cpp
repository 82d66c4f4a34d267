// `clothsim study convergence [--out DIR] [--quick] [--no-plot]`: runs the convergence study
// (sim/study/convergence.hpp, docs/convergence.md) and writes DIR/study_convergence/:
//   results.csv        one row per run (columns: results_csv_columns())
//   results.md         the same rows as a Markdown table, then the tolerance series' summary
//                      (summarize_tolerance_series: the rule's checks and the recommended tolerance)
//   error_vs_time.png  log–log error against wall time, and per sleeve the post-buckling panels
//                      (energy error, fold counts) and the tolerance series (solver error,
//                      wall time and iterations against tolerance) (scripts/plot_convergence.py,
//                      matplotlib)
// The folder is built as DIR/.study_convergence.tmp-<pid> and renamed into place at the end; an
// older report is replaced only then. If only the plot fails, the folder (with the CSV) is still
// published and the command exits with 1.
// As a sweep (docs/cluster.md): one task per run (convergence_run_ids: every sleeve simulation,
// the reference included, and every plate solve; result.json), gathered into the same report.
#include "app/output_folders.hpp"
#include "app/resources.hpp"
#include "app/study.hpp"
#include "app/sweep.hpp"
#include "sim/study/convergence.hpp"
#include "sim/study/report_format.hpp"


#include <chrono>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <sstream>
#include <string>

namespace clothsim {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// The text `write` produces for `rows`.
std::string text_of(void (*write)(std::ostream&, const std::vector<ConvergenceRow>&), const std::vector<ConvergenceRow>& rows) {
  std::ostringstream out;
  write(out, rows);
  return out.str();
}

void log_convergence(const std::string& line) { std::cerr << "clothsim: convergence: " << line << std::endl; }

ConvergencePlan plan_of(bool quick) {
  const fs::path scenes = resource_dir("scenes");
  return quick ? quick_convergence_plan(scenes) : full_convergence_plan(scenes);
}

// Publishes the report of `rows` (and `missing`, the runs that did not finish, if any) to
// out_root/study_convergence/ and prints its summary; returns the exit code.
int publish_convergence(const fs::path& out_root, bool plot, const std::vector<ConvergenceRow>& rows, double seconds,
                        const std::vector<std::string>& missing = {}) {
  const fs::path target = out_root / "study_convergence";
  const ToleranceSummary tolerance = summarize_tolerance_series(rows);
  std::ostringstream markdown;
  write_results_markdown(markdown, rows);
  write_tolerance_summary_markdown(markdown, tolerance);
  if (!missing.empty()) {
    markdown << "\n## Runs that did not finish\n\n" << missing.size()
             << " runs have no result (their rows have error nan and say so; `clothsim study convergence --plan DIR "
                "--retry-failed` runs them):\n\n";
    for (const std::string& m : missing) markdown << "- " << markdown_cell(m) << "\n";
  }
  const std::string plot_error =
      publish_report(out_root, "study_convergence",
                     {{"results.csv", text_of(write_results_csv, rows)}, {"results.md", markdown.str()}}, plot,
                     "plot_convergence.py", "error_vs_time.png");
  std::cout << "convergence study: " << rows.size() << " rows in " << format_fixed(seconds, 1) << " s; wrote "
            << (target / "results.csv").string() << (plot && plot_error.empty() ? " and error_vs_time.png" : "") << '\n';
  if (!tolerance.settings.empty())
    std::cout << "solver tolerance by the rule of docs/convergence.md: "
              << (tolerance.recommended ? format_shortest(*tolerance.recommended) : std::string("none"))
              << " (results.md)\n";
  if (!plot_error.empty()) {
    std::cerr << "clothsim: error: error_vs_time.png: " << plot_error << " (results.csv was written to "
              << target.string() << ")\n";
    return 1;
  }
  return 0;
}

std::string run_convergence_task(const Json& settings, const std::string& id, const LogFn& log) {
  return run_convergence_run(plan_of(settings.at("quick").get<bool>()), convergence_methods(), id, log);
}

int gather_convergence_report(const Json& settings, const GatherInput& input) {
  const std::vector<ConvergenceRow> rows = gather_convergence(plan_of(settings.at("quick").get<bool>()),
                                                              convergence_methods(), input.results, log_convergence);
  double task_seconds = 0.0;
  for (const ConvergenceRow& r : rows) task_seconds += r.wall_seconds;
  return publish_convergence(input.out_root, input.plot, rows, input.seconds.value_or(task_seconds), input.problems);
}

}  // namespace

const SweepHooks& convergence_sweep_hooks() {
  static const SweepHooks hooks{"result.json", run_convergence_task, gather_convergence_report};
  return hooks;
}

SweepStudy convergence_study_sweep(bool quick) {
  SweepStudy study;
  study.name = "convergence";
  study.settings = Json{{"quick", quick}};
  study.ids = convergence_run_ids(plan_of(quick), convergence_methods());
  return study;
}

int run_convergence_study(const StudyOptions& options, SweepCommand sweep) {
  sweep.out_root = options.out_root;
  sweep.plot = options.plot;
  try {
    if (sweep_requested(sweep)) {
      if ((sweep.gather || sweep.retry_failed) && options.quick) {
        std::cerr << "clothsim: error: study convergence: " << (sweep.gather ? "--gather" : "--retry-failed")
                  << " uses the plan in its folder; --quick cannot be given with it\n";
        return 1;
      }
      return run_study_command("convergence", [&] { return convergence_study_sweep(options.quick); }, sweep);
    }
    // The usual way: every run in this process, each computed once and shared by the series that
    // need it (the same rows as the tasks give, wall times aside).
    check_folder_possible(options.out_root);
    const auto start = std::chrono::steady_clock::now();
    const std::vector<ConvergenceRow> rows = run_convergence(plan_of(options.quick), convergence_methods(), log_convergence);
    return publish_convergence(options.out_root, options.plot, rows,
                               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: convergence study: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace clothsim

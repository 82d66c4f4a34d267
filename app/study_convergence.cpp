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
#include "app/output_folders.hpp"
#include "app/resources.hpp"
#include "app/study.hpp"
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

// The text `write` produces for `rows`.
std::string text_of(void (*write)(std::ostream&, const std::vector<ConvergenceRow>&), const std::vector<ConvergenceRow>& rows) {
  std::ostringstream out;
  write(out, rows);
  return out.str();
}

}  // namespace

int run_convergence_study(const StudyOptions& options) {
  const fs::path target = options.out_root / "study_convergence";
  try {
    const auto start = std::chrono::steady_clock::now();
    const fs::path scenes = resource_dir("scenes");
    const ConvergencePlan plan = options.quick ? quick_convergence_plan(scenes) : full_convergence_plan(scenes);
    const std::vector<ConvergenceRow> rows = run_convergence(plan, convergence_methods(), [](const std::string& line) {
      std::cerr << "clothsim: convergence: " << line << std::endl;
    });
    const ToleranceSummary tolerance = summarize_tolerance_series(rows);
    std::ostringstream markdown;
    write_results_markdown(markdown, rows);
    write_tolerance_summary_markdown(markdown, tolerance);
    const std::string plot_error =
        publish_report(options.out_root, "study_convergence",
                       {{"results.csv", text_of(write_results_csv, rows)}, {"results.md", markdown.str()}},
                       options.plot, "plot_convergence.py", "error_vs_time.png");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "convergence study: " << rows.size() << " rows in " << format_fixed(seconds, 1) << " s; wrote "
              << (target / "results.csv").string() << (options.plot && plot_error.empty() ? " and error_vs_time.png" : "")
              << '\n';
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
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: convergence study: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace clothsim

// `clothsim study folds [--out DIR] [--quick] [--no-plot] [--meshes ...] [--seeds ...] [--methods ...]
// [--cases ...] [--preset NAME] [--amplitude M] [--dt S] [--end S]`: runs the fold study
// (sim/study/fold_study.hpp, docs/fold_study.md) and writes DIR/study_folds/:
//   results.csv           one row per run (columns: fold_csv_columns())
//   results.md            the seeds of each case, method and mesh as a Markdown table
//   folds_vs_vertices.png counts against vertices per method with the theory band
//                         (scripts/plot_folds.py, matplotlib)
// The folder is built as DIR/.study_folds.tmp-<pid> and renamed into place at the end; an older
// report is replaced only then. A run that fails is a row with a note, not the end of the study.
// If only the plot fails, the folder (with the CSV) is still published and the command exits 1.
#include "app/output_folders.hpp"
#include "app/resources.hpp"
#include "app/study.hpp"
#include "sim/study/fold_study.hpp"
#include "sim/study/report_format.hpp"


#include <chrono>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace clothsim {

int run_fold_study_report(const StudyOptions& options, const FoldStudyArgs& args) {
  namespace fs = std::filesystem;
  const fs::path target = options.out_root / "study_folds";
  FoldStudyPlan plan;
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
  try {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<FoldRow> rows =
        run_fold_study(plan, [](const std::string& line) { std::cerr << "clothsim: folds: " << line << std::endl; });

    std::ostringstream csv_text, md_text;
    write_fold_csv(csv_text, rows);
    write_fold_markdown(md_text, rows);
    const std::string plot_error =
        publish_report(options.out_root, "study_folds", {{"results.csv", csv_text.str()}, {"results.md", md_text.str()}},
                       options.plot, "plot_folds.py", "folds_vs_vertices.png");
    int failed = 0;
    for (const FoldRow& r : rows) failed += r.status != "ok";
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::cout << "fold study: " << rows.size() << " runs (" << failed << " failed or unstable) in "
              << format_fixed(seconds, 1) << " s; wrote " << (target / "results.csv").string()
              << (options.plot && plot_error.empty() ? " and folds_vs_vertices.png" : "") << '\n';
    if (!plot_error.empty()) {
      std::cerr << "clothsim: error: folds_vs_vertices.png: " << plot_error << " (results.csv was written to "
                << target.string() << ")\n";
      return 1;
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: fold study: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace clothsim

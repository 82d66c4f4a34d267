// `clothsim study convergence|stability|folds`: the reports of issue 5 and the fold study. Each runs its cases, writes
// DIR/study_<name>/ (CSV data, a Markdown table where there is one, and a PNG plot drawn by
// scripts/plot_<name>.py with Debian's python3-matplotlib) and prints where it wrote.
// The folder is published atomically: it is built under a temporary name and renamed at the end,
// so a failed or interrupted study leaves an older report untouched.
// The fold study, the stability matrix and the convergence study can also run as a sweep of tasks (app/sweep.hpp,
// docs/cluster.md): planned into a folder, each case run by `clothsim task`, locally in parallel or
// as a Slurm job array, and gathered into the same report.
#pragma once

#include "app/sweep.hpp"
#include "sim/study/fold_study.hpp"

#include <filesystem>
#include <optional>
#include <string>

namespace clothsim {

struct StudyOptions {
  std::filesystem::path out_root = "out";  // the report goes to out_root/study_<name>/
  bool quick = false;                      // a small subset of the cases (seconds, for tests)
  bool plot = true;                        // draw the PNG (needs /usr/bin/python3 with matplotlib)
};

// Return the process exit code: 0 on success, 1 on error (message on stderr, "clothsim: error: ...").
int run_convergence_study(const StudyOptions& options, SweepCommand sweep = {});
// The convergence study's tasks (one per run, id from convergence_run_ids; result.json) and report.
const SweepHooks& convergence_sweep_hooks();
SweepStudy convergence_study_sweep(bool quick);
int run_stability_study(const StudyOptions& options, SweepCommand sweep = {});
// The stability matrix's tasks (one per case, id: its name; result.json) and report.
const SweepHooks& stability_sweep_hooks();
SweepStudy stability_study_sweep(bool quick);

// `clothsim study folds` (app/study_folds.cpp, docs/fold_study.md): the options that rerun it
// differently. Empty strings / unset values keep the plan's defaults (the full plan, or the quick
// one with --quick); the lists are parsed by sim/study/fold_study.hpp's parse_fold_*.
struct FoldStudyArgs {
  std::string meshes;   // "26x19,38x27,..." (segments x rings)
  std::string seeds;    // "1,2,3"
  std::string methods;  // "loop_kl,linear_fe,mass_spring"
  std::string cases;    // "twist,compress"
  std::string preset;   // material preset, e.g. "cotton"
  std::optional<double> amplitude;  // [m] imperfection amplitude
  std::optional<double> dt;         // [s]
  std::optional<double> end;        // [s]
};
// Runs the study as `sweep` says (app/sweep.hpp: in this process, or planned, run by an executor and
// gathered); the default SweepCommand is today's single process.
int run_fold_study_report(const StudyOptions& options, const FoldStudyArgs& args, SweepCommand sweep = {});
// The fold study's tasks (one per run, id FoldRun::id()) and report, for app/sweep.cpp.
const SweepHooks& fold_sweep_hooks();
// The plan as a sweep: its settings (plan.json) and the runs' ids in the plan's order.
SweepStudy fold_study_sweep(const FoldStudyPlan& plan);

}  // namespace clothsim

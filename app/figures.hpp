// `clothsim figures [N ...] [--out DIR] [--size WxH] [--quick] [--rerun]`: the paper's Figs. 1 and
// 7–11 reproduced from shipped scenes (docs/figures.md). Each figure is a set of *runs* (a shipped
// scene, optionally with a few keys replaced: method, material, colour, camera) and *panels* (one
// run at one time). The command
//   1. writes each run's scene to DIR/figures/scenes/<run>.json (the exact file that was run, so a
//      panel can be re-run by hand with `clothsim DIR/figures/scenes/<run>.json`),
//   2. runs it into DIR/figures/runs/<run>/ (the usual dynamic-run folder) unless a completed run
//      of the identical scene and options is already there (--rerun forces it),
//   3. counts the folds of the sleeve panels on the run's OBJ frame (count_sleeve_folds),
//   4. lays the panels out with labels (method and drawn surface, vertices, material, time, folds)
//      into DIR/figures/figN.png (scripts/montage.py, python3-matplotlib), and
//   5. writes DIR/figures/figN.md (which scene and settings made each panel, what was measured) and
//      DIR/figures/figures.md (all figN.md present, in order).
// Every file is written under a temporary name and renamed into place, so it is whole or absent.
// With --plan, --executor, -j or --retry-failed the runs are tasks of app/sweep.hpp (id: the run's
// name; docs/cluster.md): run by `clothsim task` into DIR/figures/runs/ as above, then gathered
// (steps 3–5 on the completed runs; a figure whose runs did not all finish is named, not drawn).
#pragma once

#include "app/sweep.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace clothsim {

struct FiguresOptions {
  std::vector<int> figures;               // empty: all of figure_numbers()
  std::filesystem::path out_root = "out";  // writes out_root/figures/
  int width = 480, height = 360;           // panel size [px]
  bool quick = false;                      // every run only 2 frames long (seconds; for the tests)
  bool rerun = false;                      // run every scene again even if a completed run exists
};

// The figures the command can make: 1, 7, 8, 9, 10, 11.
const std::vector<int>& figure_numbers();

// Returns the process exit code (0: every requested figure written; 1: an error, named on stderr).
int run_figures(const FiguresOptions& options, SweepCommand sweep = {});

// The figures as a sweep (settings: the figure numbers, output root, panel size, quick, rerun) and
// their task and gather, for app/sweep.cpp.
SweepStudy figures_sweep(const FiguresOptions& options);
const SweepHooks& figures_sweep_hooks();

}  // namespace clothsim

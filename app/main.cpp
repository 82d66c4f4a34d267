// Command-line entry point: `clothsim SCENE.json [--out DIR] [--end T]`. Argument parsing (CLI11)
// lives in this file only; the work is done by run_scene_file (app/run.hpp).
#include "app/compare.hpp"
#include "app/fabric_test.hpp"
#include "app/figures.hpp"
#include "app/golden.hpp"
#include "app/point_cache.hpp"
#include "app/render_saved.hpp"
#include "app/run.hpp"
#include "app/study.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

namespace {

// Parses argv into `app`. Returns -1 to go on, otherwise the exit code (0 after --help, 1 after
// printing a usage error).
int parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    std::cerr << "clothsim: error: " << e.what() << "\nRun with --help for usage.\n";
    return 1;
  }
  return -1;
}

// Parses "WxH" with 16 <= W, H <= `max`; prints the error naming `option` and returns false
// for anything else (also trailing characters).
bool parse_size(const std::string& option, const std::string& size, int max, int& width, int& height) {
  int used = 0;
  if (std::sscanf(size.c_str(), "%dx%d%n", &width, &height, &used) != 2 || used != static_cast<int>(size.size()) ||
      width < 16 || height < 16 || width > max || height > max) {
    std::cerr << "clothsim: error: " << option << ": expected WxH with 16 <= W, H <= " << max << " (got \"" << size
              << "\")\n";
    return false;
  }
  return true;
}

// `clothsim render DIR [--out DIR2] [--size WxH] [--refine K] [--surface S]`.
int render_command(int argc, char** argv) {
  CLI::App app{"clothsim render: draws a run's saved geometry again, without simulating: a dynamic run's\n"
               "DIR/frames/mesh_NNNN.obj (\"output\": {\"obj\": true}) into frame_NNNN.png, a static run's\n"
               "DIR/limit.obj into limit.png. Uses the render settings the run saved (\"render\" in\n"
               "DIR/summary.json or DIR/result.json; the defaults, with a notice, for older runs), with\n"
               "the overrides below, and the run's render.camera or else a camera framing the whole\n"
               "sequence. Writes a NEW folder (default DIR/render/) with the pictures and render.json\n"
               "(the settings used); the run's own files are not changed. An existing output folder\n"
               "is replaced only if an earlier `clothsim render` wrote it.",
               "clothsim render"};
  std::string dir, out, size, surface;
  int refine = 0;
  app.add_option("dir", dir, "Output folder of a run (with frames/mesh_*.obj or limit.obj)")->required()->type_name("DIR");
  app.add_option("--out", out, "Output folder (default DIR/render)")->type_name("DIR2");
  app.add_option("--size", size, "Image size, e.g. 960x720 (default: the run's)")->type_name("WxH");
  CLI::Option* refine_option =
      app.add_option("--refine", refine, "Refinement steps of the drawn surface, 0-4 (default: the run's)")
          ->check(CLI::Range(0, 4))
          ->type_name("K");
  app.add_option("--surface", surface,
                 "Surface drawn: method (what the run's method drew), loop_limit or flat (default: the run's)")
      ->check(CLI::IsMember({"method", "loop_limit", "flat"}))
      ->type_name("S");
  if (const int code = parse(app, argc - 1, argv + 1); code >= 0) return code;
  clothsim::RenderSavedOptions options;
  options.out = out;
  if (!size.empty() && !parse_size("--size", size, 8192, options.width, options.height)) return 1;
  if (refine_option->count() > 0) options.refine = refine;
  if (!surface.empty())
    options.surface = surface == "loop_limit" ? clothsim::DrawnSurface::loop_limit
                      : surface == "flat"     ? clothsim::DrawnSurface::flat
                                              : clothsim::DrawnSurface::method;
  return clothsim::render_saved_run(dir, options);
}

// `clothsim cache DIR`.
int cache_command(int argc, char** argv) {
  CLI::App app{"clothsim cache: a finished dynamic run's motion as a point cache for animation tools: from\n"
               "DIR/frames/mesh_NNNN.obj (\"output\": {\"obj\": true}) writes DIR/cache.pc2 (PC2, one sample\n"
               "per frame, read by Blender's Mesh Cache modifier and Houdini) and DIR/cache_rest.obj (the\n"
               "first frame with normals and texture coordinates, the object to apply it to). The scene key\n"
               "\"output\": {\"cache\": \"pc2\"} does the same at the end of the run (docs/animation_tools.md).",
               "clothsim cache"};
  std::string dir;
  app.add_option("dir", dir, "Output folder of a dynamic run (with frames/mesh_*.obj)")->required()->type_name("DIR");
  if (const int code = parse(app, argc - 1, argv + 1); code >= 0) return code;
  try {
    const clothsim::PointCacheReport r = clothsim::write_point_cache(dir);
    std::cout << "wrote " << (std::filesystem::path(dir) / "cache.pc2").string() << " (" << r.frames << " frames of "
              << r.points << " points) and cache_rest.obj\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: cache: " << e.what() << '\n';
    return 1;
  }
}

// The tolerance options of `compare` and `golden check`.
void add_tolerance_options(CLI::App& app, clothsim::ImageTolerance& tolerance, double& percent) {
  app.add_option("--tolerance", tolerance.channel,
                 "A pixel differs if one of its channels differs by more than N (of 255)")
      ->check(CLI::Range(0, 255))
      ->type_name("N")
      ->capture_default_str();
  percent = 100 * tolerance.max_fraction;
  app.add_option("--max-differing", percent, "The images are the same if at most P % of their pixels differ")
      ->check(CLI::Range(0.0, 100.0))
      ->type_name("P")
      ->capture_default_str();
}

// `clothsim compare A B [--tolerance N] [--max-differing P] [--diff PATH]`.
int compare_command(int argc, char** argv) {
  CLI::App app{"clothsim compare: compares two PNG images, or the PNG images of two folders (e.g. two runs'\n"
               "frame_NNNN.png / limit.png, or a run and its `clothsim render` output) pairwise by file\n"
               "name; an image present in one folder only counts as a difference. Prints per image the\n"
               "size, the largest and mean channel difference and the share of pixels that differ.\n"
               "Exit code 0: every image the same within the tolerance; 1: some image differs, has\n"
               "another size or is missing; 2: usage error or unreadable input.",
               "clothsim compare"};
  std::string a, b, diff;
  clothsim::ImageTolerance tolerance;
  double percent = 0;
  app.add_option("a", a, "First PNG file or folder")->required()->type_name("A");
  app.add_option("b", b, "Second PNG file or folder")->required()->type_name("B");
  add_tolerance_options(app, tolerance, percent);
  app.add_option("--diff", diff,
                 "Write the difference image(s), 4 x |A - B| per channel: a PNG file for two files; for two\n"
                 "folders a new folder with one image per pair of equal size (named as the pair) and the\n"
                 "report compare.txt (an existing folder is replaced only if it holds a compare.txt)")
      ->type_name("PATH");
  if (const int code = parse(app, argc - 1, argv + 1); code >= 0) return code == 0 ? 0 : clothsim::kExitError;
  tolerance.max_fraction = percent / 100;
  return clothsim::compare_command(a, b, tolerance, diff);
}

// `clothsim golden check|update MANIFEST [--tolerance N] [--max-differing P] [--failures DIR]`.
int golden_command(int argc, char** argv) {
  CLI::App app{"clothsim golden: golden images of your own scenes. MANIFEST lists one golden per line,\n"
               "  GOLDEN.png  SCENE.json  RENDERED  OPTIONS...\n"
               "(GOLDEN and SCENE relative to the manifest's folder, RENDERED relative to the run's output\n"
               "folder, e.g. plate/limit.png; OPTIONS further clothsim options; '#' starts a comment).\n"
               "`check` runs `clothsim SCENE --out TMP OPTIONS...` for each line in a temporary folder and\n"
               "compares RENDERED with GOLDEN (as `clothsim compare`); the rendered and difference\n"
               "images of failures and the report go to the --failures folder. Exit code 0: all pass;\n"
               "1: some golden failed; 2: usage or manifest error. `update` runs every line and, if all\n"
               "runs succeed, rewrites the goldens (each atomically; unchanged files are not touched).\n"
               "See tests/golden/README.md.",
               "clothsim golden"};
  std::string action, manifest, failures;
  clothsim::ImageTolerance tolerance;
  double percent = 0;
  app.add_option("action", action, "check or update")
      ->required()
      ->check(CLI::IsMember({"check", "update"}))
      ->type_name("ACTION");
  app.add_option("manifest", manifest, "The list of goldens")->required()->type_name("MANIFEST");
  add_tolerance_options(app, tolerance, percent);
  app.add_option("--failures", failures,
                 "check: folder for the failures' images and report, replaced by each check and removed\n"
                 "when all pass (default $TMPDIR/clothsim_golden_failures)")
      ->type_name("DIR");
  if (const int code = parse(app, argc - 1, argv + 1); code >= 0) return code == 0 ? 0 : clothsim::kExitError;
  if (action == "update") {
    for (const char* name : {"--tolerance", "--max-differing", "--failures"})
      if (app.get_option(name)->count() > 0) {
        std::cerr << "clothsim: error: " << name << " applies to `clothsim golden check` only\n";
        return clothsim::kExitError;
      }
    return clothsim::golden_update(manifest);
  }
  clothsim::GoldenCheckOptions options;
  tolerance.max_fraction = percent / 100;
  options.tolerance = tolerance;
  options.failures = failures;
  return clothsim::golden_check(manifest, options);
}

// The options that run a study's cases as tasks (app/sweep.hpp, docs/cluster.md): --plan,
// --gather, --executor, -j, --retry-failed and the Slurm options.
std::vector<CLI::Option*> add_sweep_options(CLI::App& app, clothsim::SweepCommand& sweep, std::string& plan_dir,
                                            std::string& gather_dir) {
  return {
      app.add_option("--plan", plan_dir,
                     "write the runs as tasks to DIR (plan.json, tasks.tsv);\n"
                     "alone, only plan (run each with `clothsim task DIR ID`); with --executor\n"
                     "or -j, run them there and gather")
          ->type_name("DIR"),
      app.add_option("--gather", gather_dir,
                     "build the report from the tasks in DIR that finished\n"
                     "(into the plan's --out unless --out is given), naming the missing and\n"
                     "failed ones")
          ->type_name("DIR"),
      app.add_option("--executor", sweep.executor,
                     "run the tasks here (local, the default) or as a Slurm\n"
                     "job array (slurm)")
          ->check(CLI::IsMember({"local", "slurm"}))
          ->type_name("local|slurm"),
      app.add_option("-j,--jobs", sweep.jobs,
                     "tasks at once (local: default 1, N > 1 as processes\n"
                     "through GNU parallel; slurm: the array throttle %N, default 32)")
          ->check(CLI::Range(1, 100000))
          ->type_name("N"),
      app.add_flag("--retry-failed", sweep.retry_failed,
                   "run only the tasks of the plan in --plan DIR (default\n"
                   "OUT/study_NAME.tasks, OUT/figures.tasks) that have no result, then gather"),
      app.add_flag("--dry-run", sweep.dry_run, "slurm: plan and print the job-array script without submitting"),
      app.add_flag("--no-wait", sweep.no_wait, "slurm: submit and return (gather later with --gather DIR)"),
      app.add_option("--slurm-time", sweep.slurm_time, "slurm: time limit per task")
          ->type_name("[D-]HH:MM:SS")
          ->capture_default_str(),
      app.add_option("--slurm-mem", sweep.slurm_mem, "slurm: memory per task")->type_name("SIZE")->capture_default_str(),
      app.add_option("--partition", sweep.partition, "slurm: the partition (sbatch --partition)")->type_name("NAME"),
      app.add_option("--account", sweep.account, "slurm: the account charged (sbatch --account)")->type_name("NAME"),
      app.add_option("--sbatch-arg", sweep.sbatch_args,
                     "slurm: a further sbatch option for the script, e.g.\n"
                     "--sbatch-arg=--qos=short (repeatable)")
          ->type_name("OPTION")
          ->allow_extra_args(false)};
}

// Completes `sweep` after parsing: the folders given, whether --out was, this binary.
void finish_sweep_options(CLI::App& app, char** argv, clothsim::SweepCommand& sweep, const std::string& plan_dir,
                          const std::string& gather_dir) {
  if (!plan_dir.empty()) sweep.plan = plan_dir;
  if (!gather_dir.empty()) sweep.gather = gather_dir;
  sweep.out_given = app.get_option("--out")->count() > 0;
  std::error_code ec;
  sweep.clothsim = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) sweep.clothsim = argv[0];
}

// `clothsim study convergence|stability|folds [--out DIR] [--quick] [--no-plot]`, and for `folds`
// the options that rerun it differently (--meshes, --seeds, --methods, --cases, --preset,
// --amplitude, --dt, --end).
int study_command(int argc, char** argv) {
  CLI::App app{"clothsim study: the reports of error against run time (convergence), of numerical\n"
               "stability on stiff and extreme cases (stability) and of fold counts against resolution\n"
               "(folds); see docs/studies.md.",
               "clothsim study"};
  std::string which;
  clothsim::StudyOptions options;
  std::string out = options.out_root.string();
  bool no_plot = false;
  app.add_option("study", which, "convergence, stability or folds")
      ->required()
      ->check(CLI::IsMember({"convergence", "stability", "folds"}))
      ->type_name("NAME");
  app.add_option("--out", out, "Output root; the report goes to DIR/study_<NAME>/")->type_name("DIR")->capture_default_str();
  app.add_flag("--quick", options.quick, "Run a small subset of the cases (seconds; used by the tests)");
  app.add_flag("--no-plot", no_plot, "Write the data but no PNG (no python3-matplotlib needed)");
  // `study folds` only.
  clothsim::FoldStudyArgs folds;
  double amplitude = 0.0, dt = 0.0, end = 0.0;
  std::vector<CLI::Option*> fold_options = {
      app.add_option("--meshes", folds.meshes, "folds: cylinder meshes, e.g. 26x19,38x27 (segments x rings)")
          ->type_name("SxR,..."),
      app.add_option("--seeds", folds.seeds, "folds: imperfection seeds, e.g. 1,2,3")->type_name("N,..."),
      app.add_option("--methods", folds.methods, "folds: methods, e.g. loop_kl,linear_fe,mass_spring")
          ->type_name("NAME,..."),
      app.add_option("--cases", folds.cases, "folds: twist, compress or both (comma-separated)")->type_name("NAME,..."),
      app.add_option("--preset", folds.preset, "folds: material preset (default cotton)")->type_name("NAME"),
      app.add_option("--amplitude", amplitude, "folds: imperfection amplitude [m] (default 0.5 t_eff)")->type_name("M"),
      app.add_option("--dt", dt, "folds: time step [s] (default 0.005)")->type_name("S"),
      app.add_option("--end", end, "folds: simulated time [s] (default 1, the end of the motion)")->type_name("S")};
  // Plan / task / gather and the executors: every study.
  clothsim::SweepCommand sweep;
  std::string plan_dir, gather_dir;
  add_sweep_options(app, sweep, plan_dir, gather_dir);
  if (const int code = parse(app, argc - 1, argv + 1); code >= 0) return code;
  options.out_root = out;
  options.plot = !no_plot;
  finish_sweep_options(app, argv, sweep, plan_dir, gather_dir);
  if (which != "folds")
    for (const CLI::Option* o : fold_options)
      if (o->count() > 0) {
        std::cerr << "clothsim: error: " << o->get_name() << " applies to `clothsim study folds` only\n";
        return 1;
      }
  if (which == "folds") {
    if (fold_options[5]->count() > 0) folds.amplitude = amplitude;
    if (fold_options[6]->count() > 0) folds.dt = dt;
    if (fold_options[7]->count() > 0) folds.end = end;
    return clothsim::run_fold_study_report(options, folds, sweep);
  }
  return which == "convergence" ? clothsim::run_convergence_study(options, sweep)
                                : clothsim::run_stability_study(options, sweep);
}

// `clothsim task DIR ID`.
int task_command(int argc, char** argv) {
  CLI::App app{"clothsim task: runs one task of a study planned with `clothsim study folds --plan DIR` (its\n"
               "line in DIR/tasks.tsv) into DIR/runs/ID/, published whole; a task that finished is not run\n"
               "again, one another process is running is refused. Exit code 0 when the task has its result,\n"
               "1 on an error (also written to DIR/failed/ID.txt). See docs/cluster.md.",
               "clothsim task"};
  std::string dir, id;
  app.add_option("dir", dir, "The plan's folder")->required()->type_name("DIR");
  app.add_option("id", id, "The task's id (second column of DIR/tasks.tsv)")->required()->type_name("ID");
  if (const int code = parse(app, argc - 1, argv + 1); code >= 0) return code;
  return clothsim::run_sweep_task(dir, id);
}

// `clothsim figures [N ...] [--out DIR] [--size WxH] [--quick] [--rerun]`.
int figures_command(int argc, char** argv) {
  CLI::App app{"clothsim figures: reproduces the paper's Figs. 1 and 7-12 from shipped scenes: runs the\n"
               "scenes (or reuses completed runs of the same scenes) and writes DIR/figures/figN.png\n"
               "(labelled panels), figN.md and figures.md (which scene and settings made each panel,\n"
               "fold counts); see docs/figures.md.",
               "clothsim figures"};
  clothsim::FiguresOptions options;
  std::string out = options.out_root.string(), size;
  app.add_option("figures", options.figures, "Figure numbers (1 7 8 9 10 11 12); none: all")->type_name("N ...");
  app.add_option("--out", out, "Output root; the figures go to DIR/figures/")->type_name("DIR")->capture_default_str();
  app.add_option("--size", size, "Panel size, default 480x360")->type_name("WxH");
  app.add_flag("--quick", options.quick, "Runs of 2 frames only (seconds; the panels do not show the figure)");
  app.add_flag("--rerun", options.rerun, "Run every scene again, even if a completed run of it exists");
  clothsim::SweepCommand sweep;
  std::string plan_dir, gather_dir;
  add_sweep_options(app, sweep, plan_dir, gather_dir);
  if (const int code = parse(app, argc - 1, argv + 1); code >= 0) return code;
  finish_sweep_options(app, argv, sweep, plan_dir, gather_dir);
  options.out_root = out;
  if (!size.empty()) {
    int width = 0, height = 0, used = 0;
    if (std::sscanf(size.c_str(), "%dx%d%n", &width, &height, &used) != 2 || used != static_cast<int>(size.size()) ||
        width < 16 || height < 16 || width > 4096 || height > 4096) {
      std::cerr << "clothsim: error: --size: expected WxH with 16 <= W, H <= 4096 (got \"" << size << "\")\n";
      return 1;
    }
    options.width = width;
    options.height = height;
  }
  for (int n : options.figures)
    if (std::find(clothsim::figure_numbers().begin(), clothsim::figure_numbers().end(), n) ==
        clothsim::figure_numbers().end()) {
      std::cerr << "clothsim: error: figures: no figure " << n << " (allowed: 1 7 8 9 10 11 12)\n";
      return 1;
    }
  return clothsim::run_figures(options, sweep);
}

// `clothsim fabric-test PRESET|SCENE.json [--tests cantilever,bias,cusick] [--out DIR] ...`.
int fabric_test_command(int argc, char** argv) {
  CLI::App app{"clothsim fabric-test: the standard fabric tests run virtually on a material (a preset name, or\n"
               "the \"material\" of a scene file): the cantilever bending test (ASTM D1388) along warp and\n"
               "weft, tensile tests along warp, weft and the bias (45 deg) at small strain, and the Cusick\n"
               "drape test (ISO 9073-9) on meshes of increasing refinement. Writes\n"
               "DIR/fabric_test_<name>/fabric_test.md and .csv (each result beside the law's value and the\n"
               "measured one where the preset's source has one), a picture per test and runs/; see\n"
               "docs/fabric_test.md.",
               "clothsim fabric-test"};
  clothsim::FabricTestOptions options;
  std::string out = options.out_root.string(), tests, rings;
  app.add_option("material", options.target, "A material preset (e.g. cotton_broadcloth_ortho) or a scene file")
      ->required()
      ->type_name("PRESET|SCENE.json");
  app.add_option("--tests", tests, "Comma-separated: cantilever, bias, cusick (default: all three)")->type_name("LIST");
  app.add_option("--out", out, "Output root; the report goes to DIR/fabric_test_<name>/")
      ->type_name("DIR")
      ->capture_default_str();
  app.add_option("--rings", rings,
                 "Cusick meshes, coarse to fine: rings across the hanging annulus (clamped) or of the disc (--loose) "
                 "(default 12,16,24 clamped, 16,24,32 loose)")
      ->type_name("N,N,...");
  app.add_option("--end", options.cusick_end, "Cusick: simulated time [s]")->type_name("T")->capture_default_str();
  app.add_option("--ramp", options.cusick_ramp,
                 "Cusick: gravity grows from zero over T s (the specimen lowered slowly), then --end more seconds; "
                 "0: the full weight at once")
      ->type_name("T")
      ->capture_default_str();
  app.add_option("--imperfection", options.imperfection,
                 "Cusick: a seeded imperfection of the specimen, largest normal offset A [m] (scene key imperfection)")
      ->type_name("A")
      ->capture_default_str();
  app.add_flag("--loose", options.loose,
               "Cusick: the specimen lies loose on the support disc (no upper disc clamping it, unlike the standard)");
  app.add_flag("--quick", options.quick, "Coarse meshes and short runs (seconds; the numbers are not the test's)");
  bool no_render = false;
  app.add_flag("--no-render", no_render, "Write no pictures");
  if (const int code = parse(app, argc - 1, argv + 1); code >= 0) return code;
  const auto split = [](const std::string& text) {
    std::vector<std::string> parts;
    std::string part;
    for (const char c : text + ",") {
      if (c == ',') {
        if (!part.empty()) parts.push_back(part);
        part.clear();
      } else {
        part += c;
      }
    }
    return parts;
  };
  if (!tests.empty()) options.tests = split(tests);
  if (options.quick) {
    options.rings = {6, 8};
    if (app.get_option("--end")->count() == 0) options.cusick_end = 0.2;
  }
  if (!rings.empty()) {
    options.rings.clear();
    for (const std::string& r : split(rings)) {
      std::size_t used = 0;
      int n = 0;
      try {
        n = std::stoi(r, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != r.size()) {
        std::cerr << "clothsim: error: --rings: \"" << r << "\" is not a whole number\n";
        return 1;
      }
      options.rings.push_back(n);
    }
    if (options.rings.empty()) {
      std::cerr << "clothsim: error: --rings: give at least one mesh\n";
      return 1;
    }
  }
  options.out_root = out;
  options.render = !no_render;
  return clothsim::run_fabric_test(options);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "--version") {
    std::cout << "clothsim " << CLOTHSIM_VERSION << '\n';
    return 0;
  }
  if (argc >= 2 && std::string(argv[1]) == "render") return render_command(argc, argv);
  if (argc >= 2 && std::string(argv[1]) == "study") return study_command(argc, argv);
  if (argc >= 2 && std::string(argv[1]) == "figures") return figures_command(argc, argv);
  if (argc >= 2 && std::string(argv[1]) == "task") return task_command(argc, argv);
  if (argc >= 2 && std::string(argv[1]) == "compare") return compare_command(argc, argv);
  if (argc >= 2 && std::string(argv[1]) == "cache") return cache_command(argc, argv);
  if (argc >= 2 && std::string(argv[1]) == "golden") return golden_command(argc, argv);
  if (argc >= 2 && std::string(argv[1]) == "fabric-test") return fabric_test_command(argc, argv);
  CLI::App app{
      "clothsim: Kirchhoff-Love thin-shell cloth simulator on Loop-subdivision surfaces.\n"
      "Runs the analysis described by SCENE (a JSON file, see scenes/README.md) and writes its\n"
      "results to DIR/<scene name>/: result.json, limit.obj and limit.png for a static scene;\n"
      "probes.csv, stats.csv, summary.json, frame_NNNN.png and (with output.obj) frames/ for a\n"
      "dynamic one. With --no-render no PNG is written.\n"
      "\n"
      "Other commands (each has its own --help):\n"
      "  clothsim render DIR                         draw a run's saved geometry again\n"
      "  clothsim compare A B                        compare two PNGs, or two folders' PNGs\n"
      "  clothsim cache DIR                          a run's frames as a PC2 point cache (Blender, Houdini)\n"
      "  clothsim golden check|update MANIFEST       check or rewrite golden images of scenes\n"
      "  clothsim study convergence|stability|folds  write a report (docs/studies.md)\n"
      "  clothsim figures [N ...]                    the paper's Figs. 1, 7-11 (docs/figures.md)\n"
      "  clothsim task DIR ID                        one task of a planned study (docs/cluster.md)\n"
      "  clothsim fabric-test PRESET|SCENE.json      standard fabric tests, virtually (docs/fabric_test.md)\n",
      "clothsim"};
  std::string scene;
  std::string out = "out";
  double end = 0.0;
  app.add_option("scene", scene, "Scene file (JSON)")->required()->type_name("SCENE.json");
  app.add_option("--out", out, "Output root; results go to DIR/<scene name>/")
      ->type_name("DIR")
      ->capture_default_str();
  CLI::Option* end_option =
      app.add_option("--end", end, "Dynamic scenes: simulate to time T [s] instead of time.end")->type_name("T");
  bool no_render = false, video = false;
  std::string size;
  int frames = 0;
  app.add_flag("--no-render", no_render, "Write no PNG images");
  app.add_flag("--video", video, "Also write DIR/<name>/<name>.mp4 (needs ffmpeg)");
  CLI::Option* frames_option =
      app.add_option("--frames", frames, "Dynamic scenes: simulate just long enough for N frames")->type_name("N");
  app.add_option("--size", size, "Image size, e.g. 960x720 (replaces render.width/height)")->type_name("WxH");
  std::string framing;
  app.add_option("--framing", framing,
                 "Dynamic scenes: 'motion' fixes the camera before the run (the scene's, or one framing\n"
                 "the rest shape and the boundary motions) and writes each PNG as its frame is produced;\n"
                 "'sequence' frames the whole run and writes the PNGs after it (replaces render.framing)")
      ->check(CLI::IsMember({"motion", "sequence"}))
      ->type_name("MODE");
  std::vector<std::string> overrides;
  app.add_option("--set", overrides,
                 "Override a scene key, checked like the file (repeatable): e.g. --set time.end=0.5,\n"
                 "--set material.preset=black_denim, --set boundary[0].rotation=clamped; VALUE is JSON,\n"
                 "else a string; null removes the key (scenes/README.md, \"Overrides\")")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  std::string resume;
  CLI::Option* resume_option =
      app.add_option("--resume", resume,
                     "Dynamic scenes: continue the interrupted run in DIR (e.g. out/<name>) from its\n"
                     "checkpoint.bin, with the same scene and options; the outputs end up byte-identical\n"
                     "to an uninterrupted run's (timings aside)")
          ->type_name("DIR");
  if (const int code = parse(app, argc, argv); code >= 0) return code;
  clothsim::RunOptions options;
  if (resume_option->count() > 0) {
    if (app.get_option("--out")->count() > 0) {
      std::cerr << "clothsim: error: --resume DIR names the run's folder; --out cannot be given with it\n";
      return 1;
    }
    options.resume = resume;
  }
  if (end_option->count() > 0) options.end = end;
  options.render = !no_render;
  options.video = video;
  if (frames_option->count() > 0) options.frames = frames;
  if (!framing.empty()) options.framing = framing;
  options.overrides = overrides;
  if (!size.empty()) {
    const auto x = size.find('x');
    try {
      if (x == std::string::npos) throw std::invalid_argument("no x");
      std::size_t used_w = 0, used_h = 0;
      options.width = std::stoi(size.substr(0, x), &used_w);
      options.height = std::stoi(size.substr(x + 1), &used_h);
      if (used_w != x || used_h != size.size() - x - 1 || options.width < 16 || options.height < 16 ||
          options.width > 8192 || options.height > 8192)
        throw std::invalid_argument("range");
    } catch (const std::exception&) {
      std::cerr << "clothsim: error: --size: expected WxH with 16 <= W, H <= 8192 (got \"" << size << "\")\n";
      return 1;
    }
  }
  return clothsim::run_scene_file(scene, out, options);
}

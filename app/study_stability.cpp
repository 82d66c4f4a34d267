// `clothsim study stability [--out DIR] [--quick] [--no-plot]`: runs the stability matrix of
// sim/study/stability.hpp and writes DIR/study_stability/ — results.csv, table.md, heatmap.png
// (scripts/plot_stability.py) and scenes/<case>.json (each case as a scene file, so
// `clothsim DIR/study_stability/scenes/<case>.json` reruns it). The folder is built under a
// temporary sibling name and renamed into place at the end. Exit code 1 on an error or when any
// case fails (the report is written all the same).
#include "app/output_folders.hpp"
#include "app/plotting.hpp"
#include "app/study.hpp"

#include "sim/study/report_format.hpp"
#include "sim/study/stability.hpp"

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {

namespace {

namespace fs = std::filesystem;

void log_line(const std::string& line) { std::cerr << "clothsim: " << line << std::endl; }

std::string short_number(double v) { return format_significant(v, 3); }

}  // namespace

int run_stability_study(const StudyOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const fs::path final_dir = options.out_root / "study_stability";
  const fs::path tmp = options.out_root / (".study_stability.tmp-" + std::to_string(static_cast<long>(::getpid())));
  std::vector<fs::path> created;  // output-root folders this run made (removed again on failure)
  std::error_code ec;
  try {
    created = missing_folders(options.out_root);
    const std::vector<StabilityCase> cases = stability_cases(options.quick);
    fs::create_directories(options.out_root);
    fs::remove_all(tmp);
    fs::create_directories(tmp / "scenes");
    log_line("stability study: " + std::to_string(cases.size()) + " cases" + (options.quick ? " (quick subset)" : "") +
             ", writing " + final_dir.string());

    std::vector<StabilityResult> results;
    for (size_t i = 0; i < cases.size(); ++i) {
      const StabilityCase& c = cases[i];
      write_text_file(tmp / "scenes" / (c.name + ".json"), c.scene_json);
      std::string tag = "[";
      tag += std::to_string(i + 1);
      tag += '/';
      tag += std::to_string(cases.size());
      tag += "] ";
      log_line(tag + c.name + ": " + c.description);
      StabilityResult r = run_stability_case(c, [&](const std::string& line) { log_line(tag + line); });
      log_line(tag + c.name + ": " + r.verdict() + " (" + std::to_string(r.steps) + "/" +
               std::to_string(r.planned_steps) + " steps, energy rise " + short_number(r.energy_rise) +
               ", max strain " + short_number(r.max_strain) + ", max iterations " + std::to_string(r.max_iterations) +
               ", residual " + short_number(r.residual) + ", " + short_number(r.wall_seconds) + " s)" +
               (r.pass ? "" : ": " + r.failures.front()));
      results.push_back(std::move(r));
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    write_text_file(tmp / "results.csv", stability_csv(results));
    write_text_file(tmp / "table.md", stability_markdown(results, wall));

    std::string plot_error;
    if (options.plot) {
      log_line("drawing the heat map (scripts/plot_stability.py)");
      plot_error = run_plot_script("plot_stability.py", {(tmp / "results.csv").string(), (tmp / "heatmap.png").string()});
    }
    if (const std::string warning = replace_folder(tmp, final_dir); !warning.empty()) log_line("warning: " + warning);

    std::vector<std::string> failed;
    for (const StabilityResult& r : results)
      if (!r.pass) failed.push_back(r.name);
    std::cout << "stability study: " << results.size() - failed.size() << " of " << results.size()
              << " cases pass (wall " << short_number(wall) << " s)\n"
              << "  wrote " << (final_dir / "results.csv").string() << ", table.md"
              << (options.plot && plot_error.empty() ? ", heatmap.png" : "") << " and scenes/\n";
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
  } catch (const std::exception& e) {
    fs::remove_all(tmp, ec);
    for (const fs::path& dir : created) fs::remove(dir, ec);  // deepest first; only if empty
    std::cerr << "clothsim: error: stability study: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace clothsim

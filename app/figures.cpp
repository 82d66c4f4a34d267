// `clothsim figures`: see app/figures.hpp and docs/figures.md.
#include "app/figures.hpp"

#include "app/output_folders.hpp"
#include "app/plotting.hpp"
#include "app/resources.hpp"
#include "app/run.hpp"
#include "sim/mesh/obj_io.hpp"
#include "sim/scene/scene.hpp"
#include "sim/study/fold_count.hpp"
#include "sim/study/report_format.hpp"

#include <nlohmann/json.hpp>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace clothsim {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// A shipped scene, with `patch` (a JSON merge patch, RFC 7386) applied and the name set to `id`.
struct RunSpec {
  std::string id;     // also the run's folder name
  std::string scene;  // file name in scenes/
  Json patch = Json::object();
  bool sleeve = true;  // count folds about the y axis on its panels
};

struct PanelSpec {
  std::string run;  // RunSpec::id
  double time = 0.0;  // [s]
};

struct FigureSpec {
  int number = 0;
  std::string title;    // above the montage
  std::string caption;  // the paper's caption in our words (figN.md)
  int columns = 3;
  std::vector<PanelSpec> panels;
};

const Json kBlue = Json::parse(R"({"color": [0.12, 0.25, 0.8], "back_color": [0.08, 0.12, 0.45]})");

std::vector<RunSpec> run_specs() {
  std::vector<RunSpec> runs;
  runs.push_back({"compress_denim_loop_kl_2232", "sleeve_compress_denim.json", Json::object(), true});
  Json linear = {{"method", "linear_fe"}, {"render", kBlue}};
  runs.push_back({"compress_denim_linear_fe_2232", "sleeve_compress_denim.json", linear, true});
  runs.push_back({"compress_denim_loop_kl_5856", "sleeve_compress_denim_5856.json", Json::object(), true});
  runs.push_back({"compress_denim_linear_fe_5856", "sleeve_compress_denim_5856.json", linear, true});
  runs.push_back({"catenary_black_denim", "sleeve_catenary.json", Json::object(), false});
  runs.push_back({"catenary_pink_ribbon_brown", "sleeve_catenary.json",
                  Json{{"material", {{"preset", "pink_ribbon_brown"}}}}, false});
  runs.push_back({"catenary_gray_interlock", "sleeve_catenary.json",
                  Json{{"material", {{"preset", "gray_interlock"}}}}, false});
  runs.push_back({"catenary_mesh", "sleeve_catenary.json",
                  Json{{"render", {{"wireframe", true}, {"color", {0.85, 0.85, 0.85}}, {"back_color", {0.6, 0.6, 0.6}}}}},
                  false});
  runs.push_back({"twist_cotton_494", "sleeve_twist.json", Json::object(), true});
  runs.push_back({"fig8_thin", "fig8_thin.json", Json::object(), true});
  runs.push_back({"fig8_thick", "fig8_thick.json", Json::object(), true});
  runs.push_back({"fig8_thick_stiff", "fig8_thick_stiff.json", Json::object(), true});
  // The scene's own camera cuts the top of the uncompressed sleeve: one step further back.
  runs.push_back({"metal_compress", "metal_compress.json",
                  Json{{"render", {{"camera", {{"eye", {0.27, 0.21, 0.345}}, {"target", {0, 0.09, 0}}}}}}}, true});
  runs.push_back({"sweater_on_body", "sweater_on_body.json", Json::object(), false});
  runs.push_back({"trousers_pinned", "trousers_pinned.json", Json::object(), false});
  return runs;
}

std::vector<FigureSpec> figure_specs() {
  std::vector<FigureSpec> figures;
  figures.push_back({1,
                     "Fig. 1: compressed sleeve, subdivision shell (red) vs linear FE with hinge bending (blue)",
                     "Buckling of a sleeve under axial compression. Red: the subdivision shell (loop_kl); blue: "
                     "the standard approach, linear triangles with hinge bending (linear_fe), on the same meshes "
                     "of about 2232 and 5856 vertices. The paper shows the red result reproducing the "
                     "diamond-shaped buckling pattern and the blue one changing substantially with the mesh.",
                     4,
                     {{"compress_denim_loop_kl_2232", 1.5},
                      {"compress_denim_linear_fe_2232", 1.5},
                      {"compress_denim_loop_kl_5856", 1.5},
                      {"compress_denim_linear_fe_5856", 1.5}}});
  figures.push_back({7,
                     "Fig. 7: folds of a sleeve under gravity, torsion and compression",
                     "Kinds of folds on a sleeve. Left: catenary-shaped folds under gravity. Middle: diagonal "
                     "folds from twisting one end. Right: buckling under axial compression (no gravity).",
                     3,
                     {{"catenary_black_denim", 2.0}, {"twist_cotton_494", 1.5}, {"compress_denim_loop_kl_2232", 1.5}}});
  figures.push_back({8,
                     "Fig. 8: twisted sleeves of three materials on one 1500-triangle mesh (front view)",
                     "Twisted sleeves of different materials on the same mesh of 1500 triangles. Left: a thin "
                     "material; middle: ten times thicker; right: as the middle with ten times the stretch "
                     "resistance. The number of folds follows the material although the mesh is the same.",
                     3,
                     {{"fig8_thin", 1.5}, {"fig8_thick", 1.5}, {"fig8_thick_stiff", 1.5}}});
  figures.push_back({9,
                     "Fig. 9: a sleeve under increasing torsion",
                     "A sleeve twisted further and further: fine wrinkles form first and merge into larger folds.",
                     5,
                     {{"fig8_thin", 0.1}, {"fig8_thin", 0.25}, {"fig8_thin", 0.5}, {"fig8_thin", 1.0}, {"fig8_thin", 1.5}}});
  figures.push_back({10,
                     "Fig. 10: sleeves of different materials under gravity, and the mesh",
                     "Sleeves under gravity with different material parameters; right: the mesh used (494 "
                     "vertices, 936 triangles).",
                     4,
                     {{"catenary_gray_interlock", 2.0},
                      {"catenary_pink_ribbon_brown", 2.0},
                      {"catenary_black_denim", 2.0},
                      {"catenary_mesh", 0.0}}});
  figures.push_back({11,
                     "Fig. 11: axial compression of a metal-like sleeve (with self-collision)",
                     "A sequence from the axial compression of a sleeve of a metal-like material (E t = 1e5 N/m, "
                     "nu = 0.05, 1 mm thick).",
                     5,
                     {{"metal_compress", 0.1}, {"metal_compress", 0.3}, {"metal_compress", 0.6},
                      {"metal_compress", 1.0}, {"metal_compress", 1.5}}});
  figures.push_back({12,
                     "Fig. 12: garments sewn from pattern pieces: a sweater on a body, trousers hung from their hems",
                     "Left: a woman wearing a sweater (a virtual try-on: the garment, sewn from a front, a back and "
                     "two sleeves, settles on the body and follows its arms as they rise). Right: a pair of trousers "
                     "pinned at the ends of the legs hangs under gravity, showing catenary folds and buckling.",
                     2,
                     {{"sweater_on_body", 1.5}, {"trousers_pinned", 3.0}}});
  return figures;
}

std::string fixed(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

// "cotton", or "cotton, B = 0.001157 N m" for a preset with replaced values, or the values alone.
std::string material_label(const Json& material) {
  static const std::vector<std::pair<std::string, std::string>> keys = {
      {"stretch_modulus", "E t = | N/m"}, {"bending_rigidity", "B = | N m"}, {"poisson_ratio", "nu = |"},
      {"areal_density", "rho_A = | kg/m^2"}, {"youngs_modulus", "E = | Pa"}, {"thickness", "t = | m"}};
  std::string label = material.contains("preset") ? material["preset"].get<std::string>() : std::string();
  for (const auto& [key, format] : keys) {
    if (!material.contains(key) || !material[key].is_number()) continue;
    char value[32];
    std::snprintf(value, sizeof value, "%g", material[key].get<double>());
    const size_t bar = format.find('|');
    label += (label.empty() ? "" : ", ") + format.substr(0, bar) + value + format.substr(bar + 1);
  }
  return label.empty() ? std::string("custom material") : label;
}

// What a run is: its merged scene and the facts the labels need.
struct PreparedRun {
  RunSpec spec;
  std::string scene_text;  // the merged scene (what is written to scenes/<id>.json)
  std::string method, material, surface;
  int vertices = 0;
  double fps = 30.0, end = 0.0, scene_end = 0.0;
  double wall_seconds = 0.0;  // of the run (from its summary.json)
  bool reused = false;
};

PreparedRun prepare(const RunSpec& spec, const fs::path& scenes_dir, double needed_end) {
  PreparedRun run;
  run.spec = spec;
  const fs::path source = scenes_dir / spec.scene;
  Json scene;
  try {
    scene = Json::parse(read_text_file(source));
  } catch (const Json::exception& e) {
    throw std::runtime_error(source.string() + ": " + e.what());
  }
  scene.merge_patch(spec.patch);
  scene["name"] = spec.id;
  // The run's scene is written next to the other runs': file paths in it (the mesh's and the
  // obstacles' OBJ files) are made absolute against the shipped scene's folder.
  const auto absolute = [&](Json& holder) {
    if (holder.is_object() && holder.contains("obj") && holder["obj"].is_string()) {
      const fs::path file = holder["obj"].get<std::string>();
      if (file.is_relative()) holder["obj"] = fs::absolute(scenes_dir / file).lexically_normal().string();
    }
  };
  if (scene.contains("mesh")) absolute(scene["mesh"]);
  if (scene.contains("obstacles") && scene["obstacles"].is_array())
    for (Json& o : scene["obstacles"]) absolute(o);
  if (spec.sleeve) scene["output"] = Json{{"obj", true}, {"obj_level", 1}};
  run.method = scene.value("method", std::string("loop_kl"));
  run.material = material_label(scene.value("material", Json::object()));
  const std::string surface = scene.contains("render") ? scene["render"].value("surface", std::string("method"))
                                                       : std::string("method");
  run.surface = run.method == "loop_kl" ? "limit surface"
                : surface == "loop_limit" ? "Loop limit of the flat mesh"
                                          : "flat mesh";
  run.scene_text = scene.dump(2) + "\n";
  const Scene loaded = load_scene_text(run.scene_text, source, {});
  run.vertices = loaded.problem.mesh.num_vertices();
  run.fps = loaded.problem.time.output_fps;
  run.scene_end = loaded.problem.time.end;
  if (needed_end > run.scene_end + 1e-12)
    throw std::runtime_error("figure run " + spec.id + " needs t = " + fixed(needed_end, 3) + " s but " +
                             source.string() + " ends at " + fixed(run.scene_end, 3) + " s");
  run.end = needed_end;
  return run;
}

// The stamp that says which scene and options made a run folder.
std::string stamp_of(const PreparedRun& run, const FiguresOptions& options) {
  return run.scene_text + "# end " + fixed(run.end, 6) + " size " + std::to_string(options.width) + "x" +
         std::to_string(options.height) + (options.quick ? " quick" : "") + "\n";
}

// The run's summary.json, if it says the run completed.
std::optional<Json> completed_summary(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(dir / "summary.json", ec)) return std::nullopt;
  try {
    Json summary = Json::parse(read_text_file(dir / "summary.json"));
    if (summary.value("status", std::string()) == "completed") return summary;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

// Runs `run` into root/runs/ unless a completed run of the same scene and options is there (or
// --rerun). With `reuse_only` (the gather of a sweep) it only takes a completed run, and throws
// when there is none.
void execute(PreparedRun& run, const fs::path& root, const FiguresOptions& options, bool reuse_only = false) {
  const fs::path scene_file = root / "scenes" / (run.spec.id + ".json");
  const fs::path stamp_file = root / "runs" / (run.spec.id + ".stamp");
  const fs::path dir = root / "runs" / run.spec.id;
  const std::string stamp = stamp_of(run, options);
  std::error_code ec;
  if ((!options.rerun || reuse_only) && fs::exists(stamp_file, ec) && read_text_file(stamp_file) == stamp) {
    if (const auto summary = completed_summary(dir)) {
      run.reused = true;
      run.wall_seconds = summary->value("wall_seconds", 0.0);
      if (!reuse_only) std::cerr << "clothsim: figures: run " << run.spec.id << ": reusing " << dir.string() << '\n';
      return;
    }
  }
  if (reuse_only) throw std::runtime_error("figure run " + run.spec.id + ": no completed run in " + dir.string());
  write_atomically(scene_file, run.scene_text);
  fs::remove(stamp_file, ec);
  RunOptions run_options;
  run_options.width = options.width;
  run_options.height = options.height;
  if (options.quick)
    run_options.frames = 2;
  else if (run.end <= 0.0)
    run_options.frames = 1;
  else
    run_options.end = run.end;
  std::cerr << "clothsim: figures: run " << run.spec.id << " (" << run.method << ", " << run.vertices
            << " vertices, " << run.material << ")\n";
  if (run_scene_file(scene_file, root / "runs", run_options) != 0)
    throw std::runtime_error("figure run " + run.spec.id + " failed (scene " + scene_file.string() + ")");
  const auto summary = completed_summary(dir);
  if (!summary) throw std::runtime_error("figure run " + run.spec.id + ": " + dir.string() + " did not complete");
  run.wall_seconds = summary->value("wall_seconds", 0.0);
  write_atomically(stamp_file, stamp);
}

// The frame a panel shows: index round(t · fps), clamped to the frames a quick run has.
int frame_index(const PreparedRun& run, double time, bool quick) {
  const int k = static_cast<int>(std::lround(time * run.fps));
  return quick ? std::min(k, 1) : k;
}

std::string frame_name(const char* prefix, int k, const char* suffix) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%s%04d%s", prefix, k, suffix);
  return buffer;
}

struct PanelResult {
  fs::path image;
  std::string label;
  double time = 0.0;
  std::optional<SleeveFolds> folds;
  std::string note;
};

PanelResult make_panel(const PreparedRun& run, const PanelSpec& panel, const fs::path& root, bool quick) {
  PanelResult result;
  const int k = frame_index(run, panel.time, quick);
  result.time = k / run.fps;
  const fs::path dir = root / "runs" / run.spec.id;
  result.image = dir / frame_name("frame_", k, ".png");
  std::error_code ec;
  if (!fs::exists(result.image, ec))
    throw std::runtime_error("figure run " + run.spec.id + ": " + result.image.string() + " is missing");
  if (run.spec.sleeve) {
    const fs::path obj = dir / "frames" / frame_name("mesh_", k, ".obj");
    try {
      const TriMesh mesh = read_obj(obj.string());
      result.folds = count_sleeve_folds(mesh.vertices, mesh.triangles, FoldAxis{});
    } catch (const std::exception& e) {
      result.note = std::string("folds not counted: ") + e.what();
    }
  }
  std::ostringstream label;
  label << run.method << " (" << run.surface << "), " << run.vertices << " vertices\n"
        << run.material << ", t = " << fixed(result.time, 2) << " s";
  if (result.folds) {
    const auto around = result.folds->circumferential_median;
    const auto along = result.folds->axial.median_count;
    label << "\nfolds: " << (around ? fixed(*around, 1) : std::string("-")) << " around, "
          << (along ? fixed(*along, 1) : std::string("-")) << " along";
  }
  result.label = label.str();
  return result;
}

std::string figure_markdown(const FigureSpec& figure, const std::vector<PanelResult>& panels,
                            const std::vector<const PreparedRun*>& runs, const FiguresOptions& options) {
  std::ostringstream md;
  md << "## Fig. " << figure.number << "\n\n![" << figure.title << "](fig" << figure.number << ".png)\n\n"
     << "The paper: " << figure.caption << "\n\n"
     << "| panel | run (scene file) | method (drawn surface) | vertices | material | t [s] | frame | "
        "folds around (median) | folds along (median) | run wall time [s] |\n"
     << "|---|---|---|--:|---|--:|---|--:|--:|--:|\n";
  for (size_t i = 0; i < panels.size(); ++i) {
    const PreparedRun& run = *runs[i];
    const PanelResult& p = panels[i];
    std::string around = "–", along = "–";
    if (p.folds && p.folds->circumferential_median) around = fixed(*p.folds->circumferential_median, 1);
    if (p.folds && p.folds->axial.median_count) along = fixed(*p.folds->axial.median_count, 1);
    md << "| " << i + 1 << " | `" << run.spec.id << "` (`scenes/" << run.spec.scene << "`"
       << (run.spec.patch.empty() ? std::string() : ", with `" + run.spec.patch.dump() + "`") << ") | " << run.method
       << " (" << run.surface << ") | " << run.vertices << " | " << run.material << " | " << fixed(p.time, 3) << " | `"
       << p.image.filename().string() << "` | " << around << " | " << along << " | " << fixed(run.wall_seconds, 1)
       << (run.reused ? " (earlier run)" : "") << " |\n";
  }
  md << "\nEach run's scene as run is `scenes/<run>.json` next to this file; its outputs are in `runs/<run>/`. "
     << "Panels " << options.width << " × " << options.height
     << " px. Folds are counted on the run's OBJ frame (the drawn surface refined once) with the "
        "mesh-independent counter of docs/fold_count.md: sections at 9 heights over 20–80 % of the "
        "sleeve (around) and 16 half-planes through the axis (along), prominence ≥ 2 % of the mean "
        "radius.";
  if (options.quick) md << " **Quick mode: every run is 2 frames long; the panels do not show the figure.**";
  for (const PanelResult& p : panels)
    if (!p.note.empty()) md << "\n\nNote: " << p.note;
  md << "\n";
  return md.str();
}

// Lays out the panels with scripts/montage.py into `png`.
void montage(const FigureSpec& figure, const std::vector<PanelResult>& panels, const fs::path& png) {
  Json layout = {{"title", figure.title}, {"columns", figure.columns}, {"panels", Json::array()}};
  for (const PanelResult& p : panels) layout["panels"].push_back({{"image", p.image.string()}, {"label", p.label}});
  const std::string suffix = ".tmp-" + std::to_string(::getpid());
  const fs::path layout_file = png.parent_path() / ("." + png.stem().string() + ".layout" + suffix + ".json");
  const fs::path tmp_png = png.parent_path() / ("." + png.stem().string() + suffix + ".png");
  write_text_file(layout_file, layout.dump(2));
  const std::string error = run_plot_script("montage.py", {layout_file.string(), tmp_png.string()});
  std::error_code ec;
  fs::remove(layout_file, ec);
  if (!error.empty()) {
    fs::remove(tmp_png, ec);
    throw std::runtime_error(png.string() + ": " + error);
  }
  fs::rename(tmp_png, png);
}

}  // namespace

const std::vector<int>& figure_numbers() {
  static const std::vector<int> numbers = [] {
    std::vector<int> n;
    for (const FigureSpec& f : figure_specs()) n.push_back(f.number);
    return n;
  }();
  return numbers;
}

namespace {

// The requested figures (all when none is named); throws for an unknown number.
std::vector<FigureSpec> wanted_figures(const FiguresOptions& options) {
  for (int n : options.figures)
    if (std::find(figure_numbers().begin(), figure_numbers().end(), n) == figure_numbers().end())
      throw std::invalid_argument("no figure " + std::to_string(n) + " (allowed: 1 7 8 9 10 11 12)");
  std::vector<FigureSpec> wanted;
  for (const FigureSpec& f : figure_specs())
    if (options.figures.empty() ||
        std::find(options.figures.begin(), options.figures.end(), f.number) != options.figures.end())
      wanted.push_back(f);
  return wanted;
}

// The runs the figures need, each to the latest time one of its panels shows, in run_specs() order.
std::vector<PreparedRun> prepared_runs(const std::vector<FigureSpec>& wanted) {
  std::map<std::string, double> needed;
  for (const FigureSpec& f : wanted)
    for (const PanelSpec& p : f.panels) needed[p.run] = std::max(needed[p.run], p.time);
  const fs::path scenes_dir = resource_dir("scenes");
  std::vector<PreparedRun> runs;
  for (const RunSpec& spec : run_specs())
    if (needed.count(spec.id)) runs.push_back(prepare(spec, scenes_dir, needed[spec.id]));
  return runs;
}

// Draws the figures whose runs are all in `runs` (the others are named in `skipped`) and writes
// figures.md (every figN.md present of a figure not skipped, in order).
void draw_figures(const std::vector<FigureSpec>& wanted, const std::map<std::string, PreparedRun>& runs,
                  const fs::path& root, const FiguresOptions& options, double seconds, std::vector<std::string>& skipped) {
  std::set<int> left_out;
  for (const FigureSpec& figure : wanted) {
    std::vector<PanelResult> panels;
    std::vector<const PreparedRun*> panel_runs;
    std::string missing;
    for (const PanelSpec& p : figure.panels)
      if (!runs.count(p.run) && missing.find(p.run) == std::string::npos) missing += (missing.empty() ? "" : ", ") + p.run;
    if (!missing.empty()) {
      skipped.push_back("Fig. " + std::to_string(figure.number) + " (runs " + missing + ")");
      left_out.insert(figure.number);
      continue;
    }
    for (const PanelSpec& p : figure.panels) {
      const PreparedRun& run = runs.at(p.run);
      panels.push_back(make_panel(run, p, root, options.quick));
      panel_runs.push_back(&run);
    }
    const fs::path png = root / ("fig" + std::to_string(figure.number) + ".png");
    montage(figure, panels, png);
    write_atomically(root / ("fig" + std::to_string(figure.number) + ".md"),
                     figure_markdown(figure, panels, panel_runs, options));
    std::cout << "figures: wrote " << png.string() << '\n';
  }
  // figures.md: every figN.md present, in order.
  std::string index =
      "# Figures of Thomaszewski, Wacker & Straßer (SCA 2006), reproduced by `clothsim figures`\n\n"
      "Each section says which shipped scene and settings made each panel and what was measured on it "
      "(docs/figures.md explains the set-ups).\n\n";
  for (int n : figure_numbers()) {
    const fs::path md = root / ("fig" + std::to_string(n) + ".md");
    std::error_code ec;
    if (!left_out.count(n) && fs::exists(md, ec)) index += read_text_file(md) + "\n";
  }
  if (!skipped.empty()) {
    index += "## Not drawn\n\nSome runs of this sweep did not finish (`clothsim figures --plan DIR --retry-failed` "
             "runs them):\n\n";
    for (const std::string& f : skipped) index += "- " + f + "\n";
  }
  write_atomically(root / "figures.md", index);
  std::cout << "figures: " << wanted.size() - skipped.size() << " figure(s) in " << fixed(seconds, 1) << " s; wrote "
            << (root / "figures.md").string() << '\n';
}

FiguresOptions options_of(const Json& settings) {
  FiguresOptions options;
  options.figures = settings.at("figures").get<std::vector<int>>();
  options.out_root = settings.at("out").get<std::string>();
  options.width = settings.at("width").get<int>();
  options.height = settings.at("height").get<int>();
  options.quick = settings.at("quick").get<bool>();
  options.rerun = settings.at("rerun").get<bool>();
  return options;
}

// One task: the figure run `id`, into out/figures/runs/<id>/ (or a completed one reused).
std::string run_figure_task(const nlohmann::json& settings, const std::string& id, const LogFn&) {
  const FiguresOptions options = options_of(Json(settings));
  const fs::path root = options.out_root / "figures";
  for (PreparedRun& run : prepared_runs(wanted_figures(options))) {
    if (run.spec.id != id) continue;
    fs::create_directories(root / "scenes");
    fs::create_directories(root / "runs");
    execute(run, root, options);
    return Json{{"run", id}, {"reused", run.reused}, {"wall_seconds", run.wall_seconds}}.dump(2) + "\n";
  }
  throw std::invalid_argument("the figures' plan has no run \"" + id + "\"");
}

int gather_figures(const nlohmann::json& settings, const GatherInput& input) {
  const FiguresOptions options = options_of(Json(settings));
  const fs::path root = options.out_root / "figures";
  const std::vector<FigureSpec> wanted = wanted_figures(options);
  std::map<std::string, PreparedRun> runs;
  double task_seconds = 0.0;
  for (PreparedRun& run : prepared_runs(wanted)) {
    const auto found = input.results.find(run.spec.id);
    if (found == input.results.end()) continue;
    execute(run, root, options, true);
    run.reused = Json::parse(found->second).at("reused").get<bool>();  // as the task found it
    task_seconds += run.wall_seconds;
    runs.emplace(run.spec.id, run);
  }
  std::vector<std::string> skipped;
  draw_figures(wanted, runs, root, options, input.seconds.value_or(task_seconds), skipped);
  for (const std::string& f : skipped) std::cerr << "clothsim: figures: not drawn: " << f << '\n';
  return 0;
}

}  // namespace

SweepStudy figures_sweep(const FiguresOptions& options) {
  SweepStudy study;
  study.name = "figures";
  std::vector<int> numbers;
  for (const FigureSpec& f : wanted_figures(options)) numbers.push_back(f.number);
  study.settings = nlohmann::json{{"figures", numbers},
                                  {"out", fs::absolute(options.out_root).lexically_normal().string()},
                                  {"width", options.width},
                                  {"height", options.height},
                                  {"quick", options.quick},
                                  {"rerun", options.rerun}};
  for (const PreparedRun& run : prepared_runs(wanted_figures(options))) study.ids.push_back(run.spec.id);
  return study;
}

const SweepHooks& figures_sweep_hooks() {
  static const SweepHooks hooks{"result.json", run_figure_task, gather_figures};
  return hooks;
}

int run_figures(const FiguresOptions& options, SweepCommand sweep) {
  try {
    sweep.out_root = options.out_root;
    sweep.plot = true;
    if ((sweep.gather || sweep.retry_failed) && (options.quick || options.rerun || !options.figures.empty())) {
      std::cerr << "clothsim: error: figures: " << (sweep.gather ? "--gather" : "--retry-failed")
                << " uses the plan in its folder; figure numbers, --quick and --rerun cannot be given with it\n";
      return 1;
    }
    if (!sweep.gather && !sweep.retry_failed) wanted_figures(options);  // an unknown figure before anything runs
    return run_study_command("figures", [&] { return figures_sweep(options); }, sweep);
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: figures: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace clothsim

// The clothsim command's work: scene → static solve → result.json and limit.obj, written into a
// temporary sibling folder that is renamed into place only once everything has succeeded; dynamic
// scenes are handed to run_dynamic_scene (app/dynamic_run.hpp).
#include "app/run.hpp"

#include "app/checkpoint.hpp"
#include "app/dynamic_run.hpp"
#include "app/limit_surface_drawer.hpp"
#include "app/output_folders.hpp"
#include "render/png_io.hpp"
#include "render/renderer.hpp"
#include "sim/mesh/obj_io.hpp"
#include "sim/core/layout.hpp"
#include "sim/scene/render_settings_json.hpp"
#include "sim/scene/scene.hpp"
#include "sim/setup/setup.hpp"
#include "sim/static/static_solve.hpp"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <algorithm>
#include <memory>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using OrderedJson = nlohmann::ordered_json;

void log_line(const std::string& line) { std::cerr << "clothsim: " << line << '\n'; }

OrderedJson row3(const Eigen::MatrixX3d& m, int row) {
  return OrderedJson::array({m(row, 0), m(row, 1), m(row, 2)});
}

std::string result_json(const Scene& scene, const StaticResult& result) {
  OrderedJson probes = OrderedJson::object();
  for (const Probe& p : scene.probes) {
    probes[p.name] = {{"vertex", p.vertex},
                      {"rest_position", row3(result.limit_rest, p.vertex)},
                      {"displacement", row3(result.limit_displacement, p.vertex)}};
  }
  OrderedJson out = {{"probes", probes},
                     {"vertices", scene.problem.mesh.num_vertices()},
                     {"dofs", result.dofs},
                     {"seconds", {{"assemble", result.assemble_seconds}, {"solve", result.solve_seconds}}},
                     {"overrides", scene.overrides},
                     {"drawn_surface", drawn_surface_json(scene.problem.method, scene.render)},
                     {"render", render_settings_json(scene.render)}};
  return out.dump(2) + "\n";
}

// Runs `write(tmp)` on a fresh folder `root/.<name>.tmp-<pid>`, then renames it to `root/<name>`
// (replacing an older one). On failure removes everything it created, including `root` itself
// if it did not exist before, and rethrows.
void publish(const fs::path& root, const std::string& name, const std::function<void(const fs::path&)>& write) {
  const std::string pid = std::to_string(static_cast<long>(::getpid()));
  const fs::path final_dir = root / name;
  const fs::path tmp = root / ("." + name + ".tmp-" + pid);
  const std::vector<fs::path> created = missing_folders(root);
  std::error_code ec;
  try {
    fs::create_directories(root);
    fs::remove_all(tmp);
    fs::create_directory(tmp);
    write(tmp);
    if (const std::string warning = replace_folder(tmp, final_dir); !warning.empty()) log_line("warning: " + warning);
  } catch (...) {
    fs::remove_all(tmp, ec);
    for (const fs::path& dir : created) fs::remove(dir, ec);  // deepest first; only if empty
    throw;
  }
}

void print_summary(const Scene& scene, const StaticResult& result, const fs::path& dir) {
  std::ostringstream s;
  s << std::setprecision(6);
  s << "scene " << scene.name << " (" << scene.analysis << ")\n";
  s << "  control vertices " << scene.problem.mesh.num_vertices() << ", triangles "
    << scene.problem.mesh.num_triangles() << ", free dofs " << result.dofs << "\n";
  s << "  assemble " << result.assemble_seconds << " s, solve " << result.solve_seconds << " s\n";
  for (const Probe& p : scene.probes) {
    const Eigen::MatrixX3d& u = result.limit_displacement;
    s << "  probe " << p.name << " (vertex " << p.vertex << "): displacement [" << u(p.vertex, 0) << ", "
      << u(p.vertex, 1) << ", " << u(p.vertex, 2) << "] m\n";
  }
  s << "  wrote " << (dir / "result.json").string() << ", limit.obj"
    << (std::filesystem::exists(dir / "limit.png") ? " and limit.png" : "") << "\n";
  std::cout << s.str() << std::flush;
}

void check_result(const Scene& scene, const StaticResult& result) {
  const Eigen::Index n = scene.problem.mesh.vertices.rows();
  if (result.limit_rest.rows() != n || result.limit_displacement.rows() != n)
    throw std::runtime_error(scene.file.string() + ": static analysis returned " +
                             std::to_string(result.limit_displacement.rows()) + " limit points for " +
                             std::to_string(n) + " control vertices");
}

// Shortest decimal form that reads back to the identical double, as in scene error messages
// ("0.0001", "2.0"); "nan", "inf" for those.
std::string shortest(double v) {
  if (std::isfinite(v)) return OrderedJson(v).dump();
  char buffer[16];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), v);
  return std::string(buffer, result.ptr);
}

// Applies --end to a dynamic scene; throws for a static scene or an invalid value.
void apply_end_option(Scene& scene, const RunOptions& options) {
  if (options.frames) {
    if (scene.analysis != "dynamic") throw std::runtime_error("--frames: only applies to dynamic scenes");
    if (*options.frames < 1) throw std::runtime_error("--frames: must be >= 1");
    // The last frame's time, rounded up to a whole number of steps (so that the run does not
    // warn that its end is not a multiple of time.dt: that end is this option's choice).
    const double dt = scene.problem.time.dt;
    const double last_frame = (*options.frames - 1) / scene.problem.time.output_fps;
    const double end = std::max(dt, std::ceil(last_frame / dt - 1e-9) * dt);
    scene.problem.time.end = end;
    if (const std::string problem = time_limit_problem(scene.problem.time); !problem.empty())
      throw std::runtime_error("--frames: " + problem);
    log_line("--frames " + std::to_string(*options.frames) + ": simulating to t = " + shortest(end) + " s");
  }
  if (!options.end) return;
  const double end = *options.end;
  if (scene.analysis != "dynamic")
    throw std::runtime_error("--end: only applies to dynamic scenes (" + scene.file.string() + " is " +
                             scene.analysis + ")");
  if (!(std::isfinite(end) && end > 0))
    throw std::runtime_error("--end: must be a finite number > 0 [s] (got " + shortest(end) + ")");
  if (end < scene.problem.time.dt)
    throw std::runtime_error("--end: must be >= time.dt = " + shortest(scene.problem.time.dt) + " [s] (got " +
                             shortest(end) + ")");
  log_line("--end: simulating to t = " + shortest(end) + " s instead of time.end = " +
           shortest(scene.problem.time.end) + " s");
  scene.problem.time.end = end;
  if (const std::string problem = time_limit_problem(scene.problem.time); !problem.empty())
    throw std::runtime_error("--end: " + problem);
}

// `s` as one word for a shell (single-quoted when it holds anything but [A-Za-z0-9_./=-]).
std::string shell_word(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_./=-,") ==
                        std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The options of this run that a resumed run must repeat, as command-line words (for the message
// of an interrupted run).
std::string resume_options(const RunOptions& o, const Scene& scene) {
  std::string words;
  if (o.end) words += " --end " + shortest(*o.end);
  if (o.frames) words += " --frames " + std::to_string(*o.frames);
  if (!o.render) words += " --no-render";
  if (o.video) words += " --video";
  if (o.width > 0) words += " --size " + std::to_string(o.width) + "x" + std::to_string(o.height);
  if (o.framing) words += " --framing " + *o.framing;
  for (const std::string& set : scene.overrides) words += " --set " + shell_word(set);
  return words;
}

// What a checkpoint must have been written for: the scene file's bytes (and the OBJ mesh it
// names, through the resulting vertex count) and every option that changes the outputs.
std::uint64_t run_fingerprint(const fs::path& scene_file, const Scene& scene, const RunOptions& o) {
  std::string text;
  try {
    text = read_text_file(scene_file);
  } catch (const std::exception&) {
  }
  std::uint64_t h = fnv1a(text);
  h = fnv1a(resume_options(o, scene) + "\n" + std::to_string(scene.problem.mesh.num_vertices()), h);
  return h;
}

}  // namespace

int run_scene_file(const fs::path& scene_file, const fs::path& out_root, const RunOptions& options) {
  try {
    if (out_root.empty()) throw std::runtime_error("--out: the output folder must not be empty");
    Scene scene = load_scene(scene_file, log_line, options.overrides);
    log_line("scene " + scene.name + ": " + std::to_string(scene.problem.mesh.num_vertices()) +
             " control vertices, " + std::to_string(scene.problem.mesh.num_triangles()) + " triangles");
    apply_end_option(scene, options);
    if (options.width > 0) scene.render.width = options.width;
    if (options.height > 0) scene.render.height = options.height;
    if (options.framing) scene.render.framing = *options.framing == "sequence" ? Framing::sequence : Framing::motion;
    // --resume DIR continues the run in DIR (its parent is the output root).
    fs::path root = out_root;
    std::string folder = scene.name;
    if (options.resume) {
      if (scene.analysis != "dynamic")
        throw std::runtime_error("--resume: only dynamic runs can be resumed (" + scene.file.string() + " is " +
                                 scene.analysis + ")");
      const fs::path dir = fs::path(*options.resume).lexically_normal();
      if (!fs::is_directory(dir)) throw std::runtime_error("--resume " + options.resume->string() + ": no such folder");
      root = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
      folder = dir.filename().string();
      if (folder.empty() || folder == "." || folder == "..")
        throw std::runtime_error("--resume " + options.resume->string() + ": name the run's folder, e.g. out/" +
                                 scene.name);
    }
    // One run per output folder: a second run of the same name into the same root is refused
    // while this one lives (the lock goes with the process, however it ends).
    // Folders the lock creates are removed again when the run leaves nothing in them.
    struct HeldFolder {
      std::vector<fs::path> created;
      std::unique_ptr<OutputLock> lock;
      ~HeldFolder() {
        lock.reset();
        std::error_code ec;
        for (const fs::path& dir : created) fs::remove(dir, ec);  // deepest first; only if empty
      }
    } held{missing_folders(root), nullptr};
    held.lock = std::make_unique<OutputLock>(root, folder);
    for (const std::string& line : remove_dead_temporaries(root)) log_line(line);
    if (scene.analysis == "dynamic") {
      DynamicRunOptions dynamic;
      dynamic.render = options.render;
      dynamic.video = options.video;
      dynamic.folder = folder;
      dynamic.resume = options.resume.has_value();
      dynamic.fingerprint = run_fingerprint(scene_file, scene, options);
      dynamic.resume_command = "clothsim " + shell_word(scene_file.string()) + resume_options(options, scene) + " --resume " +
                               shell_word((root / folder).string());
      return run_dynamic_scene(scene, root, dynamic);
    }

    StaticResult result;
    try {
      result = solve_static(scene.problem);
    } catch (const std::exception& e) {
      throw std::runtime_error(scene.file.string() + ": static analysis failed: " + e.what());
    }
    check_result(scene, result);

    const std::string json = result_json(scene, result);
    const Eigen::MatrixX3d deformed = result.limit_rest + result.limit_displacement;
    const std::string comment = "clothsim: deformed limit surface of scene " + scene.name;
    std::optional<render::Image> picture;
    if (options.render) {
      const LimitSurfaceDrawer drawer(*result.discretization, scene.render, scene.render.width, scene.render.height);
      const SurfaceSnapshot snapshot = drawer.snapshot(result.positions());
      render::Vec3f lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
      LimitSurfaceDrawer::extend_bounds(snapshot, lo, hi);
      render::Renderer renderer(scene.render.width, scene.render.height);
      picture = renderer.render(drawer.frame(snapshot, drawer.camera(lo, hi), lo, hi));
    }
    try {
      publish(out_root, scene.name, [&](const fs::path& dir) {
        write_text_file(dir / "result.json", json);
        write_obj((dir / "limit.obj").string(), deformed, scene.problem.mesh.triangles, comment);
        if (picture) render::write_png((dir / "limit.png").string(), *picture);
      });
    } catch (const std::exception& e) {
      throw std::runtime_error("cannot write the results to " + (out_root / scene.name).string() + ": " + e.what());
    }
    print_summary(scene, result, out_root / scene.name);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace clothsim

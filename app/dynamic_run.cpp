// The dynamic part of the clothsim command: builds the Simulator, then steps it while streaming
// probes.csv, stats.csv, OBJ frames and (with motion framing) PNG frames (flushed every step, so a
// failed or interrupted run keeps what it has written) and finally summary.json (replaced
// atomically). The Simulator is used in this file only.
#include "app/dynamic_run.hpp"

#include "app/frame_images.hpp"
#include "app/limit_surface_drawer.hpp"
#include "app/output_folders.hpp"
#include "render/renderer.hpp"

#include "sim/dynamics/simulator.hpp"
#include "sim/mesh/obj_io.hpp"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using OrderedJson = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

void log_line(const std::string& line) { std::cerr << "clothsim: " << line << '\n'; }

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Shortest decimal form that reads back to the identical double.
std::string format_double(double v) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), v);
  return std::string(buffer, result.ptr);
}

// Short human form for log lines.
std::string format_short(double v) {
  std::ostringstream s;
  s << std::setprecision(6) << v;
  return s.str();
}

// A CSV field (RFC 4180): quoted, with doubled quotes, when it holds a comma, quote or newline.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// A text file written line by line and flushed on demand; every failure throws naming the file.
class StreamFile {
 public:
  explicit StreamFile(fs::path path) : path_(std::move(path)), out_(path_, std::ios::binary) {
    if (!out_) throw std::runtime_error(path_.string() + ": cannot open the file for writing");
  }
  void line(const std::string& text) { out_ << text << '\n'; }
  void flush() {
    out_.flush();
    if (!out_) throw std::runtime_error(path_.string() + ": cannot write the file");
  }

 private:
  fs::path path_;
  std::ofstream out_;
};

// Creates a fresh, empty `root/<name>`. An older folder of that name is first renamed to
// `root/.<name>.old-<pid>` and deleted once the new one exists (restored if creating it fails).
// On failure removes the folders it created and throws.
fs::path create_output_folder(const fs::path& root, const std::string& name) {
  const fs::path final_dir = root / name;
  const fs::path old = root / ("." + name + ".old-" + std::to_string(static_cast<long>(::getpid())));
  const std::vector<fs::path> created = missing_folders(root);
  std::error_code ec;
  bool replacing = false;
  try {
    fs::create_directories(root);
    replacing = fs::exists(fs::symlink_status(final_dir));
    if (replacing) {
      fs::remove_all(old);
      fs::rename(final_dir, old);
    }
    fs::create_directory(final_dir);
  } catch (...) {
    if (replacing && !fs::exists(fs::symlink_status(final_dir, ec))) fs::rename(old, final_dir, ec);
    for (const fs::path& dir : created) fs::remove(dir, ec);  // deepest first; only if empty
    throw;
  }
  if (replacing && fs::remove_all(old, ec) == static_cast<std::uintmax_t>(-1))
    log_line("warning: could not remove the previous output " + old.string() + ": " + ec.message());
  return final_dir;
}

// Warnings about the settings, for the log and summary.json.
std::vector<std::string> settings_warnings(const Scene& scene, int steps) {
  std::vector<std::string> warnings;
  const TimeSettings& time = scene.problem.time;
  const double last = steps * time.dt;
  if (std::abs(last - time.end) > 1e-9 * time.dt)
    warnings.push_back("time.end = " + format_double(time.end) + " s is not a multiple of time.dt = " +
                       format_double(time.dt) + " s; the run ends at t = " + format_double(last) + " s");
  if (scene.write_obj_frames && time.output_fps * time.dt > 1.0 + 1e-9)
    warnings.push_back("time.output_fps = " + format_double(time.output_fps) + " exceeds 1/dt = " +
                       format_double(1.0 / time.dt) + "; some frames repeat the previous one");
  if (scene.probes.empty()) warnings.push_back("the scene has no probes; probes.csv holds only its header");
  return warnings;
}

// Running totals for summary.json.
struct RunTotals {
  int steps = 0;
  double t = 0.0;
  double rotate_ms = 0.0, assemble_ms = 0.0, solve_ms = 0.0;
  int frames = 0;
  int max_solver_iterations = 0;
  long long contact_pairs = 0, contact_impulses = 0, impact_zones = 0, contact_unresolved = 0;
  long long contact_response_iterations = 0, contact_cg_iterations = 0;
  double contact_ms = 0.0, contact_broad_ms = 0.0, contact_narrow_ms = 0.0, contact_response_ms = 0.0;
};

std::string summary_json(const Scene& scene, const RunTotals& totals, double wall_seconds,
                         const std::vector<std::string>& warnings, const std::string& status,
                         const std::string& error) {
  OrderedJson j = {{"scene", scene.name},
                   {"analysis", "dynamic"},
                   {"steps", totals.steps},
                   {"simulated_time", totals.t},
                   {"wall_seconds", wall_seconds},
                   {"seconds",
                    {{"rotate", totals.rotate_ms / 1000.0},
                     {"assemble", totals.assemble_ms / 1000.0},
                     {"solve", totals.solve_ms / 1000.0}}},
                   {"frames", totals.frames},
                   {"max_solver_iterations", totals.max_solver_iterations},
                   {"drawn_surface", drawn_surface_json(scene.problem.method, scene.render)},
                   {"warnings", warnings},
                   {"status", status}};
  if (scene.problem.has_contact())
    j["contact"] = {{"pairs_tested", totals.contact_pairs},
                    {"impulses", totals.contact_impulses},
                    {"impact_zones", totals.impact_zones},
                    {"unresolved_pairs", totals.contact_unresolved},
                    {"seconds", totals.contact_ms / 1000.0},
                    {"broad_phase_seconds", totals.contact_broad_ms / 1000.0},
                    {"narrow_phase_seconds", totals.contact_narrow_ms / 1000.0},
                    {"response_seconds", totals.contact_response_ms / 1000.0},
                    {"response_iterations", totals.contact_response_iterations},
                    {"response_cg_iterations", totals.contact_cg_iterations}};
  if (!error.empty()) j["error"] = error;
  return j.dump(2) + "\n";
}

// The streamed outputs of one run.
class Outputs {
 public:
  // `images`: the PNG frames, or null for none.
  Outputs(const Scene& scene, const fs::path& dir, FrameImages* images)
      : scene_(scene), dir_(dir), images_(images), probes_(dir / "probes.csv"), stats_(dir / "stats.csv") {
    probes_.line("step,t,name,ux,uy,uz");
    stats_.line(std::string("step,t,solver_iterations,residual,rotate_ms,assemble_ms,solve_ms,kinetic_energy,elastic_energy,external_work,boundary_work,factorizations,factor_ms") +
                (scene.problem.has_contact() ? ",contact_pairs,contact_impulses,impact_zones,contact_unresolved,contact_ms,response_iterations,response_cg_iterations" : ""));
    probes_.flush();
    stats_.flush();
    if (scene.write_obj_frames) fs::create_directory(dir / "frames");
  }

  // Probe rows and due frames for the state reached after `step` steps, at time `t` [s].
  void record_state(const Simulator& sim, int step, double t, RunTotals& totals) {
    const TimeSettings& time = scene_.problem.time;
    const bool frames_wanted = scene_.write_obj_frames || images_ != nullptr;
    const bool frame_due = frames_wanted && t >= totals.frames / time.output_fps - 1e-9 * time.dt;
    if (scene_.probes.empty() && !frame_due) return;
    if (!scene_.probes.empty()) {
      if (probe_points_.num_points() == 0) {  // the probes' surface points, once
        std::vector<int> nodes;
        for (const Probe& p : scene_.probes) nodes.push_back(p.vertex);
        probe_points_ = sim.discretization().node_points(nodes);
        probe_rest_ = sim.rest_surface_points(probe_points_);
      }
      const Eigen::MatrixX3d u = sim.surface_points(probe_points_) - probe_rest_;
      std::string prefix = std::to_string(step);
      prefix.append(1, ',').append(format_double(t)).append(1, ',');
      for (std::size_t i = 0; i < scene_.probes.size(); ++i) {
        std::string row = prefix + csv_field(scene_.probes[i].name);
        for (int k = 0; k < 3; ++k) row.append(1, ',').append(format_double(u(static_cast<Eigen::Index>(i), k)));
        probes_.line(row);
      }
      probes_.flush();
    }
    // Frame k belongs to the first state with t >= k / fps; a step longer than a frame period
    // repeats the frame so that frame k always shows time ≈ k / fps.
    bool repeated = false;
    while (frames_wanted && t >= totals.frames / time.output_fps - 1e-9 * time.dt) {
      if (scene_.write_obj_frames) {
        char file[32];
        std::snprintf(file, sizeof(file), "mesh_%04d.obj", totals.frames);
        const std::string comment = "clothsim: limit surface of scene " + scene_.name + ", frame " +
                                    std::to_string(totals.frames) + ", step " + std::to_string(step) +
                                    ", t = " + format_double(t) + " s";
        if (scene_.obj_level == 0) {
          write_obj((dir_ / "frames" / file).string(), sim.node_points(), scene_.problem.mesh.triangles, comment);
        } else {  // the surface drawn at render.refine = obj_level (render.surface), with its normals
          if (obj_surface_.num_points() == 0)
            obj_surface_ = sim.discretization().drawn_display(scene_.obj_level, scene_.render.surface);
          Eigen::MatrixX3d p, n;
          obj_surface_.evaluate(sim.discretization().control_net(sim.state().x), p, n);
          write_obj((dir_ / "frames" / file).string(), p, obj_surface_.triangles,
                    comment + " (refined " + std::to_string(scene_.obj_level) + " times: " +
                        drawn_surface_description(scene_.problem.method, scene_.render.surface, scene_.obj_level) +
                        ")",
                    &n);
        }
      }
      if (images_) {
        if (repeated) images_->repeat();
        else images_->add(sim.state().x, sim.state().t);
      }
      repeated = true;
      ++totals.frames;
    }
  }

  void record_stats(const StepStats& s) {
    std::string row = std::to_string(s.step);
    for (const std::string& field :
         {format_double(s.t), std::to_string(s.solver_iterations), format_double(s.residual),
          format_double(s.rotate_ms), format_double(s.assemble_ms), format_double(s.solve_ms),
          format_double(s.kinetic_energy), format_double(s.elastic_energy), format_double(s.external_work),
          format_double(s.boundary_work), std::to_string(s.factorizations), format_double(s.factor_ms)})
      row.append(1, ',').append(field);
    if (scene_.problem.has_contact())
      for (const std::string& field : {std::to_string(s.contact_pairs), std::to_string(s.contact_impulses),
                                       std::to_string(s.impact_zones), std::to_string(s.contact_unresolved),
                                       format_double(s.contact_ms), std::to_string(s.contact_response_iterations),
                                       std::to_string(s.contact_cg_iterations)})
        row.append(1, ',').append(field);
    stats_.line(row);
    stats_.flush();
  }

 private:
  const Scene& scene_;
  fs::path dir_;
  FrameImages* images_;
  SurfaceOperator probe_points_;  // the probes' surface points
  SurfaceOperator obj_surface_;   // output.obj_level > 0: the refined surface of the OBJ frames
  Eigen::MatrixX3d probe_rest_;   // their rest positions [m]
  StreamFile probes_;
  StreamFile stats_;
};

// Progress on stderr: a bar redrawn in place on a terminal, plain lines every 10 % otherwise.
class Progress {
 public:
  Progress(int steps, double fps) : steps_(steps), fps_(fps), terminal_(::isatty(2) != 0) {}
  void update(int step, double t, int frames, double wall) {
    const double done = static_cast<double>(step) / steps_;
    const double eta = step > 0 ? wall * (1.0 / done - 1.0) : 0.0;
    const int total_frames = static_cast<int>(std::floor(t / std::max(done, 1e-12) * fps_ + 1e-9)) + 1;
    char text[160];
    if (terminal_) {
      const int width = 30, filled = static_cast<int>(done * width);
      std::string bar(static_cast<std::size_t>(filled), '#');
      bar.resize(width, ' ');
      std::snprintf(text, sizeof(text), "\rclothsim: [%s] frame %d/%d  t = %.3f s  ETA %.0f s   ", bar.c_str(), frames,
                    total_frames, t, eta);
      std::cerr << text << (step == steps_ ? "\n" : "") << std::flush;
      return;
    }
    if (step != steps_ && step % std::max(1, (steps_ + 9) / 10) != 0) return;
    std::snprintf(text, sizeof(text), "step %d/%d (%d%%), frame %d, t = %.4g s, wall %.3g s, ETA %.3g s", step, steps_,
                  static_cast<int>(100.0 * done), frames, t, wall, eta);
    log_line(text);
  }

 private:
  int steps_;
  double fps_;
  bool terminal_;
};

// DIR/<name>.mp4 from frame_%04d.png with ffmpeg, if it is installed (a warning otherwise).
void encode_video(const fs::path& dir, const std::string& name, double fps) {
  if (std::system("command -v ffmpeg > /dev/null 2>&1") != 0) {
    log_line("warning: --video: ffmpeg is not installed; no video written");
    return;
  }
  char rate[32];
  std::snprintf(rate, sizeof(rate), "%.6g", fps);
  const std::string command = "ffmpeg -loglevel error -y -framerate " + std::string(rate) + " -i '" +
                              (dir / "frame_%04d.png").string() +
                              "' -vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' -c:v libx264 -pix_fmt yuv420p -crf 20 '" +
                              (dir / (name + ".mp4")).string() + "'";
  if (std::system(command.c_str()) != 0) throw std::runtime_error("ffmpeg failed: " + command);
  log_line("wrote " + (dir / (name + ".mp4")).string());
}

void print_summary(const Scene& scene, const Simulator& sim, const RunTotals& totals, double wall_seconds,
                   const fs::path& dir) {
  std::ostringstream s;
  s << std::setprecision(6);
  s << "scene " << scene.name << " (dynamic)\n";
  s << "  control vertices " << scene.problem.mesh.num_vertices() << ", triangles "
    << scene.problem.mesh.num_triangles() << "\n";
  s << "  steps " << totals.steps << " of dt = " << scene.problem.time.dt << " s, simulated time " << totals.t
    << " s, wall time " << wall_seconds << " s (rotate " << totals.rotate_ms / 1000.0 << " s, assemble "
    << totals.assemble_ms / 1000.0 << " s, solve " << totals.solve_ms / 1000.0 << " s)\n";
  s << "  max solver iterations per step " << totals.max_solver_iterations << "\n";
  if (!scene.probes.empty()) {
    const Eigen::MatrixX3d u = sim.node_points() - sim.node_points_rest();
    for (const Probe& p : scene.probes)
      s << "  probe " << p.name << " (vertex " << p.vertex << "): final displacement [" << u(p.vertex, 0) << ", "
        << u(p.vertex, 1) << ", " << u(p.vertex, 2) << "] m\n";
  }
  s << "  wrote " << (dir / "probes.csv").string() << ", stats.csv, summary.json";
  if (scene.write_obj_frames) s << " and " << totals.frames << " frames in frames/";
  s << "\n";
  std::cout << s.str() << std::flush;
}

}  // namespace

int run_dynamic_scene(const Scene& scene, const fs::path& out_root, bool render_frames, bool video) {
  const std::string file = scene.file.string();
  const Clock::time_point start = Clock::now();

  // Everything that can fail before the first step fails here, before any file is written.
  std::unique_ptr<Simulator> sim;
  try {
    sim = std::make_unique<Simulator>(scene.problem);
  } catch (const std::exception& e) {
    throw std::runtime_error(file + ": cannot set up the dynamic analysis: " + e.what());
  }
  // The renderer and the refinement operator, also before any file is written.
  std::unique_ptr<LimitSurfaceDrawer> drawer;
  std::unique_ptr<render::Renderer> renderer;
  Bounds motion_bounds;  // motion framing: the box framed by the camera
  if (render_frames) {
    try {
      drawer = std::make_unique<LimitSurfaceDrawer>(sim->discretization(), scene.render, scene.render.width,
                                                    scene.render.height);
      drawer->set_obstacles(scene.problem.obstacles);
      renderer = std::make_unique<render::Renderer>(scene.render.width, scene.render.height);
      if (scene.render.framing == Framing::motion)
        motion_bounds = motion_framing_bounds(*drawer, sim->discretization().rest(), scene.problem);
    } catch (const std::exception& e) {
      throw std::runtime_error(file + ": cannot set up rendering: " + e.what() + " (use --no-render to skip images)");
    }
  }
  const int steps = sim->num_steps();
  const std::vector<std::string> warnings = settings_warnings(scene, steps);
  for (const std::string& w : warnings) log_line("warning: " + w);
  log_line("dynamic analysis: " + std::to_string(steps) + " steps of dt = " + format_short(scene.problem.time.dt) +
           " s to t = " + format_short(scene.problem.time.end) + " s");

  fs::path dir;
  try {
    dir = create_output_folder(out_root, scene.name);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot create the output folder " + (out_root / scene.name).string() + ": " + e.what());
  }

  RunTotals totals;
  std::string failure;  // the error message of a failed run
  std::unique_ptr<FrameImages> images;
  std::unique_ptr<Outputs> outputs;
  try {
    write_atomically(dir / "summary.json", summary_json(scene, totals, seconds_since(start), warnings, "running", ""));
    if (drawer)
      images = std::make_unique<FrameImages>(*drawer, *renderer, scene.render.framing, motion_bounds, dir);
    outputs = std::make_unique<Outputs>(scene, dir, images.get());
    outputs->record_state(*sim, 0, sim->state().t, totals);
    Progress progress(steps, scene.problem.time.output_fps);
    for (int k = 1; k <= steps; ++k) {
      try {
        const StepStats s = sim->step();
        totals.steps = s.step;
        totals.t = s.t;
        totals.rotate_ms += s.rotate_ms;
        totals.assemble_ms += s.assemble_ms;
        totals.solve_ms += s.solve_ms;
        totals.max_solver_iterations = std::max(totals.max_solver_iterations, s.solver_iterations);
        totals.contact_pairs += s.contact_pairs;
        totals.contact_impulses += s.contact_impulses;
        totals.impact_zones += s.impact_zones;
        totals.contact_unresolved += s.contact_unresolved;
        totals.contact_ms += s.contact_ms;
        totals.contact_broad_ms += s.contact_broad_ms;
        totals.contact_narrow_ms += s.contact_narrow_ms;
        totals.contact_response_ms += s.contact_response_ms;
        totals.contact_response_iterations += s.contact_response_iterations;
        totals.contact_cg_iterations += s.contact_cg_iterations;
        outputs->record_stats(s);
        outputs->record_state(*sim, s.step, s.t, totals);
      } catch (const SimulationError&) {
        throw;
      } catch (const std::exception& e) {
        // Name the step for any other failure (write errors, solver exceptions), as SimulationError does.
        throw SimulationError(k, k * scene.problem.time.dt, e.what());
      }
      progress.update(k, totals.t, totals.frames, seconds_since(start));
    }
  } catch (const std::exception& e) {
    failure = e.what();
  }

  // Sequence framing: the images of the frames simulated so far (also after a failure), with one
  // camera for all; motion framing has written them already.
  if (images) {
    try {
      const int written = images->finish();
      log_line(std::string(scene.render.framing == Framing::motion ? "wrote " : "rendered ") +
               std::to_string(written) + " frame(s) of " + std::to_string(drawer->fine_triangles()) +
               " triangles to " + (dir / "frame_*.png").string());
      if (video && written > 0) encode_video(dir, scene.name, scene.problem.time.output_fps);
    } catch (const std::exception& e) {
      if (failure.empty()) failure = std::string("rendering failed: ") + e.what();
      else log_line("warning: rendering failed: " + std::string(e.what()));
    }
  }
  const double wall = seconds_since(start);
  try {
    write_atomically(dir / "summary.json", summary_json(scene, totals, wall, warnings,
                                                        failure.empty() ? "completed" : "failed", failure));
  } catch (const std::exception& e) {
    if (failure.empty()) failure = e.what();
    else log_line("warning: " + std::string(e.what()));
  }
  if (!failure.empty()) {
    std::cerr << "clothsim: error: " << file << ": " << failure << '\n';
    log_line("kept the outputs written so far in " + dir.string());
    return 1;
  }
  print_summary(scene, *sim, totals, wall, dir);
  return 0;
}

}  // namespace clothsim

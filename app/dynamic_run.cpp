// The dynamic part of the clothsim command: builds the Simulator, then steps it while streaming
// probes.csv, stats.csv, OBJ frames (flushed every step, so a failed or interrupted run keeps what
// it has written) and, with motion framing, PNG frames (drawn on FrameImages' drawing thread while
// the next steps are computed; every picture handed in is on disk before a checkpoint or the
// summary is written) and finally summary.json (replaced atomically). The Simulator is used in
// this file only.
#include "app/dynamic_run.hpp"

#include "app/checkpoint.hpp"
#include "app/frame_images.hpp"
#include "app/limit_surface_drawer.hpp"
#include "app/output_folders.hpp"
#include "app/point_cache.hpp"
#include "render/renderer.hpp"

#include "sim/contact/obstacle.hpp"
#include "sim/dynamics/simulator.hpp"
#include "sim/mesh/obj_io.hpp"
#include "sim/subdivision/loop.hpp"
#include "sim/scene/render_settings_json.hpp"

#include <nlohmann/json.hpp>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <csignal>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
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

// Where contact's steps spent their time (the printed summary and the settle's log line): the
// linear solves and the potential's parts [s], and the fail-safe's impulses.
std::string contact_time_parts(const ContactCounters& c) {
  return "first solves " + format_short(c.first_solve_ms / 1000.0) + " s, Newton's further solves " +
         format_short(c.newton_solve_ms / 1000.0) + " s, barrier " + format_short(c.barrier_evaluation_ms() / 1000.0) +
         " s, CCD line search " + format_short(c.line_search_ms / 1000.0) + " s, candidate search " +
         format_short(c.candidates_ms / 1000.0) + " s, fail-safe " + format_short(c.failsafe_ms / 1000.0) + " s (" +
         std::to_string(c.impulses) + " impulses)";
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
  // `append`: continue the file (a resumed run), else start it afresh.
  StreamFile(fs::path path, bool append)
      : path_(std::move(path)), out_(path_, std::ios::binary | (append ? std::ios::app : std::ios::trunc)) {
    if (!out_) throw std::runtime_error(path_.string() + ": cannot open the file for writing");
    out_.seekp(0, std::ios::end);
    good_bytes_ = static_cast<std::uintmax_t>(out_.tellp());
  }
  void line(const std::string& text) { out_ << text << '\n'; }
  // Writes the lines so far; if that fails (a full disk), cuts the file back to the last whole
  // flush, so that it never ends in part of a row, and throws naming the file.
  void flush() {
    out_.flush();
    if (!out_) {
      std::error_code ec;
      fs::resize_file(path_, good_bytes_, ec);
      throw std::runtime_error(path_.string() + ": cannot write the file" + (ec ? "" : " (cut back to its last whole row)"));
    }
    good_bytes_ = static_cast<std::uintmax_t>(out_.tellp());
  }
  // The file's length after a flush [bytes].
  std::uintmax_t bytes() {
    flush();
    return good_bytes_;
  }

 private:
  fs::path path_;
  std::ofstream out_;
  std::uintmax_t good_bytes_ = 0;
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


// The linear solver the run used: the scene's settings with "auto" resolved as the simulator
// resolves it (LinearSolver's constructor, for 3 unknowns per control vertex).
OrderedJson solver_json(const Problem& problem) {
  const LinearSolverSettings& given = problem.solver;
  const LinearSolverSettings used = resolve_automatic(given, 3 * static_cast<Eigen::Index>(problem.mesh.num_vertices()));
  OrderedJson j = {{"type", to_string(used.type)}};
  if (used.type == LinearSolverType::pcg) {
    j["preconditioner"] = to_string(used.preconditioner);
    j["tolerance"] = used.tolerance;
  }
  OrderedJson automatic = OrderedJson::array();
  if (given.type == LinearSolverType::automatic) automatic.push_back("type");
  if (used.type == LinearSolverType::pcg && given.preconditioner == PreconditionerType::automatic)
    automatic.push_back("preconditioner");
  j["chosen_automatically"] = automatic;
  return j;
}

std::string summary_json(const Scene& scene, const RunTotals& totals, const SettleReport& settle, double wall_seconds,
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
                   {"solver", solver_json(scene.problem)},
                   {"drawn_surface", drawn_surface_json(scene.problem.method, scene.render)},
                   {"render", render_settings_json(scene.render)},
                   {"overrides", scene.overrides},
                   {"warnings", warnings},
                   {"status", status}};
  if (scene.problem.settle.time > 0)
    j["settle"] = {{"time", scene.problem.settle.time},
                   {"steps", settle.steps},
                   {"membrane_strain_start", settle.strain_start},
                   {"membrane_strain_end", settle.strain_end},
                   {"seam_gap_start", settle.gap_start},
                   {"seam_gap_end", settle.gap_end},
                   // Its steps' time, booked as the run's (the "contact" keys below).
                   {"step_seconds", settle.step_ms / 1000.0},
                   {"solver_iterations", settle.solver_iterations},
                   {"factorizations", settle.factorizations},
                   {"newton_iterations", settle.contact.newton_iterations},
                   {"relinearisations", settle.contact.relinearisations},
                   {"first_solve_seconds", settle.contact.first_solve_ms / 1000.0},
                   {"newton_solve_seconds", settle.contact.newton_solve_ms / 1000.0},
                   {"barrier_seconds", settle.contact.potential_ms / 1000.0},
                   {"barrier_evaluation_seconds", settle.contact.barrier_evaluation_ms() / 1000.0},
                   {"line_search_seconds", settle.contact.line_search_ms / 1000.0},
                   {"candidates_seconds", settle.contact.candidates_ms / 1000.0},
                   {"failsafe_seconds", settle.contact.failsafe_ms / 1000.0},
                   {"impulses", settle.contact.impulses},
                   {"unresolved_pairs", settle.contact.unresolved}};
  if (scene.problem.has_contact())
    j["contact"] = {{"pairs_tested", totals.contact.pairs_tested},
                    {"impulses", totals.contact.impulses},
                    {"impact_zones", totals.contact.impact_zones},
                    {"unresolved_pairs", totals.contact.unresolved},
                    {"seconds", totals.contact.ms / 1000.0},
                    {"broad_phase_seconds", totals.contact.broad_ms / 1000.0},
                    {"narrow_phase_seconds", totals.contact.narrow_ms / 1000.0},
                    {"response_seconds", totals.contact.response_ms / 1000.0},
                    {"response_iterations", totals.contact.response_iterations},
                    {"response_cg_iterations", totals.contact.response_cg_iterations},
                    {"response_factorizations", totals.contact.response_factorizations},
                    {"method", scene.problem.collision.barrier ? "barrier" : "constraints"},
                    {"barrier_seconds", totals.contact.potential_ms / 1000.0},
                    {"newton_iterations", totals.contact.newton_iterations},
                    {"relinearisations", totals.contact.relinearisations},
                    // Where a step's time goes (docs/performance.md, "Where a garment's step goes"):
                    // the linear solves of steps with contact, the step's first one and Newton's
                    // further ones, and the potential's parts.
                    {"barrier_evaluation_seconds", totals.contact.barrier_evaluation_ms() / 1000.0},
                    {"first_solve_seconds", totals.contact.first_solve_ms / 1000.0},
                    {"newton_solve_seconds", totals.contact.newton_solve_ms / 1000.0},
                    {"line_search_seconds", totals.contact.line_search_ms / 1000.0},
                    {"candidates_seconds", totals.contact.candidates_ms / 1000.0},
                    {"failsafe_seconds", totals.contact.failsafe_ms / 1000.0},
                    {"contact_steps", totals.contact.contact_steps},
                    {"contact_step_seconds", totals.contact.contact_step_ms / 1000.0},
                    {"free_steps", totals.steps - totals.contact.contact_steps},
                    {"free_step_seconds", totals.contact.free_step_ms / 1000.0}};
  if (!error.empty()) j["error"] = error;
  return j.dump(2) + "\n";
}

// The streamed outputs of one run.
class Outputs {
 public:
  // `images`: the PNG frames, or null for none.
  // `resume`: continue the CSV files of a resumed run (already cut to the checkpoint's lengths).
  Outputs(const Scene& scene, const fs::path& dir, FrameImages* images, bool resume)
      : scene_(scene), dir_(dir), images_(images), probes_(dir / "probes.csv", resume), stats_(dir / "stats.csv", resume) {
    if (resume) return;
    probes_.line("step,t,name,ux,uy,uz");
    stats_.line(std::string("step,t,solver_iterations,residual,rotate_ms,assemble_ms,solve_ms,kinetic_energy,elastic_energy,external_work,boundary_work,factorizations,factor_ms,direct_fallbacks") +
                (scene.problem.has_contact() ? ",contact_pairs,contact_impulses,impact_zones,contact_unresolved,contact_ms,response_iterations,response_cg_iterations,response_factorizations,contact_newton_iterations,contact_active_pairs,contact_energy,contact_relinearisations,step_ms,first_solve_ms,newton_solve_ms,barrier_ms,line_search_ms,candidates_ms,failsafe_ms" : ""));
    probes_.flush();
    stats_.flush();
    if (scene.write_obj_frames) fs::create_directory(dir / "frames");
  }

  // Probe rows and due frames for the state reached after `step` steps, at time `t` [s]; writes
  // out the stats row record_stats() gave for that step too.
  void record_state(const Simulator& sim, int step, double t, RunTotals& totals) {
    const TimeSettings& time = scene_.problem.time;
    const bool frames_wanted = scene_.write_obj_frames || images_ != nullptr;
    const bool frame_due = frames_wanted && t >= totals.frames / time.output_fps - 1e-9 * time.dt;
    if (scene_.probes.empty() && !frame_due) {
      stats_.flush();
      return;
    }
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
    }
    // The step's stats row (record_stats) and probe rows go out together, once both are ready,
    // so that a process killed outright (SIGKILL) is very unlikely to leave one file a step
    // ahead of the other (--resume cuts both back to its checkpoint anyway).
    stats_.flush();
    probes_.flush();
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
          const auto& uv = scene_.problem.mesh.uv;  // a pattern's coordinates, or the OBJ's vt
          write_obj((dir_ / "frames" / file).string(), sim.node_points(), scene_.problem.mesh.triangles, comment, nullptr,
                    uv.size() == scene_.problem.mesh.triangles.size() ? &uv : nullptr);
        } else {  // the surface drawn at render.refine = obj_level (render.surface), with its normals
          if (obj_surface_.num_points() == 0) {
            obj_surface_ = sim.discretization().drawn_display(scene_.obj_level, scene_.render.surface);
            // The fine triangles' texture coordinates: each control triangle's, split as it is.
            const auto& uv = scene_.problem.mesh.uv;
            if (uv.size() == scene_.problem.mesh.triangles.size() &&
                obj_surface_.triangles.size() == uv.size() << (2 * obj_surface_.levels))
              obj_uv_ = refine_corner_uv(uv, obj_surface_.levels);
          }
          Eigen::MatrixX3d p, n;
          obj_surface_.evaluate(sim.discretization().control_net(sim.state().x), p, n);
          write_obj((dir_ / "frames" / file).string(), p, obj_surface_.triangles,
                    comment + " (refined " + std::to_string(scene_.obj_level) + " times: " +
                        drawn_surface_description(scene_.problem.method, scene_.render.surface, scene_.obj_level) +
                        ")",
                    &n, obj_uv_.empty() ? nullptr : &obj_uv_);
        }
        // The obstacles (every one but planes) as they stand at this frame, as the contact sees them:
        // `check_intersections mesh_NNNN.obj obstacles_NNNN.obj` checks a frame against them.
        std::vector<const Obstacle*> meshes;
        for (const Obstacle& o : scene_.problem.obstacles)
          if (o.shape != Obstacle::Shape::plane && o.mesh.num_triangles() > 0) meshes.push_back(&o);
        if (!meshes.empty()) {
          Eigen::Index rows = 0;
          for (const Obstacle* o : meshes) rows += o->mesh.vertices.rows();
          Eigen::MatrixX3d vertices(rows, 3);
          std::vector<Triangle> triangles;
          Eigen::Index offset = 0;
          std::string names;
          for (const Obstacle* o : meshes) {
            vertices.middleRows(offset, o->mesh.vertices.rows()) = mesh_at(*o, t);
            for (const Triangle& tri : o->mesh.triangles)
              triangles.push_back({tri[0] + static_cast<int>(offset), tri[1] + static_cast<int>(offset), tri[2] + static_cast<int>(offset)});
            offset += o->mesh.vertices.rows();
            names += (names.empty() ? "" : ", ") + o->name;
          }
          std::snprintf(file, sizeof(file), "obstacles_%04d.obj", totals.frames);
          write_obj((dir_ / "frames" / file).string(), vertices, triangles,
                    "clothsim: obstacles of scene " + scene_.name + " (" + names + "), frame " + std::to_string(totals.frames) +
                        ", t = " + format_double(t) + " s");
        }
      }
      if (images_) {
        if (repeated) images_->repeat(step);
        else images_->add(sim.state().x, sim.state().t, step);
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
          format_double(s.boundary_work), std::to_string(s.factorizations), format_double(s.factor_ms),
          std::to_string(s.direct_fallbacks)})
      row.append(1, ',').append(field);
    if (scene_.problem.has_contact())
      for (const std::string& field :
           {std::to_string(s.contact.pairs_tested), std::to_string(s.contact.impulses), std::to_string(s.contact.impact_zones),
            std::to_string(s.contact.unresolved), format_double(s.contact.ms), std::to_string(s.contact.response_iterations),
            std::to_string(s.contact.response_cg_iterations), std::to_string(s.contact.response_factorizations),
            std::to_string(s.contact.newton_iterations), std::to_string(s.contact_active_pairs), format_double(s.contact_energy),
            std::to_string(s.contact.relinearisations), format_double(s.step_ms), format_double(s.contact.first_solve_ms),
            format_double(s.contact.newton_solve_ms),
            format_double(s.contact.barrier_evaluation_ms()),
            format_double(s.contact.line_search_ms), format_double(s.contact.candidates_ms),
            format_double(s.contact.failsafe_ms)})
        row.append(1, ',').append(field);
    stats_.line(row);  // flushed by record_state, together with the probes
  }

  std::uintmax_t probes_bytes() { return probes_.bytes(); }
  std::uintmax_t stats_bytes() { return stats_.bytes(); }

 private:
  const Scene& scene_;
  fs::path dir_;
  FrameImages* images_;
  SurfaceOperator probe_points_;  // the probes' surface points
  SurfaceOperator obj_surface_;   // output.obj_level > 0: the refined surface of the OBJ frames
  std::vector<std::array<Eigen::Vector2d, 3>> obj_uv_;  // its texture coordinates (empty: none)
  Eigen::MatrixX3d probe_rest_;   // their rest positions [m]
  StreamFile probes_;
  StreamFile stats_;
};

// Progress on stderr: a bar redrawn in place on a terminal, plain lines every 10 % otherwise. The
// ETA extrapolates the wall time per step of this session (a resumed run counts from its first
// step) and adds the pictures still to draw after the run (sequence framing).
class Progress {
 public:
  // `first_step`: the step the session starts from; `render_seconds_per_frame`: the time to draw
  // one picture after the run (0 when pictures are drawn during the run).
  Progress(int steps, double fps, int first_step, double render_seconds_per_frame)
      : steps_(steps), first_(first_step), fps_(fps), render_per_frame_(render_seconds_per_frame),
        terminal_(::isatty(2) != 0) {}
  void update(int step, double t, int frames, double wall) {
    const double done = static_cast<double>(step) / steps_;
    const int total_frames = static_cast<int>(std::floor(t / std::max(done, 1e-12) * fps_ + 1e-9)) + 1;
    const double eta = (step > first_ ? wall / (step - first_) * (steps_ - step) : 0.0) +
                       render_per_frame_ * total_frames;
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
  int steps_, first_;
  double fps_, render_per_frame_;
  bool terminal_;
};

// SIGINT and SIGTERM during the steps: the first one asks the run to stop after the current step
// (it then writes a checkpoint and marks itself "interrupted"); a second one ends the process at
// once, as without the handler.
volatile std::sig_atomic_t g_interrupt = 0;

extern "C" void on_interrupt(int signal_number) {
  if (g_interrupt != 0) {
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
    return;
  }
  g_interrupt = signal_number;
}

class InterruptHandlers {
 public:
  InterruptHandlers() {
    g_interrupt = 0;
    struct sigaction action {};
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    ::sigaction(SIGINT, &action, &old_int_);
    ::sigaction(SIGTERM, &action, &old_term_);
  }
  ~InterruptHandlers() {
    ::sigaction(SIGINT, &old_int_, nullptr);
    ::sigaction(SIGTERM, &old_term_, nullptr);
  }
  InterruptHandlers(const InterruptHandlers&) = delete;
  InterruptHandlers& operator=(const InterruptHandlers&) = delete;

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

// Motion framing draws its pictures on a thread of their own while the simulation goes on
// (FrameImages); CLOTHSIM_RENDER_THREAD=0 draws them on the simulating thread instead, as each
// frame comes (the same bytes; for tests and for comparing).
bool drawing_thread() {
  const char* setting = std::getenv("CLOTHSIM_RENDER_THREAD");
  return setting == nullptr || std::string(setting) != "0";
}

// A frame's picture that failed, reported like any failure in a step, "step N (t = ...): ...",
// with the step whose state the frame showed (the drawing thread may report it a frame or two
// later); the picture of the initial state, drawn before the first step: the message alone.
[[noreturn]] void throw_picture_failure(const FramePictureError& e, double dt) {
  if (e.step() == 0) throw std::runtime_error(e.what());
  throw SimulationError(e.step(), e.step() * dt, e.what());
}

// DIR/<name>.mp4 from frame_%04d.png with ffmpeg, if it is installed (a warning otherwise).
void encode_video(const fs::path& dir, const std::string& name, double fps) {
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
  if (scene.problem.has_contact()) {
    // The whole step where contact acted against one where it did not (a free step of the same
    // scene), and where the contact steps' time went.
    const ContactCounters& c = totals.contact;
    const long long free_steps = totals.steps - c.contact_steps;
    s << "  contact: " << c.contact_steps << " steps with contact, " << free_steps << " without";
    if (c.contact_steps > 0) s << "; a step with contact " << c.contact_step_ms / static_cast<double>(c.contact_steps) << " ms";
    if (free_steps > 0) s << ", without " << c.free_step_ms / static_cast<double>(free_steps) << " ms";
    if (c.contact_steps > 0 && free_steps > 0 && c.free_step_ms > 0)
      s << " (" << (c.contact_step_ms / static_cast<double>(c.contact_steps)) / (c.free_step_ms / static_cast<double>(free_steps))
        << " times)";
    s << "\n";
    if (c.contact_steps > 0)
      s << "  contact steps: " << static_cast<double>(c.newton_iterations) / static_cast<double>(c.contact_steps)
        << " Newton solves each; of all steps' time: " << contact_time_parts(c) << "\n";
  }
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

int run_dynamic_scene(const Scene& scene, const fs::path& out_root, const DynamicRunOptions& options) {
  const std::string file = scene.file.string();
  const Clock::time_point start = Clock::now();
  const bool render_frames = options.render;
  const std::string folder = options.folder.empty() ? scene.name : options.folder;
  const fs::path run_dir = out_root / folder;
  if (options.video && std::system("command -v ffmpeg > /dev/null 2>&1") != 0)
    throw std::runtime_error("--video: ffmpeg is not installed (Debian: apt install ffmpeg); nothing was run");
  if (options.video && !render_frames) throw std::runtime_error("--video: needs the PNG frames (drop --no-render)");

  // A resumed run: its checkpoint, checked against the scene and options before anything changes.
  std::optional<RunCheckpoint> resume;
  if (options.resume) {
    const fs::path path = run_dir / "checkpoint.bin";
    if (!fs::exists(path)) {
      std::string why = "no checkpoint to resume from";
      try {
        const auto summary = nlohmann::json::parse(read_text_file(run_dir / "summary.json"));
        if (summary.value("status", "") == "completed") why = "the run is complete; nothing to resume";
      } catch (const std::exception&) {
      }
      throw std::runtime_error("--resume " + run_dir.string() + ": " + why +
                               " (checkpoints are written every output.checkpoint_every frames and when a run is "
                               "interrupted with Ctrl-C or SIGTERM)");
    }
    resume = read_checkpoint(path);
    if (resume->fingerprint != options.fingerprint)
      throw std::runtime_error("--resume " + run_dir.string() + ": the checkpoint was written for another scene or " +
                               "other options; resume with the same scene file (unchanged) and the same options "
                               "(--end, --frames, --size, --framing, --no-render, --set)");
  }

  // Everything that can fail before the first step fails here, before any file is written.
  std::unique_ptr<Simulator> sim;
  try {
    sim = std::make_unique<Simulator>(scene.problem);
    if (resume) sim->restore(resume->sim);
  } catch (const std::exception& e) {
    throw std::runtime_error(file + ": cannot set up the dynamic analysis: " + e.what());
  }
  if (scene.problem.settle.time > 0) {
    const SettleReport& settle = sim->settle_report();
    log_line("settled for " + format_short(scene.problem.settle.time) + " s (" + std::to_string(settle.steps) +
             " steps, loads off, obstacles held, no pins): largest membrane strain " +
             format_short(100 * settle.strain_start) + " % at the start, " + format_short(100 * settle.strain_end) +
             " % at the end; largest seam gap (a control edge longer than in the pattern) " +
             format_short(settle.gap_start) + " m at the start, " + format_short(settle.gap_end) + " m at the end");
    if (scene.problem.has_contact()) {
      const ContactCounters& c = settle.contact;
      log_line("settle: " + format_short(settle.step_ms / 1000.0) + " s in its steps, " +
               std::to_string(c.newton_iterations) + " Newton solves (" + std::to_string(c.relinearisations) +
               " re-linearised); " + contact_time_parts(c));
    }
  }
  // The renderer and the refinement operator, also before any file is written.
  std::unique_ptr<LimitSurfaceDrawer> drawer;
  std::unique_ptr<render::Renderer> renderer;
  Bounds motion_bounds;  // motion framing: the box framed by the camera
  double render_seconds_per_frame = 0.0;  // sequence framing: for the ETA
  if (render_frames) {
    try {
      drawer = std::make_unique<LimitSurfaceDrawer>(sim->discretization(), scene.render, scene.render.width,
                                                    scene.render.height);
      drawer->set_obstacles(scene.problem.obstacles);
      renderer = std::make_unique<render::Renderer>(scene.render.width, scene.render.height);
      if (scene.render.framing == Framing::motion) {
        motion_bounds = motion_framing_bounds(*drawer, sim->discretization().rest(), scene.problem);
      } else {  // one picture of the rest shape, timed, for the ETA of the pictures drawn after the run
        const Clock::time_point t0 = Clock::now();
        const SurfaceSnapshot rest = drawer->snapshot(sim->discretization().rest());
        Bounds b;
        LimitSurfaceDrawer::extend_bounds(rest, b.lo, b.hi);
        (void)renderer->render(drawer->frame(rest, drawer->camera(b.lo, b.hi), b.lo, b.hi));
        render_seconds_per_frame = seconds_since(t0);
      }
    } catch (const std::exception& e) {
      throw std::runtime_error(file + ": cannot set up rendering: " + e.what() + " (use --no-render to skip images)");
    }
  }
  const int steps = sim->num_steps();
  const int first_step = resume ? resume->sim.state.step : 0;
  if (first_step > steps)
    throw std::runtime_error("--resume " + run_dir.string() + ": the checkpoint is at step " +
                             std::to_string(first_step) + ", beyond the run's " + std::to_string(steps) + " steps");
  std::vector<std::string> warnings = settings_warnings(scene, steps);
  if (const long long joined = sim->contact_joined_at_rest(); joined > 0)
    warnings.push_back("contact: " + std::to_string(joined) +
                       " pairs of drawn triangles touch at rest without being neighbours in the mesh (a surface that "
                       "meets itself, such as a panel rolled to almost 360 degrees); they make no contact pairs: the "
                       "cloth is taken to be joined there");
  for (const std::string& w : warnings) log_line("warning: " + w);
  std::vector<int> unresolved_steps;  // steps that ended with contact pairs still colliding
  std::vector<int> fallback_steps;    // steps whose linear solve the direct solver finished
  if (resume)
    log_line("resuming " + run_dir.string() + " at step " + std::to_string(first_step) + " (t = " +
             format_short(resume->sim.state.t) + " s) of " + std::to_string(steps));
  else
    log_line("dynamic analysis: " + std::to_string(steps) + " steps of dt = " + format_short(scene.problem.time.dt) +
             " s to t = " + format_short(scene.problem.time.end) + " s");

  fs::path dir;
  if (resume) {
    // Back to the checkpoint: the CSV files cut to its lengths, later frames and leftovers removed.
    dir = run_dir;
    try {
      for (const auto& [name, bytes] : {std::pair{"probes.csv", resume->probes_bytes}, {"stats.csv", resume->stats_bytes}}) {
        if (fs::file_size(dir / name) < bytes)
          throw std::runtime_error((dir / name).string() + " is shorter than the checkpoint says");
        fs::resize_file(dir / name, bytes);
      }
      const int frames = resume->totals.frames;
      auto remove_from = [](const fs::path& folder_path, const std::string& prefix, const std::string& extension, int first) {
        std::error_code ec;
        for (const auto& entry : fs::directory_iterator(folder_path, ec)) {
          const std::string name = entry.path().filename().string();
          if (name.rfind(prefix, 0) != 0 || entry.path().extension() != extension) continue;
          const std::string number = name.substr(prefix.size(), name.size() - prefix.size() - extension.size());
          if (!number.empty() && number.find_first_not_of("0123456789") == std::string::npos && std::stoi(number) >= first)
            fs::remove(entry.path());
        }
      };
      remove_from(dir, "frame_", ".png", render_frames && scene.render.framing == Framing::motion ? resume->images_written : 0);
      if (scene.write_obj_frames) {
        fs::create_directories(dir / "frames");
        remove_from(dir / "frames", "mesh_", ".obj", frames);
        remove_from(dir / "frames", "obstacles_", ".obj", frames);
        remove_temporary_files(dir / "frames");
      }
      remove_temporary_files(dir);
    } catch (const std::exception& e) {
      throw std::runtime_error("--resume " + run_dir.string() + ": cannot go back to the checkpoint: " + e.what());
    }
  } else {
    try {
      dir = create_output_folder(out_root, folder);
    } catch (const std::exception& e) {
      throw std::runtime_error("cannot create the output folder " + run_dir.string() + ": " + e.what());
    }
  }

  RunTotals totals = resume ? resume->totals : RunTotals{};
  const double wall_before = resume ? resume->wall_seconds : 0.0;
  auto wall = [&] { return wall_before + seconds_since(start); };
  std::string failure;  // the error message of a failed run
  int interrupted = 0;  // the signal that interrupted the run
  std::unique_ptr<FrameImages> images;
  std::unique_ptr<Outputs> outputs;
  const fs::path checkpoint_path = dir / "checkpoint.bin";
  auto write_run_checkpoint = [&] {
    RunCheckpoint c;
    c.fingerprint = options.fingerprint;
    c.sim = sim->checkpoint();
    c.totals = totals;
    c.wall_seconds = wall();
    c.probes_bytes = outputs->probes_bytes();
    c.stats_bytes = outputs->stats_bytes();
    if (images) {
      const FrameResume r = images->resume_point();
      c.images_written = r.written;
      c.spool_bytes = r.spool_bytes;
      for (int k = 0; k < 3; ++k) {
        c.bounds_lo[k] = r.bounds.lo[k];
        c.bounds_hi[k] = r.bounds.hi[k];
      }
    }
    write_checkpoint(checkpoint_path, c);
  };
  const InterruptHandlers handlers;  // until the summary is written
  {
    try {
      // The "running" summary is padded with spaces, so that the final one can still be written
      // over it in place if the disk fills up (overwrite_in_place).
      write_atomically(dir / "summary.json", summary_json(scene, totals, sim->settle_report(), wall(), warnings, "running", "") +
                                                 std::string(4096, ' ') + "\n");
      if (drawer) {
        FrameResume r;
        if (resume) {
          r.frames = resume->totals.frames;
          r.written = resume->images_written;
          for (int k = 0; k < 3; ++k) {
            r.bounds.lo[k] = resume->bounds_lo[k];
            r.bounds.hi[k] = resume->bounds_hi[k];
          }
          r.spool_bytes = resume->spool_bytes;
          r.state_size = sim->state().x.size();
        }
        images = std::make_unique<FrameImages>(*drawer, *renderer, scene.render.framing, motion_bounds, dir,
                                               resume ? &r : nullptr, drawing_thread());
      }
      outputs = std::make_unique<Outputs>(scene, dir, images.get(), resume.has_value());
      if (!resume) outputs->record_state(*sim, 0, sim->state().t, totals);
      Progress progress(steps, scene.problem.time.output_fps, first_step, render_seconds_per_frame);
      for (int k = first_step + 1; k <= steps; ++k) {
        try {
          const StepStats s = sim->step();
          totals.steps = s.step;
          totals.t = s.t;
          totals.rotate_ms += s.rotate_ms;
          totals.assemble_ms += s.assemble_ms;
          totals.solve_ms += s.solve_ms;
          totals.max_solver_iterations = std::max(totals.max_solver_iterations, s.solver_iterations);
          totals.contact += s.contact;
          if (s.contact.unresolved > 0) {
            // The fail-safe gave up on these pairs: the surfaces may cross from this step on.
            unresolved_steps.push_back(s.step);
            log_line("warning: step " + std::to_string(s.step) + " (t = " + format_short(s.t) + " s): " +
                     std::to_string(s.contact.unresolved) +
                     " contact pair(s) still colliding at the end of the step; frames from this time on may show "
                     "crossing surfaces (stats.csv: contact_unresolved)");
          }
          if (s.direct_fallbacks > 0) {
            // Conjugate gradients failed and the direct solver finished the solve (LinearSolver::solve):
            // the step is as accurate as with "cholmod", but a solver that fails may need other settings.
            fallback_steps.push_back(s.step);
            log_line("warning: step " + std::to_string(s.step) + " (t = " + format_short(s.t) + " s): " +
                     std::to_string(s.direct_fallbacks) +
                     " linear solve(s) fell back to the direct solver (CHOLMOD), which solved them: " +
                     s.direct_fallback_reason + " (stats.csv: direct_fallbacks)");
          }
          const int frames_before = totals.frames;
          outputs->record_stats(s);
          outputs->record_state(*sim, s.step, s.t, totals);
          const int every = scene.checkpoint_every;
          const bool checkpoint_due = every > 0 && totals.frames / every > frames_before / every && k < steps;
          if (g_interrupt != 0 && k < steps) interrupted = g_interrupt;
          if (checkpoint_due || interrupted != 0) write_run_checkpoint();
        } catch (const SimulationError&) {
          throw;
        } catch (const FramePictureError& e) {
          throw_picture_failure(e, scene.problem.time.dt);  // possibly a frame of an earlier step
        } catch (const std::exception& e) {
          // Name the step for any other failure (write errors, solver exceptions), as SimulationError does.
          throw SimulationError(k, k * scene.problem.time.dt, e.what());
        }
        progress.update(k, totals.t, totals.frames, wall() - wall_before);
        if (interrupted != 0) break;
      }
      // Motion framing: the last pictures on disk before the summary says what was written.
      if (images) {
        try {
          images->drain();
        } catch (const FramePictureError& e) {
          throw_picture_failure(e, scene.problem.time.dt);
        }
      }
    } catch (const std::exception& e) {
      failure = e.what();
    }
  }

  // Sequence framing: the images of the frames simulated so far (also after a failure or an
  // interruption, keeping the spool for --resume then), with one camera for all; motion framing
  // has written them already.
  if (images) {
    try {
      const int written = images->finish(/*keep_spool=*/interrupted != 0);
      log_line(std::string(scene.render.framing == Framing::motion ? "wrote " : "rendered ") +
               std::to_string(written) + " frame(s) of " + std::to_string(drawer->fine_triangles()) +
               " triangles to " + (dir / "frame_*.png").string());
      if (options.video && written > 0 && interrupted == 0) encode_video(dir, scene.name, scene.problem.time.output_fps);
    } catch (const std::exception& e) {
      if (failure.empty()) failure = std::string("rendering failed: ") + e.what();
      else log_line("warning: rendering failed: " + std::string(e.what()));
    }
  }
  // The point cache of the frames on disk (also after a failure or an interruption: what was written).
  if (scene.point_cache == "pc2") {
    try {
      const PointCacheReport cache = write_point_cache(dir);
      log_line("wrote " + (dir / "cache.pc2").string() + " (" + std::to_string(cache.frames) + " frames of " +
               std::to_string(cache.points) + " points) and cache_rest.obj");
    } catch (const std::exception& e) {
      if (failure.empty()) failure = std::string("point cache: ") + e.what();
      else log_line("warning: point cache: " + std::string(e.what()));
    }
  }
  const std::string status = !failure.empty() ? "failed" : interrupted != 0 ? "interrupted" : "completed";
  if (!unresolved_steps.empty()) {
    std::string list;
    for (size_t i = 0; i < unresolved_steps.size() && i < 20; ++i) list += (i ? ", " : "") + std::to_string(unresolved_steps[i]);
    if (unresolved_steps.size() > 20) list += ", ...";
    warnings.push_back("contact: " + std::to_string(unresolved_steps.size()) +
                       " step(s) ended with contact pairs still colliding (steps " + list +
                       "); frames from those times on may show crossing surfaces");
  }
  if (!fallback_steps.empty()) {
    std::string list;
    for (size_t i = 0; i < fallback_steps.size() && i < 20; ++i) list += (i ? ", " : "") + std::to_string(fallback_steps[i]);
    if (fallback_steps.size() > 20) list += ", ...";
    warnings.push_back("solver: the conjugate gradient solver did not converge in " + std::to_string(fallback_steps.size()) +
                       " step(s) (steps " + list + "); the direct solver (CHOLMOD) solved them instead (see the log)");
  }
  const std::string summary = summary_json(scene, totals, sim->settle_report(), wall(), warnings, status, failure);
  try {
    write_atomically(dir / "summary.json", summary);
  } catch (const std::exception& e) {
    // A full disk: the padded "running" summary is rewritten in place instead.
    if (!overwrite_in_place(dir / "summary.json", summary)) {
      if (failure.empty()) failure = e.what();
      else log_line("warning: " + std::string(e.what()));
    }
  }
  if (status == "completed") {
    std::error_code ec;
    fs::remove(checkpoint_path, ec);  // nothing left to resume
  }
  if (!failure.empty()) {
    std::cerr << "clothsim: error: " << file << ": " << failure << '\n';
    log_line("kept the outputs written so far in " + dir.string());
    return 1;
  }
  if (interrupted != 0) {
    log_line(std::string(interrupted == SIGINT ? "interrupted (SIGINT)" : "interrupted (SIGTERM)") + " after step " +
             std::to_string(totals.steps) + " (t = " + format_short(totals.t) + " s); wrote " +
             checkpoint_path.string() + (options.resume_command.empty() ? "" : "; continue with: " + options.resume_command));
    return 128 + interrupted;
  }
  print_summary(scene, *sim, totals, wall(), dir);
  return 0;
}

}  // namespace clothsim

// Scene files: loading and validating the JSON description of one analysis (mesh, material,
// boundary conditions, loads, probes, numerics, and for dynamic scenes time, damping, solver,
// initial state, scripted motions and output; contract in scenes/README.md) into one Problem.
// Every error is a SceneError whose
// message starts with the scene file's path and the key path ("scenes/x.json: boundary[0].fix[1]:
// unknown component ...").
#pragma once

#include "sim/problem/problem.hpp"
#include "sim/core/log.hpp"
#include "sim/discretization/drawn_surface.hpp"

#include <Eigen/Core>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {

class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A named point whose displacement is reported after the analysis.
struct Probe {
  std::string name;
  Eigen::Vector3d at = Eigen::Vector3d::Zero();  // requested position [m]
  int vertex = -1;                               // nearest control vertex of the prepared mesh
};

// How a dynamic run's camera is chosen when the scene gives none, and so when its PNG frames are
// written ("render.framing").
enum class Framing {
  motion,    // fixed before the run from the rest shape and the scripted boundary motions (plus a
             // margin); each frame's picture is written as soon as the frame is produced
  sequence,  // framed on the bounds of the whole simulated sequence; pictures written after the run
};

// "render": how the application draws the limit surface (plain settings; sim/ does not render).
struct RenderSettings {
  int width = 960, height = 720;  // image size [px]
  int refine = 2;                  // refinement steps of the drawn surface (0–4)
  // "render.surface": the method's own surface, the Loop limit surface over the nodes, or the
  // flat triangles (sim/discretization/drawn_surface.hpp); pictures and OBJ frames at
  // output.obj_level >= 1 show it, contact keeps the method's own surface.
  DrawnSurface surface = DrawnSurface::method;
  Eigen::Vector3d color{0.8, 0.1, 0.1};       // front faces, linear RGB in [0, 1]
  Eigen::Vector3d back_color{0.5, 0.1, 0.1};  // back faces
  Eigen::Vector3d background{1, 1, 1};
  bool wireframe = false;  // overlay the control mesh
  // "render.texture": "none", or "grain": a short line along the (deformed) warp direction across
  // every control triangle, so that a picture shows how the cloth is cut (the grain of
  // material.grain, warp_deg 0 by default; an OBJ mesh needs texture coordinates for it), or
  // "checker": squares of kCheckerCell on the texture coordinates (a pattern's, in metres), every
  // other one darker, so that the pieces' layout and their stretching read at a glance.
  // Default: "checker" where the mesh has texture coordinates (a pattern, an OBJ with vt on every
  // face), "none" otherwise (resolved by the scene loader; `texture_given` when the scene sets it).
  std::string texture = "none";
  bool texture_given = false;
  static constexpr double kCheckerCell = 0.05;  // [texture units: m for a pattern] side of a checker square
  // "render.ground": a ground plane normal to `world_up` through the lowest corner of the framed
  // box (see `framing`). Default: on when the scene has gravity (resolved by the scene loader;
  // `ground_given` when the scene sets it).
  bool ground = false;
  bool ground_given = false;
  // "render.shadow": the cloth and the obstacles cast a soft shadow on the ground (a light 30°
  // off up, on the key light's side). No effect without a ground.
  bool shadow = true;
  // "render.up": the direction that is up in an automatically framed picture and the ground's
  // normal (unit). Default: opposite to gravity, +y without gravity; a z-up scene is drawn
  // upright over a ground in the x–y plane. `up_given` when the scene sets it. A scene's own
  // camera has its own up (render.camera.up).
  Eigen::Vector3d world_up{0, 1, 0};
  bool up_given = false;
  bool has_camera = false;  // otherwise framed automatically, see `framing`
  Eigen::Vector3d eye{0, 0, 1}, target{0, 0, 0}, up{0, 1, 0};  // [m]
  double fov_deg = 35.0;   // vertical field of view [deg]
  Framing framing = Framing::motion;  // dynamic scenes only
};

struct Scene {
  std::string name;             // safe folder name: [A-Za-z0-9_.-]+, not starting with '.'
  std::string description;
  std::filesystem::path file;   // the scene file, as given to load_scene
  std::string analysis;         // "static" or "dynamic"
  // The problem: mesh (prepared by the discretisation), material, boundary, loads, numerics and,
  // for dynamic scenes, time, damping, solver, corotational and initial state.
  Problem problem;
  bool write_obj_frames = false;  // dynamic scenes: "output": {"obj": true}
  int obj_level = 0;              // "output.obj_level": OBJ frames hold the limit surface refined this
                                  // many times (0: the limit points at the control connectivity)
  // "output.cache": "pc2" builds a point cache from the OBJ frames at the end of the run
  // (cache.pc2, cache_rest.obj; app/point_cache.hpp); "none" (default) does not.
  std::string point_cache = "none";
  int checkpoint_every = 0;       // "output.checkpoint_every": a checkpoint for --resume every this
                                  // many frames (0: only when interrupted)
  RenderSettings render;
  std::vector<Probe> probes;
  std::vector<std::string> overrides;  // the --set arguments applied, in order (see load_scene)
};

// Reads, validates and builds the scene in `file`; relative mesh paths are resolved against the
// file's folder. Log lines (mesh preparation, selection sizes, warnings) go to `log`, which may be
// empty. Throws SceneError.
//
// `overrides` are `clothsim --set` arguments "key.path=value", applied in order to the parsed file
// before it is read, so that an overridden scene is checked exactly like a file: the value is
// JSON if it parses as JSON and otherwise the text as a string (`time.end=0.5`, `name=foo`,
// `render.camera.eye=[1,2,3]`); `null` removes the key (or array element). Array elements are
// indexed `boundary[0].rotation` or `boundary.0.rotation`; an index equal to the length appends.
// Missing objects on the way are created. A malformed argument, a key below a number or string,
// or an index out of range throws SceneError("--set <argument>: ..."); a problem the loader
// finds at (or inside, or around) an overridden key ends "(set by --set <argument>)".
Scene load_scene(const std::filesystem::path& file, const LogFn& log,
                 const std::vector<std::string>& overrides = {});
// The same for a scene given as JSON text (a study's variant of a scene file): `file` names the
// scene in error messages, and relative OBJ paths are resolved against its folder.
Scene load_scene_text(const std::string& text, const std::filesystem::path& file, const LogFn& log,
                      const std::vector<std::string>& overrides = {});

// Edit distance between `a` and `b` (insertions, deletions, substitutions and swaps of adjacent
// characters each count 1; letters compared case-insensitively).
std::size_t edit_distance(const std::string& a, const std::string& b);
// The name in `allowed` closest to `given` by edit_distance if it is close enough to be a typo
// (distance at most a third of the longer name's length; the first of equally close names), or
// "" (also when `given` is itself allowed). Scene errors for unknown keys and values end with
// "; did you mean \"<name>\"?" when there is one.
std::string closest_name(const std::string& given, const std::vector<std::string>& allowed);

// Index of the row of `vertices` [m] nearest to `point` [m] (Euclidean; ties → lowest index),
// or -1 if there are no vertices.
int nearest_vertex(const Eigen::MatrixX3d& vertices, const Eigen::Vector3d& point);

// Limits of a dynamic run, checked when a scene is read and again after --end / --frames: at most
// kMaxSteps time steps (⌈end/dt⌉) and kMaxFrames frames (⌊end · output_fps⌋ + 1).
inline constexpr double kMaxSteps = 1e8;
inline constexpr double kMaxFrames = 1e6;
// Empty if `t` is within the limits, otherwise what is wrong (naming time.dt, time.end or
// time.output_fps and the limit).
std::string time_limit_problem(const TimeSettings& t);

// Indices (ascending) of the rows p of `vertices` [m] inside the closed box lo <= p <= hi [m].
std::vector<int> select_box(const Eigen::MatrixX3d& vertices, const Eigen::Vector3d& lo,
                            const Eigen::Vector3d& hi);

// Indices (ascending) of the rows p of `vertices` [m] in the closed ball |p − center| <= radius [m].
std::vector<int> select_ball(const Eigen::MatrixX3d& vertices, const Eigen::Vector3d& center, double radius);

}  // namespace clothsim

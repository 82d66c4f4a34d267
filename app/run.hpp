// Running one scene from the command line: load and validate it, run the analysis, and write
// the output folder DIR/<name>/ (static: published atomically, nothing is left behind on failure;
// dynamic: streamed, see app/dynamic_run.hpp).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {

struct RunOptions {
  std::optional<double> end;  // --end T [s]: replaces time.end of a dynamic scene
  bool render = true;         // --no-render turns PNG output off
  int width = 0, height = 0;  // --size WxH: replaces render.width/height (0: keep)
  std::optional<int> frames;  // --frames N: simulate just long enough for N frames
  bool video = false;         // --video: also encode DIR/<name>/<name>.mp4 with ffmpeg
  std::optional<std::string> framing;  // --framing motion|sequence: replaces render.framing
  std::vector<std::string> overrides;  // --set KEY=VALUE, in order: scene keys replaced before the
                                       // scene is checked (load_scene)
  std::optional<std::filesystem::path> resume;  // --resume DIR: continue the dynamic run in DIR
};

// Loads `scene_file`, runs its analysis and writes `out_root`/<scene name>/, replacing an older
// folder of that name: result.json and limit.obj for a static scene; probes.csv, stats.csv,
// summary.json and optional OBJ frames for a dynamic one. Log lines and errors go to stderr
// ("clothsim: ...", "clothsim: error: ..."), the summary to stdout. Returns the process exit code:
// 0 on success, 1 on any error. Invalid input (scene, options) creates no output folder or file;
// a dynamic run that fails part-way keeps what it has written (summary.json says "failed").
int run_scene_file(const std::filesystem::path& scene_file, const std::filesystem::path& out_root,
                   const RunOptions& options = {});

}  // namespace clothsim

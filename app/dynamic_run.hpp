// Running a dynamic scene from the command line: the Simulator steps to time.end while probes.csv,
// stats.csv, OBJ frames, PNG frames (render.framing "motion"; "sequence" draws them after the run,
// see app/frame_images.hpp) and summary.json are streamed into DIR/<name>/ (contract in
// scenes/README.md, "Outputs of a dynamic run").
#pragma once

#include "sim/scene/scene.hpp"

#include <filesystem>

namespace clothsim {

// Runs `scene` (analysis "dynamic"). Everything that can be checked before the first step is
// checked first (the Simulator is built): such errors are thrown as std::runtime_error naming
// the scene file, and nothing has been written. Then `out_root`/<name>/ is created (an older
// folder of that name is replaced) and outputs are streamed into it. Returns 0 when the run
// completes; when it fails part-way (SimulationError, write error) it prints
// "clothsim: error: <file>: step N (t = ... s): <message>" to stderr, keeps the files written
// so far, records status "failed" in summary.json and returns 1. Log lines and progress go to
// stderr, the summary to stdout.
int run_dynamic_scene(const Scene& scene, const std::filesystem::path& out_root, bool render_frames = true,
                      bool video = false);

}  // namespace clothsim

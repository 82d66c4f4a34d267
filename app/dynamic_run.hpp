// Running a dynamic scene from the command line: the Simulator steps to time.end while probes.csv,
// stats.csv, OBJ frames, PNG frames (render.framing "motion"; "sequence" draws them after the run,
// see app/frame_images.hpp) and summary.json are streamed into DIR/<name>/ (contract in
// scenes/README.md, "Outputs of a dynamic run").
#pragma once

#include "sim/scene/scene.hpp"

#include <cstdint>
#include <filesystem>
#include <string>

namespace clothsim {

struct DynamicRunOptions {
  bool render = true;             // PNG frames (render settings of the scene)
  bool video = false;             // also DIR/<name>.mp4 (needs ffmpeg; checked before the run)
  std::string folder;             // the run's folder in out_root; empty: the scene's name
  bool resume = false;            // continue out_root/folder from its checkpoint.bin
  std::uint64_t fingerprint = 0;  // of the scene file and the options: a checkpoint must match it
  std::string resume_command;     // the command that resumes this run, for the interruption message
};

// Runs `scene` (analysis "dynamic"). Everything that can be checked before the first step is
// checked first (the Simulator is built; with `resume`, the checkpoint is read and must match
// the fingerprint): such errors are thrown as std::runtime_error naming the scene file or the
// folder, and nothing has been written. Then out_root/<folder>/ is created (an older folder of
// that name is replaced) or, resuming, cut back to the checkpoint, and outputs are streamed into
// it. The caller holds the folder's OutputLock.
//
// Returns 0 when the run completes (its checkpoint.bin is then removed). When it fails part-way
// (SimulationError, write error) it prints "clothsim: error: <file>: step N (t = ... s):
// <message>" to stderr, keeps the files written so far, records status "failed" in summary.json
// and returns 1. SIGINT / SIGTERM stop it after the current step: it writes checkpoint.bin and
// what is due, records status "interrupted" and returns 128 + the signal number (a second signal
// ends the process at once). With output.checkpoint_every = N it also writes checkpoint.bin each
// time N more frames are out. Log lines and progress go to stderr, the summary to stdout.
int run_dynamic_scene(const Scene& scene, const std::filesystem::path& out_root, const DynamicRunOptions& options);

}  // namespace clothsim

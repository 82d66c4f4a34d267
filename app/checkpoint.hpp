// Checkpoints of a dynamic run (scene key output.checkpoint_every, SIGINT / SIGTERM): the
// Simulator's state and what the streamed outputs had reached, so that `clothsim SCENE --resume
// DIR` continues the run and writes exactly what the uninterrupted run would have written.
//
// File format (DIR/checkpoint.bin, replaced atomically): the line "clothsim checkpoint\n", a
// 32-bit version, then fixed-size fields and vectors (64-bit length + doubles) in this machine's
// byte order, and the line "end\n". It is read back only by the same build on the same kind of
// machine; anything else is refused with a message.
#pragma once

#include "sim/core/contact_counters.hpp"
#include "sim/dynamics/simulator.hpp"

#include <cstdint>
#include <filesystem>
#include <string_view>

namespace clothsim {

// Running totals of a dynamic run, for summary.json (and the checkpoint).
struct RunTotals {
  int steps = 0;
  double t = 0.0;
  double rotate_ms = 0.0, assemble_ms = 0.0, solve_ms = 0.0;
  int frames = 0;
  int max_solver_iterations = 0;
  ContactCounters contact;
};

struct RunCheckpoint {
  std::uint64_t fingerprint = 0;  // of the scene and the options that shape the outputs
  SimulatorCheckpoint sim;
  RunTotals totals;
  double wall_seconds = 0.0;                  // of the run so far
  std::uint64_t probes_bytes = 0, stats_bytes = 0;  // lengths of probes.csv and stats.csv
  int images_written = 0;                     // frame_NNNN.png written (motion framing)
  std::uint64_t spool_bytes = 0;              // sequence framing: length of the frame spool
  float bounds_lo[3] = {0, 0, 0}, bounds_hi[3] = {0, 0, 0};  // sequence framing: bounds so far
};

// Writes `c` to `path` through a temporary file and a rename. Throws std::runtime_error naming
// the path.
void write_checkpoint(const std::filesystem::path& path, const RunCheckpoint& c);

// Reads a checkpoint; throws std::runtime_error naming the path if it is missing, truncated or
// of another format version.
RunCheckpoint read_checkpoint(const std::filesystem::path& path);

// 64-bit FNV-1a hash of `data`, continuing from `hash`.
std::uint64_t fnv1a(std::string_view data, std::uint64_t hash = 14695981039346656037ull);

}  // namespace clothsim

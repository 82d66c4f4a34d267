// `clothsim render DIR`: draws a finished run's saved geometry again, without simulating — a
// dynamic run's frames/mesh_NNNN.obj into frame_NNNN.png, a static run's limit.obj into
// limit.png — with the render settings the run saved ("render" in summary.json / result.json,
// sim/scene/render_settings_json.hpp), some of them overridden, into a new folder (by default
// DIR/render/) that is published whole; the run's own files are never changed.
#pragma once

#include "sim/discretization/drawn_surface.hpp"

#include <filesystem>
#include <optional>

namespace clothsim {

struct RenderSavedOptions {
  std::filesystem::path out;           // --out; empty: DIR/render
  int width = 0, height = 0;           // --size WxH (0: the saved size)
  std::optional<int> refine;           // --refine K, 0..4
  std::optional<DrawnSurface> surface;  // --surface
};

// The marker and record of a render folder: the settings used and where the geometry came from.
inline constexpr const char* kRenderRecord = "render.json";

// Draws the run in `dir` again. The camera is the saved render.camera if the run had one, else
// one framed on the whole saved sequence (as "framing": "sequence"); obstacles are not drawn (the
// OBJ frames hold the cloth only). An existing output folder is replaced only if it is empty or
// an earlier output of this command (it holds render.json). Errors (no such folder, no saved
// geometry, unreadable or invalid settings, refined OBJ frames, an output folder that is not
// ours) go to stderr naming the file or option. Returns 0 on success, 1 on any error; nothing is
// left behind on failure.
int render_saved_run(const std::filesystem::path& dir, const RenderSavedOptions& options);

}  // namespace clothsim

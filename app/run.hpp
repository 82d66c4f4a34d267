// Running one scene from the command line: load and validate it, run the analysis, and publish
// the output folder DIR/<name>/ atomically (nothing is left behind on failure).
#pragma once

#include <filesystem>

namespace clothsim {

// Loads `scene_file`, runs its analysis and writes `out_root`/<scene name>/ (result.json,
// limit.obj), replacing an older folder of that name. Log lines and errors go to stderr
// ("clothsim: ...", "clothsim: error: ..."), the summary to stdout. Returns the process exit code:
// 0 on success, 1 on any error (in which case no output folder or file has been created).
int run_scene_file(const std::filesystem::path& scene_file, const std::filesystem::path& out_root);

}  // namespace clothsim

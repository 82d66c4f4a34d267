// Small filesystem helpers shared by the static and dynamic runs.
#pragma once

#include <filesystem>
#include <vector>

namespace clothsim {

// The missing ancestors of `dir` (deepest first), i.e. the folders create_directories(dir)
// would make; used to remove exactly those again when a run fails.
std::vector<std::filesystem::path> missing_folders(const std::filesystem::path& dir);

}  // namespace clothsim

// Small filesystem helpers shared by the static and dynamic runs and the studies.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace clothsim {

// The missing ancestors of `dir` (deepest first), i.e. the folders create_directories(dir)
// would make; used to remove exactly those again when a run fails.
std::vector<std::filesystem::path> missing_folders(const std::filesystem::path& dir);

// Writes `text` to `path` (binary, replacing the file); throws std::runtime_error naming the path
// when the file cannot be written.
void write_text_file(const std::filesystem::path& path, const std::string& text);

// Writes `text` to `path` through a temporary sibling (".<name>.tmp-<pid>") and a rename, so a
// reader never sees a half-written file; throws std::runtime_error naming the path on failure.
void write_atomically(const std::filesystem::path& path, const std::string& text);

// The whole file as text; throws std::runtime_error naming the path if it cannot be read.
std::string read_text_file(const std::filesystem::path& path);

// Renames the finished folder `staging` to `target`, replacing an older `target` only once the
// new one is in place: the old one is moved aside to a hidden sibling (".<name>.old-<pid>"),
// restored if the rename fails (and the error rethrown), and deleted afterwards. Returns a
// warning (empty if none) when the old folder could not be deleted.
std::string replace_folder(const std::filesystem::path& staging, const std::filesystem::path& target);

// A study's report folder out_root/<folder>/, published whole: the `files` (name, text) are written
// to out_root/.<folder>.tmp-<pid>, the PNG `png` is drawn from the first file (a CSV) by
// scripts/<plot_script> unless `plot` is false, and the folder is renamed into place (replacing an
// older one only then). Returns the plot's error ("" if none or not drawn): the folder is published
// with the data even then. Throws std::runtime_error if the data cannot be written; the temporary
// folder and any output-root folders it created are removed again.
struct ReportFile {
  std::string name, text;
};
std::string publish_report(const std::filesystem::path& out_root, const std::string& folder,
                           const std::vector<ReportFile>& files, bool plot, const std::string& plot_script,
                           const std::string& png);

}  // namespace clothsim

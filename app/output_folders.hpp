// Small filesystem helpers shared by the static and dynamic runs and the studies.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace clothsim {

// The missing ancestors of `dir` (deepest first), i.e. the folders create_directories(dir)
// would make; used to remove exactly those again when a run fails.
std::vector<std::filesystem::path> missing_folders(const std::filesystem::path& dir);

// Throws std::runtime_error naming the path when `dir` cannot become a folder: it, or the nearest
// of its ancestors that exists, is not a folder. Lets a long study refuse an unusable --out before
// it runs anything.
void check_folder_possible(const std::filesystem::path& dir);

// The files in `dir` whose names start with `prefix` and end with `suffix`, sorted by name (none if
// `dir` cannot be read).
std::vector<std::filesystem::path> files_like(const std::filesystem::path& dir, const std::string& prefix,
                                              const std::string& suffix);

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

namespace clothsim {

// Exclusive use of the output folder out_root/<name> by this process: an advisory lock (flock) on
// the file out_root/.<name>.lock, which holds the PID of its owner. The kernel releases the lock
// when the owner exits however it exits (even on SIGKILL), so a stale lock file never blocks a
// later run. The constructor creates out_root if needed (removed again by release() if the run
// created nothing else there) and throws std::runtime_error naming the folder and the PID of the
// run that holds it. The destructor removes the lock file.
class OutputLock {
 public:
  OutputLock(const std::filesystem::path& out_root, const std::string& name);
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

// Removes what dead runs left in `out_root`: hidden temporary folders and files
// ".<name>.tmp-<pid>", ".<name>.tmp-<pid>-..." and ".<name>.old-<pid>" whose process <pid> no
// longer exists (never those of a live process, nor this one's). Returns one line per removed
// entry for the log. Never throws.
std::vector<std::string> remove_dead_temporaries(const std::filesystem::path& out_root);

// Removes the hidden temporary files (".*.tmp*") directly in `dir`: for a run folder whose
// lock this process holds, every such file is a leftover of a killed run. Returns their number.
int remove_temporary_files(const std::filesystem::path& dir);

// Whether a process with this PID exists (kill(pid, 0) does not fail with ESRCH).
bool process_alive(long pid);

// Rewrites the existing file `path` in place with `text` followed by spaces up to its old size,
// without allocating disk space: the fallback for a summary that cannot be replaced through a
// temporary file because the disk is full. Returns false (and changes nothing) if the file does
// not exist or is shorter than `text`, or if the write fails.
bool overwrite_in_place(const std::filesystem::path& path, const std::string& text);

}  // namespace clothsim

// `clothsim study convergence|stability`: the two reports of issue 5. Each runs its cases, writes
// DIR/study_<name>/ (CSV data, a Markdown table where there is one, and a PNG plot drawn by
// scripts/plot_<name>.py with Debian's python3-matplotlib) and prints where it wrote.
// The folder is published atomically: it is built under a temporary name and renamed at the end,
// so a failed or interrupted study leaves an older report untouched.
#pragma once

#include <filesystem>

namespace clothsim {

struct StudyOptions {
  std::filesystem::path out_root = "out";  // the report goes to out_root/study_<name>/
  bool quick = false;                      // a small subset of the cases (seconds, for tests)
  bool plot = true;                        // draw the PNG (needs /usr/bin/python3 with matplotlib)
};

// Return the process exit code: 0 on success, 1 on error (message on stderr, "clothsim: error: ...").
int run_convergence_study(const StudyOptions& options);
int run_stability_study(const StudyOptions& options);

}  // namespace clothsim

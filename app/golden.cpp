// clothsim golden check|update: the manifest, the runs (this same binary, one process per
// golden), the comparisons and the outputs.
#include "app/golden.hpp"

#include "app/command_output.hpp"
#include "app/output_folders.hpp"
#include "render/png_io.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

extern char** environ;

namespace clothsim {
namespace {

namespace fs = std::filesystem;

// The marker file of a failures folder (its report).
const char* const kFailuresReport = "golden_failures.txt";

// A fresh temporary folder, removed with everything in it when the object goes.
class TempFolder {
 public:
  TempFolder() {
    std::string pattern = (fs::temp_directory_path() / "clothsim_golden_XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr)
      throw std::runtime_error("cannot create a temporary folder " + pattern);
    path_ = pattern;
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string fixed(double v, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  return buffer;
}

// The last `n` non-empty lines of `text`, each indented.
std::string last_lines(const std::string& text, int n) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  std::string out;
  for (std::size_t i = lines.size() > static_cast<std::size_t>(n) ? lines.size() - n : 0; i < lines.size(); ++i)
    out += "\n    " + lines[i];
  return out;
}

struct RunOutcome {
  bool ok = false;
  std::string problem;  // why not ok
  fs::path rendered;    // the image, if ok
  double seconds = 0;
};

// Runs `clothsim SCENE --out OUT OPTIONS...` with this same binary, stdout and stderr to
// OUT.log.
RunOutcome run_entry(const GoldenEntry& e, const fs::path& out) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::string> args = {"clothsim", e.scene.string(), "--out", out.string()};
  args.insert(args.end(), e.options.begin(), e.options.end());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const fs::path log = out.string() + ".log";
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, "/proc/self/exe", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) throw std::runtime_error("cannot run clothsim (/proc/self/exe): " + std::system_category().message(spawned));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error("waitpid failed for the run of " + e.scene.string());
  RunOutcome r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string text;
    try {
      text = read_text_file(log);
    } catch (const std::exception&) {
    }
    r.problem = "the run failed (" +
                (WIFEXITED(status) ? "exit code " + std::to_string(WEXITSTATUS(status))
                                   : "signal " + std::to_string(WIFSIGNALED(status) ? WTERMSIG(status) : 0)) +
                "):" + last_lines(text, 5);
    return r;
  }
  r.rendered = out / e.rendered;
  if (!fs::is_regular_file(r.rendered)) {
    r.problem = "the run wrote no " + e.rendered;
    return r;
  }
  r.ok = true;
  return r;
}

// A file name for a golden's failure images: GOLDEN without ".png", '/' replaced by '_'.
std::string failure_stem(const GoldenEntry& e) {
  std::string stem = e.golden_text.substr(0, e.golden_text.size() - 4);
  for (char& c : stem)
    if (c == '/' || c == '\\') c = '_';
  return stem;
}

std::string seconds_text(double s) { return " [" + fixed(s, 1) + " s]"; }

fs::path default_failures_folder() { return fs::temp_directory_path() / "clothsim_golden_failures"; }

}  // namespace

std::vector<GoldenEntry> read_golden_manifest(const fs::path& manifest) {
  std::ifstream in(manifest, std::ios::binary);
  if (!in || fs::is_directory(manifest)) throw std::runtime_error(manifest.string() + ": cannot read the manifest");
  const fs::path base = manifest.parent_path();
  std::vector<GoldenEntry> entries;
  std::set<fs::path> listed;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const std::string where = manifest.string() + ":" + std::to_string(number) + ": ";
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    if (w.empty() || w[0].front() == '#') continue;
    if (w.size() < 3) throw std::runtime_error(where + "expected GOLDEN.png SCENE RENDERED OPTIONS... (got \"" + line + "\")");
    GoldenEntry e;
    e.golden_text = w[0];
    e.golden = (base / w[0]).lexically_normal();
    e.scene = (base / w[1]).lexically_normal();
    e.rendered = w[2];
    e.options.assign(w.begin() + 3, w.end());
    e.line = number;
    if (fs::path(w[0]).extension() != ".png" || fs::path(w[0]).stem().empty())
      throw std::runtime_error(where + "GOLDEN must be a .png file (got \"" + w[0] + "\")");
    if (!fs::is_regular_file(e.scene)) throw std::runtime_error(where + "scene " + e.scene.string() + ": no such file");
    const fs::path rendered = fs::path(w[2]).lexically_normal();
    if (rendered.is_absolute() || rendered.extension() != ".png" || rendered.empty() || *rendered.begin() == "..")
      throw std::runtime_error(where + "RENDERED must be a .png path inside the run's output folder, e.g. " +
                               "plate_ss/limit.png (got \"" + w[2] + "\")");
    for (const std::string& option : e.options)
      if (option == "--out" || option.rfind("--out=", 0) == 0)
        throw std::runtime_error(where + "--out is chosen by clothsim golden (each run writes to a temporary folder)");
    if (!listed.insert(e.golden).second)
      throw std::runtime_error(where + "golden " + w[0] + " is listed twice");
    entries.push_back(std::move(e));
  }
  if (in.bad()) throw std::runtime_error(manifest.string() + ": cannot read the manifest");
  if (entries.empty()) throw std::runtime_error(manifest.string() + ": lists no goldens");
  return entries;
}

int golden_check(const fs::path& manifest, const GoldenCheckOptions& options) {
  try {
    const std::vector<GoldenEntry> entries = read_golden_manifest(manifest);
    const fs::path failures =
        output_folder_path(options.failures.empty() ? default_failures_folder() : options.failures, "--failures");
    if (fs::exists(failures) && !replaceable_folder(failures, kFailuresReport))
      throw std::runtime_error("--failures: " + failures.string() +
                               " exists and was not written by clothsim golden check (it holds no " +
                               kFailuresReport + "); choose a new folder or remove it");
    const TempFolder tmp;
    struct Failure {
      const GoldenEntry* entry;
      fs::path rendered;    // empty if the run made none
      render::Image diff;   // empty if there is none
    };
    std::vector<Failure> failed;
    std::string report = "clothsim golden check " + manifest.string() + "\n" + describe(options.tolerance) + "\n";
    auto say = [&](const std::string& line) {
      std::cout << line << std::endl;
      report += line + "\n";
    };
    for (std::size_t k = 0; k < entries.size(); ++k) {
      const GoldenEntry& e = entries[k];
      const RunOutcome run = run_entry(e, tmp.path() / ("run" + std::to_string(k)));
      const std::string head = "golden " + e.golden_text + ": ";
      if (!run.ok) {
        say(head + "FAILED: " + run.problem + seconds_text(run.seconds));
        failed.push_back({&e, {}, {}});
        continue;
      }
      if (!fs::exists(e.golden)) {
        say(head + "FAILED: no golden " + e.golden.string() + " (clothsim golden update " + manifest.string() +
            " writes it)" + seconds_text(run.seconds));
        failed.push_back({&e, run.rendered, {}});
        continue;
      }
      render::Image expected;
      try {
        expected = render::read_png(e.golden.string());
      } catch (const std::exception& error) {
        say(head + "FAILED: " + error.what() + seconds_text(run.seconds));
        failed.push_back({&e, run.rendered, {}});
        continue;
      }
      render::Image diff;
      const ImageComparison c = compare_pictures(e.golden_text, expected, render::read_png(run.rendered.string()),
                                                 options.tolerance, &diff);
      if (c.same) {
        say(head + "ok (" + describe_statistics(c, options.tolerance) + ")" + seconds_text(run.seconds));
      } else {
        const bool sizes_differ = c.width_a != c.width_b || c.height_a != c.height_b;
        say(head + "FAILED: " +
            (sizes_differ ? "size: golden " + std::to_string(c.width_a) + "x" + std::to_string(c.height_a) +
                                ", rendered " + std::to_string(c.width_b) + "x" + std::to_string(c.height_b)
                          : describe_statistics(c, options.tolerance)) +
            seconds_text(run.seconds));
        failed.push_back({&e, run.rendered, std::move(diff)});
      }
    }
    const std::string summary = "golden: " + std::to_string(entries.size()) + " golden(s): " +
                                std::to_string(entries.size() - failed.size()) + " passed, " +
                                std::to_string(failed.size()) + " failed";
    if (failed.empty()) {
      if (remove_replaceable_folder(failures, kFailuresReport))
        std::cout << "golden: removed the failure images of an earlier check, " << failures.string() << '\n';
      std::cout << summary << '\n';
      return kExitSame;
    }
    report += summary + "\n";
    std::string kept;
    publish_folder(failures, kFailuresReport, "--failures", [&](const fs::path& staging) {
      for (const Failure& f : failed) {
        const std::string stem = failure_stem(*f.entry);
        if (!f.rendered.empty()) {
          fs::copy_file(f.rendered, staging / (stem + ".actual.png"));
          kept += "\n  " + (failures / (stem + ".actual.png")).string() + " (rendered)";
        }
        if (!f.diff.rgb.empty()) {
          render::write_png((staging / (stem + ".diff.png")).string(), f.diff);
          kept += "\n  " + (failures / (stem + ".diff.png")).string() + " (4 x |golden - rendered| per channel)";
        }
      }
      write_text_file(staging / kFailuresReport, report);
    });
    std::cout << summary << "; report and images in " << failures.string() << kept
              << "\nIf the changes are intended: clothsim golden update " << manifest.string() << '\n';
    return kExitDifferent;
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: " << e.what() << '\n';
    return kExitError;
  }
}

int golden_update(const fs::path& manifest) {
  try {
    const std::vector<GoldenEntry> entries = read_golden_manifest(manifest);
    const TempFolder tmp;
    std::vector<RunOutcome> runs;
    bool all_ok = true;
    for (std::size_t k = 0; k < entries.size(); ++k) {
      const GoldenEntry& e = entries[k];
      runs.push_back(run_entry(e, tmp.path() / ("run" + std::to_string(k))));
      const RunOutcome& run = runs.back();
      if (run.ok) {
        render::read_png(run.rendered.string());  // a PNG that can be read back, or an error naming it
        std::cout << "golden " << e.golden_text << ": rendered " << e.rendered << seconds_text(run.seconds) << '\n';
      } else {
        std::cout << "golden " << e.golden_text << ": FAILED: " << run.problem << seconds_text(run.seconds) << '\n';
        all_ok = false;
      }
    }
    if (!all_ok) {
      std::cout << "golden: no golden was written (a run failed)\n";
      return kExitDifferent;
    }
    int written = 0;
    for (std::size_t k = 0; k < entries.size(); ++k) {
      const GoldenEntry& e = entries[k];
      const std::string bytes = read_text_file(runs[k].rendered);
      const bool existed = fs::exists(e.golden);
      if (existed && read_text_file(e.golden) == bytes) {
        std::cout << "golden " << e.golden_text << ": unchanged\n";
        continue;
      }
      if (!e.golden.parent_path().empty()) fs::create_directories(e.golden.parent_path());
      write_atomically(e.golden, bytes);
      ++written;
      std::cout << "golden " << e.golden_text << ": " << (existed ? "changed" : "new") << ", wrote "
                << e.golden.string() << '\n';
    }
    std::cout << "golden: " << entries.size() << " golden(s), " << written
              << " written; look at the new images before committing them\n";
    return kExitSame;
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: " << e.what() << '\n';
    return kExitError;
  }
}

}  // namespace clothsim

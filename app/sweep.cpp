#include "app/sweep.hpp"

#include "app/command_output.hpp"
#include "app/figures.hpp"
#include "app/output_folders.hpp"
#include "app/study.hpp"
#include "sim/study/report_format.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <csignal>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <thread>

namespace clothsim {

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

constexpr int kPlanFormat = 1;

std::string shell_word(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_./:=+-,%@") ==
                        std::string::npos)
    return s;
  std::string quoted = "'";
  for (char c : s) {
    if (c == '\'') quoted += "'\\''";
    else quoted += c;
  }
  return quoted + "'";
}

bool safe_id(const std::string& id) {
  return !id.empty() && id.front() != '.' &&
         id.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-") == std::string::npos;
}

fs::path absolute_path(const fs::path& p) {
  std::error_code ec;
  const fs::path a = fs::absolute(p, ec);
  return (ec ? p : a).lexically_normal();
}

double epoch_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string host_name() {
  char buffer[256] = {};
  if (::gethostname(buffer, sizeof buffer - 1) != 0) return "";
  return buffer;
}

fs::path log_file(const fs::path& dir, int index) { return dir / "logs" / ("task_" + std::to_string(index) + ".log"); }

// Runs argv (argv[0] looked up on $PATH) with stdout and stderr to `output` (empty: inherited) and
// waits; calls `poll` every half second meanwhile, and when it returns true stops waiting: the
// process is sent SIGTERM and the result is 0. Returns the exit status (128 + signal when killed),
// or -1 with `error` set when it cannot be started.
int run_process(const std::vector<std::string>& argv, const fs::path& output, std::string& error,
                const std::function<bool()>& poll = {}) {
  std::vector<std::string> storage = argv;
  std::vector<char*> args;
  for (std::string& a : storage) args.push_back(a.data());
  args.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    error = std::string("cannot start ") + argv.front() + ": " + std::strerror(errno);
    return -1;
  }
  if (pid == 0) {
    if (!output.empty()) {
      const int fd = ::open(output.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd < 0) _exit(126);
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      ::close(fd);
    }
    ::execvp(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, poll ? WNOHANG : 0);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) {
      error = std::string("waiting for ") + argv.front() + " failed: " + std::strerror(errno);
      return -1;
    }
    if (done == 0) {
      if (poll()) {
        ::kill(pid, SIGTERM);
        while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
        }
        return 0;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
  }
  if (WIFEXITED(status)) {
    if (WEXITSTATUS(status) == 127) error = argv.front() + " could not be run";
    return WEXITSTATUS(status);
  }
  return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

// Why a task that left no result stopped, from its log (Slurm's messages) or "".
std::string reason_from_log(const fs::path& log) {
  std::error_code ec;
  if (!fs::exists(log, ec)) return "it did not run (no result, no log)";
  std::string text;
  try {
    text = read_text_file(log);
  } catch (const std::exception&) {
    return "its log " + log.string() + " cannot be read";
  }
  if (text.find("DUE TO TIME LIMIT") != std::string::npos)
    return "killed at its time limit (--slurm-time; log " + log.string() + ")";
  if (text.find("Out Of Memory") != std::string::npos || text.find("oom-kill") != std::string::npos ||
      text.find("OUT_OF_MEMORY") != std::string::npos)
    return "killed for lack of memory (--slurm-mem; log " + log.string() + ")";
  if (text.find("NODE_FAIL") != std::string::npos || text.find("NODE FAILURE") != std::string::npos)
    return "its node failed (log " + log.string() + ")";
  if (text.find("CANCELLED") != std::string::npos) return "cancelled (log " + log.string() + ")";
  return "started but left no result (log " + log.string() + ")";
}

struct TaskTimes {
  double start = 0.0, end = 0.0, seconds = 0.0;
};

std::optional<TaskTimes> task_times(const fs::path& dir, const std::string& id) {
  try {
    const Json j = Json::parse(read_text_file(dir / "runs" / id / "task.json"));
    return TaskTimes{j.at("start").get<double>(), j.at("end").get<double>(), j.at("seconds").get<double>()};
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// "N tasks in W s (their own times add up to S s, at most C at once): about O s of dispatch
// overhead per task", from the task.json of `ids`, the executor having started at `start` (epoch
// seconds) and run `wall` seconds; empty when none of them finished. The overhead of a task is
// the time from the moment a slot was free (at the start, or when an earlier task ended there)
// to its start, the slots being the most tasks seen running at once.
std::string overhead_line(const fs::path& dir, const std::vector<std::string>& ids, double start, double wall) {
  std::vector<TaskTimes> tasks;
  double sum = 0.0;
  for (const std::string& id : ids)
    if (const auto t = task_times(dir, id)) {
      tasks.push_back(*t);
      sum += t->seconds;
    }
  if (tasks.empty()) return "";
  std::vector<std::pair<double, int>> events;
  for (const TaskTimes& t : tasks) {
    events.push_back({t.start, 1});
    events.push_back({t.end, -1});
  }
  std::sort(events.begin(), events.end());
  int running = 0, most = 0;
  for (const auto& e : events) most = std::max(most, running += e.second);
  std::sort(tasks.begin(), tasks.end(), [](const TaskTimes& a, const TaskTimes& b) { return a.start < b.start; });
  std::vector<double> free_at(static_cast<size_t>(std::max(1, most)), start);  // when each slot is free
  double delay = 0.0;
  for (const TaskTimes& t : tasks) {
    auto slot = std::min_element(free_at.begin(), free_at.end());
    delay += std::max(0.0, t.start - *slot);
    *slot = t.end;
  }
  return std::to_string(tasks.size()) + " tasks in " + format_fixed(wall, 1) + " s (their own times add up to " +
         format_fixed(sum, 1) + " s, at most " + std::to_string(most) + " at once): about " +
         format_fixed(delay / static_cast<double>(tasks.size()), 2) + " s of dispatch overhead per task";
}

// The command of study `name`: "clothsim study folds", "clothsim figures".
std::string command_of(const std::string& name) { return name == "figures" ? "clothsim figures" : "clothsim study " + name; }

std::string resume_command(const std::string& name, const fs::path& dir, const SweepCommand& c) {
  std::string command = command_of(name) + " --plan " + shell_word(dir.string()) + " --retry-failed";
  const std::string executor = c.executor.empty() ? (c.jobs > 1 ? "local" : "") : c.executor;
  if (!executor.empty()) command += " --executor " + executor;
  if (c.jobs > 0) command += " -j " + std::to_string(c.jobs);
  if (executor == "slurm") {
    const SweepCommand defaults;
    if (c.slurm_time != defaults.slurm_time) command += " --slurm-time " + shell_word(c.slurm_time);
    if (c.slurm_mem != defaults.slurm_mem) command += " --slurm-mem " + shell_word(c.slurm_mem);
    if (!c.partition.empty()) command += " --partition " + shell_word(c.partition);
    if (!c.account.empty()) command += " --account " + shell_word(c.account);
    for (const std::string& a : c.sbatch_args) command += " --sbatch-arg=" + shell_word(a);
  }
  if (c.out_given) command += " --out " + shell_word(c.out_root.string());
  if (!c.plot) command += " --no-plot";
  return command;
}

void log_line(const std::string& line) { std::cerr << "clothsim: " << line << std::endl; }

}  // namespace

const SweepHooks& sweep_hooks(const std::string& name) {
  if (name == "folds") return fold_sweep_hooks();
  if (name == "stability") return stability_sweep_hooks();
  if (name == "convergence") return convergence_sweep_hooks();
  if (name == "figures") return figures_sweep_hooks();
  throw std::invalid_argument("\"" + name + "\" cannot be run as tasks (folds, stability, convergence and figures can)");
}

std::filesystem::path find_on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (!path || name.empty()) return {};
  std::istringstream in(path);
  std::string folder;
  while (std::getline(in, folder, ':')) {
    const fs::path candidate = fs::path(folder.empty() ? "." : folder) / name;
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return {};
}

std::string array_ranges(const std::vector<int>& indices) {
  std::string out;
  for (size_t i = 0; i < indices.size();) {
    size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    if (!out.empty()) out += ',';
    out += std::to_string(indices[i]);  // appended piecewise (GCC 12 warns falsely on "-" + std::string&&)
    if (j > i) {
      out += '-';
      out += std::to_string(indices[j]);
    }
    i = j + 1;
  }
  return out;
}

std::string tasks_tsv(const SweepStudy& study, const fs::path& dir, const fs::path& clothsim) {
  std::string text = "index\tid\tcommand\n";
  for (size_t i = 0; i < study.ids.size(); ++i)
    text += std::to_string(i) + "\t" + study.ids[i] + "\t" + shell_word(clothsim.string()) + " task " +
            shell_word(dir.string()) + " " + study.ids[i] + "\n";
  return text;
}

void write_sweep_plan(const fs::path& dir_in, const SweepStudy& study, const fs::path& clothsim,
                      const fs::path& out_root) {
  const fs::path dir = absolute_path(dir_in);
  std::set<std::string> seen;
  for (const std::string& id : study.ids) {
    if (!safe_id(id)) throw std::invalid_argument("task id \"" + id + "\" has characters other than letters, digits, . _ -");
    if (!seen.insert(id).second) throw std::invalid_argument("task id \"" + id + "\" is given twice");
  }
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_empty(dir, ec))
    throw std::runtime_error(dir.string() + " exists and is not empty");
  fs::create_directories(dir);
  for (const char* sub : {"runs", "logs", "failed"}) fs::create_directories(dir / sub);
  Json plan = {{"format", kPlanFormat},
               {"study", study.name},
               {"tasks", study.ids.size()},
               {"out", absolute_path(out_root).string()},
               {"settings", study.settings}};
  write_atomically(dir / "tasks.tsv", tasks_tsv(study, dir, absolute_path(clothsim)));
  write_atomically(dir / "plan.json", plan.dump(2) + "\n");
}

SweepPlan read_sweep_plan(const fs::path& dir_in) {
  SweepPlan plan;
  plan.dir = absolute_path(dir_in);
  const fs::path plan_file = plan.dir / "plan.json", tasks_file = plan.dir / "tasks.tsv";
  std::error_code ec;
  if (!fs::is_directory(plan.dir, ec)) throw std::runtime_error(plan.dir.string() + ": no such folder");
  if (!fs::exists(plan_file, ec))
    throw std::runtime_error(plan_file.string() + ": not found (is " + plan.dir.string() +
                             " a folder written by --plan?)");
  try {
    const Json j = Json::parse(read_text_file(plan_file));
    if (j.at("format").get<int>() != kPlanFormat)
      throw std::runtime_error("format " + j.at("format").dump() + " is not " + std::to_string(kPlanFormat));
    plan.study = j.at("study").get<std::string>();
    plan.settings = j.at("settings");
    plan.out_root = j.at("out").get<std::string>();
  } catch (const std::exception& e) {
    throw std::runtime_error(plan_file.string() + ": " + e.what());
  }
  std::istringstream in(read_text_file(tasks_file));
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1) {
      if (line != "index\tid\tcommand") throw std::runtime_error(tasks_file.string() + ": line 1 is not the header");
      continue;
    }
    const size_t a = line.find('\t'), b = a == std::string::npos ? a : line.find('\t', a + 1);
    if (b == std::string::npos || line.substr(0, a) != std::to_string(plan.ids.size()) ||
        !safe_id(line.substr(a + 1, b - a - 1)))
      throw std::runtime_error(tasks_file.string() + ": line " + std::to_string(number) +
                               " is not \"<index><TAB><id><TAB><command>\" with the next index");
    plan.ids.push_back(line.substr(a + 1, b - a - 1));
  }
  return plan;
}

std::vector<TaskStatus> sweep_status(const SweepPlan& plan) {
  const SweepHooks& hooks = sweep_hooks(plan.study);
  std::vector<TaskStatus> out;
  std::error_code ec;
  for (size_t i = 0; i < plan.ids.size(); ++i) {
    TaskStatus s;
    s.index = static_cast<int>(i);
    s.id = plan.ids[i];
    const fs::path run = plan.dir / "runs" / s.id, failed = plan.dir / "failed" / (s.id + ".txt");
    if (fs::exists(run / "task.json", ec) && fs::exists(run / hooks.result_file, ec)) {
      s.state = TaskState::finished;
    } else if (fs::exists(failed, ec)) {
      s.state = TaskState::failed;
      try {
        s.reason = "failed: " + first_line(read_text_file(failed));
      } catch (const std::exception&) {
        s.reason = "failed (" + failed.string() + ")";
      }
    } else {
      s.reason = reason_from_log(log_file(plan.dir, s.index));
    }
    out.push_back(s);
  }
  return out;
}

int run_sweep_task(const fs::path& dir, const std::string& id) {
  SweepPlan plan;
  try {
    plan = read_sweep_plan(dir);
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: task: " << e.what() << '\n';
    return 1;
  }
  const auto where = std::find(plan.ids.begin(), plan.ids.end(), id);
  if (where == plan.ids.end()) {
    std::cerr << "clothsim: error: task: no task \"" << id << "\" in " << (plan.dir / "tasks.tsv").string() << " ("
              << plan.ids.size() << " tasks" << (plan.ids.empty() ? "" : ", e.g. " + plan.ids.front()) << ")\n";
    return 1;
  }
  const int index = static_cast<int>(where - plan.ids.begin());
  const fs::path runs = plan.dir / "runs", target = runs / id;
  const fs::path failed = plan.dir / "failed" / (id + ".txt");
  std::error_code ec;
  try {
    const SweepHooks& hooks = sweep_hooks(plan.study);
    fs::create_directories(runs);
    fs::create_directories(plan.dir / "failed");
    OutputLock lock(runs, id);
    if (fs::exists(target / "task.json", ec) && fs::exists(target / hooks.result_file, ec)) {
      std::cout << "task " << id << ": already finished (" << target.string() << ")\n";
      return 0;
    }
    // What a killed run of this task left (its staging folder). Only this task's: on a shared file
    // system the other tasks' temporaries may belong to live processes on other nodes.
    for (const fs::directory_entry& e : fs::directory_iterator(runs)) {
      const std::string name = e.path().filename().string();
      if (name.rfind("." + id + ".tmp-", 0) == 0 || name.rfind("." + id + ".old-", 0) == 0) fs::remove_all(e.path(), ec);
    }
    const double start = epoch_seconds();
    const auto clock = std::chrono::steady_clock::now();
    log_line("task " + id + " (" + std::to_string(index + 1) + "/" + std::to_string(plan.ids.size()) + " of study " +
             plan.study + ")");
    std::string result;
    try {
      result = hooks.run(plan.settings, id, [&](const std::string& line) { log_line(id + ": " + line); });
    } catch (const std::exception& e) {
      std::string message = e.what();
      std::replace(message.begin(), message.end(), '\n', ' ');
      write_atomically(failed, message + "\n");
      std::cerr << "clothsim: error: task " << id << ": " << message << " (" << failed.string() << ")\n";
      return 1;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock).count();
    const Json info = {{"id", id},         {"index", index},        {"study", plan.study},
                       {"host", host_name()}, {"start", start},     {"end", epoch_seconds()},
                       {"seconds", seconds}, {"clothsim", CLOTHSIM_VERSION}};
    publish_folder(target, "task.json", "task " + id, [&](const fs::path& staging) {
      write_text_file(staging / hooks.result_file, result);
      write_text_file(staging / "task.json", info.dump(2) + "\n");
    });
    fs::remove(failed, ec);
    std::cout << "task " << id << ": finished in " << format_fixed(seconds, 1) << " s (" << target.string() << ")\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: task " << id << ": " << e.what() << '\n';
    return 1;
  }
}

int gather_sweep(const fs::path& dir, const std::optional<fs::path>& out_root, bool plot, std::optional<double> seconds,
                 const std::string& resume) {
  try {
    const SweepPlan plan = read_sweep_plan(dir);
    const SweepHooks& hooks = sweep_hooks(plan.study);
    GatherInput input;
    input.out_root = out_root.value_or(plan.out_root);
    input.plot = plot;
    input.ids = plan.ids;
    input.seconds = seconds;
    for (const TaskStatus& s : sweep_status(plan)) {
      if (s.state == TaskState::finished)
        input.results[s.id] = read_text_file(plan.dir / "runs" / s.id / hooks.result_file);
      else
        input.problems.push_back(s.id + " (task " + std::to_string(s.index) + "): " + s.reason);
    }
    const int code = hooks.gather(plan.settings, input);
    if (input.problems.empty()) return code;
    std::cerr << "clothsim: error: study " << plan.study << ": " << input.problems.size() << " of " << plan.ids.size()
              << " tasks did not finish; the report has the other " << plan.ids.size() - input.problems.size()
              << ":\n";
    for (const std::string& p : input.problems) std::cerr << "  " << p << '\n';
    std::cerr << "Run them with: "
              << (resume.empty() ? command_of(plan.study) + " --plan " + shell_word(plan.dir.string()) +
                                       " --retry-failed [--executor ...]"
                                 : resume)
              << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: gather: " << e.what() << '\n';
    return 1;
  }
}

std::string check_sweep_command(const SweepCommand& c) {
  if (!c.executor.empty() && c.executor != "local" && c.executor != "slurm")
    return "--executor: \"" + c.executor + "\" is not local or slurm";
  if (c.jobs < 0) return "-j: needs a number of tasks >= 1";
  if (c.gather && (c.plan || !c.executor.empty() || c.jobs > 0 || c.retry_failed || c.dry_run || c.no_wait))
    return "--gather DIR builds the report only; it takes no --plan, --executor, -j, --retry-failed, --dry-run or "
           "--no-wait";
  const bool slurm = c.executor == "slurm";
  const SweepCommand defaults;
  if (!slurm) {
    if (c.dry_run) return "--dry-run applies to --executor slurm only";
    if (c.no_wait) return "--no-wait applies to --executor slurm only";
    if (c.slurm_time != defaults.slurm_time) return "--slurm-time applies to --executor slurm only";
    if (c.slurm_mem != defaults.slurm_mem) return "--slurm-mem applies to --executor slurm only";
    if (!c.partition.empty()) return "--partition applies to --executor slurm only";
    if (!c.account.empty()) return "--account applies to --executor slurm only";
    if (!c.sbatch_args.empty()) return "--sbatch-arg applies to --executor slurm only";
  }
  if (!std::regex_match(c.slurm_time, std::regex(R"((\d+-)?\d+(:\d+){0,2})")))
    return "--slurm-time: \"" + c.slurm_time + "\" is not a Slurm time limit (MINUTES, HH:MM:SS or D-HH:MM:SS)";
  if (!std::regex_match(c.slurm_mem, std::regex(R"([1-9]\d*[KMGT]?)")))
    return "--slurm-mem: \"" + c.slurm_mem + "\" is not a Slurm memory size (e.g. 4G, 500M)";
  for (const std::string& a : c.sbatch_args)
    if (a.rfind("-", 0) != 0 || a.find('\n') != std::string::npos)
      return "--sbatch-arg: \"" + a + "\" is not an sbatch option (give it as --sbatch-arg=--constraint=avx2)";
  for (const std::string* s : {&c.partition, &c.account})
    if (s->find_first_of(" \t\n'\"") != std::string::npos)
      return std::string(s == &c.partition ? "--partition" : "--account") + ": \"" + *s + "\" has blanks or quotes";
  return "";
}

bool sweep_requested(const SweepCommand& c) {
  return c.plan || c.gather || !c.executor.empty() || c.jobs > 1 || c.retry_failed;
}

std::string slurm_array_script(const SweepPlan& plan, const std::vector<int>& indices, const SweepCommand& c) {
  const int throttle = c.jobs > 0 ? c.jobs : kDefaultSlurmThrottle;
  const std::string tasks = shell_word((plan.dir / "tasks.tsv").string());
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "# " << command_of(plan.study) << " as a Slurm job array: array task I runs line I of tasks.tsv\n"
    << "# (`clothsim task DIR ID`, whose result goes to DIR/runs/ID/). Written by clothsim; submit it again\n"
    << "# with `sbatch " << (plan.dir / "slurm_array.sh").string() << "`, gather with\n"
    << "# `" << command_of(plan.study) << " --gather " << plan.dir.string() << "` (docs/cluster.md).\n"
    << "#SBATCH --job-name=clothsim-" << plan.study << '\n'
    << "#SBATCH --array=" << array_ranges(indices) << '%' << throttle << '\n'
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=1\n"
    << "#SBATCH --time=" << c.slurm_time << '\n'
    << "#SBATCH --mem=" << c.slurm_mem << '\n'
    << "#SBATCH --output=" << (plan.dir / "logs" / "task_%a.log").string() << '\n';
  if (!c.partition.empty()) s << "#SBATCH --partition=" << c.partition << '\n';
  if (!c.account.empty()) s << "#SBATCH --account=" << c.account << '\n';
  for (const std::string& a : c.sbatch_args) s << "#SBATCH " << a << '\n';
  s << "set -euo pipefail\n"
    << "export OPENBLAS_NUM_THREADS=\"${SLURM_CPUS_PER_TASK:-1}\" OMP_NUM_THREADS=\"${SLURM_CPUS_PER_TASK:-1}\"\n"
    << "line=$(awk -F '\\t' -v i=\"$SLURM_ARRAY_TASK_ID\" 'NR > 1 && $1 == i' " << tasks << ")\n"
    << "id=$(printf '%s\\n' \"$line\" | cut -f2)\n"
    << "if [ -z \"$id\" ]; then\n"
    << "  echo \"clothsim: error: no task $SLURM_ARRAY_TASK_ID in \"" << tasks << " >&2\n"
    << "  exit 2\n"
    << "fi\n"
    << "echo \"clothsim task $id: array task $SLURM_ARRAY_TASK_ID of job $SLURM_ARRAY_JOB_ID on $(hostname)\"\n"
    << "exec " << shell_word(c.clothsim.string()) << " task " << shell_word(plan.dir.string()) << " \"$id\"\n";
  return s.str();
}

namespace {

// The indices of the tasks without a result.
std::vector<int> pending_tasks(const SweepPlan& plan) {
  std::vector<int> pending;
  for (const TaskStatus& s : sweep_status(plan))
    if (s.state != TaskState::finished) pending.push_back(s.index);
  return pending;
}

int count_finished(const SweepPlan& plan, const std::vector<int>& indices) {
  const SweepHooks& hooks = sweep_hooks(plan.study);
  int n = 0;
  std::error_code ec;
  for (int i : indices)
    n += fs::exists(plan.dir / "runs" / plan.ids[i] / "task.json", ec) &&
         fs::exists(plan.dir / "runs" / plan.ids[i] / hooks.result_file, ec);
  return n;
}

std::vector<std::string> ids_of(const SweepPlan& plan, const std::vector<int>& indices) {
  std::vector<std::string> ids;
  for (int i : indices) ids.push_back(plan.ids[i]);
  return ids;
}

// The local executor: one task after another in this process (-j 1), or N at once with GNU
// parallel, each a `clothsim task` process with its output in logs/. Returns false (message
// printed) when the tasks could not be started at all.
bool run_local(const SweepPlan& plan, const std::vector<int>& pending, const SweepCommand& c) {
  const int jobs = std::max(1, c.jobs);
  if (jobs == 1) {
    for (int i : pending) run_sweep_task(plan.dir, plan.ids[i]);
    return true;
  }
  const fs::path parallel = find_on_path("parallel");
  if (parallel.empty()) {
    std::cerr << "clothsim: error: -j " << jobs
              << ": GNU parallel is not on the PATH (Debian package parallel, scripts/install_deps.sh); -j 1 runs "
                 "the tasks one after another without it\n";
    return false;
  }
  // Each task gets its share of the cores for the BLAS threads of its factorisations.
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const std::string threads = std::to_string(std::max(1u, cores / static_cast<unsigned>(jobs)));
  ::setenv("OPENBLAS_NUM_THREADS", threads.c_str(), 0);
  ::setenv("OMP_NUM_THREADS", threads.c_str(), 0);
  std::string list;
  for (int i : pending) list += std::to_string(i) + "\t" + plan.ids[i] + "\n";
  const fs::path list_file = plan.dir / "logs" / "local_pending.tsv";
  write_atomically(list_file, list);
  const std::string command = shell_word(c.clothsim.string()) + " task " + shell_word(plan.dir.string()) + " {2} > " +
                              shell_word((plan.dir / "logs").string()) + "/task_{1}.log 2>&1";
  std::string error;
  const int code = run_process({parallel.string(), "--will-cite", "--jobs", std::to_string(jobs), "--colsep", "\t",
                                "--joblog", (plan.dir / "logs" / "local_joblog.txt").string(), command, "::::",
                                list_file.string()},
                               {}, error);
  if (code < 0) {
    std::cerr << "clothsim: error: " << error << '\n';
    return false;
  }
  return true;
}

volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void note_interrupt(int) { g_interrupted = 1; }

// The Slurm executor. Returns 0 when the array ran (the gather follows), 2 when it is submitted
// and not waited for, 3 when the wait was interrupted (SIGINT, SIGTERM: the array goes on), 1 on
// an error (message printed).
int run_slurm(const SweepPlan& plan, const std::vector<int>& pending, const SweepCommand& c, const std::string& resume) {
  if (plan.dir.string().find_first_of(" \t\n'\"%") != std::string::npos) {
    std::cerr << "clothsim: error: --executor slurm: the plan's folder " << plan.dir.string()
              << " has blanks, quotes or %, which an #SBATCH --output line cannot hold; plan into another folder\n";
    return 1;
  }
  const std::string script = slurm_array_script(plan, pending, c);
  const fs::path script_file = plan.dir / "slurm_array.sh";
  write_atomically(script_file, script);
  fs::permissions(script_file, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                  fs::perm_options::add);
  if (c.dry_run) {
    std::cout << script;
    std::cerr << "clothsim: dry run: the job-array script above is " << script_file.string()
              << " (not submitted); submit it with `sbatch " << script_file.string() << "` and gather with `"
              << command_of(plan.study) << " --gather " << shell_word(plan.dir.string()) << "`\n";
    return 2;
  }
  const fs::path sbatch = find_on_path("sbatch");
  if (sbatch.empty()) {
    SweepCommand here = c;  // the same study with the local executor
    const SweepCommand defaults;
    here.executor = "local";
    here.jobs = 0;
    here.slurm_time = defaults.slurm_time;
    here.slurm_mem = defaults.slurm_mem;
    here.partition = here.account = "";
    here.sbatch_args.clear();
    std::cerr << "clothsim: error: --executor slurm: sbatch is not on the PATH (Slurm's client, Debian package "
                 "slurm-client); the "
              << pending.size() << " tasks are planned in " << plan.dir.string()
              << ". Run them here with: " << resume_command(plan.study, plan.dir, here) << '\n';
    return 1;
  }
  const fs::path submit_out = plan.dir / "logs" / "sbatch.txt";
  std::vector<std::string> argv = {sbatch.string(), "--parsable"};
  if (!c.no_wait) argv.push_back("--wait");
  argv.push_back(script_file.string());
  std::string job;
  const double start = epoch_seconds();
  auto last_report = std::chrono::steady_clock::now();
  int last_done = -1, polls = 0;
  auto poll = [&] {
    if (job.empty()) {
      std::string text;
      try {
        text = read_text_file(submit_out);
      } catch (const std::exception&) {
      }
      const std::string line = first_line(text);
      if (!line.empty() && std::all_of(line.begin(), line.end(), [](char ch) { return std::isdigit(ch) || ch == ';'; })) {
        job = line.substr(0, line.find(';'));
        log_line("slurm: submitted job array " + job + " (" + std::to_string(pending.size()) +
                 " tasks); waiting for it (logs in " + (plan.dir / "logs").string() + ")");
      }
    }
    if (std::chrono::steady_clock::now() - last_report > std::chrono::seconds(30)) {
      last_report = std::chrono::steady_clock::now();
      const int done = count_finished(plan, pending);
      if (done != last_done)
        log_line("slurm: " + std::to_string(done) + " of " + std::to_string(pending.size()) + " tasks finished");
      last_done = done;
    }
    // Every task has its result: stop waiting for sbatch --wait, which notices the end of the
    // array only at its next poll of the controller (up to 30 s later; the array is not cancelled).
    return !job.empty() && !c.no_wait && ++polls % 4 == 0 &&
           count_finished(plan, pending) == static_cast<int>(pending.size());
  };
  std::string error;
  // Ctrl-C or SIGTERM while waiting ends the wait, not the array.
  struct sigaction on_signal = {}, old_int = {}, old_term = {};
  on_signal.sa_handler = note_interrupt;
  sigemptyset(&on_signal.sa_mask);
  g_interrupted = 0;
  ::sigaction(SIGINT, &on_signal, &old_int);
  ::sigaction(SIGTERM, &on_signal, &old_term);
  const int code = run_process(argv, submit_out, error, [&] { return poll() || g_interrupted != 0; });
  ::sigaction(SIGINT, &old_int, nullptr);
  ::sigaction(SIGTERM, &old_term, nullptr);
  poll();  // the job id, if sbatch returned before the first poll
  const double wall = epoch_seconds() - start;
  if (g_interrupted) {
    const std::string gather = command_of(plan.study) + " --gather " + shell_word(plan.dir.string()) +
                               (c.out_given ? " --out " + shell_word(c.out_root.string()) : "") +
                               (c.plot ? "" : " --no-plot");
    if (job.empty())
      std::cerr << "clothsim: interrupted while submitting; `squeue -u $USER` shows whether the array was submitted. "
                << "Gather what finished with: " << gather << '\n';
    else
      std::cerr << "clothsim: interrupted; job array " << job << " goes on running on the cluster (squeue -j " << job
                << "; `scancel " << job << "` stops it). " << count_finished(plan, pending) << " of " << pending.size()
                << " tasks have finished so far. When it has ended, gather with: " << gather
                << "\nand run what did not finish with: " << resume << '\n';
    return 3;
  }
  if (code < 0) {
    std::cerr << "clothsim: error: --executor slurm: " << error << '\n';
    return 1;
  }
  if (job.empty()) {
    std::string text;
    try {
      text = read_text_file(submit_out);
    } catch (const std::exception&) {
    }
    while (!text.empty() && text.back() == '\n') text.pop_back();
    std::cerr << "clothsim: error: --executor slurm: sbatch rejected the job array (exit status " << code
              << "): " << text << "\nNone of the " << pending.size() << " tasks ran; the script is "
              << script_file.string() << ". Correct the options and run: " << resume << '\n';
    return 1;
  }
  if (c.no_wait) {
    std::cout << "slurm: submitted job array " << job << " (" << pending.size() << " tasks of " << plan.ids.size()
              << "); when it has ended (squeue -j " << job << "), gather with: " << command_of(plan.study)
              << " --gather " << shell_word(plan.dir.string()) << (c.out_given ? " --out " + shell_word(c.out_root.string()) : "")
              << (c.plot ? "" : " --no-plot") << '\n';
    return 2;
  }
  // The overhead is measured up to the end of the last task.
  double last_end = start;
  for (int i : pending)
    if (const auto t = task_times(plan.dir, plan.ids[i])) last_end = std::max(last_end, t->end);
  if (const std::string line = overhead_line(plan.dir, ids_of(plan, pending), start, last_end - start); !line.empty())
    std::cout << "slurm: job array " << job << ": " << line << "; " << format_fixed(wall, 1)
              << " s from submission to the end of the wait\n";
  if (code != 0) log_line("slurm: job array " + job + " ended with exit status " + std::to_string(code) + " (some task failed)");
  return 0;
}

}  // namespace

int run_study_command(const std::string& name, const std::function<SweepStudy()>& make_study, const SweepCommand& c) {
  if (const std::string problem = check_sweep_command(c); !problem.empty()) {
    std::cerr << "clothsim: error: study " << name << ": " << problem << '\n';
    return 1;
  }
  const std::optional<fs::path> out_root = c.out_given ? std::optional<fs::path>(c.out_root) : std::nullopt;
  try {
    if (out_root || !c.gather) check_folder_possible(c.out_root);  // before any case runs
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: study " << name << ": --out " << e.what() << '\n';
    return 1;
  }
  if (c.gather) {
    try {
      const SweepPlan plan = read_sweep_plan(*c.gather);
      if (plan.study != name) {
        std::cerr << "clothsim: error: --gather: " << plan.dir.string() << " holds a plan of study " << plan.study
                  << ", not " << name << '\n';
        return 1;
      }
    } catch (const std::exception& e) {
      std::cerr << "clothsim: error: --gather: " << e.what() << '\n';
      return 1;
    }
    return gather_sweep(*c.gather, out_root, c.plot);
  }
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  if (!sweep_requested(c)) {
    // The usual way: plan, every task and the gather in this process, nothing left but the report.
    const SweepStudy study = make_study();
    const SweepHooks& hooks = sweep_hooks(name);
    GatherInput input;
    input.out_root = c.out_root;
    input.plot = c.plot;
    input.ids = study.ids;
    for (size_t i = 0; i < study.ids.size(); ++i) {
      const std::string tag = "[" + std::to_string(i + 1) + "/" + std::to_string(study.ids.size()) + "] " + study.ids[i];
      input.results[study.ids[i]] =
          hooks.run(study.settings, study.ids[i], [&](const std::string& line) { log_line(tag + ": " + line); });
    }
    input.seconds = elapsed();
    return hooks.gather(study.settings, input);
  }

  // A plan in a folder.
  const fs::path dir =
      absolute_path(c.plan.value_or(c.out_root / ((name == "figures" ? name : "study_" + name) + ".tasks")));
  SweepPlan plan;
  try {
    std::error_code ec;
    if (c.retry_failed) {
      plan = read_sweep_plan(dir);
      if (plan.study != name)
        throw std::runtime_error(dir.string() + " holds a plan of study " + plan.study + ", not " + name);
    } else {
      const SweepStudy study = make_study();
      if (fs::exists(dir, ec) && !fs::is_empty(dir, ec)) {
        if (c.plan)
          throw std::runtime_error("--plan: " + dir.string() +
                                   " is not empty; --retry-failed runs the tasks of the plan in it that have not "
                                   "finished, or remove it to plan anew");
        if (!fs::exists(dir / "plan.json", ec))
          throw std::runtime_error(dir.string() + " exists and holds no plan; it is left alone (remove it or give --plan DIR)");
        fs::remove_all(dir);  // the previous sweep of the usual folder
      }
      write_sweep_plan(dir, study, c.clothsim, c.out_root);
      plan = read_sweep_plan(dir);
      if (c.plan && c.executor.empty() && c.jobs == 0) {
        std::cout << "planned " << plan.ids.size() << " tasks of study " << name << " in " << dir.string()
                  << " (tasks.tsv); run each with `clothsim task " << shell_word(dir.string())
                  << " ID`, then gather with `" << command_of(name) << " --gather " << shell_word(dir.string())
                  << "`\n";
        return 0;
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: study " << name << ": " << e.what() << '\n';
    return 1;
  }

  const std::string resume = resume_command(name, dir, c);
  const std::vector<int> pending = pending_tasks(plan);
  const std::string executor = c.executor.empty() ? "local" : c.executor;
  log_line("study " + name + ": " + std::to_string(pending.size()) + " of " + std::to_string(plan.ids.size()) +
           " tasks to run (" + executor + (executor == "local" ? ", " + std::to_string(std::max(1, c.jobs)) + " at once" : "") +
           "; plan in " + dir.string() + ")");
  if (!pending.empty()) {
    if (executor == "slurm") {
      const int code = run_slurm(plan, pending, c, resume);
      if (code == 1) return 1;
      if (code == 2) return 0;
      if (code == 3) return 130;
    } else {
      const double before = elapsed(), before_epoch = epoch_seconds();
      if (!run_local(plan, pending, c)) return 1;
      if (c.jobs > 1)
        if (const std::string line = overhead_line(plan.dir, ids_of(plan, pending), before_epoch, elapsed() - before);
            !line.empty())
          std::cout << "local: " << line << '\n';
    }
  }
  return gather_sweep(dir, out_root.value_or(c.retry_failed ? plan.out_root : c.out_root), c.plot, elapsed(), resume);
}

}  // namespace clothsim

// A study as a sweep of independent tasks (issue 31, docs/cluster.md): plan, run each task
// anywhere, gather.
//
// A planned sweep is a folder DIR:
//   plan.json        the study's name, its settings (everything a task needs to redo its case) and
//                    the output root the report goes to by default
//   tasks.tsv        a header line "index<TAB>id<TAB>command", then one line per task: its array
//                    index (0, 1, ...), its stable id (derived from the case's parameters, the same
//                    in every plan) and the exact command that runs it, `clothsim task DIR ID`
//   runs/<id>/       a finished task: its result file (the study's, e.g. row.csv) and task.json
//                    (host, start and end time, seconds); published whole, so it is there or absent
//   failed/<id>.txt  the error of a task that stopped with one (removed when it finishes later)
//   logs/task_<index>.log   each task's output under an executor
//   slurm_array.sh   the job-array script of --executor slurm
// `clothsim task DIR ID` runs one task (a finished one is not run again); gathering builds the
// study's usual report from the tasks that finished and names the others.
#pragma once

#include "sim/core/log.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {

// A study split into tasks.
struct SweepStudy {
  std::string name;              // "folds": `clothsim study folds`, report folder <out>/study_folds/
  nlohmann::json settings;       // stored in plan.json; given to each task and to the gather
  std::vector<std::string> ids;  // the tasks' stable ids, in the report's order
};

// What the gather of a study gets.
struct GatherInput {
  std::filesystem::path out_root;               // the report goes to out_root/study_<name>/
  bool plot = true;                             // draw the PNG
  std::vector<std::string> ids;                 // every task, in the plan's order
  std::map<std::string, std::string> results;   // the finished tasks: id → result text
  std::vector<std::string> problems;            // one line per task that did not finish ("id: why")
  std::optional<double> seconds;                // wall time of the whole study, when it ran just now
};

// How a study runs one task and builds its report.
struct SweepHooks {
  std::string result_file;  // the file a task leaves in runs/<id>/ (e.g. "row.csv")
  // Runs task `id` and returns its result text; progress lines to `log`. Throws on an error.
  std::function<std::string(const nlohmann::json& settings, const std::string& id, const LogFn& log)> run;
  // Builds and publishes the report (a Markdown note naming input.problems when there are any);
  // prints its summary. Returns the exit code: 0, or 1 if the report could not be made whole.
  std::function<int(const nlohmann::json& settings, const GatherInput& input)> gather;
};

// The hooks of study `name` ("folds"); throws std::invalid_argument for a study without them.
const SweepHooks& sweep_hooks(const std::string& name);

// A plan as read back from its folder.
struct SweepPlan {
  std::filesystem::path dir;       // absolute
  std::string study;
  nlohmann::json settings;
  std::filesystem::path out_root;  // where the report goes unless --out says otherwise
  std::vector<std::string> ids;    // index i → id
};

// Writes DIR/plan.json and DIR/tasks.tsv (each atomically; the commands name `clothsim`, the
// binary, and DIR as absolute paths) and creates runs/, logs/ and failed/. DIR must not exist or
// be empty. Throws std::runtime_error naming the file on failure, std::invalid_argument for
// duplicate or unsafe ids (an id is letters, digits and . _ - only).
void write_sweep_plan(const std::filesystem::path& dir, const SweepStudy& study, const std::filesystem::path& clothsim,
                      const std::filesystem::path& out_root);

// Reads DIR/plan.json and DIR/tasks.tsv; throws std::runtime_error naming the file and the problem.
SweepPlan read_sweep_plan(const std::filesystem::path& dir);

// The tasks.tsv text of a plan (header and one line per task).
std::string tasks_tsv(const SweepStudy& study, const std::filesystem::path& dir, const std::filesystem::path& clothsim);

enum class TaskState { finished, failed, missing };
struct TaskStatus {
  int index = 0;
  std::string id;
  TaskState state = TaskState::missing;
  std::string reason;  // failed / missing: why, from failed/<id>.txt or the task's log
};
// Every task's state, in index order.
std::vector<TaskStatus> sweep_status(const SweepPlan& plan);

// `clothsim task DIR ID`: runs task ID of the plan in DIR into DIR/runs/ID/ (whole or absent,
// under a lock: a second process running the same task is refused naming its PID). A task that
// already finished is not run again. Returns the exit code (0, or 1 with the error on stderr and
// in DIR/failed/ID.txt).
int run_sweep_task(const std::filesystem::path& dir, const std::string& id);

// Builds the report of the plan in DIR from the finished tasks into `out_root` (none: the plan's).
// Names the tasks that did not finish on stderr and in the report, followed by `resume` (the
// command that runs the rest); returns 1 then, and when the study's gather fails.
int gather_sweep(const std::filesystem::path& dir, const std::optional<std::filesystem::path>& out_root, bool plot,
                 std::optional<double> seconds = std::nullopt, const std::string& resume = "");

// The command-line options that choose how a study runs.
struct SweepCommand {
  std::optional<std::filesystem::path> plan;    // --plan DIR
  std::optional<std::filesystem::path> gather;  // --gather DIR
  std::string executor;                         // --executor: "", "local" or "slurm"
  int jobs = 0;                                 // -j N (0: not given)
  bool retry_failed = false;                    // --retry-failed
  bool dry_run = false;                         // --dry-run (slurm)
  bool no_wait = false;                         // --no-wait (slurm)
  std::string slurm_time = "1:00:00";           // --slurm-time
  std::string slurm_mem = "4G";                 // --slurm-mem
  std::string partition, account;               // --partition, --account
  std::vector<std::string> sbatch_args;         // --sbatch-arg (repeatable)
  std::filesystem::path clothsim;               // this binary
  std::filesystem::path out_root = "out";       // --out
  bool out_given = false;                       // --out was given
  bool plot = true;
};

// The default throttle of a Slurm array (tasks at once) when -j is not given.
constexpr int kDefaultSlurmThrottle = 32;

// Checks the options (a time limit and memory sbatch accepts, -j >= 1, slurm-only options with
// --executor slurm, ...); returns the error message naming the option, or "".
std::string check_sweep_command(const SweepCommand& command);

// Whether the options ask for more than today's single process (a plan, a gather, an executor,
// -j > 1 or a retry).
bool sweep_requested(const SweepCommand& command);

// Runs study `name` as the options say: in this process one task after another (no sweep option:
// the usual way, with no folder left besides the report), or planned into a folder (--plan DIR,
// else <out>/study_<name>.tasks) and run there by an executor, then gathered; or only gathered
// (--gather DIR). `make_study` builds the study from its own options (not called for --gather
// and --retry-failed, which use the plan in the folder). Returns the exit code.
int run_study_command(const std::string& name, const std::function<SweepStudy()>& make_study,
                      const SweepCommand& command);

// The job-array script for the tasks `indices` (ascending) of the plan in DIR.
std::string slurm_array_script(const SweepPlan& plan, const std::vector<int>& indices, const SweepCommand& command);

// "0-3,5,7-8" for {0,1,2,3,5,7,8} (ascending, no duplicates).
std::string array_ranges(const std::vector<int>& indices);

// `name` found in a folder of $PATH (an executable file), or empty.
std::filesystem::path find_on_path(const std::string& name);

}  // namespace clothsim

// `clothsim study folds` as a sweep (issue 31, docs/cluster.md), through the built binary on a
// small plan (the quick twist with two methods, 4 runs): `-j 2` (GNU parallel) and
// `--plan` + `clothsim task` per line of tasks.tsv + `--gather` give the serial run's results.csv
// in every column but the times; --executor slurm without sbatch on the PATH, with a submission
// sbatch rejects, and as a dry run; a stand-in sbatch that runs the array here but leaves one
// task out, the gather naming it and the printed --retry-failed command finishing the study; an
// interrupted wait (the array goes on; the gather command printed); `clothsim figures` as tasks
// (a figure with missing runs named, not drawn; then the one-process run's figure); bad
// plan folders are errors; the convergence study's tasks run by hand and gathered equal its
// one-process results; the stability matrix
// planned, two cases run by hand and gathered, the others named.
#include "tests/support/cli_fixture.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using testing::CliFixture;
using testing::CliResult;
using testing::contains;
using testing::read_file_bytes;
using testing::run_shell;

const char* kPlan = "study folds --quick --no-plot --cases twist --methods loop_kl,mass_spring";

// results.csv without its wall_seconds column (the 11th).
std::string without_times(const std::string& csv) {
  std::istringstream in(csv);
  std::string out, line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream l(line);
    while (std::getline(l, cell, ',')) cells.push_back(cell);
    if (cells.size() > 10) cells.erase(cells.begin() + 10);
    for (size_t i = 0; i < cells.size(); ++i) out += (i ? "," : "") + cells[i];
    out += '\n';
  }
  return out;
}

// The commands of a plan's tasks.tsv, in its order (the last column of every line but the header).
std::vector<std::string> task_commands(const fs::path& plan) {
  std::vector<std::string> commands;
  std::istringstream in(read_file_bytes(plan / "tasks.tsv"));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) commands.push_back(line.substr(line.rfind('\t') + 1));
  return commands;
}

class StudySweepCli : public CliFixture {
 protected:
  // A stand-in for sbatch on PATH (dir_/bin): `sbatch --parsable [--wait] SCRIPT` prints job id 42 and
  // runs every index of the script's --array line one after another, except `skip`.
  std::string fake_sbatch(const std::string& skip) {
    write("bin/sbatch",
          "#!/bin/bash\n"
          "script=\"${@: -1}\"\n"
          "spec=$(sed -n 's/^#SBATCH --array=\\([^%]*\\).*/\\1/p' \"$script\")\n"
          "log=$(sed -n 's/^#SBATCH --output=//p' \"$script\")\n"
          "echo 42\n"
          "status=0\n"
          "for part in ${spec//,/ }; do\n"
          "  for i in $(seq ${part%-*} ${part#*-}); do\n"
          "    [ \"$i\" = \"" + skip + "\" ] && continue\n"
          "    SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_JOB_ID=42 bash \"$script\" > \"${log//%a/$i}\" 2>&1 || status=$?\n"
          "  done\n"
          "done\n"
          "exit $status\n");
    fs::permissions(dir_ / "bin" / "sbatch", fs::perms::owner_all);
    return "PATH=" + (dir_ / "bin").string() + ":/usr/bin:/bin ";
  }
  CliResult run_env(const std::string& env, const std::string& args) {
    const fs::path out = dir_ / ".o", err = dir_ / ".e";
    CliResult r;
    r.exit_code = run_shell(env + testing::shell_quote(CLOTHSIM_BINARY) + " " + args + " >" + q(out) + " 2>" + q(err));
    r.out = read_file_bytes(out);
    r.err = read_file_bytes(err);
    return r;
  }
};

TEST_F(StudySweepCli, LocalJobsAndPlanTaskGatherGiveTheSerialResults) {
  const CliResult serial = run(std::string(kPlan) + " --out " + q(dir_ / "serial"));
  ASSERT_EQ(serial.exit_code, 0) << serial.err;
  EXPECT_TRUE(contains(serial.out, "fold study: 4 runs (0 failed or unstable)")) << serial.out;
  const std::string expected = without_times(read_file_bytes(dir_ / "serial" / "study_folds" / "results.csv"));
  ASSERT_EQ(std::count(expected.begin(), expected.end(), '\n'), 5) << expected;

  // By hand: plan, one `clothsim task` per line of tasks.tsv (in reverse), gather.
  const fs::path plan = dir_ / "plan";
  const CliResult planned = run(std::string(kPlan) + " --plan " + q(plan) + " --out " + q(dir_ / "byhand"));
  ASSERT_EQ(planned.exit_code, 0) << planned.err;
  EXPECT_TRUE(contains(planned.out, "planned 4 tasks")) << planned.out;
  EXPECT_FALSE(fs::exists(dir_ / "byhand")) << "planning ran something";
  const std::vector<std::string> commands = task_commands(plan);
  ASSERT_EQ(commands.size(), 4u);
  EXPECT_EQ(commands[0].rfind(std::string(CLOTHSIM_BINARY) + " task ", 0), 0u) << commands[0];
  for (auto it = commands.rbegin(); it != commands.rend(); ++it)
    ASSERT_EQ(run_shell(*it + " >/dev/null 2>&1"), 0) << *it;
  const CliResult gathered = run("study folds --no-plot --gather " + q(plan));
  ASSERT_EQ(gathered.exit_code, 0) << gathered.err;
  EXPECT_EQ(without_times(read_file_bytes(dir_ / "byhand" / "study_folds" / "results.csv")), expected);

  // -j 2: GNU parallel runs two `clothsim task` processes at once.
  if (run_shell("command -v parallel >/dev/null") != 0) {
    std::printf("skipped -j 2: GNU parallel is not installed (scripts/install_deps.sh)\n");
    return;
  }
  const CliResult local = run(std::string(kPlan) + " -j 2 --out " + q(dir_ / "local"));
  ASSERT_EQ(local.exit_code, 0) << local.err;
  EXPECT_TRUE(contains(local.out, "local: 4 tasks in")) << local.out;
  // The limit is what -j asked for; how many tasks the log shows overlapping depends on the
  // scheduler (tasks of 0.1 s on a loaded machine may run one after another), but never above 2.
  EXPECT_TRUE(contains(local.err, "4 of 4 tasks to run (local, 2 at once;")) << local.err;
  EXPECT_TRUE(contains(local.out, "at most 1 at once") || contains(local.out, "at most 2 at once")) << local.out;
  EXPECT_EQ(without_times(read_file_bytes(dir_ / "local" / "study_folds" / "results.csv")), expected);
  EXPECT_TRUE(fs::exists(dir_ / "local" / "study_folds.tasks" / "logs" / "task_3.log"));
  // Again: the usual folder of the previous sweep is replaced, not resumed.
  const CliResult again = run(std::string(kPlan) + " -j 2 --out " + q(dir_ / "local"));
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_TRUE(contains(again.err, "4 of 4 tasks to run")) << again.err;
}

TEST_F(StudySweepCli, SlurmWithoutSbatchRejectedAndDryRun) {
  // No sbatch on the PATH: a clear error, the plan kept, the command that runs it here.
  const fs::path plan = dir_ / "plan";
  const CliResult none = run_env("PATH=/nonexistent ", std::string(kPlan) + " --executor slurm --plan " + q(plan));
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_TRUE(contains(none.err, "sbatch is not on the PATH")) << none.err;
  EXPECT_TRUE(contains(none.err, "--plan " + plan.string() + " --retry-failed --executor local")) << none.err;
  EXPECT_TRUE(fs::exists(plan / "tasks.tsv"));
  EXPECT_TRUE(fs::is_empty(plan / "runs"));

  // A dry run prints the script and submits nothing (no sbatch needed).
  const CliResult dry = run_env("PATH=/nonexistent ", std::string(kPlan) + " --executor slurm --dry-run -j 3 "
                                                        "--slurm-time 10 --partition short --plan " + q(dir_ / "dry"));
  ASSERT_EQ(dry.exit_code, 0) << dry.err;
  EXPECT_EQ(dry.out.rfind("#!/bin/bash\n", 0), 0u) << dry.out;
  EXPECT_TRUE(contains(dry.out, "#SBATCH --array=0-3%3\n")) << dry.out;
  EXPECT_TRUE(contains(dry.out, "#SBATCH --time=10\n")) << dry.out;
  EXPECT_TRUE(contains(dry.out, "#SBATCH --partition=short\n")) << dry.out;
  EXPECT_EQ(read_file_bytes(dir_ / "dry" / "slurm_array.sh"), dry.out);
  EXPECT_TRUE(contains(dry.err, "not submitted")) << dry.err;
  EXPECT_TRUE(fs::is_empty(dir_ / "dry" / "runs"));

  // sbatch refuses the job: its message, nothing ran, the command to submit again.
  write("reject/sbatch", "#!/bin/sh\necho 'sbatch: error: Batch job submission failed: Invalid partition name specified' >&2\nexit 1\n");
  fs::permissions(dir_ / "reject" / "sbatch", fs::perms::owner_all);
  const CliResult rejected = run_env("PATH=" + (dir_ / "reject").string() + ":/usr/bin:/bin ",
                                     std::string(kPlan) + " --executor slurm --partition nosuch --plan " + q(dir_ / "rej"));
  EXPECT_EQ(rejected.exit_code, 1);
  EXPECT_TRUE(contains(rejected.err, "sbatch rejected the job array")) << rejected.err;
  EXPECT_TRUE(contains(rejected.err, "Invalid partition name specified")) << rejected.err;
  EXPECT_TRUE(contains(rejected.err, "--retry-failed --executor slurm --partition nosuch")) << rejected.err;
  EXPECT_TRUE(fs::is_empty(dir_ / "rej" / "runs"));

  // Bad values are named.
  const CliResult mem = run(std::string(kPlan) + " --executor slurm --slurm-mem lots --plan " + q(dir_ / "mem"));
  EXPECT_EQ(mem.exit_code, 1);
  EXPECT_TRUE(contains(mem.err, "--slurm-mem: \"lots\"")) << mem.err;
  EXPECT_FALSE(fs::exists(dir_ / "mem"));
}

TEST_F(StudySweepCli, AMissingTaskIsNamedAndTheRetryCommandFinishesTheStudy) {
  // The stand-in sbatch leaves array task 2 out, as if its node had vanished.
  const std::string env = fake_sbatch("2");
  const fs::path plan = dir_ / "plan";
  const CliResult first =
      run_env(env, std::string(kPlan) + " --executor slurm --slurm-mem 1G --plan " + q(plan) + " --out " + q(dir_ / "out"));
  EXPECT_EQ(first.exit_code, 1) << first.err;
  EXPECT_TRUE(contains(first.err, "submitted job array 42 (4 tasks)")) << first.err;
  EXPECT_TRUE(contains(first.err, "1 of 4 tasks did not finish")) << first.err;
  EXPECT_TRUE(contains(first.err, "twist-mass_spring-13x9-seed1 (task 2): it did not run")) << first.err;
  EXPECT_TRUE(contains(first.out, "slurm: job array 42: 3 tasks in")) << first.out;
  // The report has the three that finished.
  const std::string csv = read_file_bytes(dir_ / "out" / "study_folds" / "results.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4) << csv;
  std::smatch m;
  const std::string err = first.err;
  ASSERT_TRUE(std::regex_search(err, m, std::regex("Run them with: (clothsim study folds [^\n]*)"))) << err;
  const std::string retry = m[1].str();
  EXPECT_TRUE(contains(retry, "--retry-failed --executor slurm --slurm-mem 1G")) << retry;

  // The printed command, with the stand-in now running every task it is given: only task 2 runs.
  const std::string all = fake_sbatch("none");
  const CliResult second = run_env(all, retry.substr(std::string("clothsim ").size()));
  ASSERT_EQ(second.exit_code, 0) << second.err;
  EXPECT_TRUE(contains(second.err, "1 of 4 tasks to run")) << second.err;
  EXPECT_TRUE(contains(read_file_bytes(plan / "slurm_array.sh"), "#SBATCH --array=2%32\n"));
  EXPECT_TRUE(contains(second.out, "fold study: 4 runs (0 failed or unstable)")) << second.out;
}

TEST_F(StudySweepCli, AnInterruptedWaitLeavesTheArrayAndSaysHowToGather) {
  // A stand-in sbatch that accepts the array and then waits (a long job).
  write("slow/sbatch", "#!/bin/bash\necho 42\nexec sleep 60\n");
  fs::permissions(dir_ / "slow" / "sbatch", fs::perms::owner_all);
  const fs::path plan = dir_ / "plan";
  CliResult r;
  r.exit_code = run_shell("{ PATH=" + (dir_ / "slow").string() + ":/usr/bin:/bin " +
                          testing::shell_quote(CLOTHSIM_BINARY) + " " + kPlan + " --executor slurm --plan " + q(plan) +
                          " --out " + q(dir_ / "out") + " & p=$!; sleep 2; kill -INT $p; wait $p; } >" + q(dir_ / ".o") +
                          " 2>" + q(dir_ / ".e"));
  r.err = read_file_bytes(dir_ / ".e");
  EXPECT_EQ(r.exit_code, 130) << r.err;
  EXPECT_TRUE(contains(r.err, "interrupted; job array 42 goes on running")) << r.err;
  EXPECT_TRUE(contains(r.err, "scancel 42")) << r.err;
  EXPECT_TRUE(contains(r.err, "gather with: clothsim study folds --gather " + plan.string())) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out")) << "nothing is gathered while the array runs";
}

TEST_F(StudySweepCli, StabilityTasksAreGatheredAndTheMissingCasesNamed) {
  // The quick matrix planned; two of its fast cases run by hand, in reverse order.
  const fs::path plan = dir_ / "plan";
  const CliResult planned = run("study stability --quick --no-plot --plan " + q(plan) + " --out " + q(dir_ / "out"));
  ASSERT_EQ(planned.exit_code, 0) << planned.err;
  EXPECT_TRUE(contains(planned.out, "planned 9 tasks of study stability")) << planned.out;
  for (const char* id : {"mesh_coarse_90_dt_5e-2", "material_Et_1e7_dt_5e-2"}) {
    const CliResult task = run("task " + q(plan) + " " + id);
    ASSERT_EQ(task.exit_code, 0) << task.err;
  }
  const CliResult gathered = run("study stability --no-plot --gather " + q(plan));
  EXPECT_EQ(gathered.exit_code, 1);
  EXPECT_TRUE(contains(gathered.out, "stability study: 2 of 2 cases pass")) << gathered.out;
  EXPECT_TRUE(contains(gathered.err, "7 of 9 tasks did not finish")) << gathered.err;
  EXPECT_TRUE(contains(gathered.err, "dt_1e-2 (task 0): it did not run")) << gathered.err;
  const fs::path report = dir_ / "out" / "study_stability";
  const std::string csv = read_file_bytes(report / "results.csv");
  // In the plan's order (material_Et_1e7_dt_5e-2 is task 3, mesh_coarse_90_dt_5e-2 task 7).
  const size_t a = csv.find("\nmaterial_Et_1e7_dt_5e-2,true,false,"), b = csv.find("\nmesh_coarse_90_dt_5e-2,true,false,");
  EXPECT_NE(a, std::string::npos) << csv;
  EXPECT_NE(b, std::string::npos) << csv;
  EXPECT_LT(a, b) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;
  EXPECT_TRUE(contains(read_file_bytes(report / "table.md"), "## Cases that did not finish"));
  // Every case's scene is written, finished or not.
  EXPECT_TRUE(fs::exists(report / "scenes" / "dt_1e-2.json"));
  // Gathering again gives the same files.
  const std::string table = read_file_bytes(report / "table.md");
  EXPECT_EQ(run("study stability --no-plot --gather " + q(plan)).exit_code, 1);
  EXPECT_EQ(read_file_bytes(report / "results.csv"), csv);
  EXPECT_EQ(read_file_bytes(report / "table.md"), table);
}

// fig N.md without its last column (the runs' wall times).
std::string without_wall_times(const std::string& md) {
  std::istringstream in(md);
  std::string out, line;
  while (std::getline(in, line)) {
    if (line.rfind("| ", 0) == 0 && line.size() > 2) {
      const size_t last = line.rfind(" | ", line.size() - 3);
      if (last != std::string::npos) line = line.substr(0, last);
    }
    out += line + '\n';
  }
  return out;
}

TEST_F(StudySweepCli, FiguresAsTasksGiveTheSameFigureAndNameWhatIsMissing) {
  const CliResult serial = run("figures 10 --quick --out " + q(dir_ / "serial"));
  ASSERT_EQ(serial.exit_code, 0) << serial.err;
  const fs::path a = dir_ / "serial" / "figures";
  // Planned: the four runs of Fig. 10; two run by hand, the gather names the figure it cannot draw.
  const fs::path plan = dir_ / "plan";
  ASSERT_EQ(run("figures 10 --quick --plan " + q(plan) + " --out " + q(dir_ / "tasks")).exit_code, 0);
  ASSERT_EQ(run("task " + q(plan) + " catenary_mesh").exit_code, 0);
  ASSERT_EQ(run("task " + q(plan) + " catenary_black_denim").exit_code, 0);
  const CliResult partial = run("figures --gather " + q(plan));
  EXPECT_EQ(partial.exit_code, 1);
  EXPECT_TRUE(contains(partial.err, "not drawn: Fig. 10 (runs catenary_gray_interlock, catenary_pink_ribbon_brown)"))
      << partial.err;
  EXPECT_TRUE(contains(partial.err, "Run them with: clothsim figures --plan " + plan.string() + " --retry-failed"))
      << partial.err;
  const fs::path b = dir_ / "tasks" / "figures";
  EXPECT_FALSE(fs::exists(b / "fig10.png"));
  EXPECT_TRUE(contains(read_file_bytes(b / "figures.md"), "## Not drawn"));
  // The rest in this process, then the same figure as the one-process run (but for wall times).
  const CliResult rest = run("figures --plan " + q(plan) + " --retry-failed -j 1");
  ASSERT_EQ(rest.exit_code, 0) << rest.err;
  EXPECT_TRUE(contains(rest.err, "2 of 4 tasks to run")) << rest.err;
  EXPECT_EQ(read_file_bytes(b / "fig10.png"), read_file_bytes(a / "fig10.png"));
  EXPECT_EQ(without_wall_times(read_file_bytes(b / "fig10.md")), without_wall_times(read_file_bytes(a / "fig10.md")));
  EXPECT_FALSE(contains(read_file_bytes(b / "figures.md"), "## Not drawn"));
}

TEST_F(StudySweepCli, ConvergenceTasksGiveTheOneProcessResults) {
  // The quick convergence study planned, every task run by hand (in reverse), gathered: the
  // one-process results.csv in every column but wall_seconds (the 11th); one task left out is
  // named by the gather and its rows say so.
  const CliResult serial = run("study convergence --quick --no-plot --out " + q(dir_ / "serial"));
  ASSERT_EQ(serial.exit_code, 0) << serial.err;
  const std::string expected = without_times(read_file_bytes(dir_ / "serial" / "study_convergence" / "results.csv"));
  const fs::path plan = dir_ / "plan";
  const CliResult planned = run("study convergence --quick --no-plot --plan " + q(plan) + " --out " + q(dir_ / "tasks"));
  ASSERT_EQ(planned.exit_code, 0) << planned.err;
  const std::vector<std::string> commands = task_commands(plan);
  ASSERT_GT(commands.size(), 5u);
  for (auto it = commands.rbegin(); it + 1 != commands.rend(); ++it)  // all but the first
    ASSERT_EQ(run_shell(*it + " >/dev/null 2>&1"), 0) << *it;
  const CliResult partial = run("study convergence --no-plot --gather " + q(plan));
  EXPECT_EQ(partial.exit_code, 1);
  const std::string first = commands.front().substr(commands.front().rfind(' ') + 1);
  EXPECT_TRUE(contains(partial.err, first)) << partial.err;
  EXPECT_TRUE(contains(read_file_bytes(dir_ / "tasks" / "study_convergence" / "results.md"), "Runs that did not finish"));
  ASSERT_EQ(run_shell(commands.front() + " >/dev/null 2>&1"), 0);
  const CliResult gathered = run("study convergence --no-plot --gather " + q(plan));
  ASSERT_EQ(gathered.exit_code, 0) << gathered.err;
  EXPECT_EQ(without_times(read_file_bytes(dir_ / "tasks" / "study_convergence" / "results.csv")), expected);
}

TEST_F(StudySweepCli, BadFoldersAndOptionsAreErrors) {
  const CliResult gather = run("study folds --gather " + q(dir_));
  EXPECT_EQ(gather.exit_code, 1);
  EXPECT_TRUE(contains(gather.err, (dir_ / "plan.json").string() + ": not found")) << gather.err;

  write("full/keep.txt", "mine");
  const CliResult full = run(std::string(kPlan) + " --plan " + q(dir_ / "full"));
  EXPECT_EQ(full.exit_code, 1);
  EXPECT_TRUE(contains(full.err, "is not empty")) << full.err;
  EXPECT_EQ(read_file_bytes(dir_ / "full" / "keep.txt"), "mine");

  const CliResult mixed = run("study folds --quick --gather " + q(dir_));
  EXPECT_EQ(mixed.exit_code, 1);
  EXPECT_TRUE(contains(mixed.err, "--gather uses the plan in its folder")) << mixed.err;

  // -j 2 without GNU parallel: named, with the way to run the plan without it.
  const CliResult no_parallel = run_env("PATH=/nonexistent ", std::string(kPlan) + " -j 2 --plan " + q(dir_ / "np"));
  EXPECT_EQ(no_parallel.exit_code, 1);
  EXPECT_TRUE(contains(no_parallel.err, "GNU parallel is not on the PATH")) << no_parallel.err;
  EXPECT_TRUE(fs::exists(dir_ / "np" / "tasks.tsv"));
  // A plan of the fold study is not gathered as another study.
  const CliResult wrong = run("study stability --gather " + q(dir_ / "np"));
  EXPECT_EQ(wrong.exit_code, 1);
  EXPECT_TRUE(contains(wrong.err, "holds a plan of study folds, not stability")) << wrong.err;

  const CliResult task = run("task " + q(dir_) + " twist-loop_kl-13x9-seed1");
  EXPECT_EQ(task.exit_code, 1);
  EXPECT_TRUE(contains(task.err, "plan.json")) << task.err;
}

}  // namespace
}  // namespace clothsim

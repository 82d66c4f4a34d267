// Plan / task / gather of app/sweep.hpp (issue 31), built directly: the fold study's tasks.tsv
// (header, one line per run, stable ids, the exact command), the plan read back, a bad plan folder
// named; the fold CSV read back and written again unchanged; one real task run into its folder and
// not run again; the gather from a hand-made sweep (finished, failed, timed-out and missing tasks:
// the report has the finished rows in the plan's order and names the others with their reasons;
// two gathers give identical files); the job-array script of a dry run (array ranges, throttle,
// limits, pass-through options, log files) and its line lookup run by bash; the checks of the
// sweep options.
#include "app/study.hpp"
#include "app/sweep.hpp"
#include "sim/study/fold_study.hpp"
#include "tests/support/process.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using testing::read_file_bytes;
using testing::run_shell;
using testing::shell_quote;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

FoldStudyPlan quick_plan() { return quick_fold_plan(fs::path(CLOTHSIM_SOURCE_DIR) / "scenes"); }

class Sweep : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::make_temp_dir("clothsim_sweep_"); }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // A finished task made by hand: runs/<id>/row.csv with `row`, and task.json.
  void finish(const fs::path& plan_dir, const std::string& id, const FoldRow& row) const {
    fs::create_directories(plan_dir / "runs" / id);
    std::ostringstream csv;
    write_fold_csv(csv, {row});
    std::ofstream(plan_dir / "runs" / id / "row.csv", std::ios::binary) << csv.str();
    std::ofstream(plan_dir / "runs" / id / "task.json")
        << "{\"id\": \"" << id << "\", \"start\": 100.0, \"end\": 101.5, \"seconds\": 1.5}\n";
  }

  fs::path dir_;
};

FoldRow row_of(const std::string& case_name, const std::string& method, int segments, int rings, double folds) {
  FoldRow r;
  r.case_name = case_name;
  r.method = method;
  r.segments = segments;
  r.rings = rings;
  r.vertices = segments * rings;
  r.seed = 1;
  r.amplitude = 1.25e-4;
  r.dt = 0.005;
  r.steps = 20;
  r.end_time = 0.1;
  r.wall_seconds = 0.321;
  r.circumferential_median = folds;
  r.axial_median = std::numeric_limits<double>::quiet_NaN();
  r.circumferential_theory = {6.12345, 8.02345};
  r.axial_theory = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  r.t_eff = 2.5e-4;
  r.preset = "cotton";
  r.status = "ok";
  return r;
}

TEST_F(Sweep, TasksTsvHasOneLinePerRunWithStableIdsAndTheExactCommand) {
  const SweepStudy study = fold_study_sweep(quick_plan());
  const fs::path plan_dir = dir_ / "plan";
  write_sweep_plan(plan_dir, study, "/opt/clothsim/bin/clothsim", dir_ / "out");
  const std::vector<std::string> lines = lines_of(read_file_bytes(plan_dir / "tasks.tsv"));
  // Quick plan: 2 cases × 3 methods × 2 meshes × 1 seed.
  ASSERT_EQ(lines.size(), 13u);
  EXPECT_EQ(lines[0], "index\tid\tcommand");
  EXPECT_EQ(lines[1], "0\ttwist-loop_kl-13x9-seed1\t/opt/clothsim/bin/clothsim task " + plan_dir.string() +
                          " twist-loop_kl-13x9-seed1");
  EXPECT_EQ(lines[12], "11\tcompress-mass_spring-18x13-seed1\t/opt/clothsim/bin/clothsim task " + plan_dir.string() +
                           " compress-mass_spring-18x13-seed1");
  std::set<std::string> ids(study.ids.begin(), study.ids.end());
  EXPECT_EQ(ids.size(), 12u);

  // The ids depend on the run only: with a second seed and another mesh, the quick plan's runs keep theirs.
  FoldStudyPlan bigger = quick_plan();
  bigger.seeds = {1, 2};
  bigger.meshes.push_back({26, 19});
  const SweepStudy more = fold_study_sweep(bigger);
  EXPECT_EQ(more.ids.size(), 36u);
  for (const std::string& id : study.ids)
    EXPECT_NE(std::find(more.ids.begin(), more.ids.end(), id), more.ids.end()) << id;

  const SweepPlan plan = read_sweep_plan(plan_dir);
  EXPECT_EQ(plan.study, "folds");
  EXPECT_EQ(plan.ids, study.ids);
  EXPECT_EQ(plan.settings, study.settings);
  EXPECT_EQ(plan.out_root, dir_ / "out");
  for (const char* sub : {"runs", "logs", "failed"}) EXPECT_TRUE(fs::is_directory(plan_dir / sub)) << sub;

  // A folder that is not empty is not planned into.
  EXPECT_THROW(write_sweep_plan(plan_dir, study, "clothsim", dir_ / "out"), std::runtime_error);
  // Unsafe ids are refused.
  SweepStudy bad = study;
  bad.ids.push_back("../escape");
  EXPECT_THROW(write_sweep_plan(dir_ / "bad", bad, "clothsim", dir_ / "out"), std::invalid_argument);
  bad.ids.back() = study.ids.front();
  EXPECT_THROW(write_sweep_plan(dir_ / "bad2", bad, "clothsim", dir_ / "out"), std::invalid_argument);
}

TEST_F(Sweep, ABadPlanFolderIsAnErrorNamingTheFile) {
  try {
    read_sweep_plan(dir_);
    ADD_FAILURE() << "no error for a folder without plan.json";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((dir_ / "plan.json").string()), std::string::npos) << e.what();
  }
  write_sweep_plan(dir_ / "plan", fold_study_sweep(quick_plan()), "clothsim", dir_ / "out");
  std::ofstream(dir_ / "plan" / "tasks.tsv") << "index\tid\tcommand\n0\tok\tx\n5\tskipped\tx\n";
  try {
    read_sweep_plan(dir_ / "plan");
    ADD_FAILURE() << "no error for an index out of order";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("tasks.tsv: line 3"), std::string::npos) << e.what();
  }
}

TEST(FoldCsv, ReadBackAndWrittenAgainIsTheSameText) {
  std::vector<FoldRow> rows = {row_of("twist", "loop_kl", 13, 9, 7), row_of("compress", "linear_fe", 18, 13, 0)};
  rows[1].axial_median = 3.5;
  rows[1].axial_theory = {1.23456e-5, 2.5};
  rows[1].status = "failed";
  rows[1].note = "solver: \"no convergence\", step 3\nsecond line";
  rows[1].circumferential_median = std::numeric_limits<double>::quiet_NaN();
  std::ostringstream first;
  write_fold_csv(first, rows);
  const std::vector<FoldRow> back = read_fold_csv(first.str());
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].note, rows[1].note);
  EXPECT_TRUE(std::isnan(back[1].circumferential_median));
  std::ostringstream second;
  write_fold_csv(second, back);
  EXPECT_EQ(second.str(), first.str());

  EXPECT_THROW(read_fold_csv("case,method\ntwist,loop_kl\n"), std::invalid_argument);
  std::string broken = first.str();
  broken.replace(broken.find(",13,9,"), 6, ",13,x9,");
  try {
    read_fold_csv(broken);
    ADD_FAILURE() << "no error for a bad integer";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("column rings"), std::string::npos) << e.what();
  }
}

TEST_F(Sweep, OneTaskRunsIntoItsFolderOnceAndAnUnknownIdIsRefused) {
  FoldStudyPlan plan = quick_plan();
  plan.cases = {"twist"};
  plan.methods = {"mass_spring"};
  plan.meshes = {{13, 9}};
  plan.end = 0.02;
  const fs::path plan_dir = dir_ / "plan";
  write_sweep_plan(plan_dir, fold_study_sweep(plan), "clothsim", dir_ / "out");
  const std::string id = "twist-mass_spring-13x9-seed1";
  ASSERT_EQ(run_sweep_task(plan_dir, id), 0);
  const fs::path run = plan_dir / "runs" / id;
  const std::vector<FoldRow> rows = read_fold_csv(read_file_bytes(run / "row.csv"));
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].status, "ok");
  EXPECT_EQ(rows[0].steps, 4);
  const std::string info = read_file_bytes(run / "task.json");
  EXPECT_NE(info.find("\"seconds\""), std::string::npos) << info;
  for (const fs::directory_entry& e : fs::directory_iterator(plan_dir / "runs"))
    EXPECT_EQ(e.path().filename(), id) << "left behind: " << e.path();

  // Finished: not run again (task.json unchanged).
  ASSERT_EQ(run_sweep_task(plan_dir, id), 0);
  EXPECT_EQ(read_file_bytes(run / "task.json"), info);
  EXPECT_EQ(run_sweep_task(plan_dir, "twist-mass_spring-99x9-seed1"), 1);
  EXPECT_FALSE(fs::exists(plan_dir / "runs" / "twist-mass_spring-99x9-seed1"));
  EXPECT_EQ(run_sweep_task(dir_ / "no_plan", id), 1);
}

TEST_F(Sweep, GatherNamesMissingAndFailedTasksAndTwoGathersAreIdentical) {
  const SweepStudy study = fold_study_sweep(quick_plan());
  const fs::path plan_dir = dir_ / "plan";
  write_sweep_plan(plan_dir, study, "clothsim", dir_ / "out");
  // Finished: tasks 0, 1 and 5 (written out of order); failed with a message: 2; killed by Slurm's
  // time limit: 3; started without a result: 4; never ran: 6-11.
  finish(plan_dir, study.ids[5], row_of("twist", "mass_spring", 18, 13, 9));
  finish(plan_dir, study.ids[0], row_of("twist", "loop_kl", 13, 9, 7));
  finish(plan_dir, study.ids[1], row_of("twist", "loop_kl", 18, 13, 8));
  std::ofstream(plan_dir / "failed" / (study.ids[2] + ".txt")) << "sleeve_twist.json: cannot read the file\n";
  std::ofstream(plan_dir / "logs" / "task_3.log")
      << "clothsim task x\nslurmstepd: error: *** JOB 12 ON vm CANCELLED AT 2026-11-28T15:00:00 DUE TO TIME LIMIT ***\n";
  std::ofstream(plan_dir / "logs" / "task_4.log") << "clothsim task x\n";
  // A half-written run (a hidden staging folder of a killed task) is not a result.
  fs::create_directories(plan_dir / "runs" / ("." + study.ids[6] + ".tmp-999999"));

  const SweepPlan plan = read_sweep_plan(plan_dir);
  const std::vector<TaskStatus> status = sweep_status(plan);
  ASSERT_EQ(status.size(), 12u);
  EXPECT_EQ(status[0].state, TaskState::finished);
  EXPECT_EQ(status[2].state, TaskState::failed);
  EXPECT_NE(status[2].reason.find("cannot read the file"), std::string::npos) << status[2].reason;
  EXPECT_EQ(status[3].state, TaskState::missing);
  EXPECT_NE(status[3].reason.find("time limit"), std::string::npos) << status[3].reason;
  EXPECT_NE(status[4].reason.find("left no result"), std::string::npos) << status[4].reason;
  EXPECT_NE(status[6].reason.find("did not run"), std::string::npos) << status[6].reason;

  ::testing::internal::CaptureStderr();
  const int code = gather_sweep(plan_dir, dir_ / "a", false, std::nullopt, "RESUME-COMMAND");
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(code, 1) << "a gather with missing tasks must fail";
  EXPECT_NE(err.find("9 of 12 tasks did not finish"), std::string::npos) << err;
  for (int i : {2, 3, 4, 6, 11}) EXPECT_NE(err.find(study.ids[i] + " (task " + std::to_string(i) + ")"), std::string::npos) << err;
  EXPECT_EQ(err.find(study.ids[0] + " (task"), std::string::npos) << err;
  EXPECT_NE(err.find("RESUME-COMMAND"), std::string::npos) << err;

  const std::vector<FoldRow> rows = read_fold_csv(read_file_bytes(dir_ / "a" / "study_folds" / "results.csv"));
  ASSERT_EQ(rows.size(), 3u);  // in the plan's order: tasks 0, 1, 5
  EXPECT_EQ(rows[0].circumferential_median, 7);
  EXPECT_EQ(rows[1].circumferential_median, 8);
  EXPECT_EQ(rows[2].method, "mass_spring");
  const std::string md = read_file_bytes(dir_ / "a" / "study_folds" / "results.md");
  EXPECT_NE(md.find("## Runs that did not finish"), std::string::npos) << md;
  EXPECT_NE(md.find(study.ids[3] + " (task 3): killed at its time limit"), std::string::npos) << md;

  ::testing::internal::CaptureStderr();
  EXPECT_EQ(gather_sweep(plan_dir, dir_ / "b", false), 1);
  ::testing::internal::GetCapturedStderr();
  for (const char* file : {"results.csv", "results.md"})
    EXPECT_EQ(read_file_bytes(dir_ / "a" / "study_folds" / file), read_file_bytes(dir_ / "b" / "study_folds" / file))
        << file;
  std::set<std::string> names;
  for (const fs::directory_entry& e : fs::directory_iterator(dir_ / "b" / "study_folds"))
    names.insert(e.path().filename().string());
  EXPECT_EQ(names, (std::set<std::string>{"results.csv", "results.md"}));
}

TEST(SweepScript, ArrayRanges) {
  EXPECT_EQ(array_ranges({0, 1, 2, 3}), "0-3");
  EXPECT_EQ(array_ranges({0, 1, 2, 3, 5, 7, 8}), "0-3,5,7-8");
  EXPECT_EQ(array_ranges({4}), "4");
  EXPECT_EQ(array_ranges({}), "");
}

TEST_F(Sweep, TheJobArrayScriptHasTheLimitsThrottleLogsAndFindsItsTask) {
  const SweepStudy study = fold_study_sweep(quick_plan());
  const fs::path plan_dir = dir_ / "plan";
  write_sweep_plan(plan_dir, study, "clothsim", dir_ / "out");
  const SweepPlan plan = read_sweep_plan(plan_dir);
  SweepCommand c;
  c.executor = "slurm";
  c.jobs = 4;
  c.slurm_time = "0:30:00";
  c.slurm_mem = "2G";
  c.partition = "short";
  c.account = "proj42";
  c.sbatch_args = {"--qos=low", "--constraint=avx2"};
  c.clothsim = "/bin/echo";  // the script's last line then prints what it would run
  const std::string script = slurm_array_script(plan, {0, 1, 2, 5, 11}, c);
  for (const std::string& line :
       {std::string("#!/bin/bash\n"), std::string("\n#SBATCH --array=0-2,5,11%4\n"), std::string("\n#SBATCH --time=0:30:00\n"),
        std::string("\n#SBATCH --mem=2G\n"), std::string("\n#SBATCH --partition=short\n"),
        std::string("\n#SBATCH --account=proj42\n"), std::string("\n#SBATCH --qos=low\n"),
        std::string("\n#SBATCH --constraint=avx2\n"), std::string("\n#SBATCH --cpus-per-task=1\n"),
        "\n#SBATCH --output=" + (plan.dir / "logs" / "task_%a.log").string() + "\n"})
    EXPECT_NE(script.find(line), std::string::npos) << "missing " << line << " in\n" << script;
  // Every #SBATCH line comes before the first command (sbatch ignores them after it).
  const size_t first_command = script.find("\nset -euo pipefail");
  EXPECT_EQ(script.rfind("#SBATCH", first_command), script.rfind("#SBATCH"));

  const fs::path file = dir_ / "array.sh";
  std::ofstream(file) << script;
  const fs::path out = dir_ / "task5.txt";
  ASSERT_EQ(run_shell("SLURM_ARRAY_TASK_ID=5 SLURM_ARRAY_JOB_ID=7 bash " + shell_quote(file.string()) + " > " +
                      shell_quote(out.string())),
            0);
  const std::vector<std::string> lines = lines_of(read_file_bytes(out));
  ASSERT_EQ(lines.size(), 2u) << read_file_bytes(out);
  EXPECT_EQ(lines[1], "task " + plan.dir.string() + " " + study.ids[5]);
  EXPECT_NE(run_shell("SLURM_ARRAY_TASK_ID=12 SLURM_ARRAY_JOB_ID=7 bash " + shell_quote(file.string()) +
                      " >/dev/null 2>&1"),
            0)
      << "an index past the plan must fail";

  // Without -j the throttle is the default.
  c.jobs = 0;
  EXPECT_NE(slurm_array_script(plan, {0, 1}, c).find("--array=0-1%" + std::to_string(kDefaultSlurmThrottle) + "\n"),
            std::string::npos);
}

TEST(SweepCommandCheck, BadOptionsAreNamed) {
  SweepCommand c;
  EXPECT_EQ(check_sweep_command(c), "");
  EXPECT_FALSE(sweep_requested(c));
  c.jobs = 1;
  EXPECT_FALSE(sweep_requested(c)) << "-j 1 is the usual single process";
  c.jobs = 2;
  EXPECT_TRUE(sweep_requested(c));
  c = {};
  c.dry_run = true;
  EXPECT_NE(check_sweep_command(c).find("--dry-run"), std::string::npos);
  c = {};
  c.slurm_mem = "8G";
  EXPECT_NE(check_sweep_command(c).find("--slurm-mem applies to --executor slurm only"), std::string::npos);
  c.executor = "slurm";
  EXPECT_EQ(check_sweep_command(c), "");
  c.slurm_mem = "lots";
  EXPECT_NE(check_sweep_command(c).find("--slurm-mem: \"lots\""), std::string::npos);
  c.slurm_mem = "8G";
  c.slurm_time = "2 hours";
  EXPECT_NE(check_sweep_command(c).find("--slurm-time: \"2 hours\""), std::string::npos);
  c.slurm_time = "1-12:00:00";
  EXPECT_EQ(check_sweep_command(c), "");
  c.sbatch_args = {"qos=low"};
  EXPECT_NE(check_sweep_command(c).find("--sbatch-arg"), std::string::npos);
  c = {};
  c.gather = "x";
  c.executor = "local";
  EXPECT_NE(check_sweep_command(c).find("--gather DIR builds the report only"), std::string::npos);
}

}  // namespace
}  // namespace clothsim

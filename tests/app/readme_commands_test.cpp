// Every command of the Commands table in docs/cli.md (the README links to it), run in a cheap
// form. The table is read from docs/cli.md at test time and each row is matched, by its command
// (the first backticked text of its first cell, up to the first " ["), to a form below: a row
// with no form here fails the test, so the table cannot gain or change a command unnoticed. A
// form runs shell commands that must exit with code 0, and for the commands that have a --help,
// every --option the row documents must appear in that help. Commands that install packages,
// rebuild the project or rewrite the repository's goldens are only checked for syntax; benchmarks
// and tools that the test build does not make, and scripts whose Python modules are missing, are
// skipped with a notice.
#include "tests/support/process.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;
using testing::read_file_bytes;
using testing::run_shell;
using testing::shell_quote;

struct Row {
  std::string command;  // the first cell
  std::string key;      // its first backticked text, up to the first " ["
};

// The rows of the table under "## Commands" (up to the next heading).
std::vector<Row> readme_command_rows() {
  std::ifstream in(fs::path(CLOTHSIM_SOURCE_DIR) / "docs" / "cli.md");
  std::vector<Row> rows;
  std::string line;
  bool in_section = false;
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0) {
      in_section = line == "## Commands";
      continue;
    }
    if (!in_section || line.rfind("| `", 0) != 0) continue;
    // The first cell ends at the first '|' that is not escaped (`\|` stands for a literal bar).
    std::size_t end = 1;
    while (end < line.size() && !(line[end] == '|' && line[end - 1] != '\\')) ++end;
    Row row;
    row.command = line.substr(2, end - 3);
    const std::size_t open = row.command.find('`');
    const std::size_t close = row.command.find('`', open + 1);
    row.key = row.command.substr(open + 1, close - open - 1);
    if (const std::size_t bracket = row.key.find(" ["); bracket != std::string::npos) row.key.resize(bracket);
    rows.push_back(row);
  }
  return rows;
}

// The --options a row documents (in any of its backticked commands).
std::set<std::string> documented_options(const std::string& cell) {
  std::set<std::string> out;
  const std::regex option("--[a-z][a-z0-9-]*");
  for (std::sregex_iterator it(cell.begin(), cell.end(), option), end; it != end; ++it) out.insert(it->str());
  return out;
}

struct Form {
  std::vector<std::string> commands;  // shell commands; {clothsim}, {src}, {build}, {tmp}, {python} are replaced
  std::string help;                   // prints a help that must list the row's --options (empty: none)
  std::string needs;                  // a file that must exist ({build}/...), or "python:MODULE"; else skipped
};

const std::map<std::string, Form>& forms() {
  static const std::map<std::string, Form> f = {
      {"clothsim SCENE.json",
       {{"{clothsim} {src}/scenes/plate_ss.json --out {tmp}/out --size 64x48",
         "{clothsim} {src}/scenes/sleeve_twist.json --out {tmp}/out --end 0.004 --size 64x48 --framing sequence",
         "{clothsim} {src}/scenes/sleeve_twist.json --out {tmp}/out_motion --end 0.002 --no-render --framing motion"},
        "{clothsim} --help",
        ""}},
      {"clothsim --help", {{"{clothsim} --help", "{clothsim} --version"}, "", ""}},
      {"clothsim SCENE.json --frames N",
       {{"{clothsim} {src}/scenes/sleeve_twist.json --out {tmp}/out_frames --frames 1 --size 32x32",
         // --video needs ffmpeg (optional, README "Quick start"; docs/cli.md).
         "if command -v ffmpeg >/dev/null 2>&1; then {clothsim} {src}/scenes/sleeve_twist.json --out {tmp}/out_video "
         "--frames 1 --size 32x32 --video; fi"},
        "{clothsim} --help",
        ""}},
      // Interrupted with SIGINT once its second step is out (of 300), then resumed; ResumeTest.*
      // checks the bytes.
      {"clothsim SCENE.json --resume DIR",
       {{"{clothsim} {src}/scenes/sleeve_twist.json --out {tmp}/out_resume --end 0.3 --no-render >/dev/null 2>&1 & p=$!; "
         "s={tmp}/out_resume/sleeve_twist/stats.csv; "
         "while [ \"$(cat $s 2>/dev/null | wc -l)\" -lt 3 ]; do sleep 0.02; done; kill -INT $p; wait $p; test $? -eq 130",
         "{clothsim} {src}/scenes/sleeve_twist.json --end 0.3 --no-render --resume {tmp}/out_resume/sleeve_twist"},
        "{clothsim} --help",
        ""}},
      // Install packages, build, run: only their syntax is checked.
      {"scripts/install_deps.sh", {{"test -x {src}/scripts/install_deps.sh", "bash -n {src}/scripts/install_deps.sh"}, "", ""}},
      {"scripts/demo.sh", {{"test -x {src}/scripts/demo.sh", "bash -n {src}/scripts/demo.sh"}, "", ""}},
      {"scripts/test.sh", {{"test -x {src}/scripts/test.sh", "bash -n {src}/scripts/test.sh"}, "", ""}},
      // Rewrites the repository's goldens: only its syntax is checked (`clothsim golden` runs below).
      {"scripts/update_goldens.sh", {{"test -x {src}/scripts/update_goldens.sh", "bash -n {src}/scripts/update_goldens.sh"}, "", ""}},
      // Install and start Slurm as root, run studies through it (.ci/run): only their syntax is checked.
      {"scripts/slurm_local.sh start\\|stop",
       {{"test -x {src}/scripts/slurm_local.sh", "bash -n {src}/scripts/slurm_local.sh"}, "", ""}},
      {"scripts/slurm_check.sh", {{"test -x {src}/scripts/slurm_check.sh", "bash -n {src}/scripts/slurm_check.sh"}, "", ""}},
      // Benchmarks: listed, not run (the test build does not make them; scripts/test.sh does).
      {"build/release/bench/plate_bench", {{"{build}/bench/plate_bench --benchmark_list_tests"}, "", "{build}/bench/plate_bench"}},
      {"build/release/bench/refine_bench", {{"{build}/bench/refine_bench --benchmark_list_tests"}, "", "{build}/bench/refine_bench"}},
      {"build/release/bench/render_bench", {{"{build}/bench/render_bench --benchmark_list_tests"}, "", "{build}/bench/render_bench"}},
      {"build/release/bench/dynamics_bench",
       {{"{build}/bench/dynamics_bench --benchmark_list_tests"}, "", "{build}/bench/dynamics_bench"}},
      {"build/release/bench/contact_bench",
       {{"{build}/bench/contact_bench --benchmark_list_tests"}, "", "{build}/bench/contact_bench"}},
      {"build/release/bench/plate_convergence",
       {{"{build}/bench/plate_convergence --max 8 --csv {tmp}/plate_convergence.csv",
         "test -s {tmp}/plate_convergence.csv"},
        "",
        "{build}/bench/plate_convergence"}},
      // A run with OBJ frames, drawn again.
      {"clothsim render DIR",
       {{"{clothsim} {tmp}/sleeve_obj.json --out {tmp}/out --end 0.004 --no-render",
         "{clothsim} render {tmp}/out/sleeve_obj --size 64x48"},
        "{clothsim} render --help",
        ""}},
      {"clothsim compare A B",
       {{"{clothsim} {src}/scenes/plate_ss.json --out {tmp}/cmp --size 64x48",
         "{clothsim} compare {tmp}/cmp/plate_ss/limit.png {tmp}/cmp/plate_ss/limit.png"},
        "{clothsim} compare --help",
        ""}},
      {"clothsim cache DIR",
       {{"{clothsim} {src}/scenes/sleeve_twist.json --out {tmp}/cache --no-render --frames 3 --set output.obj=true",
         "{clothsim} cache {tmp}/cache/sleeve_twist", "test -s {tmp}/cache/sleeve_twist/cache.pc2",
         "test -s {tmp}/cache/sleeve_twist/cache_rest.obj"},
        "{clothsim} cache --help",
        ""}},
      {"clothsim golden check\\|update MANIFEST",
       {{"{clothsim} golden update {tmp}/goldens.txt", "{clothsim} golden check {tmp}/goldens.txt"},
        "{clothsim} golden --help",
        ""}},
      {"clothsim study convergence",
       {{"{clothsim} study convergence --quick --no-plot --out {tmp}/studies"}, "{clothsim} study --help", ""}},
      {"clothsim study folds",
       {{"{clothsim} study folds --quick --no-plot --cases twist --out {tmp}/studies"}, "{clothsim} study --help", ""}},
      // The fold study as tasks: plan, one task, the rest in this process (--executor local -j 1),
      // gather; the Slurm scripts of the three studies as dry runs (no Slurm needed). -j N > 1, the
      // stability tasks and the Slurm executor: StudySweepCli.*, scripts/slurm_check.sh.
      {"clothsim study folds\\|stability\\|convergence --plan DIR",
       {{"{clothsim} study folds --quick --no-plot --cases twist --methods mass_spring --plan {tmp}/sweep "
         "--out {tmp}/sweep_out",
         "{clothsim} task {tmp}/sweep twist-mass_spring-13x9-seed1",
         "{clothsim} study folds --no-plot --plan {tmp}/sweep --retry-failed --executor local -j 1",
         "{clothsim} study folds --no-plot --gather {tmp}/sweep",
         "test -s {tmp}/sweep_out/study_folds/results.csv",
         "{clothsim} study folds --quick --no-plot --cases twist --plan {tmp}/sweep_dry --executor slurm --dry-run "
         "--slurm-time 10 --slurm-mem 1G --partition p --account a --sbatch-arg=--qos=low --no-wait",
         "{clothsim} study stability --quick --no-plot --plan {tmp}/stability_dry --executor slurm --dry-run",
         "{clothsim} study convergence --quick --no-plot --plan {tmp}/convergence_dry --executor slurm --dry-run"},
        "{clothsim} study --help",
        ""}},
      {"clothsim task DIR ID",
       {{"{clothsim} study folds --quick --no-plot --cases twist --methods mass_spring --plan {tmp}/task_plan",
         "{clothsim} task {tmp}/task_plan twist-mass_spring-18x13-seed1",
         "test -s {tmp}/task_plan/runs/twist-mass_spring-18x13-seed1/row.csv"},
        "{clothsim} task --help",
        ""}},
      // The quick stability study takes about 40 s; StudyStabilityCli.* runs it. Here: its options.
      {"clothsim study stability", {{}, "{clothsim} study --help", ""}},
      {"clothsim figures",
       {{"{clothsim} figures 10 --quick --size 64x48 --out {tmp}/figs"}, "{clothsim} figures --help", "python:matplotlib"}},
      {"clothsim fabric-test PRESET\\|SCENE.json",
       {{"{clothsim} fabric-test cotton_broadcloth_ortho --quick --tests cantilever,bias,cusick --rings 6,8 --end 0.2 --out {tmp}/fabric",
         "test -s {tmp}/fabric/fabric_test_cotton_broadcloth_ortho/fabric_test.csv"},
        "{clothsim} fabric-test --help",
        ""}},
      {"scripts/shape_difference.py A.obj B.obj",
       {{"{python} {src}/scripts/shape_difference.py --help"}, "{python} {src}/scripts/shape_difference.py --help", "python:numpy"}},
      {"scripts/catenary_fit.py RUN_DIR",
       {{"{python} {src}/scripts/catenary_fit.py --help"}, "{python} {src}/scripts/catenary_fit.py --help", "python:numpy"}},
      {"scripts/layer_count.py FRAME.obj",
       {{"{python} {src}/scripts/layer_count.py {tmp}/two_layers.obj"},
        "{python} {src}/scripts/layer_count.py --help",
        ""}},
      // Two steps of a contact scene; its row of the table.
      {"scripts/contact_ratio.py RUN",
       {{"{clothsim} {src}/scenes/sheet_on_sphere.json --out {tmp}/ratio --end 0.004 --no-render",
         "{python} {src}/scripts/contact_ratio.py {tmp}/ratio/sheet_on_sphere | grep -q '| `sheet_on_sphere` | 2 |'"},
        "{python} {src}/scripts/contact_ratio.py --help",
        ""}},
      // The timing scene's sleeve at a tiny size, two steps; the table and the plot of its rows.
      {"scripts/scaling.py run --bin CLOTHSIM --csv OUT.csv",
       {{"{python} {src}/scripts/scaling.py run --bin {clothsim} --csv {tmp}/scaling.csv --sizes 8x6 --end 0.02 --repeats 1",
         "{python} {src}/scripts/scaling.py table {tmp}/scaling.csv | grep -q '| run | 48 |'",
         "{python} {src}/scripts/scaling.py plot {tmp}/scaling.png {tmp}/scaling.csv && test -s {tmp}/scaling.png"},
        "{python} {src}/scripts/scaling.py --help",
        "python:matplotlib"}},
      // Two steps of the garment drop on a coarse T-shirt, clothsim alone (Blender's side:
      // GarmentDrop.AgainstBlender, where Blender is installed); its row of the table.
      {"bench/garment_drop.py",
       {{"{python} {src}/bench/garment_drop.py --bin {clothsim} --checker {build}/tools/check_intersections --no-blender "
         "--edge-length 0.06 --end 0.01 --rounds 1 --work {tmp}/garment | grep -q '| clothsim | 5 |'"},
        "{python} {src}/bench/garment_drop.py --help",
        ""}},
      // Two labels on the same build, one small scene, two steps; the before/after table.
      {"scripts/scene_times.py run --csv OUT.csv --bin LABEL=CLOTHSIM[@SCENES_DIR]",
       {{"{python} {src}/scripts/scene_times.py run --csv {tmp}/times.csv --bin a={clothsim} --bin b={clothsim}@{src}/scenes "
         "--steps 2 --repeats 1 --only sleeve_twist",
         "{python} {src}/scripts/scene_times.py table {tmp}/times.csv --before a --after b | grep -q '`sleeve_twist` | 2 |'"},
        "{python} {src}/scripts/scene_times.py --help",
        ""}},
      // One small scene over 20 ms: the default tolerance passes; a tolerance far too loose (0.9)
      // must fail with exit code 1.
      {"scripts/tolerance_check.py run --csv OUT.csv",
       {{"{python} {src}/scripts/tolerance_check.py run --csv {tmp}/tol.csv --bin {clothsim} --window 0.02 --only sleeve_gravity",
         "{python} {src}/scripts/tolerance_check.py table {tmp}/tol.csv | grep -q '`sleeve_gravity` |.*| pass |'",
         "{python} {src}/scripts/tolerance_check.py run --csv {tmp}/loose.csv --bin {clothsim} --window 0.02 "
         "--only sleeve_gravity --tolerance 0.9 >/dev/null; test $? -eq 1 && grep -q ',FAIL,' {tmp}/loose.csv"},
        "{python} {src}/scripts/tolerance_check.py --help",
        "python:numpy"}},
      {"build/release/tools/check_intersections SURFACE.obj",
       {{"{clothsim} {src}/scenes/plate_ss.json --out {tmp}/ci --no-render",
         "{build}/tools/check_intersections {tmp}/ci/plate_ss/limit.obj"},
        "",
        "{build}/tools/check_intersections"}},
  };
  return f;
}

class ReadmeCommands : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_ = testing::make_temp_dir("clothsim_readme_commands_");
    // The render row needs a run with OBJ frames: sleeve_twist with output.obj on.
    nlohmann::json scene = nlohmann::json::parse(read_file_bytes(fs::path(CLOTHSIM_SOURCE_DIR) / "scenes/sleeve_twist.json"));
    scene["name"] = "sleeve_obj";
    scene["output"]["obj"] = true;
    std::ofstream(tmp_ / "sleeve_obj.json") << scene.dump(2);
    // The golden row: one golden of a small static picture, made by `golden update`.
    std::ofstream(tmp_ / "goldens.txt") << "plate.png " << (fs::path(CLOTHSIM_SOURCE_DIR) / "scenes/plate_ss.json").string()
                                        << " plate_ss/limit.png --size 64x48\n";
    // The layer-count row: a 0.2 m square with a second layer over half of it, 2 mm above.
    std::ofstream(tmp_ / "two_layers.obj") << "v 0 0.001 0\nv 0.2 0.001 0\nv 0.2 0.001 0.2\nv 0 0.001 0.2\n"
                                              "v 0 0.003 0\nv 0.1 0.003 0\nv 0.1 0.003 0.2\nv 0 0.003 0.2\n"
                                              "f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\n";
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }

  std::string expand(std::string text) const {
    const std::string build = fs::path(CLOTHSIM_BINARY).parent_path().string();
    const std::vector<std::pair<std::string, std::string>> values = {
        {"{clothsim}", shell_quote(CLOTHSIM_BINARY)}, {"{src}", shell_quote(CLOTHSIM_SOURCE_DIR)},
        {"{build}", shell_quote(build)},              {"{tmp}", shell_quote(tmp_.string())},
        {"{python}", "/usr/bin/python3"}};
    for (const auto& [name, value] : values)
      for (std::size_t at = text.find(name); at != std::string::npos; at = text.find(name, at + value.size()))
        text.replace(at, name.size(), value);
    return text;
  }

  // Runs `command`, its stdout and stderr kept in out.txt; returns the exit code.
  int run(const std::string& command) {
    return run_shell(expand(command) + " >" + shell_quote((tmp_ / "out.txt").string()) + " 2>&1");
  }
  std::string output() const { return read_file_bytes(tmp_ / "out.txt"); }

  // Why the form cannot run here (empty: it can).
  std::string missing(const Form& form) const {
    if (form.needs.empty()) return "";
    if (form.needs.rfind("python:", 0) == 0) {
      const std::string module = form.needs.substr(7);
      if (run_shell("/usr/bin/python3 -c 'import " + module + "' >/dev/null 2>&1") == 0) return "";
      return "python3 module " + module + " is not installed";
    }
    std::string path = form.needs;
    path.replace(0, 7, fs::path(CLOTHSIM_BINARY).parent_path().string());  // "{build}"
    return fs::exists(path) ? "" : path + " is not built";
  }

  fs::path tmp_;
};

TEST_F(ReadmeCommands, EveryRowHasACheapFormThatRuns) {
  const std::vector<Row> rows = readme_command_rows();
  ASSERT_GE(rows.size(), 15u) << "the Commands table of docs/cli.md was not found";
  for (const Row& row : rows) {
    SCOPED_TRACE("docs/cli.md row: " + row.command);
    const auto form = forms().find(row.key);
    if (form == forms().end()) {
      ADD_FAILURE() << "no cheap form for the docs/cli.md command '" << row.key
                    << "': add one to tests/app/readme_commands_test.cpp";
      continue;
    }
    if (const std::string why = missing(form->second); !why.empty()) {
      std::printf("skipped '%s': %s\n", row.key.c_str(), why.c_str());
      continue;
    }
    for (const std::string& command : form->second.commands)
      EXPECT_EQ(run(command), 0) << expand(command) << "\n" << output();
    if (form->second.help.empty()) continue;
    if (run(form->second.help) != 0) {
      ADD_FAILURE() << expand(form->second.help) << " failed:\n" << output();
      continue;
    }
    const std::string help = output();
    for (const std::string& option : documented_options(row.command))
      EXPECT_NE(help.find(option), std::string::npos)
          << "docs/cli.md documents " << option << " but `" << expand(form->second.help) << "` does not list it";
  }
}

}  // namespace
}  // namespace clothsim

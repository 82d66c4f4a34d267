#include "sim/study/fold_study.hpp"

#include "sim/dynamics/simulator.hpp"
#include "sim/scene/scene.hpp"
#include "sim/setup/setup.hpp"
#include "sim/shell/material_presets.hpp"
#include "sim/study/fold_count.hpp"
#include "sim/study/report_format.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <utility>

namespace clothsim {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const std::vector<std::string>& known_cases() {
  static const std::vector<std::string> cases = {"twist", "compress"};
  return cases;
}

std::string scene_file_of(const std::string& case_name) { return "sleeve_" + case_name + ".json"; }

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

// Comma-separated items of `text`, surrounding blanks removed; an empty item is an error.
std::vector<std::string> split_list(const std::string& text, const std::string& option) {
  std::vector<std::string> items;
  std::string item;
  std::istringstream in(text);
  auto trim = [](std::string s) {
    const auto first = s.find_first_not_of(" \t");
    if (first == std::string::npos) return std::string();
    return s.substr(first, s.find_last_not_of(" \t") - first + 1);
  };
  if (text.empty()) throw std::invalid_argument(option + ": empty list");
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string piece = trim(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (piece.empty()) throw std::invalid_argument(option + ": empty item in \"" + text + "\"");
    items.push_back(piece);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return items;
}

// A whole decimal integer (optional sign) or nothing.
std::optional<long long> whole_number(const std::string& s) {
  if (s.empty() || s.size() > 12) return std::nullopt;
  size_t i = (s[0] == '-' || s[0] == '+') ? 1 : 0;
  if (i == s.size()) return std::nullopt;
  for (size_t k = i; k < s.size(); ++k)
    if (s[k] < '0' || s[k] > '9') return std::nullopt;
  return std::stoll(s);
}

std::vector<std::string> checked_names(const std::string& text, const std::string& option,
                                       const std::vector<std::string>& allowed, const std::string& what) {
  std::vector<std::string> names = split_list(text, option);
  std::set<std::string> seen;
  for (const std::string& n : names) {
    if (std::find(allowed.begin(), allowed.end(), n) == allowed.end())
      throw std::invalid_argument(option + ": unknown " + what + " \"" + n + "\" (allowed: " + joined(allowed) + ")");
    if (!seen.insert(n).second) throw std::invalid_argument(option + ": \"" + n + "\" is given twice");
  }
  return names;
}

using Json = nlohmann::json;

Json read_scene_json(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw SceneError(file.string() + ": cannot read the scene file");
  std::ostringstream text;
  text << in.rdbuf();
  try {
    return Json::parse(text.str());
  } catch (const Json::exception& e) {
    throw SceneError(file.string() + ": malformed JSON: " + e.what());
  }
}

// The sleeve's geometry from a scene: the cylinder primitive's radius and length [m].
struct SleeveShape {
  double radius = 0.0, length = 0.0;
  double end = 0.0;  // the scene's time.end [s]
};

SleeveShape sleeve_shape(const Json& j, const std::filesystem::path& file) {
  const Json mesh = j.value("mesh", Json::object());
  if (j.value("analysis", "static") != "dynamic" || mesh.value("primitive", "") != "cylinder" ||
      mesh.value("angle_deg", 360.0) != 360.0 || !mesh.contains("radius") || !mesh.contains("length"))
    throw std::invalid_argument(file.string() + ": the fold study needs a dynamic scene whose mesh is a full "
                                                "\"cylinder\" primitive with radius and length");
  SleeveShape s;
  s.radius = mesh["radius"].get<double>();
  s.length = mesh["length"].get<double>();
  s.end = j.at("time").at("end").get<double>();
  return s;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string count_text(double v) { return std::isfinite(v) ? format_shortest(v) : "–"; }

std::string band_text(const FoldBand& b) {
  if (!b.known()) return "–";
  return format_fixed(b.lo, 1) + "–" + format_fixed(b.hi, 1);
}

}  // namespace

// --- Theory -------------------------------------------------------------------------------------

double effective_thickness(const ShellMaterial& material) {
  if (!(material.stretch_modulus > 0.0) || !(material.bending_rigidity >= 0.0))
    throw std::invalid_argument("effective_thickness: needs a positive stretch modulus and a non-negative bending rigidity");
  return std::sqrt(12.0 * material.bending_rigidity / material.stretch_modulus);
}

double axisymmetric_buckling_wavelength(double radius, double thickness, double poisson_ratio) {
  if (!(radius > 0.0) || !(thickness > 0.0) || !(poisson_ratio >= 0.0 && poisson_ratio < 1.0))
    throw std::invalid_argument("axisymmetric_buckling_wavelength: needs R > 0, t > 0 and 0 <= nu < 1");
  return 2.0 * std::numbers::pi * std::sqrt(radius * thickness) /
         std::pow(12.0 * (1.0 - poisson_ratio * poisson_ratio), 0.25);
}

FoldBand twist_circumferential_band(double radius, double length, double thickness) {
  if (!(radius > 0.0) || !(length > 0.0) || !(thickness > 0.0))
    throw std::invalid_argument("twist_circumferential_band: needs R, L, t > 0");
  const double scale = std::sqrt(radius / length) * std::pow(radius / thickness, 0.25);
  return {kTwistPrefactorLow * scale, kTwistPrefactorHigh * scale};
}

FoldBand compression_axial_band(double radius, double length, double thickness, double poisson_ratio) {
  if (!(length > 0.0)) throw std::invalid_argument("compression_axial_band: needs L > 0");
  const double lambda = axisymmetric_buckling_wavelength(radius, thickness, poisson_ratio);
  return {length / (2.0 * lambda), length / lambda};
}

FoldBand compression_circumferential_band(double radius, double thickness, double poisson_ratio) {
  const double lambda = axisymmetric_buckling_wavelength(radius, thickness, poisson_ratio);
  return {0.0, std::numbers::pi * radius / lambda};
}

// --- Counting -----------------------------------------------------------------------------------

FoldCounts count_drawn_folds(const Discretization& discretization, const Eigen::VectorXd& x,
                             const Eigen::Vector3d& axis_point, const Eigen::Vector3d& axis_direction, int levels) {
  const SurfaceOperator drawn = discretization.display(levels);
  const Eigen::MatrixX3d points = discretization.surface_positions(drawn, x);
  FoldAxis axis;
  axis.point = axis_point;
  axis.direction = axis_direction;
  const SleeveFolds folds = count_sleeve_folds(points, drawn.triangles, axis);
  FoldCounts counts;
  counts.circumferential_median = folds.circumferential_median;
  counts.axial_median = folds.axial.median_count;
  counts.prominence_threshold = folds.prominence_threshold;
  return counts;
}

// --- The plan -----------------------------------------------------------------------------------

FoldStudyPlan full_fold_plan(const std::filesystem::path& scenes_dir) {
  FoldStudyPlan plan;
  plan.scenes_dir = scenes_dir;
  plan.cases = known_cases();
  plan.methods = {"loop_kl", "linear_fe", "mass_spring"};
  plan.meshes = {{26, 19}, {38, 27}, {54, 39}, {76, 55}};
  plan.seeds = {1, 2, 3};
  plan.end = 1.0;  // the end of both scenes' motion (they settle to 1.5 s; a third more cost)
  return plan;
}

FoldStudyPlan quick_fold_plan(const std::filesystem::path& scenes_dir) {
  FoldStudyPlan plan = full_fold_plan(scenes_dir);
  plan.meshes = {{13, 9}, {18, 13}};
  plan.seeds = {1};
  plan.end = 0.1;
  return plan;
}

std::vector<FoldMesh> parse_fold_meshes(const std::string& text) {
  std::vector<FoldMesh> meshes;
  for (const std::string& item : split_list(text, "--meshes")) {
    const size_t x = item.find('x');
    const auto segments = x == std::string::npos ? std::nullopt : whole_number(item.substr(0, x));
    const auto rings = x == std::string::npos ? std::nullopt : whole_number(item.substr(x + 1));
    if (!segments || !rings)
      throw std::invalid_argument("--meshes: \"" + item + "\" is not SEGMENTSxRINGS (e.g. 26x19)");
    if (*segments < 3 || *rings < 2 || *segments > 2000 || *rings > 2000)
      throw std::invalid_argument("--meshes: \"" + item + "\": needs 3 <= segments <= 2000 and 2 <= rings <= 2000");
    meshes.push_back({static_cast<int>(*segments), static_cast<int>(*rings)});
  }
  return meshes;
}

std::vector<int> parse_fold_seeds(const std::string& text) {
  std::vector<int> seeds;
  for (const std::string& item : split_list(text, "--seeds")) {
    const auto seed = whole_number(item);
    if (!seed || *seed < 0 || *seed > 2147483647)
      throw std::invalid_argument("--seeds: \"" + item + "\" is not a non-negative integer");
    if (std::find(seeds.begin(), seeds.end(), static_cast<int>(*seed)) != seeds.end())
      throw std::invalid_argument("--seeds: " + item + " is given twice");
    seeds.push_back(static_cast<int>(*seed));
  }
  return seeds;
}

std::vector<std::string> parse_fold_methods(const std::string& text) {
  return checked_names(text, "--methods", discretization_methods(), "method");
}

std::vector<std::string> parse_fold_cases(const std::string& text) {
  return checked_names(text, "--cases", known_cases(), "case");
}

void validate_fold_plan(const FoldStudyPlan& plan) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("fold study: " + what); };
  if (plan.cases.empty()) fail("no cases");
  if (plan.methods.empty()) fail("no methods");
  if (plan.meshes.empty()) fail("no meshes");
  if (plan.seeds.empty()) fail("no seeds");
  for (const std::string& c : plan.cases)
    if (std::find(known_cases().begin(), known_cases().end(), c) == known_cases().end())
      fail("unknown case \"" + c + "\" (allowed: " + joined(known_cases()) + ")");
  const std::vector<std::string> methods = discretization_methods();
  for (const std::string& m : plan.methods)
    if (std::find(methods.begin(), methods.end(), m) == methods.end())
      fail("unknown method \"" + m + "\" (allowed: " + joined(methods) + ")");
  for (const FoldMesh& m : plan.meshes)
    if (m.segments < 3 || m.rings < 2) fail("a mesh needs at least 3 segments and 2 rings");
  for (int s : plan.seeds)
    if (s < 0) fail("seeds must be >= 0");
  if (!material_preset(plan.preset))
    fail("unknown material preset \"" + plan.preset + "\" (allowed: " + joined(material_preset_names()) + ")");
  if (plan.amplitude && !(*plan.amplitude >= 0.0 && std::isfinite(*plan.amplitude)))
    fail("the imperfection amplitude must be a finite number >= 0 [m]");
  if (plan.wavelength && !(plan.wavelength->first > 0.0 && plan.wavelength->first <= plan.wavelength->second &&
                           std::isfinite(plan.wavelength->second)))
    fail("the imperfection wavelengths must be 0 < shortest <= longest [m]");
  if (!(plan.dt > 0.0 && std::isfinite(plan.dt))) fail("the time step must be > 0 [s]");
  if (plan.end && !(*plan.end >= plan.dt && std::isfinite(*plan.end))) fail("the end time must be at least one time step [s]");
}

// --- Running ------------------------------------------------------------------------------------

std::string FoldRun::id() const {
  return case_name + "-" + method + "-" + std::to_string(mesh.segments) + "x" + std::to_string(mesh.rings) + "-seed" +
         std::to_string(seed);
}

std::vector<FoldRun> fold_study_runs(const FoldStudyPlan& plan) {
  validate_fold_plan(plan);
  std::vector<FoldRun> runs;
  for (const std::string& case_name : plan.cases)
    for (const std::string& method : plan.methods)
      for (const FoldMesh& mesh : plan.meshes)
        for (int seed : plan.seeds) runs.push_back({case_name, method, mesh, seed});
  return runs;
}

FoldRow run_fold_case(const FoldStudyPlan& plan, const FoldRun& run) {
  validate_fold_plan(plan);
  const ShellMaterial material = *material_preset(plan.preset);
  const double t_eff = effective_thickness(material);
  const double nu = material.poisson_ratio;
  const std::filesystem::path file = plan.scenes_dir / scene_file_of(run.case_name);
  const Json base = read_scene_json(file);
  const SleeveShape shape = sleeve_shape(base, file);
  const double end = plan.end.value_or(shape.end);
  FoldBand circumferential{kNaN, kNaN}, axial{kNaN, kNaN};
  if (run.case_name == "twist") {
    circumferential = twist_circumferential_band(shape.radius, shape.length, t_eff);
  } else {
    circumferential = compression_circumferential_band(shape.radius, t_eff, nu);
    axial = compression_axial_band(shape.radius, shape.length, t_eff, nu);
  }
  const double lambda = axisymmetric_buckling_wavelength(shape.radius, t_eff, nu);
  const std::pair<double, double> wavelength =
      plan.wavelength.value_or(std::make_pair(0.5 * lambda, 2.0 * std::numbers::pi * shape.radius));
  const double amplitude = plan.amplitude.value_or(kDefaultAmplitudeFactor * t_eff);
  const Eigen::Vector3d axis_point = Eigen::Vector3d::Zero(), axis_direction = Eigen::Vector3d::UnitY();

  FoldRow row;
  row.case_name = run.case_name;
  row.method = run.method;
  row.segments = run.mesh.segments;
  row.rings = run.mesh.rings;
  row.vertices = run.mesh.vertices();
  row.seed = run.seed;
  row.amplitude = amplitude;
  row.dt = plan.dt;
  row.circumferential_median = row.axial_median = kNaN;
  row.circumferential_theory = circumferential;
  row.axial_theory = axial;
  row.t_eff = t_eff;
  row.preset = plan.preset;
  row.status = "ok";

  Json j = base;
  j["name"] = "fold_study_" + run.case_name;
  j["method"] = run.method;
  j["mesh"]["segments"] = run.mesh.segments;
  j["mesh"]["rings"] = run.mesh.rings;
  j["material"] = Json{{"preset", plan.preset}};
  j["time"]["dt"] = plan.dt;
  j["time"]["end"] = end;
  j["imperfection"] = Json{{"amplitude", amplitude}, {"seed", run.seed},
                           {"wavelength", {wavelength.first, wavelength.second}}};
  if (plan.self_collision) {
    if (!j.contains("collision")) j["collision"] = Json{{"self", true}};
    else j["collision"]["self"] = true;
  } else {
    j.erase("collision");
  }
  j.erase("output");
  // PCG with a Cholesky factor of an earlier step's matrix: the block-Jacobi default needs
  // thousands of iterations per step on the fine meshes (and does not converge for the flat
  // methods at 5 ms).
  j["solver"]["preconditioner"] = "cholesky";
  // The scene itself is the study's input: an error there stops the study.
  const Problem problem = load_scene_text(j.dump(2), file, LogFn()).problem;
  const auto start = std::chrono::steady_clock::now();
  try {
    Simulator sim(problem);
    const int steps = sim.num_steps();
    for (int k = 0; k < steps; ++k) {
      sim.step();
      ++row.steps;
    }
    row.end_time = sim.state().t;
    const Eigen::VectorXd& x = sim.state().x;
    if (!x.allFinite()) throw std::runtime_error("non-finite positions at the end");
    const FoldCounts counts = count_drawn_folds(sim.discretization(), x, axis_point, axis_direction);
    row.circumferential_median = counts.circumferential_median.value_or(kNaN);
    row.axial_median = counts.axial_median.value_or(kNaN);
    // A run that has not failed outright but left the sleeve's neighbourhood has blown up.
    double reach = 0.0;
    for (int n = 0; n < x.size() / 3; ++n) {
      const Eigen::Vector3d p = x.segment<3>(3 * n);
      reach = std::max({reach, std::hypot(p.x(), p.z()) / shape.radius, std::abs(p.y() - 0.5 * shape.length) /
                                                                            (0.5 * shape.length)});
    }
    if (reach > 2.0) {
      row.status = "unstable";
      row.note = "a node ended " + format_fixed(reach, 1) +
                 " x the radius (or half-length) from the sleeve's axis (or middle)";
    }
  } catch (const std::exception& e) {
    row.status = "failed";
    row.note = e.what();
    row.circumferential_median = row.axial_median = kNaN;
  }
  row.wall_seconds = seconds_since(start);
  return row;
}

std::vector<FoldRow> run_fold_study(const FoldStudyPlan& plan, const LogFn& log) {
  const std::vector<FoldRun> runs = fold_study_runs(plan);
  const int total = static_cast<int>(runs.size());
  int done = 0;
  std::vector<FoldRow> rows;
  for (const FoldRun& run : runs) {
    FoldRow row = run_fold_case(plan, run);
    ++done;
    if (log)
      log("[" + std::to_string(done) + "/" + std::to_string(total) + "] " + run.case_name + " " + run.method + " " +
          std::to_string(run.mesh.segments) + "x" + std::to_string(run.mesh.rings) + " seed " +
          std::to_string(run.seed) + ": circumferential " + count_text(row.circumferential_median) + ", axial " +
          count_text(row.axial_median) + " (" + format_fixed(row.wall_seconds, 1) + " s" +
          (row.status == "ok" ? "" : ", " + row.status + ": " + row.note) + ")");
    rows.push_back(std::move(row));
  }
  return rows;
}

// --- Output -------------------------------------------------------------------------------------

const std::vector<std::string>& fold_csv_columns() {
  static const std::vector<std::string> columns = {
      "case", "method", "segments", "rings", "vertices", "seed", "amplitude", "dt", "steps", "end_time",
      "wall_seconds", "circumferential_median", "axial_median", "circumferential_theory_lo",
      "circumferential_theory_hi", "axial_theory_lo", "axial_theory_hi", "t_eff", "preset", "status", "note"};
  return columns;
}

void write_fold_csv(std::ostream& out, const std::vector<FoldRow>& rows) {
  const std::vector<std::string>& columns = fold_csv_columns();
  for (size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << columns[i];
  out << '\n';
  for (const FoldRow& r : rows)
    out << csv_field(r.case_name) << ',' << csv_field(r.method) << ',' << r.segments << ',' << r.rings << ','
        << r.vertices << ',' << r.seed << ',' << format_shortest(r.amplitude) << ',' << format_shortest(r.dt) << ','
        << r.steps << ',' << format_shortest(r.end_time) << ',' << format_fixed(r.wall_seconds, 3) << ','
        << format_shortest(r.circumferential_median) << ',' << format_shortest(r.axial_median) << ','
        << format_significant(r.circumferential_theory.lo, 6) << ',' << format_significant(r.circumferential_theory.hi, 6)
        << ',' << format_significant(r.axial_theory.lo, 6) << ',' << format_significant(r.axial_theory.hi, 6) << ','
        << format_significant(r.t_eff, 6) << ',' << csv_field(r.preset) << ',' << csv_field(r.status) << ','
        << csv_field(r.note) << '\n';
}

std::vector<FoldRow> read_fold_csv(const std::string& text) {
  // Records of fields: quoted fields may hold commas, doubled quotes and line breaks.
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> record;
  std::string field;
  bool quoted = false, any = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c != '"') field += c;
      else if (i + 1 < text.size() && text[i + 1] == '"') field += text[++i];
      else quoted = false;
    } else if (c == '"') {
      quoted = any = true;
    } else if (c == ',') {
      record.push_back(std::move(field));
      field.clear();
      any = true;
    } else if (c == '\n') {
      record.push_back(std::move(field));
      field.clear();
      records.push_back(std::move(record));
      record.clear();
      any = false;
    } else {
      field += c;
      any = true;
    }
  }
  if (quoted) throw std::invalid_argument("fold CSV: a quoted field is not closed");
  if (any || !field.empty()) {
    record.push_back(std::move(field));
    records.push_back(std::move(record));
  }
  const std::vector<std::string>& columns = fold_csv_columns();
  if (records.empty() || records.front() != columns)
    throw std::invalid_argument("fold CSV: the first line is not the header of fold_csv_columns()");
  std::vector<FoldRow> rows;
  for (size_t line = 1; line < records.size(); ++line) {
    const std::vector<std::string>& f = records[line];
    auto fail = [&](size_t column, const std::string& what) {
      throw std::invalid_argument("fold CSV: record " + std::to_string(line + 1) + ", column " +
                                  (column < columns.size() ? columns[column] : std::to_string(column + 1)) + ": " +
                                  what);
    };
    if (f.size() != columns.size())
      fail(f.size(), std::to_string(f.size()) + " fields instead of " + std::to_string(columns.size()));
    auto number = [&](size_t column) {
      const std::string& s = f[column];
      double v = 0.0;
      const auto result = std::from_chars(s.data(), s.data() + s.size(), v);
      if (result.ec != std::errc() || result.ptr != s.data() + s.size()) fail(column, "\"" + s + "\" is not a number");
      return v;
    };
    auto whole = [&](size_t column) {
      const std::string& s = f[column];
      int v = 0;
      const auto result = std::from_chars(s.data(), s.data() + s.size(), v);
      if (result.ec != std::errc() || result.ptr != s.data() + s.size()) fail(column, "\"" + s + "\" is not an integer");
      return v;
    };
    FoldRow r;
    r.case_name = f[0];
    r.method = f[1];
    r.segments = whole(2);
    r.rings = whole(3);
    r.vertices = whole(4);
    r.seed = whole(5);
    r.amplitude = number(6);
    r.dt = number(7);
    r.steps = whole(8);
    r.end_time = number(9);
    r.wall_seconds = number(10);
    r.circumferential_median = number(11);
    r.axial_median = number(12);
    r.circumferential_theory = {number(13), number(14)};
    r.axial_theory = {number(15), number(16)};
    r.t_eff = number(17);
    r.preset = f[18];
    r.status = f[19];
    r.note = f[20];
    rows.push_back(std::move(r));
  }
  return rows;
}

void write_fold_markdown(std::ostream& out, const std::vector<FoldRow>& rows) {
  // Group the seeds of one case, method and mesh (in the order the rows come).
  struct Group {
    const FoldRow* first = nullptr;
    std::vector<const FoldRow*> runs;
  };
  std::vector<Group> groups;
  std::map<std::string, size_t> index;
  for (const FoldRow& r : rows) {
    const std::string key = r.case_name + "|" + r.method + "|" + std::to_string(r.segments) + "x" + std::to_string(r.rings);
    auto [it, inserted] = index.emplace(key, groups.size());
    if (inserted) groups.push_back({&r, {}});
    groups[it->second].runs.push_back(&r);
  }
  auto seeds_text = [](const Group& g, bool circumferential) {
    double lo = kNaN, hi = kNaN;
    std::string each;
    for (const FoldRow* r : g.runs) {
      const double v = circumferential ? r->circumferential_median : r->axial_median;
      const bool ok = r->status == "ok" && std::isfinite(v);
      each += (each.empty() ? "" : " / ") + (ok ? format_shortest(v) : std::string("✗"));
      if (ok) {
        lo = std::isfinite(lo) ? std::min(lo, v) : v;
        hi = std::isfinite(hi) ? std::max(hi, v) : v;
      }
    }
    if (!std::isfinite(lo)) return each;
    return (lo == hi ? format_shortest(lo) : format_shortest(lo) + "–" + format_shortest(hi)) + " (" + each + ")";
  };
  out << "| case | method | mesh | vertices | circumferential (seeds) | theory | axial (seeds) | theory | s/run | notes |\n"
      << "|---|---|---|---:|---|---|---|---|---:|---|\n";
  for (const Group& g : groups) {
    double seconds = 0.0;
    std::string notes;
    for (const FoldRow* r : g.runs) {
      seconds += r->wall_seconds;
      if (r->status != "ok") notes += (notes.empty() ? "" : "; ") + ("seed " + std::to_string(r->seed) + " " + r->status + ": " + r->note);
    }
    const FoldRow& r = *g.first;
    out << "| " << r.case_name << " | " << r.method << " | " << r.segments << "×" << r.rings << " | " << r.vertices
        << " | " << seeds_text(g, true) << " | " << band_text(r.circumferential_theory) << " | " << seeds_text(g, false)
        << " | " << band_text(r.axial_theory) << " | " << format_fixed(seconds / static_cast<double>(g.runs.size()), 1)
        << " | " << markdown_cell(notes) << " |\n";
  }
  if (!rows.empty()) {
    const FoldRow& r = rows.front();
    out << "\nSeeds: median fold counts of each seed's run in the order of the seeds (✗: failed or unstable), "
           "summarised as min–max. Material preset "
        << r.preset << ", t_eff = " << format_significant(r.t_eff * 1e3, 4) << " mm, imperfection amplitude "
        << format_significant(r.amplitude * 1e3, 4) << " mm, dt = " << format_shortest(r.dt) << " s, self-collision off.\n";
  }
}

}  // namespace clothsim

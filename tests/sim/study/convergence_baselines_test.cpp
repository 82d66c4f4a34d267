// The convergence study's baselines and post-buckling measures (sim/study/convergence.hpp,
// docs/convergence.md): linear_fe and mass_spring as methods (the flat surface sampled by
// barycentric interpolation of the nodal displacements; clamped plates skipped; mass_spring
// dynamic only), and the end-of-run columns — elastic energy and fold counts against the
// reference run — on synthetic runs with known answers and on the quick plan's real runs against
// an independent recomputation of the reference's end state.
#include "sim/study/convergence.hpp"

#include "sim/dynamics/simulator.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/scene/scene.hpp"
#include "sim/study/fold_count.hpp"
#include "sim/study/plates.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace clothsim {
namespace {

constexpr double kPi = std::numbers::pi;

const Method& registered(const std::string& name) {
  static const std::vector<Method> methods = convergence_methods();
  for (const Method& m : methods)
    if (m.name == name) return m;
  throw std::runtime_error("no method " + name);
}

// The flat baselines sample their surface by barycentric interpolation of the nodal
// displacements: the method's displacement at points inside triangles and at the centre vertex,
// against the nodal displacements of an independent solve_static of the same problem,
// interpolated by hand.
TEST(ConvergenceBaselines, LinearFeSamplesAreBarycentricInterpolationOfNodalDisplacements) {
  Problem problem = plate_problem(kAnalyticPlates[0], 8, Quadrature::one_point);
  problem.method = "linear_fe";
  const std::vector<SurfaceSample> points = {{0, 0.2, 0.3}, {17, 0.6, 0.1}, {100, 1.0 / 3, 1.0 / 3}, {127, 0.0, 1.0}};
  const MethodRun run = registered("linear_fe").solve_static(problem, points);
  ASSERT_EQ(run.displacements.size(), 1u);
  ASSERT_EQ(run.displacements[0].rows(), 4);
  EXPECT_EQ(run.vertices, 81);
  const StaticResult independent = solve_static(problem);
  ASSERT_EQ(independent.discretization->method(), "linear_fe");
  const Eigen::VectorXd& u = independent.displacement;
  double largest = 0.0;
  for (size_t p = 0; p < points.size(); ++p) {
    const Triangle& t = problem.mesh.triangles[static_cast<size_t>(points[p].triangle)];
    const double weights[3] = {1 - points[p].v - points[p].w, points[p].v, points[p].w};
    for (int k = 0; k < 3; ++k) {
      double expected = 0.0;
      for (int corner = 0; corner < 3; ++corner) expected += weights[corner] * u(3 * t[corner] + k);
      EXPECT_NEAR(run.displacements[0](static_cast<Eigen::Index>(p), k), expected, 1e-12 * (1 + std::abs(expected)))
          << "point " << p << " component " << k;
      largest = std::max(largest, std::abs(expected));
    }
  }
  EXPECT_GT(largest, 1e-6) << "the plate did not deflect";
}

// linear_fe takes the simply supported plates and skips the clamped ones (no rows, a log line);
// mass_spring has no static solve.
TEST(ConvergenceBaselines, PlatesWithClampedBordersAreSkippedByLinearFe) {
  ConvergencePlan plan;
  plan.plates.push_back({kAnalyticPlates[0], {4, 8}});  // simply supported, uniform
  plan.plates.push_back({kAnalyticPlates[1], {4, 8}});  // clamped, uniform
  std::vector<std::string> log;
  const std::vector<ConvergenceRow> rows =
      run_convergence(plan, {registered("linear_fe"), registered("mass_spring")},
                      [&](const std::string& line) { log.push_back(line); });
  ASSERT_EQ(rows.size(), 2u);
  for (const ConvergenceRow& r : rows) {
    EXPECT_EQ(r.case_name, "plate_ss_uniform");
    EXPECT_EQ(r.method, "linear_fe");
    EXPECT_TRUE(std::isfinite(r.error));
    EXPECT_GT(r.value, 0.0);
    EXPECT_TRUE(r.note.empty()) << r.note;
    EXPECT_FALSE(r.energy_error.has_value());  // plates have no post-buckling measures
  }
  bool skipped = false;
  for (const std::string& line : log)
    skipped |= line.find("case plate_clamped_uniform method linear_fe skipped: ") == 0 &&
               line.find("\"clamped\" borders are not supported") != std::string::npos;
  EXPECT_TRUE(skipped);
}

// A synthetic method whose run ends on a given surface with a given elastic energy; its
// displacements are a constant offset (so the pointwise error is 0).
Method synthetic(const std::string& name, const TriMesh& surface, double energy) {
  Method m;
  m.name = name;
  m.run_dynamic = [surface, energy](const Problem&, const std::vector<SurfaceSample>& points,
                                    const std::vector<double>& times) {
    MethodRun run;
    run.vertices = surface.num_vertices();
    run.steps = 1;
    run.wall_seconds = 1.0;
    const Eigen::MatrixX3d offset = Eigen::RowVector3d(1e-3, 0, 0).replicate(static_cast<Eigen::Index>(points.size()), 1);
    run.displacements.assign(times.size(), offset);
    run.final_elastic_energy = energy;
    run.final_surface = surface.vertices;
    run.final_surface_triangles = surface.triangles;
    return run;
  };
  return m;
}

// A fine cylinder about the y axis (R = 5 cm, L = 20 cm) with radius R + dr(θ, s).
template <class Radius>
TriMesh shaped_sleeve(Radius dr) {
  const double r0 = 0.05, length = 0.2;
  TriMesh mesh = make_cylinder(r0, length, 160, 121);
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    const double x = mesh.vertices(v, 0), z = mesh.vertices(v, 2), s = mesh.vertices(v, 1);
    const double theta = std::atan2(-z, x);
    const double scale = (r0 + dr(theta, s / length)) / r0;
    mesh.vertices(v, 0) *= scale;
    mesh.vertices(v, 2) *= scale;
  }
  return mesh;
}

// Known answers: the reference ends with 8 cosine lobes around the sleeve (no folds along it) and
// E_ref = 2 J; a run with 5 lobes and E = 2.5 J differs by −3 circumferential folds, 0 axial, and
// |2.5 − 2| / 2 = 0.25; a run with 4 bellows rings (troughs at both ends, 4 crests inside, round
// sections) and E = 0.5 J by −8 and +4 folds and 0.75. The reference row itself: 0 and 0.
TEST(ConvergenceBaselines, PostBucklingColumnsOfSyntheticRunsWithKnownFolds) {
  const double a = 0.005;  // [m] 10 % of the radius, five times the counter's prominence 2 % · R
  const TriMesh lobes8 = shaped_sleeve([&](double theta, double) { return a * std::cos(8 * theta); });
  const TriMesh lobes5 = shaped_sleeve([&](double theta, double) { return a * std::cos(5 * theta + 0.3); });
  const TriMesh bellows4 = shaped_sleeve([&](double, double s) { return -a * std::cos(2 * kPi * 4 * s); });

  ConvergencePlan plan = quick_convergence_plan(CLOTHSIM_SOURCE_DIR "/scenes");
  plan.plates.clear();
  SleeveStudyCase& c = plan.sleeves.at(0);
  c.meshes = {{8, 6}};
  c.mesh_dt = c.reference_dt = 2e-3;
  c.reference_mesh = {8, 6};
  c.dts.clear();
  c.reference_method = "lobes8";
  const std::vector<ConvergenceRow> rows =
      run_convergence(plan, {synthetic("lobes8", lobes8, 2.0), synthetic("lobes5", lobes5, 2.5),
                             synthetic("bellows4", bellows4, 0.5)},
                      {});
  std::map<std::string, ConvergenceRow> by_method;
  for (const ConvergenceRow& r : rows)
    if (r.series != "reference") by_method[r.method] = r;
  ASSERT_EQ(rows.size(), 4u);
  ASSERT_EQ(by_method.size(), 3u);

  const ConvergenceRow& ref = rows[0];
  ASSERT_EQ(ref.series, "reference");
  ASSERT_TRUE(ref.folds_circumferential && ref.folds_axial && ref.energy_error);
  EXPECT_EQ(*ref.folds_circumferential, 8.0);
  EXPECT_EQ(*ref.folds_axial, 0.0);
  EXPECT_EQ(*ref.energy_error, 0.0);
  EXPECT_EQ(*ref.fold_difference_circumferential, 0.0);
  EXPECT_EQ(*ref.fold_difference_axial, 0.0);
  EXPECT_EQ(*ref.elastic_energy, 2.0);

  const ConvergenceRow& five = by_method.at("lobes5");
  ASSERT_TRUE(five.folds_circumferential && five.fold_difference_circumferential && five.energy_error);
  EXPECT_EQ(*five.folds_circumferential, 5.0);
  EXPECT_EQ(*five.folds_axial, 0.0);
  EXPECT_EQ(*five.reference_folds_circumferential, 8.0);
  EXPECT_EQ(*five.fold_difference_circumferential, -3.0);
  EXPECT_EQ(*five.fold_difference_axial, 0.0);
  EXPECT_NEAR(*five.energy_error, 0.25, 1e-15);
  EXPECT_EQ(*five.reference_elastic_energy, 2.0);

  const ConvergenceRow& bellows = by_method.at("bellows4");
  ASSERT_TRUE(bellows.folds_axial && bellows.fold_difference_axial && bellows.energy_error);
  EXPECT_EQ(*bellows.folds_circumferential, 0.0);
  EXPECT_EQ(*bellows.folds_axial, 4.0);
  EXPECT_EQ(*bellows.fold_difference_circumferential, -8.0);
  EXPECT_EQ(*bellows.fold_difference_axial, 4.0);
  EXPECT_NEAR(*bellows.energy_error, 0.75, 1e-15);

  // The CSV carries them as the nine fields after `note`, then the run's solver tolerance (the
  // study's 1e-8 for its other series) and the tolerance series' columns (empty: not a
  // tolerance-series row).
  std::ostringstream csv;
  write_results_csv(csv, {five});
  const std::string line = csv.str().substr(csv.str().find('\n') + 1);
  EXPECT_NE(line.find(",2.5,2,0.25,5,0,8,0,-3,0,1e-08,,,,,,\n"), std::string::npos) << line;
}

// The end state of a sleeve run computed here without the study: the scene with the given mesh
// and time step, loop_kl with three-point quadrature or a baseline, to `end`; its elastic energy and
// (loop_kl) the fold medians of its drawn surface (display operator, kFoldSurfaceLevels).
struct EndState {
  double energy = 0.0;
  std::optional<double> circumferential, axial;
};

EndState independent_end_state(const std::string& method, int segments, int rings, double dt, double end) {
  std::ifstream in(CLOTHSIM_SOURCE_DIR "/scenes/sleeve_twist.json");
  nlohmann::json j = nlohmann::json::parse(in);
  j["method"] = method == "loop_three_point" ? "loop_kl" : method;
  j["mesh"]["segments"] = segments;
  j["mesh"]["rings"] = rings;
  j["time"]["dt"] = dt;
  j["time"]["end"] = end;
  j.erase("imperfection");  // the study runs the perfect sleeve (docs/convergence.md)
  Problem problem = load_scene_text(j.dump(), CLOTHSIM_SOURCE_DIR "/scenes/sleeve_twist.json", {}).problem;
  problem.quadrature = Quadrature::three_point;
  Simulator sim(problem);
  while (sim.state().t < end - 1e-9 * dt) sim.step();
  if (method != "loop_three_point") return {sim.elastic_energy(), {}, {}};
  const SurfaceOperator drawn = sim.discretization().display(kFoldSurfaceLevels);
  const SleeveFolds folds = count_sleeve_folds(sim.surface_points(drawn), drawn.triangles, FoldAxis{});
  return {sim.elastic_energy(), folds.circumferential_median, folds.axial.median_count};
}

// The quick plan with the baselines: both appear with finite errors in the mesh series only, with
// no folds counted before buckling; the reference row's post-buckling columns are 0; the reference's energy and fold counts, and a
// baseline's energy error, agree with an independent recomputation.
TEST(ConvergenceBaselines, QuickSleeveWithBaselinesAgainstAnIndependentReference) {
  ConvergencePlan plan = quick_convergence_plan(CLOTHSIM_SOURCE_DIR "/scenes");
  plan.plates.clear();
  const std::vector<ConvergenceRow> rows = run_convergence(plan, convergence_methods(), {});
  // reference + 2 Loop rules × (2 meshes + 3 steps) + 2 baselines × 2 meshes + 2 Loop rules × 6
  // tolerances (the baselines do not run the tolerance series)
  ASSERT_EQ(rows.size(), 1u + 10u + 4u + 12u);
  const ConvergenceRow& ref = rows[0];
  ASSERT_EQ(ref.series, "reference");
  ASSERT_TRUE(ref.energy_error && ref.fold_difference_circumferential && ref.fold_difference_axial);
  EXPECT_EQ(*ref.energy_error, 0.0);
  EXPECT_EQ(*ref.fold_difference_circumferential, 0.0);
  EXPECT_EQ(*ref.fold_difference_axial, 0.0);

  int baseline_rows = 0;
  const ConvergenceRow* mass_spring_12x9 = nullptr;
  for (const ConvergenceRow& r : rows) {
    ASSERT_TRUE(r.elastic_energy && r.energy_error) << r.method << " " << r.setting << " " << r.note;
    EXPECT_GT(*r.elastic_energy, 0.0) << r.method << " " << r.setting;
    if (r.method != "linear_fe" && r.method != "mass_spring") continue;
    ++baseline_rows;
    EXPECT_EQ(r.series, "mesh");
    EXPECT_TRUE(std::isfinite(r.error)) << r.method << " " << r.setting << " " << r.note;
    EXPECT_GT(r.error, 0.0);
    EXPECT_TRUE(std::isfinite(*r.energy_error));
    // Not buckled yet at 20 ms (the reference has no folds either): the coarse flat meshes' facet
    // corners (an 8-gon's stand 3.8 mm off the circle, P = 1 mm) must not count as folds.
    EXPECT_EQ(r.folds_circumferential, std::optional<double>(0.0)) << r.method << " " << r.setting;
    EXPECT_EQ(r.folds_axial, std::optional<double>(0.0)) << r.method << " " << r.setting;
    if (r.method == "mass_spring" && r.setting == "12x9 dt=0.002") mass_spring_12x9 = &r;
  }
  EXPECT_EQ(baseline_rows, 4);
  ASSERT_NE(mass_spring_12x9, nullptr);

  const SleeveStudyCase& c = plan.sleeves[0];
  const EndState reference =
      independent_end_state("loop_three_point", c.reference_mesh.segments, c.reference_mesh.rings, c.reference_dt, 0.02);
  EXPECT_NEAR(*ref.elastic_energy, reference.energy, 1e-9 * reference.energy);
  EXPECT_EQ(ref.folds_circumferential, reference.circumferential);
  EXPECT_EQ(ref.folds_axial, reference.axial);
  const EndState spring = independent_end_state("mass_spring", 12, 9, 2e-3, 0.02);
  EXPECT_NEAR(*mass_spring_12x9->elastic_energy, spring.energy, 1e-9 * spring.energy);
  EXPECT_NEAR(*mass_spring_12x9->energy_error, std::abs(spring.energy - reference.energy) / reference.energy, 1e-8);
}

}  // namespace
}  // namespace clothsim

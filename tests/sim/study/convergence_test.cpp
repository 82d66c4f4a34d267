// The convergence study's machinery (sim/study/convergence.hpp, surface_sampling.hpp): parameter
// points and the limit-surface sampling operator (rigid motions, seam, agreement with the limit
// points of solve_static), the relative RMS norm, the plate series (error falls at second order),
// a tiny sleeve series against its reference, the method registry, and the CSV columns.
#include "sim/loop_shell/loop_shell.hpp"
#include "sim/study/convergence.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/shell/ghost_layer.hpp"
#include "sim/study/plates.hpp"
#include "sim/study/report_format.hpp"
#include "sim/study/surface_sampling.hpp"

#include <gtest/gtest.h>

#include <set>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace clothsim {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

std::vector<SurfaceSample> cylinder_points(const TriMesh& mesh, int n_theta, int n_s) {
  return locate_points(mesh.triangles, cylinder_chart(mesh.vertices), cylinder_parameter_grid(n_theta, n_s), kTwoPi);
}

TEST(SurfaceSampling, LocatedPointsReproduceTheirChartCoordinates) {
  const TriMesh mesh = make_cylinder(0.05, 0.2, 13, 10);
  const Eigen::MatrixX2d chart = cylinder_chart(mesh.vertices);
  const Eigen::MatrixX2d targets = cylinder_parameter_grid(32, 16);
  const std::vector<SurfaceSample> points = locate_points(mesh.triangles, chart, targets, kTwoPi);
  ASSERT_EQ(points.size(), 32u * 16u);
  int seam = 0;
  for (size_t p = 0; p < points.size(); ++p) {
    const Triangle& t = mesh.triangles[static_cast<size_t>(points[p].triangle)];
    const double v = points[p].v, w = points[p].w;
    EXPECT_GE(v, 0.0);
    EXPECT_GE(w, 0.0);
    EXPECT_LE(v + w, 1.0);
    // Unwrap the triangle's angles next to its first vertex, as a seam triangle needs.
    double theta[3], s = 0.0;
    for (int k = 0; k < 3; ++k) {
      theta[k] = chart(t[k], 0);
      if (k > 0) theta[k] -= kTwoPi * std::round((theta[k] - theta[0]) / kTwoPi);
    }
    if (std::abs(theta[1] - chart(t[1], 0)) > 1 || std::abs(theta[2] - chart(t[2], 0)) > 1) ++seam;
    s = (1 - v - w) * chart(t[0], 1) + v * chart(t[1], 1) + w * chart(t[2], 1);
    const double angle = (1 - v - w) * theta[0] + v * theta[1] + w * theta[2];
    const Eigen::Index row = static_cast<Eigen::Index>(p);
    EXPECT_NEAR(std::remainder(angle - targets(row, 0), kTwoPi), 0.0, 1e-12) << "point " << p;
    EXPECT_NEAR(s, targets(row, 1), 1e-12) << "point " << p;
  }
  EXPECT_GT(seam, 0) << "no point fell into a triangle across the seam θ = 0";
}

TEST(SurfaceSampling, PointOutsideTheMeshIsAnError) {
  const TriMesh mesh = make_grid(1.0, 1.0, 2, 2);
  const Eigen::MatrixX2d chart = mesh.vertices.leftCols<2>();
  EXPECT_THROW(locate_points(mesh.triangles, chart, Eigen::MatrixX2d::Constant(1, 2, 0.7)), std::invalid_argument);
}

// The displacement field of a rigid motion x = Q X + c, sampled at parameter points, is the rigid
// motion of the rest limit points: W (Q X + c − X) = (Q − I) W X + c (the rows of W sum to 1).
TEST(SurfaceSampling, RigidMotionGivesItsOwnDisplacement) {
  const TriMesh mesh = make_cylinder(0.05, 0.2, 13, 10);
  const LoopShellDiscretization d(mesh, {}, ShellMaterial{}, Quadrature::one_point);
  const std::vector<SurfaceSample> points = cylinder_points(mesh, 32, 16);
  const Eigen::SparseMatrix<double, Eigen::RowMajor>& w = d.samples(points).position;
  const Eigen::MatrixX3d net = d.control_net(d.rest());
  ASSERT_EQ(w.rows(), 32 * 16);
  ASSERT_EQ(w.cols(), net.rows());
  const Eigen::VectorXd row_sums = w * Eigen::VectorXd::Ones(w.cols());
  EXPECT_LT((row_sums.array() - 1.0).abs().maxCoeff(), 1e-14);

  const Eigen::Matrix3d q = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  const Eigen::RowVector3d c(0.03, -0.2, 0.11);
  const Eigen::MatrixX3d moved_nodes = (mesh.vertices * q.transpose()).rowwise() + c;
  const Eigen::MatrixX3d u = w * (d.control_net(to_flat(moved_nodes)) - net);
  const Eigen::MatrixX3d rest_points = w * net;
  const Eigen::MatrixX3d expected = (rest_points * (q - Eigen::Matrix3d::Identity()).transpose()).rowwise() + c;
  EXPECT_LT((u - expected).cwiseAbs().maxCoeff(), 1e-12);
  // The rest limit points lie close to the cylinder (the limit surface of a coarse polygon sits
  // slightly inside it) at the requested height.
  const Eigen::MatrixX2d grid = cylinder_parameter_grid(32, 16);
  for (Eigen::Index p = 0; p < rest_points.rows(); ++p) {
    EXPECT_NEAR(std::hypot(rest_points(p, 0), rest_points(p, 2)), 0.05, 2e-3) << "point " << p;
    EXPECT_NEAR(rest_points(p, 1), 0.2 * grid(p, 1), 1e-12) << "point " << p;
  }
}

// At a control vertex the sampling operator gives the vertex's limit point: the plate centre
// sampled through the chart equals solve_static's limit displacement there.
TEST(SurfaceSampling, PlateCentreMatchesTheLimitDisplacementOfTheCentreVertex) {
  const Problem problem = plate_problem(kAnalyticPlates[0], 8, Quadrature::one_point);
  const StaticResult result = solve_static(problem);
  const Eigen::MatrixX2d chart = problem.mesh.vertices.leftCols<2>();
  const std::vector<SurfaceSample> centre = locate_points(problem.mesh.triangles, chart, Eigen::MatrixX2d::Zero(1, 2));
  const Discretization& d = *result.discretization;
  const SurfaceOperator sample = d.samples(centre);
  const Eigen::MatrixX3d u = d.surface_positions(sample, result.positions()) - d.surface_positions(sample, d.rest());
  const int vertex = nearest_vertex(problem.mesh, Eigen::Vector3d::Zero());
  EXPECT_NEAR(u(0, 2), result.limit_displacement(vertex, 2), 1e-12 * std::abs(result.limit_displacement(vertex, 2)));
}

TEST(SurfaceSampling, RelativeRmsDifference) {
  const std::vector<Eigen::MatrixX3d> ref = {Eigen::MatrixX3d::Random(20, 3), Eigen::MatrixX3d::Random(20, 3)};
  EXPECT_EQ(relative_rms_difference(ref, ref), 0.0);
  std::vector<Eigen::MatrixX3d> twice = ref;
  for (Eigen::MatrixX3d& m : twice) m *= 2;
  EXPECT_NEAR(relative_rms_difference(twice, ref), 1.0, 1e-14);
  EXPECT_NEAR(rms_norm(twice), 2 * rms_norm(ref), 1e-14);
  // A uniform offset d of every point against u_ref = e_x: error = |d|.
  const std::vector<Eigen::MatrixX3d> unit = {Eigen::MatrixX3d::Constant(5, 3, 0.0).rowwise() + Eigen::RowVector3d(1, 0, 0)};
  const std::vector<Eigen::MatrixX3d> off = {unit[0].rowwise() + Eigen::RowVector3d(0, 0.03, 0.04)};
  EXPECT_NEAR(relative_rms_difference(off, unit), 0.05, 1e-14);
  EXPECT_THROW(relative_rms_difference({ref[0]}, ref), std::invalid_argument);
  EXPECT_THROW(relative_rms_difference(ref, {Eigen::MatrixX3d::Zero(20, 3), Eigen::MatrixX3d::Zero(20, 3)}),
               std::invalid_argument);
}

ConvergencePlan plate_plan(std::vector<int> divisions) {
  ConvergencePlan plan;
  plan.plates.push_back({kAnalyticPlates[0], std::move(divisions)});
  return plan;
}

// Simply supported plate under uniform load, 8², 16², 32²: the relative error of the centre
// deflection falls strictly, at about second order, and is small on the finest grid (measured:
// one-point 4.1 %, 0.96 %, 0.23 %; three-point 0.50 %, 0.13 %, 0.032 %).
TEST(ConvergenceStudy, PlateErrorFallsWithRefinement) {
  const std::vector<Method> loop = {convergence_methods()[0], convergence_methods()[1]};
  const std::vector<ConvergenceRow> rows = run_convergence(plate_plan({8, 16, 32}), loop, {});
  ASSERT_EQ(rows.size(), 6u);
  for (size_t m = 0; m < 2; ++m) {
    const ConvergenceRow* r = &rows[3 * m];
    EXPECT_EQ(r[0].method, m == 0 ? "loop_one_point" : "loop_three_point");
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(r[k].case_name, "plate_ss_uniform");
      EXPECT_EQ(r[k].series, "mesh");
      EXPECT_EQ(r[k].dt, 0.0);
      EXPECT_GT(r[k].wall_seconds, 0.0);
      EXPECT_GT(r[k].dofs, 0);
      EXPECT_TRUE(r[k].note.empty()) << r[k].note;
    }
    EXPECT_EQ(r[0].setting, "8x8");
    EXPECT_EQ(r[2].vertices, 33 * 33);
    EXPECT_LT(r[1].error, r[0].error) << r[1].method;
    EXPECT_LT(r[2].error, r[1].error) << r[2].method;
    EXPECT_LT(r[2].error, m == 0 ? 0.003 : 0.0005) << r[2].method;
    EXPECT_FALSE(r[0].order.has_value());
    for (int k = 1; k < 3; ++k) {
      ASSERT_TRUE(r[k].order.has_value());
      EXPECT_GT(*r[k].order, 1.8) << r[k].method << " " << r[k].setting;
      EXPECT_LT(*r[k].order, 2.3) << r[k].method << " " << r[k].setting;
    }
    EXPECT_NEAR(r[2].reference_value, 0.00406235 / (1e7 * 1e-6 / 12 / (1 - 0.09)), 1e-15);
  }
}

// The quick plan's sleeve (twist to 0.02 s), here with two error windows: the reference rows have
// error 0 and a note, the mesh series' error falls from 8 × 6 to 12 × 9, every run has its figures,
// and the run shared by the mesh and time-step series (12 × 9 at 2 ms) is reported identically in
// both. Rows come per run, one for each window.
TEST(ConvergenceStudy, SleeveSeriesAgainstTheFinestRun) {
  ConvergencePlan plan = quick_convergence_plan(CLOTHSIM_SOURCE_DIR "/scenes");
  plan.plates.clear();
  ASSERT_EQ(plan.sleeves.size(), 1u);
  plan.sleeves[0].windows = {{"early", {0.01, 0.02}}, {"first", {0.01}}};
  plan.sleeves[0].tolerances.clear();  // the tolerance series: ToleranceSeriesOnTheQuickPlan
  const std::vector<Method> methods = {convergence_methods()[0]};  // the reference method joins anyway
  const std::vector<ConvergenceRow> all = run_convergence(plan, methods, {});
  ASSERT_EQ(all.size(), 2 * (1u + 2u + 3u));
  std::vector<ConvergenceRow> rows, first;
  for (const ConvergenceRow& r : all) (r.window == "early" ? rows : first).push_back(r);
  ASSERT_EQ(rows.size(), first.size());
  for (size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(first[k].window, "first");
    EXPECT_EQ(first[k].setting, rows[k].setting);
    EXPECT_EQ(first[k].wall_seconds, rows[k].wall_seconds);  // the same run
    EXPECT_LT(first[k].value, rows[k].value);  // the sleeve twists further after 0.01 s
  }
  EXPECT_EQ(rows[0].series, "reference");
  EXPECT_EQ(rows[0].method, "loop_three_point");
  EXPECT_EQ(rows[0].error, 0.0);
  EXPECT_FALSE(rows[0].note.empty());
  EXPECT_EQ(rows[0].value, rows[0].reference_value);
  for (const ConvergenceRow& r : all) {
    EXPECT_EQ(r.case_name, "sleeve_twist");
    EXPECT_GT(r.steps, 0);
    EXPECT_GT(r.solver_iterations, 0);
    EXPECT_GT(r.value, 0.0);
    EXPECT_TRUE(std::isfinite(r.error));
    EXPECT_NEAR(r.steps * r.dt, 0.02, 1e-12);
  }
  EXPECT_EQ(rows[1].series, "mesh");
  EXPECT_EQ(rows[1].setting, "8x6 dt=0.002");
  EXPECT_LT(rows[2].error, rows[1].error);
  EXPECT_LT(rows[2].error, 0.05);
  EXPECT_EQ(rows[5].series, "dt");
  EXPECT_EQ(rows[5].setting, rows[2].setting);
  EXPECT_EQ(rows[5].error, rows[2].error);
  EXPECT_EQ(rows[5].wall_seconds, rows[2].wall_seconds);
}

// The quick plan's tolerance series (12 × 9 at 2 ms, both Loop rules, tolerances 1e-2 … 1e-10 and
// the tight run at 1e-12): every run reports the tolerance it was solved to; the tight run's solver
// error is 0 and looser tolerances give larger solver errors and fewer iterations; every row of a
// setting carries the tight run's error as its discretisation error, and total, discretisation and
// solver error obey the triangle inequality; the run at the other series' tolerance (1e-8) is the
// mesh series' 12 × 9 run.
TEST(ConvergenceStudy, ToleranceSeriesOnTheQuickPlan) {
  ConvergencePlan plan = quick_convergence_plan(CLOTHSIM_SOURCE_DIR "/scenes");
  plan.plates.clear();
  ASSERT_EQ(plan.sleeves.size(), 1u);
  const SleeveStudyCase& c = plan.sleeves[0];
  ASSERT_EQ(c.tolerances, (std::vector<double>{1e-2, 1e-3, 1e-5, 1e-8, 1e-10}));
  ASSERT_EQ(c.tight_tolerance, 1e-12);
  const std::vector<Method> loop = {convergence_methods()[0], convergence_methods()[1]};
  const std::vector<ConvergenceRow> rows = run_convergence(plan, loop, {});
  for (const Method& method : loop) {
    SCOPED_TRACE(method.name);
    std::map<double, const ConvergenceRow*> at;  // the tolerance rows by tolerance
    const ConvergenceRow* mesh_12x9 = nullptr;
    for (const ConvergenceRow& r : rows) {
      if (r.series == "tolerance") {
        if (r.method != method.name) continue;
        ASSERT_TRUE(r.tolerance.has_value());
        EXPECT_TRUE(at.emplace(*r.tolerance, &r).second) << "two rows at tolerance " << *r.tolerance;
        EXPECT_EQ(r.setting, "12x9 dt=0.002 tol=" + format_shortest(*r.tolerance));
        EXPECT_EQ(r.dt, 2e-3);
        EXPECT_EQ(r.window, "early");
        continue;
      }
      // Every other sleeve run is solved to the study's 1e-8 (kSeriesTolerance) and has no solver
      // error.
      EXPECT_EQ(r.tolerance, std::optional<double>(1e-8)) << r.series << " " << r.setting;
      EXPECT_FALSE(r.solver_error.has_value()) << r.series << " " << r.setting;
      if (r.method == method.name && r.series == "mesh" && r.setting == "12x9 dt=0.002") mesh_12x9 = &r;
    }
    ASSERT_EQ(at.size(), 6u);
    ASSERT_NE(mesh_12x9, nullptr);
    const ConvergenceRow& tight = *at.at(1e-12);
    ASSERT_TRUE(tight.solver_error && tight.solver_energy_error);
    EXPECT_EQ(*tight.solver_error, 0.0);
    EXPECT_EQ(*tight.solver_energy_error, 0.0);
    EXPECT_NE(tight.note.find("solver reference"), std::string::npos) << tight.note;
    for (const auto& [tolerance, r] : at) {
      ASSERT_TRUE(r->solver_error && r->discretization_error && r->discretization_energy_error) << tolerance;
      EXPECT_TRUE(std::isfinite(r->error)) << tolerance;
      EXPECT_EQ(*r->discretization_error, tight.error) << tolerance;
      EXPECT_EQ(*r->discretization_energy_error, *tight.energy_error) << tolerance;
      EXPECT_EQ(r->solver_reference_folds_circumferential, tight.folds_circumferential) << tolerance;
      EXPECT_EQ(r->solver_reference_folds_axial, tight.folds_axial) << tolerance;
      // |total − discretisation| <= |u − u_tight| / |u_ref| = solver error · RMS|u_tight| / RMS|u_ref|.
      EXPECT_LE(std::abs(r->error - *r->discretization_error),
                *r->solver_error * tight.value / r->reference_value * (1 + 1e-9) + 1e-15)
          << tolerance;
    }
    EXPECT_GT(*at.at(1e-8)->solver_error, 0.0);
    EXPECT_GT(*at.at(1e-3)->solver_error, *at.at(1e-8)->solver_error);
    EXPECT_GT(*at.at(1e-2)->solver_error, *at.at(1e-5)->solver_error);
    EXPECT_LT(at.at(1e-2)->solver_iterations, tight.solver_iterations);
    // The run at 1e-8 is the mesh series' run.
    EXPECT_EQ(at.at(1e-8)->wall_seconds, mesh_12x9->wall_seconds);
    EXPECT_EQ(at.at(1e-8)->error, mesh_12x9->error);
  }
}

// A tolerance setting measured in one of the case's windows only (ToleranceSetting::windows): at
// dt = 0.02 s it cannot sample the "early" window's 0.01 s, so it names "late" (0.02 s). Its rows
// are that window's only; the tight run's discretisation error is its total error against the
// reference, which is sampled at the case's times (a mix-up of the two time lists would compare
// the reference's 0.01 s sample). A setting that names no window, or an unknown one, is refused.
TEST(ConvergenceStudy, ToleranceSettingMeasuredInItsOwnWindows) {
  ConvergencePlan plan = quick_convergence_plan(CLOTHSIM_SOURCE_DIR "/scenes");
  plan.plates.clear();
  ASSERT_EQ(plan.sleeves.size(), 1u);
  SleeveStudyCase& c = plan.sleeves[0];
  c.windows = {{"early", {0.01, 0.02}}, {"late", {0.02}}};
  c.meshes = {{12, 9}};
  c.dts = {1e-2};
  c.tolerances = {1e-3};
  c.tolerance_settings = {{"loop_one_point", {12, 9}, 0.02, {"late"}}};
  const std::vector<Method> methods = {convergence_methods()[0]};
  ASSERT_EQ(methods[0].name, "loop_one_point");
  const std::vector<ConvergenceRow> rows = run_convergence(plan, methods, {});
  std::vector<const ConvergenceRow*> tolerance_rows;
  for (const ConvergenceRow& r : rows)
    if (r.series == "tolerance") tolerance_rows.push_back(&r);
  ASSERT_EQ(tolerance_rows.size(), 2u);  // 1e-3 and the tight run, in "late" only
  for (const ConvergenceRow* r : tolerance_rows) {
    EXPECT_EQ(r->window, "late");
    EXPECT_EQ(r->steps, 1);
    EXPECT_EQ(r->dt, 0.02);
    ASSERT_TRUE(r->solver_error && r->discretization_error);
    EXPECT_TRUE(std::isfinite(r->error));
  }
  const ConvergenceRow& tight = *tolerance_rows[1];
  EXPECT_EQ(tight.setting, "12x9 dt=0.02 tol=1e-12");
  EXPECT_EQ(*tight.solver_error, 0.0);
  EXPECT_GT(tight.error, 0.0);
  EXPECT_EQ(*tolerance_rows[0]->discretization_error, tight.error);

  c.tolerance_settings = {{"loop_one_point", {12, 9}, 0.02, {}}};  // all windows: 0.01 s is not a step
  EXPECT_THROW(run_convergence(plan, methods, {}), std::invalid_argument);
  c.tolerance_settings = {{"loop_one_point", {12, 9}, 0.02, {"nope"}}};
  EXPECT_THROW(run_convergence(plan, methods, {}), std::invalid_argument);
}

// A tolerance-series row for summarize_tolerance_series (only the fields it reads).
ConvergenceRow tolerance_row(const std::string& mesh, double tolerance, const std::string& window, double solver_error,
                             double discretization_error, double energy_error, double circumferential, double axial) {
  ConvergenceRow r;
  r.case_name = "sleeve_made_up";
  r.method = "loop_one_point";
  r.series = "tolerance";
  r.window = window;
  r.dt = 1e-3;
  r.setting = mesh + " dt=0.001 tol=" + format_shortest(tolerance);
  r.tolerance = tolerance;
  r.error = 0.5;
  r.solver_error = solver_error;
  r.discretization_error = discretization_error;
  r.solver_energy_error = energy_error;
  r.folds_circumferential = circumferential;
  r.folds_axial = axial;
  return r;
}

// The rule on made-up rows of two settings at the same time step (ratio 1/10; baseline 1e-8: 1e-8
// is a candidate and a baseline run, 1e-9 a baseline run, 1e-12 the tight run; amplification
// limit 1e3):
//  - 26 × 19, "early" (discretisation error 0.01, bound 1e-3): 1e-2 passes (5e-4), 1e-3 fails
//    (2e-3), 1e-4 and 1e-8 pass: the loosest passing with every tighter candidate passing is 1e-4;
//    "long": the baseline runs' solver error 0.5 is 5e8 times 1e-9, so the window is unresolved
//    and does not count. End state: the baseline runs span 10 % energy and 5–6 / 1 folds; 1e-3
//    (20 %) and 1e-4 (7 folds) lie outside (no energy discretisation error given).
//  - 52 × 37: "early" passes down from 1e-2, "long" (bound 0.03) from 1e-3.
// Recommended: the tightest of 1e-4, 1e-2, 1e-3.
TEST(ConvergenceStudy, ToleranceRuleOnMadeUpRows) {
  std::vector<ConvergenceRow> rows;
  const std::string a_mesh = "26x19", b_mesh = "52x37";
  auto add = [&](const std::string& mesh, double tolerance, double early, double late, double energy, double circ,
                 double axial) {
    rows.push_back(tolerance_row(mesh, tolerance, "early", early, mesh == a_mesh ? 0.01 : 0.02, energy, circ, axial));
    rows.push_back(tolerance_row(mesh, tolerance, "long", late, 0.3, energy, circ, axial));
  };
  add(a_mesh, 1e-2, 5e-4, 0.6, 0.05, 5, 1);
  add(a_mesh, 1e-3, 2e-3, 0.4, 0.2, 6, 1);
  add(a_mesh, 1e-4, 1e-5, 0.5, 0.0, 7, 1);
  add(a_mesh, 1e-8, 1e-9, 0.5, 0.0, 5, 1);
  add(a_mesh, 1e-9, 1e-10, 0.5, 0.1, 6, 1);
  add(a_mesh, 1e-12, 0.0, 0.0, 0.0, 5, 1);
  add(b_mesh, 1e-2, 1e-3, 0.05, 0.0, 5, 1);
  add(b_mesh, 1e-3, 1e-4, 0.01, 0.0, 5, 1);
  add(b_mesh, 1e-4, 1e-5, 0.001, 0.0, 5, 1);
  add(b_mesh, 1e-9, 1e-10, 1e-9, 0.0, 5, 1);
  add(b_mesh, 1e-12, 0.0, 0.0, 0.0, 5, 1);
  ConvergenceRow other = rows.front();  // rows of other series are ignored
  other.series = "mesh";
  other.solver_error = 1.0;
  rows.push_back(other);

  const ToleranceSummary summary = summarize_tolerance_series(rows);
  ASSERT_EQ(summary.settings.size(), 2u);
  const ToleranceSettingCheck& a = summary.settings[0];
  EXPECT_EQ(a.setting, "26x19 dt=0.001");
  EXPECT_EQ(a.dt, 1e-3);
  EXPECT_EQ(a.tight_tolerance, 1e-12);
  EXPECT_EQ(a.candidates, (std::vector<double>{1e-2, 1e-3, 1e-4, 1e-8}));
  ASSERT_EQ(a.windows.size(), 2u);
  EXPECT_EQ(a.windows[0].window, "early");
  EXPECT_TRUE(a.windows[0].resolved);
  EXPECT_EQ(a.windows[0].loosest, std::optional<double>(1e-4));
  EXPECT_EQ(a.windows[0].discretization_error, 0.01);
  EXPECT_EQ(a.windows[0].baseline_solver_error, 1e-9);
  EXPECT_NEAR(a.windows[0].amplification, 0.1, 1e-15);
  EXPECT_FALSE(a.windows[1].resolved);
  EXPECT_EQ(a.windows[1].baseline_solver_error, 0.5);
  EXPECT_NEAR(a.windows[1].amplification, 5e8, 1e-6);
  EXPECT_EQ(a.windows[1].loosest, std::nullopt);
  EXPECT_EQ(a.energy_spread, 0.1);
  EXPECT_EQ(a.folds_circumferential_min, 5.0);
  EXPECT_EQ(a.folds_circumferential_max, 6.0);
  EXPECT_EQ(a.folds_axial_min, 1.0);
  EXPECT_EQ(a.folds_axial_max, 1.0);
  EXPECT_EQ(a.outside_spread, (std::vector<double>{1e-3, 1e-4}));
  const ToleranceSettingCheck& b = summary.settings[1];
  EXPECT_EQ(b.setting, "52x37 dt=0.001");
  EXPECT_EQ(b.candidates, (std::vector<double>{1e-2, 1e-3, 1e-4}));
  EXPECT_EQ(b.windows[0].loosest, std::optional<double>(1e-2));
  EXPECT_TRUE(b.windows[1].resolved);
  EXPECT_EQ(b.windows[1].loosest, std::optional<double>(1e-3));
  EXPECT_TRUE(b.outside_spread.empty());
  EXPECT_EQ(summary.recommended, std::optional<double>(1e-4));

  std::ostringstream md;
  write_tolerance_summary_markdown(md, summary);
  EXPECT_NE(md.str().find("Recommended tolerance by the rule: 1e-04\n"), std::string::npos) << md.str();
  EXPECT_NE(md.str().find("| sleeve_made_up | loop_one_point | 26x19 dt=0.001 | long | 0.3 | 0.5 | 5e+08 | no | none |"),
            std::string::npos)
      << md.str();

  // With an energy discretisation error of 2.5 the energy bound is 0.25: 1e-3's 20 % is inside,
  // 1e-4's seven folds are not.
  std::vector<ConvergenceRow> with_energy = rows;
  for (ConvergenceRow& r : with_energy) r.discretization_energy_error = 2.5;
  EXPECT_EQ(summarize_tolerance_series(with_energy).settings[0].outside_spread, (std::vector<double>{1e-4}));

  // A resolved window in which even the tightest candidate fails: no recommendation.
  ConvergenceRow& b_early_1e4 = rows[16];
  ASSERT_EQ(b_early_1e4.setting, "52x37 dt=0.001 tol=1e-04");
  ASSERT_EQ(b_early_1e4.window, "early");
  b_early_1e4.solver_error = 0.05;  // bound 2e-3
  const ToleranceSummary failing = summarize_tolerance_series(rows);
  EXPECT_EQ(failing.settings[1].windows[0].loosest, std::nullopt);
  EXPECT_EQ(failing.recommended, std::nullopt);
  // No tolerance series: nothing.
  EXPECT_TRUE(summarize_tolerance_series({other}).settings.empty());
  std::ostringstream none;
  write_tolerance_summary_markdown(none, summarize_tolerance_series({other}));
  EXPECT_TRUE(none.str().empty());
}

TEST(ConvergenceStudy, SampleTimesMustBeMultiplesOfEveryTimeStep) {
  ConvergencePlan plan = quick_convergence_plan(CLOTHSIM_SOURCE_DIR "/scenes");
  plan.plates.clear();
  plan.sleeves[0].dts.push_back(3e-3);
  EXPECT_THROW(run_convergence(plan, convergence_methods(), {}), std::invalid_argument);
}

// A method is one registration: a made-up static-only method joins the plate case (and no
// sleeve case), with its own name in the rows.
TEST(ConvergenceStudy, ExtraMethodsBecomeExtraRows) {
  const std::vector<Method> registered = convergence_methods();
  ASSERT_EQ(registered.size(), 4u);
  EXPECT_EQ(registered[0].name, "loop_one_point");
  EXPECT_EQ(registered[1].name, "loop_three_point");
  EXPECT_EQ(registered[2].name, "linear_fe");
  EXPECT_EQ(registered[3].name, "mass_spring");

  Method exact;
  exact.name = "analytic_times_1.01";
  exact.solve_static = [](const Problem& problem, const std::vector<SurfaceSample>& points) {
    MethodRun run;
    run.vertices = problem.mesh.num_vertices();
    run.displacements = {Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(points.size()), 3)};
    run.displacements[0](0, 2) = -1.01 * plate_reference_deflection(kAnalyticPlates[0], problem);
    return run;
  };
  const std::vector<ConvergenceRow> rows = run_convergence(plate_plan({4}), {registered[0], exact}, {});
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].method, "analytic_times_1.01");
  EXPECT_NEAR(rows[1].error, 0.01, 1e-12);
}

TEST(ConvergenceStudy, FailedRunsAreRecordedNotFatal) {
  Method broken;
  broken.name = "broken";
  broken.solve_static = [](const Problem&, const std::vector<SurfaceSample>&) -> MethodRun {
    throw std::runtime_error("singular, on purpose");
  };
  const std::vector<ConvergenceRow> rows = run_convergence(plate_plan({4}), {broken}, {});
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_TRUE(std::isnan(rows[0].error));
  EXPECT_NE(rows[0].note.find("singular, on purpose"), std::string::npos) << rows[0].note;
}

// The study as independent runs: the quick plan's runs listed (unique ids, the reference first
// among the sleeve's), each run alone (in reverse order) and the rows gathered from their results
// are the rows of the one-process study in every column but wall_seconds; a missing result marks exactly the rows that need it; an unknown id is
// refused.
TEST(ConvergenceStudy, RunsAsTasksGiveTheSameRows) {
  ConvergencePlan plan = quick_convergence_plan(CLOTHSIM_SOURCE_DIR "/scenes");
  const std::vector<Method> methods = convergence_methods();
  const std::vector<std::string> ids = convergence_run_ids(plan, methods);
  ASSERT_GT(ids.size(), 5u);
  EXPECT_EQ(std::set<std::string>(ids.begin(), ids.end()).size(), ids.size());
  for (const std::string& id : ids)
    EXPECT_EQ(id.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-"), std::string::npos)
        << id;
  const auto sleeve = std::find_if(ids.begin(), ids.end(), [](const std::string& id) { return id.rfind("sleeve_", 0) == 0; });
  ASSERT_NE(sleeve, ids.end());
  EXPECT_EQ(sleeve->rfind("sleeve_twist.loop_three_point.", 0), 0u) << *sleeve;  // the reference run

  std::map<std::string, std::string> results;
  for (auto it = ids.rbegin(); it != ids.rend(); ++it) results[*it] = run_convergence_run(plan, methods, *it, {});
  const std::vector<ConvergenceRow> gathered = gather_convergence(plan, methods, results, {});
  const std::vector<ConvergenceRow> direct = run_convergence(plan, methods, {});
  ASSERT_EQ(gathered.size(), direct.size());
  const auto without_time = [](std::vector<ConvergenceRow> rows) {
    for (ConvergenceRow& r : rows) r.wall_seconds = 0;
    std::ostringstream out;
    write_results_csv(out, rows);
    return out.str();
  };
  EXPECT_EQ(without_time(gathered), without_time(direct));

  // Without the reference run's result: every row of the sleeve is marked, no plate row.
  std::map<std::string, std::string> partial = results;
  partial.erase(*sleeve);
  for (const ConvergenceRow& r : gather_convergence(plan, methods, partial, {})) {
    if (r.case_name.rfind("sleeve_", 0) == 0) {
      EXPECT_TRUE(std::isnan(r.error)) << r.setting;
      EXPECT_NE(r.note.find("run " + *sleeve + " did not finish"), std::string::npos) << r.note;
    } else {
      EXPECT_TRUE(std::isfinite(r.error)) << r.case_name;
    }
  }
  EXPECT_THROW(run_convergence_run(plan, methods, "no_such_run", {}), std::invalid_argument);
  partial[ids.front()] = "{not json";
  EXPECT_THROW(gather_convergence(plan, methods, partial, {}), std::runtime_error);
}

// Line n (from 0) of `text`, without its line break.
std::string nth_line(const std::string& text, int n) {
  size_t start = 0;
  for (int k = 0; k < n && start != std::string::npos; ++k) {
    start = text.find('\n', start);
    if (start != std::string::npos) ++start;
  }
  if (start == std::string::npos) return "";
  return text.substr(start, text.find('\n', start) - start);
}

TEST(ConvergenceStudy, CsvHasTheDocumentedColumnsAndOneLinePerRun) {
  const std::vector<std::string> expected = {
      "case",     "method",       "series",            "window", "setting", "vertices",        "dofs",
      "h",        "dt",           "steps",             "wall_seconds",      "solver_iterations", "error",
      "order",    "quantity",     "value",             "reference_value",   "reference_precision", "reference",
      "note",     "elastic_energy", "reference_elastic_energy", "energy_error", "folds_circumferential",
      "folds_axial", "reference_folds_circumferential", "reference_folds_axial", "fold_difference_circumferential",
      "fold_difference_axial", "tolerance", "solver_error", "discretization_error", "solver_energy_error",
      "discretization_energy_error", "solver_reference_folds_circumferential", "solver_reference_folds_axial"};
  EXPECT_EQ(results_csv_columns(), expected);

  const std::vector<Method> loop = {convergence_methods()[0], convergence_methods()[1]};
  std::vector<ConvergenceRow> rows = run_convergence(plate_plan({4, 8}), loop, {});
  ASSERT_EQ(rows.size(), 4u);
  rows[0].note = "a, \"quoted\" note";
  std::ostringstream csv;
  write_results_csv(csv, rows);
  const std::string text = csv.str();
  EXPECT_EQ(static_cast<size_t>(std::count(text.begin(), text.end(), '\n')), rows.size() + 1);
  EXPECT_EQ(nth_line(text, 0),
            "case,method,series,window,setting,vertices,dofs,h,dt,steps,wall_seconds,solver_iterations,error,order,"
            "quantity,value,reference_value,reference_precision,reference,note,elastic_energy,reference_elastic_energy,"
            "energy_error,folds_circumferential,folds_axial,reference_folds_circumferential,reference_folds_axial,"
            "fold_difference_circumferential,fold_difference_axial,tolerance,solver_error,discretization_error,"
            "solver_energy_error,discretization_energy_error,solver_reference_folds_circumferential,"
            "solver_reference_folds_axial");
  EXPECT_EQ(nth_line(text, 1).rfind("plate_ss_uniform,loop_one_point,mesh,static,4x4,25,", 0), 0u) << text;
  EXPECT_NE(nth_line(text, 1).find(",\"a, \"\"quoted\"\" note\""), std::string::npos) << text;
  EXPECT_NE(nth_line(text, 2).find(",mesh,static,8x8,81,"), std::string::npos) << text;
  // A plate row has no post-buckling measures, no iterative solver and no tolerance series: the
  // sixteen last fields are empty.
  const std::string line = nth_line(text, 2);
  EXPECT_EQ(line.substr(line.size() - 16), std::string(16, ',')) << line;

  std::ostringstream md;
  write_results_markdown(md, rows);
  const std::string table = md.str();
  EXPECT_EQ(static_cast<size_t>(std::count(table.begin(), table.end(), '\n')), rows.size() + 2);
}

// docs/convergence.md documents every column of results.csv, in the order written: the names in
// the first cells of the table under "## results.csv" (a cell may name several, `a`, `b`).
TEST(ConvergenceStudy, CsvColumnsAreTheDocumentedOnes) {
  std::ifstream in(CLOTHSIM_SOURCE_DIR "/docs/convergence.md");
  ASSERT_TRUE(in) << "docs/convergence.md";
  std::vector<std::string> documented;
  bool section = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("## ", 0) == 0) section = line == "## results.csv";
    if (!section || line.rfind("| `", 0) != 0) continue;
    const std::string cell = line.substr(1, line.find('|', 1) - 1);
    for (size_t open = cell.find('`'); open != std::string::npos; open = cell.find('`', open + 1)) {
      const size_t close = cell.find('`', open + 1);
      ASSERT_NE(close, std::string::npos) << line;
      documented.push_back(cell.substr(open + 1, close - open - 1));
      open = close;
    }
  }
  EXPECT_EQ(documented, results_csv_columns());
}

}  // namespace
}  // namespace clothsim

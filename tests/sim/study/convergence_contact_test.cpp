// The convergence study on a self-colliding sleeve (sleeve_compress: "collision": {"self": true}),
// the only study case whose runs build the contact stage. Regression test for the full study's
// compression case, which failed at set-up ("display: levels must be >= 0") or ran out of memory
// (23 GB) when the contact stage's call of Discretization::display reached the wrong function —
// a contact_stage object compiled against an older Discretization interface (docs/convergence.md,
// "Results"). Small meshes, 8 ms of simulated time: well under a second.
#include "sim/study/convergence.hpp"

#include "sim/contact/contact_stage.hpp"
#include "sim/dynamics/simulator.hpp"
#include "sim/scene/scene.hpp"
#include "sim/setup/setup.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

namespace clothsim {
namespace {

const char* const kScene = CLOTHSIM_SOURCE_DIR "/scenes/sleeve_compress.json";

// sleeve_compress with the given mesh and time step, loaded here without the study.
Problem compress_problem(int segments, int rings, double dt, double end) {
  std::ifstream in(kScene);
  nlohmann::json j = nlohmann::json::parse(in);
  j["mesh"]["segments"] = segments;
  j["mesh"]["rings"] = rings;
  j["time"]["dt"] = dt;
  j["time"]["end"] = end;
  j.erase("imperfection");  // the study runs the perfect sleeve (docs/convergence.md)
  return load_scene_text(j.dump(), kScene, {}).problem;
}

// The collision surface of the scene's contact stage is the Loop limit surface refined
// render.refine = 2 times (no "render" or "collision.surface_level" key in the scene): each of the
// sleeve's triangles carries 4^2 = 16 fine triangles, and the fine points are the vertices of the
// twice-refined cylinder, counted by hand with Euler's formula (V − E + F = 0 for a cylinder).
TEST(ConvergenceContact, CollisionSurfaceOfTheCompressedSleeveIsTwiceRefined) {
  const Problem problem = compress_problem(12, 9, 1e-3, 0.008);
  ASSERT_TRUE(problem.collision.self);
  ASSERT_EQ(problem.collision_level, 2);
  const std::shared_ptr<Discretization> d = make_discretization(problem);
  const Eigen::VectorXd mass = d->lumped_mass(problem.material.areal_density);
  const std::vector<char> free(static_cast<size_t>(3 * d->num_nodes()), 1);
  ContactParameters parameters;
  parameters.surface_level = problem.collision_level;
  const ContactStage stage(*d, mass, free, problem.collision, problem.obstacles, parameters);
  const SurfaceOperator& surface = stage.surface();
  const size_t control_triangles = static_cast<size_t>(problem.mesh.num_triangles());
  ASSERT_EQ(control_triangles, 2u * 12u * 8u);  // 12 segments × 8 ring gaps, two triangles each
  EXPECT_EQ(surface.levels, 2);
  EXPECT_EQ(surface.triangles.size(), 16u * control_triangles);
  // Cylinder (Euler characteristic 0): V = E − F; at level 2, F = 16 · 192 = 3072 and the two rims
  // have 4 · 12 edges each, so E = (3 F + 2 · 48) / 2 = 4656 and V = 1584.
  EXPECT_EQ(surface.position.rows(), 1584);
}

// The study on sleeve_compress: every row finite (no failed run), and the reference run's end
// state — elastic energy and fold counts, with the contact stage acting — equal to a Simulator run
// of the same scene done here without the study.
TEST(ConvergenceContact, CompressedSleeveRunsThroughTheStudy) {
  SleeveStudyCase c;
  c.name = "sleeve_compress";
  c.scene = kScene;
  c.windows = {{"early", {0.004, 0.008}}};
  c.grid_theta = 16;
  c.grid_s = 8;
  c.meshes = {{8, 6}, {12, 9}};
  c.mesh_dt = 1e-3;
  c.dt_mesh = {12, 9};
  c.dts = {2e-3};
  c.dt_series_methods = {"loop_three_point"};
  c.reference_mesh = {16, 11};
  c.reference_dt = 1e-3;
  ConvergencePlan plan;
  plan.sleeves.push_back(c);
  std::vector<Method> methods;
  for (const Method& m : convergence_methods())
    if (m.name == "loop_three_point" || m.name == "mass_spring") methods.push_back(m);
  const std::vector<ConvergenceRow> rows = run_convergence(plan, methods, {});
  // reference + three-point (2 meshes + 1 step) + mass_spring (2 meshes)
  ASSERT_EQ(rows.size(), 6u);
  for (const ConvergenceRow& r : rows) {
    EXPECT_TRUE(r.note.find("failed") == std::string::npos) << r.method << " " << r.setting << ": " << r.note;
    EXPECT_TRUE(std::isfinite(r.error)) << r.method << " " << r.setting << ": " << r.note;
    EXPECT_TRUE(r.elastic_energy && *r.elastic_energy > 0) << r.method << " " << r.setting;
    EXPECT_GT(r.steps, 0) << r.method << " " << r.setting;
  }
  const ConvergenceRow& ref = rows[0];
  ASSERT_EQ(ref.series, "reference");
  ASSERT_TRUE(ref.elastic_energy.has_value());

  Problem problem = compress_problem(16, 11, 1e-3, 0.008);
  problem.quadrature = Quadrature::three_point;
  Simulator sim(problem);
  while (sim.state().t < 0.008 - 1e-12) sim.step();
  EXPECT_NEAR(*ref.elastic_energy, sim.elastic_energy(), 1e-9 * sim.elastic_energy());
  const SurfaceOperator drawn = sim.discretization().display(kFoldSurfaceLevels);
  const SleeveFolds folds = count_sleeve_folds(sim.surface_points(drawn), drawn.triangles, FoldAxis{});
  EXPECT_EQ(ref.folds_circumferential, folds.circumferential_median);
  EXPECT_EQ(ref.folds_axial, folds.axial.median_count);
}

}  // namespace
}  // namespace clothsim

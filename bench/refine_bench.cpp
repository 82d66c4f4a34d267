// Limit-surface refinement for rendering: building the sparse operator once per mesh, and one
// frame's positions and normals, for the 2542-vertex sleeve refined twice (79 360 triangles).
#include "sim/mesh/generators.hpp"
#include "sim/shell/ghost_layer.hpp"
#include "sim/subdivision/limit_refinement.hpp"

#include <benchmark/benchmark.h>

namespace clothsim {
namespace {

const ExtendedMesh& sleeve() {
  static const ExtendedMesh ext = build_ghost_layer(make_cylinder(0.05, 0.2, 62, 41));
  return ext;
}

void BM_BuildRefinementOperator(benchmark::State& state) {
  const ExtendedMesh& ext = sleeve();
  for (auto _ : state) {
    LimitRefinement r = build_limit_refinement(ext.rest, ext.triangles, ext.num_real_triangles, 2);
    benchmark::DoNotOptimize(r.position.nonZeros());
  }
}
BENCHMARK(BM_BuildRefinementOperator)->Unit(benchmark::kMillisecond)->Repetitions(7)->ReportAggregatesOnly(true);

void BM_RefineOneFrame(benchmark::State& state) {
  const ExtendedMesh& ext = sleeve();
  const LimitRefinement r = build_limit_refinement(ext.rest, ext.triangles, ext.num_real_triangles, 2);
  Eigen::MatrixX3d p, n;
  for (auto _ : state) {
    evaluate_limit(r, ext.rest, p, n);
    benchmark::DoNotOptimize(p.data());
  }
  state.counters["triangles"] = static_cast<double>(r.triangles.size());
}
BENCHMARK(BM_RefineOneFrame)->Unit(benchmark::kMillisecond)->Repetitions(7)->ReportAggregatesOnly(true);

}  // namespace
}  // namespace clothsim

BENCHMARK_MAIN();

// Google Benchmark timings of the static plate pipeline on a simply supported square plate
// under a uniform load (1 m side, q = 1 N/m²), for 32², 64² and 128² cell grids: model set-up
// (ghost layer, DOF map, element basis), stiffness/load assembly, and CHOLMOD factorise+solve.
// See docs/performance.md for how to run it and for measured numbers.
#include "tests/support/plates.hpp"
#include "sim/shell/shell_model.hpp"
#include "sim/solver/direct_solver.hpp"

#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <Eigen/SparseCore>

#include <stdexcept>

namespace clothsim {
namespace {

constexpr int kLargest = 128;  // the peak-memory counter is set after this size's solve
const Eigen::Vector3d kLoad(0.0, 0.0, -1.0);  // [N/m²]

Problem make_problem(const benchmark::State& state) {
  return testing::square_plate(static_cast<int>(state.range(0)), /*clamped=*/false, Quadrature::one_point);
}

void set_size_counters(benchmark::State& state, const ShellModel& model) {
  state.counters["vertices"] = static_cast<double>(model.num_vertices());
  state.counters["dofs"] = static_cast<double>(model.dofs().num_free());
}

// (a) ShellModel constructor: ghost layer, DOF map and per-element basis data.
void BM_PlateSetup(benchmark::State& state) {
  const Problem p = make_problem(state);
  for (auto _ : state) {
    ShellModel model(p.mesh, p.material, p.boundary, p.quadrature);
    benchmark::DoNotOptimize(model);
    benchmark::ClobberMemory();
  }
  set_size_counters(state, ShellModel(p.mesh, p.material, p.boundary, p.quadrature));
}

// (b) Sparse stiffness assembly and the consistent uniform load.
void BM_PlateAssembly(benchmark::State& state) {
  const Problem p = make_problem(state);
  const ShellModel model(p.mesh, p.material, p.boundary, p.quadrature);
  for (auto _ : state) {
    Eigen::SparseMatrix<double> k = model.stiffness();
    Eigen::VectorXd f = model.area_load(kLoad);
    benchmark::DoNotOptimize(k.valuePtr());
    benchmark::DoNotOptimize(f.data());
    benchmark::ClobberMemory();
  }
  set_size_counters(state, model);
}

// (c) CHOLMOD analysis + supernodal factorisation + solve (a fresh solver each iteration, as
// solve_static does).
void BM_PlateSolve(benchmark::State& state) {
  const Problem p = make_problem(state);
  const ShellModel model(p.mesh, p.material, p.boundary, p.quadrature);
  const Eigen::SparseMatrix<double> k = model.stiffness();
  const Eigen::VectorXd f = model.area_load(kLoad);
  for (auto _ : state) {
    DirectSolver solver;
    if (!solver.factorize(k)) {
      state.SkipWithError("stiffness matrix not positive definite");
      break;
    }
    Eigen::VectorXd u = solver.solve(f);
    benchmark::DoNotOptimize(u.data());
    benchmark::ClobberMemory();
  }
  set_size_counters(state, model);
  if (state.range(0) == kLargest) {
    // Peak resident set of the whole process so far (Linux reports ru_maxrss in KiB). This is
    // the last benchmark registered, so with the default filter it is the run's overall peak.
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    state.counters["peak_rss_MiB"] = static_cast<double>(usage.ru_maxrss) / 1024.0;
  }
}

void plate_sizes(benchmark::internal::Benchmark* b) {
  b->Arg(32)->Arg(64)->Arg(kLargest)->Unit(benchmark::kMillisecond)->UseRealTime()->Repetitions(5)->ReportAggregatesOnly(true);
}

BENCHMARK(BM_PlateSetup)->Apply(plate_sizes);
BENCHMARK(BM_PlateAssembly)->Apply(plate_sizes);
BENCHMARK(BM_PlateSolve)->Apply(plate_sizes);

}  // namespace
}  // namespace clothsim

BENCHMARK_MAIN();

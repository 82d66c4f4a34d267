// Milliseconds per time step of the paper's timing scene (scenes/sleeve_compress_2542.json:
// 2542 vertices, dt = 0.01 s; paper §5: 2.45 s per step on a 2.2 GHz Athlon 64), split into
// rotation extraction, assembly and solve, for both linear solvers. One benchmark iteration is one
// step; a repetition is the whole scene (100 steps, t = 0 … 1 s: the start, the snap into folds
// and the slow compression after it), and Google Benchmark reports the median over repetitions.
// Averaging over the whole run matters: after the buckling the fold pattern, and with it the
// number of iterations per step, changes with round-off (another build or another process's
// memory layout), while the whole run's average moves little.
#include "sim/dynamics/simulator.hpp"
#include "sim/scene/scene.hpp"

#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <fstream>
#include <iterator>
#include <memory>
#include <string>

namespace clothsim {
namespace {

// 0: PCG with block Jacobi, 1: CHOLMOD every step, 2: PCG preconditioned with a refreshed CHOLMOD
// factor; all without contact. 3: as 2, with self-collision (thickness 1 mm, the drawn surface).
// 4: as 2 with the baseline method linear_fe (flat triangles, hinge bending) on the same mesh;
// 5: as 2 with mass_spring. 6: as 3 with collision.method "constraints" (contact after the solve
// only, the method before 2026-11-28).
std::unique_ptr<Simulator> make_simulator(int variant) {
  const std::string file = std::string(CLOTHSIM_SOURCE_DIR) + "/scenes/sleeve_compress_2542.json";
  Scene scene;
  if (variant == 4 || variant == 5) {  // the scene with "method" set, read as a scene file would be
    std::ifstream in(file);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string method = variant == 4 ? "linear_fe" : "mass_spring";
    text.insert(text.find('{') + 1, "\"method\": \"" + method + "\", ");
    scene = load_scene_text(text, file, nullptr);
  } else {
    scene = load_scene(file, nullptr);
  }
  Problem problem = scene.problem;
  problem.solver.type = variant == 1 ? LinearSolverType::cholmod : LinearSolverType::pcg;
  problem.solver.preconditioner = variant >= 2 ? PreconditionerType::cholesky : PreconditionerType::block_jacobi;
  problem.collision.self = variant == 3 || variant == 6;
  if (problem.collision.self) problem.collision.thickness = 1e-3;
  problem.collision.barrier = variant != 6;
  return std::make_unique<Simulator>(problem);
}

void BM_SleeveCompress2542Step(benchmark::State& state) {
  const int variant = static_cast<int>(state.range(0));
  auto sim = make_simulator(variant);
  double rotate = 0, assemble = 0, solve = 0, iterations = 0, factor = 0, factorizations = 0;
  double contact = 0, broad = 0, narrow = 0, response = 0;
  int steps = 0;
  for (auto _ : state) {
    if (sim->state().t >= 0.995) {  // keep within the scripted compression
      state.PauseTiming();
      sim = make_simulator(variant);
      state.ResumeTiming();
    }
    const StepStats s = sim->step();
    rotate += s.rotate_ms;
    assemble += s.assemble_ms;
    solve += s.solve_ms;
    iterations += s.solver_iterations;
    factor += s.factor_ms;
    factorizations += s.factorizations;
    contact += s.contact.ms;
    broad += s.contact.broad_ms;
    narrow += s.contact.narrow_ms;
    response += s.contact.response_ms;
    ++steps;
  }
  state.counters["rotate_ms"] = rotate / steps;
  state.counters["assemble_ms"] = assemble / steps;
  state.counters["solve_ms"] = solve / steps;
  state.counters["iterations"] = iterations / steps;
  state.counters["factor_ms"] = factor / steps;  // part of solve_ms
  state.counters["factorizations"] = factorizations / steps;
  state.counters["vertices"] = sim->num_vertices();
  if (variant == 3 || variant == 6) {
    state.counters["contact_ms"] = contact / steps;  // of it:
    state.counters["broad_ms"] = broad / steps;
    state.counters["narrow_ms"] = narrow / steps;
    state.counters["response_ms"] = response / steps;
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["peak_rss_MiB"] = static_cast<double>(usage.ru_maxrss) / 1024.0;
  state.SetLabel(variant == 0   ? "pcg, block Jacobi"
                 : variant == 1 ? "cholmod"
                 : variant == 2 ? "pcg, cholesky preconditioner"
                 : variant == 3 ? "pcg, cholesky preconditioner, self-collision"
                 : variant == 4 ? "linear_fe, pcg, cholesky preconditioner"
                 : variant == 5 ? "mass_spring, pcg, cholesky preconditioner"
                                : "pcg, cholesky preconditioner, self-collision, method constraints");
}
BENCHMARK(BM_SleeveCompress2542Step)
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Arg(3)
    ->Arg(4)
    ->Arg(5)
    ->Arg(6)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(100)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace clothsim

BENCHMARK_MAIN();

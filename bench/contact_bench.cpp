// Contact-heavy scenes, milliseconds per step of contact against the rest of the step (rotation,
// assembly and the linear solves), for both contact methods (collision.method "barrier", the
// default, and "constraints", the method before 2026-11-28): issue 28's ratio, one command away.
// One benchmark iteration is one step; a repetition is the scene's first `steps` steps from its
// start (each repetition a fresh Simulator), and Google Benchmark reports medians over
// repetitions. Counters per step: contact_ms (the barrier's evaluations and the fail-safe),
// rest_ms (rotate + assemble + solve, the barrier's extra Newton solves included), ratio
// (contact_ms / rest_ms), newton (linear solves with the barrier), impulses (fail-safe),
// step_ms (the whole step).
//
// BM_CrushedSleeve/self and /no_self: issue 28's second ratio, the sleeve of sleeve_compress
// crushed by 60 % of its length (0.12 m in 1.2 s) with and without self-collision, whole runs of
// 1,200 steps (without self-collision it passes through itself); divide the step_ms medians.
#include "sim/dynamics/simulator.hpp"
#include "sim/scene/scene.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

namespace clothsim {
namespace {

struct Case {
  const char* scene;
  int steps;  // from the start: through the landing or the first contact into resting contact
  std::vector<std::string> overrides = {};  // --set arguments
};
const std::vector<Case> kCases = {{"cusick_drape", 100}, {"sleeve_on_arm", 100}, {"sheet_on_sphere", 250}, {"sheet_fall", 150}};

std::unique_ptr<Simulator> make_simulator(const Case& c, bool barrier) {
  const Scene scene = load_scene(std::string(CLOTHSIM_SOURCE_DIR) + "/scenes/" + c.scene + ".json", nullptr, c.overrides);
  Problem problem = scene.problem;
  if (problem.has_contact()) problem.collision.barrier = barrier;
  return std::make_unique<Simulator>(problem);
}

void contact_scene(benchmark::State& state, const Case& c, bool barrier) {
  std::unique_ptr<Simulator> sim;
  double contact = 0, rest = 0, newton = 0, impulses = 0, whole = 0;
  int steps = 0;
  for (auto _ : state) {
    if (!sim) {  // each repetition is one fresh run of c.steps steps (the iterations)
      state.PauseTiming();
      sim = make_simulator(c, barrier);
      state.ResumeTiming();
    }
    const auto t0 = std::chrono::steady_clock::now();
    const StepStats s = sim->step();
    whole += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    contact += s.contact.ms;
    rest += s.rotate_ms + s.assemble_ms + s.solve_ms;
    newton += static_cast<double>(s.contact.newton_iterations);
    impulses += static_cast<double>(s.contact.impulses);
    ++steps;
  }
  state.counters["contact_ms"] = contact / steps;
  state.counters["rest_ms"] = rest / steps;
  state.counters["ratio"] = contact / rest;
  state.counters["newton"] = newton / steps;
  state.counters["impulses"] = impulses / steps;
  state.counters["step_ms"] = whole / steps;
}

}  // namespace
}  // namespace clothsim

int main(int argc, char** argv) {
  using clothsim::kCases;
  for (const clothsim::Case& c : kCases)
    for (const bool barrier : {true, false})
      benchmark::RegisterBenchmark((std::string("BM_ContactScene/") + c.scene + (barrier ? "/barrier" : "/constraints")).c_str(),
                                   [c, barrier](benchmark::State& state) { clothsim::contact_scene(state, c, barrier); })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime()
          ->Iterations(c.steps)
          ->Repetitions(3)
          ->ReportAggregatesOnly(true);
  const std::vector<std::string> crush = {"boundary[1].motion[0].displacement=[0,-0.12,0]", "time.end=1.2"};
  for (const bool self : {true, false}) {
    std::vector<std::string> set = crush;
    set.push_back(std::string("collision.self=") + (self ? "true" : "false"));
    const clothsim::Case c{"sleeve_compress", 1200, set};
    benchmark::RegisterBenchmark((std::string("BM_CrushedSleeve/") + (self ? "self" : "no_self")).c_str(),
                                 [c](benchmark::State& state) { clothsim::contact_scene(state, c, true); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(c.steps)
        ->Repetitions(3)
        ->ReportAggregatesOnly(true);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

// Writes the implicit-Euler systems of the compressed sleeve (scenes/sleeve_compress_2542.json) at
// any mesh size, for studying preconditioners apart from the simulator (bench/multilevel_bench.cpp,
// docs/performance.md "Multilevel preconditioners").
//
//   sleeve_systems --segments 124 --rings 81 --steps 25 --dump 20,21,23,25 --out DIR
//                  [--scene FILE] [--set key=value ...] [--mtx]
//
// Runs the scene (contact off, as dynamics_bench does; --set overrides applied after
// mesh.segments/mesh.rings) with its own solver settings and writes, for every step in --dump,
// DIR/step_NNNN.sys (bench/system_io.hpp: A, b, PCG's start, the solution, positions, free mask;
// with --mtx also Matrix Market copies). The run is unchanged by the recording: the matrix is read
// through a force term that adds nothing (its add_matrix() sees the integrator's system matrix,
// which keeps its values after the solve), the force through the same term's add_force().
// Prints one line per step (iterations, factorisations, solve time, residual check).
#include "bench/system_io.hpp"
#include "sim/dynamics/simulator.hpp"
#include "sim/core/force_term.hpp"
#include "sim/scene/scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace clothsim {
namespace {

// Adds nothing; remembers the system matrix it is handed and the force summed before it.
class SystemRecorder final : public ForceTerm {
 public:
  std::string name() const override { return "system recorder"; }
  void update(const Eigen::VectorXd&, const Eigen::VectorXd&, double) override {}
  void add_force(Eigen::VectorXd& f) const override { force_ = f; }
  bool has_matrix() const override { return true; }
  void add_matrix(const MatrixWeights&, Eigen::SparseMatrix<double>& a) const override { matrix_ = &a; }
  const Eigen::SparseMatrix<double>* matrix() const { return matrix_; }
  const Eigen::VectorXd& force() const { return force_; }

 private:
  mutable const Eigen::SparseMatrix<double>* matrix_ = nullptr;
  mutable Eigen::VectorXd force_;
};

int run(int argc, char** argv) {
  std::string scene_file = std::string(CLOTHSIM_SOURCE_DIR) + "/scenes/sleeve_compress_2542.json";
  int segments = 62, rings = 41, steps = 25;
  std::set<int> dump;
  std::string out_dir = "systems";
  std::vector<std::string> overrides;
  bool mtx = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(arg + " needs a value");
      return argv[++i];
    };
    if (arg == "--segments") segments = std::stoi(value());
    else if (arg == "--rings") rings = std::stoi(value());
    else if (arg == "--steps") steps = std::stoi(value());
    else if (arg == "--dump") for (int s : bench::parse_list(value())) dump.insert(s);
    else if (arg == "--out") out_dir = value();
    else if (arg == "--scene") scene_file = value();
    else if (arg == "--set") overrides.push_back(value());
    else if (arg == "--mtx") mtx = true;
    else {
      std::cerr << "usage: sleeve_systems [--segments S] [--rings R] [--steps N] [--dump a,b,...] [--out DIR]\n"
                   "                      [--scene FILE] [--set key=value]... [--mtx]\n";
      return 2;
    }
  }
  std::vector<std::string> all = {"mesh.segments=" + std::to_string(segments), "mesh.rings=" + std::to_string(rings),
                                   "collision.self=false", "mesh.max_vertices=10000000"};
  all.insert(all.end(), overrides.begin(), overrides.end());
  const Scene scene = load_scene(scene_file, nullptr, all);
  Simulator sim(scene.problem);
  auto recorder_owner = std::make_unique<SystemRecorder>();
  const SystemRecorder* recorder = recorder_owner.get();
  sim.add_term(std::move(recorder_owner));
  std::filesystem::create_directories(out_dir);
  const double dt = scene.problem.time.dt;
  const int n3 = 3 * sim.num_vertices();
  Eigen::VectorXd mass(n3);
  for (int v = 0; v < sim.num_vertices(); ++v) mass.segment<3>(3 * v).setConstant(sim.vertex_mass()(v));
  std::vector<char> free(static_cast<std::size_t>(n3));
  int constrained = 0, dependent = 0;
  for (int d = 0; d < n3; ++d) {
    const DofStatus st = sim.discretization().status(d);
    free[static_cast<std::size_t>(d)] = st == DofStatus::free;
    constrained += st != DofStatus::free;
    dependent += st == DofStatus::dependent;
  }
  std::printf("sleeve %d x %d: %d vertices, %d unknowns (%d constrained, %d dependent), dt %g\n", segments, rings,
              sim.num_vertices(), n3 - constrained, constrained, dependent, dt);
  Eigen::VectorXd v_previous;
  double total_ms = 0.0;
  for (int k = 1; k <= steps; ++k) {
    const DynamicState before = sim.state();
    const auto t0 = std::chrono::steady_clock::now();
    const StepStats stats = sim.step();
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    total_ms += ms;
    const DynamicState& after = sim.state();
    std::printf("step %3d: %4d iterations, %d factorisations (%.0f ms), solve %.0f ms, step %.0f ms", k,
                stats.solver_iterations, stats.factorizations, stats.factor_ms, stats.solve_ms, ms);
    if (dump.count(k)) {
      bench::StepSystem s;
      s.segments = segments;
      s.rings = rings;
      s.step = k;
      s.dt = dt;
      s.t = before.t;
      s.a = *recorder->matrix();
      s.b = mass.cwiseProduct(before.v) + dt * recorder->force();
      s.solution = after.v;
      s.positions = before.x;
      s.free = free;
      // The integrator's start (ImplicitEuler::step): v + (v − v_prev) on the free entries (v in
      // the first step), the prescribed velocities elsewhere (kept by the solve), 0 for dependent.
      s.start = after.v;
      for (int d = 0; d < n3; ++d) {
        const DofStatus st = sim.discretization().status(d);
        if (st == DofStatus::free)
          s.start(d) = v_previous.size() == n3 ? 2.0 * before.v(d) - v_previous(d) : before.v(d);
        else if (st == DofStatus::dependent)
          s.start(d) = 0.0;
      }
      // The recorded system must be the one solved: A x − b small on the free rows.
      const Eigen::VectorXd r = s.a * s.solution - s.b;
      double rn = 0.0, bn = 0.0;
      for (int d = 0; d < n3; ++d)
        if (free[static_cast<std::size_t>(d)]) rn += r(d) * r(d), bn += s.b(d) * s.b(d);
      char name[64];
      std::snprintf(name, sizeof name, "step_%04d", k);
      const std::string path = out_dir + "/" + name + ".sys";
      bench::write_system(path, s);
      if (mtx) bench::write_matrix_market(out_dir + "/" + name, s);
      std::printf(", written %s (check: |Ax-b|/|b| = %.2e)", path.c_str(), std::sqrt(rn / std::max(bn, 1e-300)));
    }
    std::printf("\n");
    std::fflush(stdout);
    v_previous = before.v;
  }
  std::printf("%.1f ms per step on average (%d steps)\n", total_ms / steps, steps);
  return 0;
}

}  // namespace
}  // namespace clothsim

int main(int argc, char** argv) {
  try {
    return clothsim::run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "sleeve_systems: " << e.what() << "\n";
    return 1;
  }
}

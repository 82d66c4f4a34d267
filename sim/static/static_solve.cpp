#include "sim/static/static_solve.hpp"

#include "sim/problem/validate.hpp"
#include "sim/setup/setup.hpp"
#include "sim/solver/direct_solver.hpp"

#include <chrono>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

StaticResult solve_static(const Problem& problem) {
  check_problem(problem, Analysis::statics);
  const auto t0 = std::chrono::steady_clock::now();
  const std::shared_ptr<Discretization> d = make_discretization(problem);
  if (const std::vector<std::string> free_motions = d->unrestrained_rigid_motions(); !free_motions.empty()) {
    std::string list;
    for (const std::string& m : free_motions) list += (list.empty() ? "" : "; ") + m;
    throw std::runtime_error("the boundary conditions leave " + std::to_string(free_motions.size()) +
                             " rigid motion(s) free, so the structure can move without deforming (" + list +
                             "): fix more displacement components");
  }
  const int n3 = 3 * d->num_nodes();
  const Eigen::VectorXd& rest = d->rest();
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n3);

  // K: the linear element's matrix at rest.
  const std::unique_ptr<ForceTerm> elastic = d->elastic_term(/*corotational=*/false, /*tension_stiffening=*/false);
  elastic->update(rest, zero, 0.0);
  Eigen::SparseMatrix<double> k = d->matrix_pattern();
  elastic->add_matrix({1.0, 0.0}, k);

  // f: the loads at the rest state.
  const std::unique_ptr<ExternalLoads> loads = make_external_loads(*d, problem, GravityModel::consistent, /*ramp_time=*/0.0);
  loads->update(rest, zero, 0.0);
  Eigen::VectorXd f = zero;
  loads->add_force(f);

  // The free DOFs alone: the others become unit rows and columns with zero load.
  std::vector<char> free(static_cast<size_t>(n3), 1);
  int dofs = 0;
  for (int i = 0; i < n3; ++i) {
    free[static_cast<size_t>(i)] = d->status(i) == DofStatus::free;
    dofs += free[static_cast<size_t>(i)];
    if (!free[static_cast<size_t>(i)]) f(i) = 0.0;
  }
  set_dirichlet_identity(k, free);
  StaticResult result;
  result.assemble_seconds = seconds_since(t0);
  result.dofs = dofs;

  const auto t1 = std::chrono::steady_clock::now();
  DirectSolver solver;
  if (!solver.factorize(k))
    throw std::runtime_error("the stiffness matrix is singular or not positive definite: the structure can move "
                             "without deforming (add boundary conditions that hold all rigid motions)");
  Eigen::VectorXd u = solver.solve(f);
  result.solve_seconds = seconds_since(t1);
  if (!u.allFinite()) throw std::runtime_error("the solution is not finite");
  d->make_consistent(u);  // tied components take their values from the rule

  std::vector<int> all(static_cast<size_t>(d->num_nodes()));
  for (int v = 0; v < d->num_nodes(); ++v) all[static_cast<size_t>(v)] = v;
  const SurfaceOperator points = d->node_points(all);
  result.limit_rest = d->surface_positions(points, rest);
  result.limit_displacement = d->surface_positions(points, rest + u) - result.limit_rest;
  result.displacement = std::move(u);
  result.discretization = std::move(d);
  return result;
}

}  // namespace clothsim

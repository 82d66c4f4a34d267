#include "sim/setup/setup.hpp"

#include "sim/flat_fe/flat_fe.hpp"
#include "sim/flat_fe/mass_spring.hpp"
#include "sim/forces/follower_couples.hpp"
#include "sim/forces/point_loads.hpp"
#include "sim/forces/surface_load.hpp"
#include "sim/loop_shell/loop_shell.hpp"

#include <stdexcept>

namespace clothsim {

namespace {

[[noreturn]] void unknown_method(const std::string& method) {
  std::string known;
  for (const std::string& m : discretization_methods()) known += (known.empty() ? "" : ", ") + m;
  throw std::invalid_argument("unknown discretisation method \"" + method + "\" (known: " + known + ")");
}

}  // namespace

std::vector<std::string> discretization_methods() { return {"loop_kl", "linear_fe", "mass_spring"}; }

TriMesh prepare_mesh(const std::string& method, const TriMesh& mesh, const LogFn& log) {
  if (method == "loop_kl") return LoopShellDiscretization::prepare_mesh(mesh, log);
  if (method == "linear_fe") return LinearFeDiscretization::prepare_mesh(mesh, log);
  if (method == "mass_spring") return MassSpringDiscretization::prepare_mesh(mesh, log);
  unknown_method(method);
}

std::shared_ptr<Discretization> make_discretization(const Problem& problem) {
  if (problem.method == "loop_kl")
    return std::make_shared<LoopShellDiscretization>(problem.mesh, problem.boundary, problem.material, problem.quadrature,
                                                     problem.rest);
  if (problem.method == "linear_fe")
    return std::make_shared<LinearFeDiscretization>(problem.mesh, problem.boundary, problem.material);
  if (problem.method == "mass_spring")
    return std::make_shared<MassSpringDiscretization>(problem.mesh, problem.boundary, problem.material);
  unknown_method(problem.method);
}

std::unique_ptr<ExternalLoads> make_external_loads(const Discretization& d, const Problem& problem, GravityModel gravity,
                                                   double ramp_time) {
  std::vector<std::unique_ptr<ForceTerm>> constant, varying;
  if ((problem.material.areal_density * problem.gravity).squaredNorm() > 0)
    constant.push_back(make_gravity(d, problem.material.areal_density, problem.gravity, gravity));
  if (problem.surface_load.squaredNorm() > 0) constant.push_back(make_surface_load(d, problem.surface_load));
  if (problem.pressure != 0.0) constant.push_back(make_pressure(d, problem.pressure));
  if (!problem.point_loads.empty()) constant.push_back(make_point_loads(d, problem.point_loads));
  if (!problem.moments.empty()) varying.push_back(std::make_unique<FollowerCouples>(problem.moments));
  return std::make_unique<ExternalLoads>(std::move(constant), std::move(varying), ramp_time, 3 * d.num_nodes());
}

}  // namespace clothsim

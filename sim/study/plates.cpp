#include "sim/study/plates.hpp"

#include "sim/mesh/generators.hpp"
#include "sim/scene/scene.hpp"

#include <cmath>

namespace clothsim {

int nearest_vertex(const TriMesh& mesh, const Eigen::Vector3d& point) { return nearest_vertex(mesh.vertices, point); }

Problem square_plate(int divisions, bool clamped, Quadrature rule, double side) {
  Problem p;
  p.mesh = make_grid(side, side, divisions, divisions);
  p.material = ShellMaterial::from_solid(1e7, 0.3, 0.01, 1000);
  const double h = side / 2 - 1e-9 * side;
  BoundaryCondition bc;
  bc.vertices = select_vertices(p.mesh, [&](const auto& x) { return std::abs(x(0)) >= h || std::abs(x(1)) >= h; });
  bc.clamped = clamped;
  p.boundary = {bc};
  p.quadrature = rule;
  return p;
}

double plate_rigidity(const Problem& problem) {
  const double nu = problem.material.poisson_ratio;
  return problem.material.bending_rigidity / (1 - nu * nu);
}

Problem plate_problem(const AnalyticPlate& plate, int divisions, Quadrature rule, double side) {
  Problem p = square_plate(divisions, plate.clamped, rule, side);
  if (plate.point_load)
    p.point_loads.push_back({nearest_vertex(p.mesh, Eigen::Vector3d::Zero()), Eigen::Vector3d(0, 0, -kPlateForce)});
  else
    p.surface_load = Eigen::Vector3d(0, 0, -kPlatePressure);
  return p;
}

double plate_reference_deflection(const AnalyticPlate& plate, const Problem& problem, double side) {
  const double d = plate_rigidity(problem);
  return plate.point_load ? plate.coefficient * kPlateForce * side * side / d
                          : plate.coefficient * kPlatePressure * std::pow(side, 4) / d;
}

}  // namespace clothsim

// Orthotropic test fixtures shared by the Loop element's and linear_fe's tests: the woven
// law, a uniform warp on every triangle, and a strip pulled along x whose axial strain is compared with the orthotropic
// membrane formula (docs/materials.md).
#pragma once

#include "sim/mesh/generators.hpp"
#include "sim/problem/problem.hpp"
#include "sim/shell/material.hpp"
#include "sim/static/static_solve.hpp"
#include "sim/study/plates.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace clothsim::testing {

// The woven example (stiff along the yarns, soft in shear), its bending rigidities
// scaled by `bending_scale`.
inline Orthotropy woven_example(double bending_scale = 1.0) {
  Orthotropy o;
  o.warp_stretch = 5000;
  o.weft_stretch = 3000;
  o.shear_stretch = 60;
  o.poisson = 0.25;
  o.warp_bending = 1.2e-5 * bending_scale;
  o.weft_bending = 0.9e-5 * bending_scale;
  o.twist = 0.5e-5 * bending_scale;
  return o;
}

// Every triangle's rest warp direction set to `dir`.
inline void set_warp(TriMesh& mesh, const Eigen::Vector3d& dir) { mesh.warp.assign(mesh.triangles.size(), dir); }

// A flat strip [−L/2, L/2] × [−W/2, W/2] (40 × 8 cells) of `material` with its warp at `angle`
// [rad] from +x, its left end on rollers (x held, one point also in y, all of it in z), pulled
// along x by `force` [N] spread evenly over the right end: the axial strain of the limit surface
// between x = −L/4 and x = L/4, solved with `method`.
inline double pulled_strip_strain(const std::string& method, const ShellMaterial& material, double angle, double force,
                                  double length, double width) {
  Problem p;
  if (!method.empty()) p.method = method;
  p.mesh = make_grid(length, width, 40, 8);
  set_warp(p.mesh, Eigen::Vector3d(std::cos(angle), std::sin(angle), 0));
  p.material = material;
  BoundaryCondition roller, pin, flat;
  roller.vertices = select_vertices(p.mesh, [&](const auto& x) { return x(0) < -length / 2 + 1e-9; });
  roller.fix = {true, false, false};
  pin.vertices = {nearest_vertex(p.mesh, Eigen::Vector3d(-length / 2, 0, 0))};
  pin.fix = {false, true, false};
  flat.vertices = select_vertices(p.mesh, [](const auto&) { return true; });
  flat.fix = {false, false, true};
  p.boundary = {roller, pin, flat};
  const std::vector<int> tip = select_vertices(p.mesh, [&](const auto& x) { return x(0) > length / 2 - 1e-9; });
  for (size_t i = 0; i < tip.size(); ++i) {
    const double share = (i == 0 || i + 1 == tip.size()) ? 0.5 : 1.0;
    p.point_loads.push_back({tip[i], Eigen::Vector3d(share * force / static_cast<double>(tip.size() - 1), 0, 0)});
  }
  const StaticResult r = solve_static(p);
  const int a = nearest_vertex(p.mesh, Eigen::Vector3d(-length / 4, 0, 0));
  const int b = nearest_vertex(p.mesh, Eigen::Vector3d(length / 4, 0, 0));
  return (r.limit_displacement(b, 0) - r.limit_displacement(a, 0)) / (r.limit_rest(b, 0) - r.limit_rest(a, 0));
}

}  // namespace clothsim::testing

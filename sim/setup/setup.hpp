// From a Problem to what an analysis runs: the discretisation the problem names, and the
// problem's external loads as force terms on it. The static (sim/static) and dynamic
// (sim/dynamics) analyses both build through here, so a new discretisation is registered in one
// place (setup.cpp: prepare_mesh and make_discretization) and a load in one place
// (make_external_loads).
#pragma once

#include "sim/core/log.hpp"
#include "sim/discretization/discretization.hpp"
#include "sim/forces/external_loads.hpp"
#include "sim/forces/gravity.hpp"
#include "sim/mesh/mesh.hpp"
#include "sim/problem/problem.hpp"

#include <memory>
#include <string>
#include <vector>

namespace clothsim {

// The discretisation methods a problem can name (Problem::method): "loop_kl" (the Loop-subdivision
// Kirchhoff–Love shell, sim/loop_shell/), "linear_fe" (flat corotated membrane triangles with
// hinge bending, the baseline: sim/flat_fe/flat_fe.hpp) and "mass_spring" (edge and bending springs
// on the same flat triangles: sim/flat_fe/mass_spring.hpp).
std::vector<std::string> discretization_methods();

// The mesh `method` needs, made from `mesh` (for "loop_kl": refined once by Loop subdivision when
// a triangle has two irregular vertices; for "linear_fe" and "mass_spring": the mesh itself,
// checked); logs what it did. Boundary selections and probes refer to the prepared mesh's
// vertices. Throws std::invalid_argument for an unknown method and MeshError for an invalid mesh
// (naming the element).
TriMesh prepare_mesh(const std::string& method, const TriMesh& mesh, const LogFn& log);

// The discretisation of the problem's (prepared) mesh, boundary conditions, material and
// quadrature with the problem's method. Throws std::invalid_argument for an unknown method and
// std::runtime_error naming what the discretisation cannot take.
std::shared_ptr<Discretization> make_discretization(const Problem& problem);

// The problem's external loads on `d` as one term: gravity in the given model, surface load,
// pressure, point loads (constant), follower couples (state-dependent), ramped over `ramp_time`
// [s] (0: full loads from the start).
std::unique_ptr<ExternalLoads> make_external_loads(const Discretization& d, const Problem& problem, GravityModel gravity,
                                                   double ramp_time);

}  // namespace clothsim

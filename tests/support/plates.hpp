// Square and strip plates with analytic solutions (docs/formulas.md §9, Analytic references),
// built through the public static-analysis API. The definitions live in sim/study/plates.hpp (shared with the convergence
// study and bench/plate_convergence); this header keeps the tests' clothsim::testing names.
#pragma once

#include "sim/mesh/generators.hpp"
#include "sim/study/plates.hpp"

namespace clothsim::testing {

using clothsim::nearest_vertex;
using clothsim::plate_rigidity;
using clothsim::select_vertices;
using clothsim::square_plate;

}  // namespace clothsim::testing

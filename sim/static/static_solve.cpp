// TEMPORARY development placeholder; replaced by the real implementation before landing.
#include "sim/static/static_solve.hpp"
#include <stdexcept>
namespace clothsim {
StaticResult solve_static(const StaticProblem&) { throw std::runtime_error("solve_static: not implemented yet"); }
TriMesh prepare_control_mesh(const TriMesh& mesh, const LogFn&) { return mesh; }
}  // namespace clothsim

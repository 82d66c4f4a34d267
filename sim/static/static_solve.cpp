#include "sim/static/static_solve.hpp"

#include "sim/mesh/topology.hpp"
#include "sim/shell/shell_model.hpp"
#include "sim/solver/direct_solver.hpp"
#include "sim/subdivision/loop.hpp"

#include <chrono>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

TriMesh prepare_control_mesh(const TriMesh& mesh, const LogFn& log) {
  check_triangles(mesh);
  auto count_bad = [](const TriMesh& m) {
    const ExtendedMesh ext = build_ghost_layer(m);
    int bad = 0;
    for (const Triangle& t : m.triangles)
      if (irregular_vertex_count(ext, t) > 1) ++bad;
    return bad;
  };
  const int bad = count_bad(mesh);
  if (bad == 0) return mesh;
  TriMesh refined = loop_subdivide(mesh);
  if (log)
    log("mesh: " + std::to_string(bad) + " triangle(s) have more than one irregular vertex; refined once by Loop "
        "subdivision: " + std::to_string(mesh.num_vertices()) + " -> " + std::to_string(refined.num_vertices()) +
        " vertices, " + std::to_string(mesh.num_triangles()) + " -> " + std::to_string(refined.num_triangles()) +
        " triangles");
  if (const int still = count_bad(refined); still > 0)
    throw MeshError(std::to_string(still) + " triangle(s) still have more than one irregular vertex after refinement");
  return refined;
}

StaticResult solve_static(const StaticProblem& problem) {
  if (const std::string bad = validate(problem.material); !bad.empty()) throw std::runtime_error("material: " + bad);
  const int n = problem.mesh.num_vertices();
  for (const PointLoad& p : problem.point_loads)
    if (p.vertex < 0 || p.vertex >= n) throw std::runtime_error("point load at vertex " + std::to_string(p.vertex) + ": no such vertex");

  const auto t0 = std::chrono::steady_clock::now();
  const ShellModel model(problem.mesh, problem.material, problem.boundary, problem.quadrature);
  if (const std::vector<std::string> free_motions = model.unrestrained_rigid_motions(); !free_motions.empty()) {
    std::string list;
    for (const std::string& m : free_motions) list += (list.empty() ? "" : "; ") + m;
    throw std::runtime_error("the boundary conditions leave " + std::to_string(free_motions.size()) +
                             " rigid motion(s) free, so the structure can move without deforming (" + list +
                             "): fix more displacement components");
  }
  Eigen::SparseMatrix<double> k = model.stiffness();
  model.restrict_to_free(k);
  Eigen::VectorXd f = model.area_load(problem.surface_load + problem.material.areal_density * problem.gravity);
  if (problem.pressure != 0.0) f += model.pressure_load(problem.pressure);
  for (const PointLoad& p : problem.point_loads) f += model.point_load(p.vertex, p.force);
  for (size_t i = 0; i < problem.moments.size(); ++i)
    if (!add_moment_forces(problem.moments[i], problem.mesh.vertices, f))
      throw std::runtime_error("moment " + std::to_string(i) + ": its vertices lie on a line parallel to the moment");
  model.restrict_to_free(f);
  StaticResult result;
  result.assemble_seconds = seconds_since(t0);
  result.dofs = model.dofs().num_free();

  const auto t1 = std::chrono::steady_clock::now();
  DirectSolver solver;
  if (!solver.factorize(k))
    throw std::runtime_error("the stiffness matrix is singular or not positive definite: the structure can move "
                             "without deforming (add boundary conditions that hold all rigid motions)");
  const Eigen::VectorXd u = solver.solve(f);
  result.solve_seconds = seconds_since(t1);
  if (!u.allFinite()) throw std::runtime_error("the solution is not finite");

  result.displacement = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(u.data(), n, 3);
  const Eigen::MatrixX3d ext_u = model.dofs().expand(result.displacement);
  result.displacement = ext_u.topRows(n);  // tied components take their values from the rule
  result.limit_rest = model.limit_points(model.extended().rest);
  result.limit_displacement = model.limit_points(ext_u);
  result.extended_displacement = ext_u;
  return result;
}

}  // namespace clothsim

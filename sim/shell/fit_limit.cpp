// Fitting a control mesh to its limit surface: the limit-point operator L (limit masks over the
// ghost-layer extended one-rings, ghosts folded by the DOF map) and the sparse LU solve of
// L P = X with iterative refinement (fit_limit.hpp, docs/fit_limit.md).
#include "sim/shell/fit_limit.hpp"

#include "sim/shell/dof_map.hpp"
#include "sim/subdivision/loop.hpp"

#include <Eigen/OrderingMethods>
// Eigen's SparseLU grows its work arrays by a float factor (SparseLU_Memory.h), which -Wconversion
// reports when Eigen is not included as a system header.
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#endif
#include <Eigen/SparseLU>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {

namespace {

constexpr double kTolerance = 1e-12;  // max limit-point error / bounding-box diagonal
constexpr int kMaxSolves = 6;         // 1 solve + up to 5 iterative-refinement steps

// A triangle with more than one irregular vertex makes the shell refine the mesh once by Loop
// subdivision on load (LoopShellDiscretization::prepare_mesh). On a closed mesh that keeps the
// limit surface, so the fit stays exact; at borders the refinement's crease rule differs from
// the ghost layer and the limit points would move: throws MeshError naming the first such
// triangle (and how many there are).
void check_refinement_keeps_limit(const TriMesh& mesh, const ExtendedMesh& ext) {
  if (ext.ghosts.empty()) return;  // closed
  int bad = 0, first = -1;
  for (int t = 0; t < mesh.num_triangles(); ++t)
    if (irregular_vertex_count(ext, mesh.triangles[static_cast<size_t>(t)]) > 1) {
      if (first < 0) first = t;
      ++bad;
    }
  if (bad == 0) return;
  const Triangle& tri = mesh.triangles[static_cast<size_t>(first)];
  std::ostringstream s;
  s << "fit_limit: triangle " << first << " (" << tri[0] << ", " << tri[1] << ", " << tri[2]
    << ") has more than one irregular vertex (valences " << ext.topology.valence(tri[0]) << ", "
    << ext.topology.valence(tri[1]) << ", " << ext.topology.valence(tri[2])
    << ", border vertices counting 3 more for the ghost layer)";
  if (bad > 1) s << ", and so do " << bad - 1 << " other triangle(s)";
  s << "; the shell refines such a mesh once by Loop subdivision (LoopShellDiscretization::prepare_mesh), "
       "whose border rule differs from the ghost layer, so on a mesh with borders the fitted limit points "
       "would move: refine the mesh first (prepare_mesh) and fit the refined mesh";
  throw MeshError(s.str());
}

void check_finite(const TriMesh& mesh) {
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (!mesh.vertices.row(v).allFinite())
      throw MeshError("fit_limit: vertex " + std::to_string(v) + " has a non-finite position");
}

// Max row norm of r divided by `scale`.
double max_row_norm(const Eigen::MatrixX3d& r, double scale) {
  return r.rows() == 0 ? 0.0 : r.rowwise().norm().maxCoeff() / scale;
}

}  // namespace

Eigen::SparseMatrix<double> limit_point_operator(const ExtendedMesh& ext) {
  // Ghost positions follow the real ones through the DOF map without boundary conditions (the
  // free-edge rule, the same in every component: checked here, since L is one scalar matrix).
  const DofMap dofs(ext, {});
  std::vector<Eigen::Triplet<double>> entries;
  auto add = [&](int row, int vertex, double weight) {
    if (vertex < ext.num_real) {
      entries.emplace_back(row, vertex, weight);
      return;
    }
    const Combination& x = dofs.combination(vertex, 0);
    for (int c = 1; c < 3; ++c) {
      const Combination& other = dofs.combination(vertex, c);
      bool same = other.size() == x.size();
      for (size_t i = 0; same && i < x.size(); ++i)
        same = other[i].first == x[i].first + c && other[i].second == x[i].second;
      if (!same)
        throw std::logic_error("limit_point_operator: ghost vertex " + std::to_string(vertex) +
                               " does not follow the same rule in every component");
    }
    for (const auto& [dof, w] : x) {
      if (dof % 3 != 0)
        throw std::logic_error("limit_point_operator: ghost vertex " + std::to_string(vertex) +
                               " mixes components");
      entries.emplace_back(row, dof / 3, weight * w);
    }
  };
  for (int v = 0; v < ext.num_real; ++v) {
    const std::vector<int>& ring = ext.topology.ring(v);
    const int valence = static_cast<int>(ring.size());
    const double w = limit_neighbour_weight(valence);
    add(v, v, 1.0 - valence * w);
    for (int r : ring) add(v, r, w);
  }
  Eigen::SparseMatrix<double> l(ext.num_real, ext.num_real);
  l.setFromTriplets(entries.begin(), entries.end());  // sums the folded duplicates
  l.makeCompressed();
  return l;
}

LimitFit fit_limit(const TriMesh& mesh) {
  if (mesh.num_vertices() == 0 || mesh.triangles.empty()) throw MeshError("fit_limit: the mesh is empty");
  check_finite(mesh);
  check_triangles(mesh);                                // repeated or out-of-range indices, zero area
  const ExtendedMesh ext = build_ghost_layer(mesh);     // non-manifold, orientation, valence > 12
  check_refinement_keeps_limit(mesh, ext);

  // Solve in centred, unit-size coordinates: rows of L sum to 1, so L (P − c)/d = (X − c)/d, and
  // the residual is then directly relative to the mesh's size whatever its position and scale.
  const Eigen::RowVector3d centre = mesh.vertices.colwise().mean();
  const double size =
      (mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff()).norm();  // > 0: check_triangles
  const Eigen::MatrixX3d target = (mesh.vertices.rowwise() - centre) / size;

  const Eigen::SparseMatrix<double> l = limit_point_operator(ext);
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu;
  lu.compute(l);
  if (lu.info() != Eigen::Success)
    throw std::runtime_error("fit_limit: the limit-point operator of this mesh (" +
                             std::to_string(mesh.num_vertices()) + " vertices) is singular (" + lu.lastErrorMessage() +
                             "); no control mesh on this connectivity has these limit points");

  Eigen::MatrixX3d p = Eigen::MatrixX3d::Zero(target.rows(), 3);
  Eigen::MatrixX3d r = target;
  LimitFit fit;
  fit.residual = max_row_norm(r, 1.0);
  while (fit.residual > kTolerance && fit.iterations < kMaxSolves) {
    const Eigen::MatrixX3d dp = lu.solve(r);
    if (!dp.allFinite())
      throw std::runtime_error("fit_limit: the LU solve of the limit-point system gave non-finite positions "
                               "(the operator is numerically singular)");
    p += dp;
    r = target - l * p;
    fit.residual = max_row_norm(r, 1.0);
    ++fit.iterations;
  }
  if (!(fit.residual <= kTolerance)) {
    std::ostringstream s;
    s << "fit_limit: the limit points of the fitted mesh miss the vertices by " << fit.residual
      << " of the mesh's size after " << fit.iterations << " solve(s), more than the tolerance " << kTolerance
      << " (the limit-point operator is ill-conditioned for this mesh)";
    throw std::runtime_error(s.str());
  }
  fit.control = mesh;
  fit.control.vertices = (size * p).rowwise() + centre;
  return fit;
}

}  // namespace clothsim

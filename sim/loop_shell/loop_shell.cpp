#include "sim/loop_shell/loop_shell.hpp"

#include "sim/core/layout.hpp"
#include "sim/discretization/flat_refinement.hpp"
#include "sim/forces/corotated_shell.hpp"
#include "sim/shell/ghost_layer.hpp"
#include "sim/subdivision/limit_refinement.hpp"
#include "sim/subdivision/loop.hpp"
#include "sim/subdivision/patch.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace clothsim {

TriMesh LoopShellDiscretization::prepare_mesh(const TriMesh& mesh, const LogFn& log) {
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

LoopShellDiscretization::LoopShellDiscretization(const TriMesh& mesh, const std::vector<BoundaryCondition>& boundary,
                                                 const ShellMaterial& material, Quadrature quadrature, RestShape rest)
    : mesh_(mesh), model_(mesh, material, boundary, quadrature, rest), rest_(to_flat(mesh.vertices)) {
  for (int dof = 0; dof < 3 * mesh.num_vertices(); ++dof)
    if (status(dof) == DofStatus::dependent) dependent_.push_back(dof);
  const ExtendedMesh& ext = model_.extended();
  std::vector<Eigen::Triplet<double>> dv, dw;
  // The rest tangents at the barycentres come from each element's patch at rest (the centre's
  // vertices are the element's patch, in its order).
  rest_dv_.resize(ext.num_real_triangles, 3);
  rest_dw_.resize(ext.num_real_triangles, 3);
  for (int t = 0; t < ext.num_real_triangles; ++t) {
    const PatchEvaluation centre = evaluate_patch(ext.topology, ext.triangles[static_cast<size_t>(t)], 1.0 / 3, 1.0 / 3);
    for (size_t k = 0; k < centre.vertices.size(); ++k) {
      const Eigen::Index col = static_cast<Eigen::Index>(k);
      if (centre.basis(kDv, col) != 0.0) dv.emplace_back(t, centre.vertices[k], centre.basis(kDv, col));
      if (centre.basis(kDw, col) != 0.0) dw.emplace_back(t, centre.vertices[k], centre.basis(kDw, col));
    }
    const Eigen::MatrixX3d& reference = model_.elements()[static_cast<size_t>(t)].reference;
    rest_dv_.row(t) = centre.basis.row(kDv) * reference;
    rest_dw_.row(t) = centre.basis.row(kDw) * reference;
  }
  centre_dv_.resize(ext.num_real_triangles, ext.num_vertices());
  centre_dv_.setFromTriplets(dv.begin(), dv.end());
  centre_dw_.resize(ext.num_real_triangles, ext.num_vertices());
  centre_dw_.setFromTriplets(dw.begin(), dw.end());
}

void LoopShellDiscretization::make_consistent(Eigen::VectorXd& u) const {
  for (int dof : dependent_) {
    double value = 0.0;
    for (const auto& [d, w] : model_.dofs().combination(dof / 3, dof % 3)) value += w * u(d);
    u(dof) = value;
  }
}

Eigen::VectorXd LoopShellDiscretization::lumped_mass(double areal_density) const {
  return model_.rest_shape() == RestShape::pattern ? lumped_vertex_mass_uv(mesh_, areal_density)
                                                   : lumped_vertex_mass(mesh_, areal_density);
}

Eigen::VectorXd LoopShellDiscretization::traction_load(
    const std::function<Eigen::Vector3d(const Eigen::Vector3d& normal)>& traction) const {
  return model_.surface_traction_load([&](const SurfacePoint& s) { return traction(s.a3); });
}

std::unique_ptr<ForceTerm> LoopShellDiscretization::elastic_term(bool corotational, bool tension_stiffening) const {
  return std::make_unique<CorotatedShell>(model_, corotational, tension_stiffening);
}

Eigen::MatrixX3d LoopShellDiscretization::control_net(const Eigen::VectorXd& x) const {
  Eigen::VectorXd u = x - rest_;
  make_consistent(u);
  return model_.extended().rest + model_.dofs().expand(as_rows(u));
}

SurfaceOperator LoopShellDiscretization::node_points(const std::vector<int>& nodes) const {
  // The limit position mask over each vertex's (closed, extended) one-ring.
  const ExtendedMesh& ext = model_.extended();
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t i = 0; i < nodes.size(); ++i) {
    const int v = nodes[i], row = static_cast<int>(i);
    if (v < 0 || v >= ext.num_real)
      throw std::out_of_range("node_points: node " + std::to_string(v) + " is not a vertex of the mesh (" +
                              std::to_string(ext.num_real) + " vertices)");
    const std::vector<int>& ring = ext.topology.ring(v);
    const int valence = static_cast<int>(ring.size());
    const double w = limit_neighbour_weight(valence);
    entries.emplace_back(row, v, 1.0 - valence * w);
    for (int r : ring) entries.emplace_back(row, r, w);
  }
  SurfaceOperator op;
  op.position.resize(static_cast<Eigen::Index>(nodes.size()), ext.num_vertices());
  op.position.setFromTriplets(entries.begin(), entries.end());
  return op;
}

SurfaceOperator LoopShellDiscretization::samples(const std::vector<SurfaceSample>& points) const {
  // Row p: the subdivision basis (value row) of the point's patch at (v, w).
  const ExtendedMesh& ext = model_.extended();
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t p = 0; p < points.size(); ++p) {
    const SurfaceSample& sp = points[p];
    if (sp.triangle < 0 || sp.triangle >= ext.num_real_triangles)
      throw std::invalid_argument("surface samples: point " + std::to_string(p) + " names triangle " +
                                  std::to_string(sp.triangle) + ", not a triangle of the mesh");
    const PatchEvaluation pe = evaluate_patch(ext.topology, ext.triangles[static_cast<size_t>(sp.triangle)], sp.v, sp.w);
    for (size_t k = 0; k < pe.vertices.size(); ++k)
      if (pe.basis(0, static_cast<Eigen::Index>(k)) != 0.0)
        entries.emplace_back(static_cast<int>(p), pe.vertices[k], pe.basis(0, static_cast<Eigen::Index>(k)));
  }
  SurfaceOperator op;
  op.position.resize(static_cast<Eigen::Index>(points.size()), ext.num_vertices());
  op.position.setFromTriplets(entries.begin(), entries.end());
  return op;
}

SurfaceOperator LoopShellDiscretization::display(int levels) const {
  const ExtendedMesh& ext = model_.extended();
  LimitRefinement r = build_limit_refinement(ext.rest, ext.triangles, ext.num_real_triangles, levels);
  SurfaceOperator op;
  op.position = std::move(r.position);
  op.tangent1 = std::move(r.tangent1);
  op.tangent2 = std::move(r.tangent2);
  op.triangles = std::move(r.triangles);
  op.levels = r.levels;
  return op;
}

SurfaceOperator LoopShellDiscretization::flat_display(int levels) const {
  return midpoint_display(mesh_, levels, model_.extended().num_vertices());
}

double LoopShellDiscretization::max_membrane_strain(const Eigen::VectorXd& u) const {
  const Eigen::MatrixX3d net = control_net(rest_ + u);
  const Eigen::MatrixX3d a1 = centre_dv_ * net, a2 = centre_dw_ * net;
  double worst = 0.0;
  for (Eigen::Index e = 0; e < a1.rows(); ++e) {
    const Eigen::Vector3d c1 = a1.row(e), c2 = a2.row(e), r1 = rest_dv_.row(e), r2 = rest_dw_.row(e);
    Eigen::Matrix2d g, rest;
    g << c1.dot(c1), c1.dot(c2), c1.dot(c2), c2.dot(c2);
    rest << r1.dot(r1), r1.dot(r2), r1.dot(r2), r2.dot(r2);
    // Eigenvalues of G⁻¹E: those of the symmetric L⁻¹ E L⁻ᵀ with G = L Lᵀ.
    const Eigen::Matrix2d l_inv = Eigen::Matrix2d(rest.llt().matrixL()).inverse();
    const Eigen::Matrix2d strain = 0.5 * l_inv * (g - rest) * l_inv.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(0.5 * (strain + strain.transpose()), Eigen::EigenvaluesOnly);
    worst = std::max(worst, eig.eigenvalues().cwiseAbs().maxCoeff());
  }
  return worst;
}

void LoopShellDiscretization::add_point_forces(const SurfaceOperator& op, const Eigen::MatrixX3d& forces,
                                               Eigen::VectorXd& f) const {
  // Jᵀ F: each point's force spread over its control points with the operator's weights, then
  // from each control point (a ghost: a combination of nodes) onto the nodes' components.
  for (Eigen::Index p = 0; p < op.position.rows(); ++p)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(op.position, p); it; ++it)
      for (int c = 0; c < 3; ++c)
        for (const auto& [dof, w] : model_.dofs().combination(static_cast<int>(it.col()), c))
          f(dof) += it.value() * w * forces(p, c);
}

Eigen::SparseMatrix<double, Eigen::RowMajor> LoopShellDiscretization::point_jacobian(const SurfaceOperator& op) const {
  // The operator's weights composed with each control point's combination of node components.
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index p = 0; p < op.position.rows(); ++p)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(op.position, p); it; ++it)
      for (int c = 0; c < 3; ++c)
        for (const auto& [dof, w] : model_.dofs().combination(static_cast<int>(it.col()), c))
          entries.emplace_back(static_cast<int>(3 * p + c), dof, it.value() * w);
  Eigen::SparseMatrix<double, Eigen::RowMajor> j(3 * op.position.rows(), 3 * static_cast<Eigen::Index>(mesh_.num_vertices()));
  j.setFromTriplets(entries.begin(), entries.end());  // sums repeated entries
  return j;
}

}  // namespace clothsim

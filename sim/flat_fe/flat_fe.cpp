#include "sim/flat_fe/flat_fe.hpp"

#include "sim/discretization/flat_refinement.hpp"
#include "sim/flat_fe/flat_fe_term.hpp"
#include "sim/mesh/topology.hpp"
#include "sim/shell/dof_map.hpp"
#include "sim/shell/ghost_layer.hpp"
#include "sim/shell/shell_model.hpp"
#include "sim/subdivision/limit_refinement.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace clothsim {

namespace {

// The interior edges of a consistently oriented mesh as hinges (ordered by the first triangle
// that runs the edge, then by the edge's place in it).
std::vector<Hinge> find_hinges(const TriMesh& mesh) {
  std::map<std::pair<int, int>, std::pair<int, int>> directed;  // (a, b) → (triangle, apex) of the triangle running a → b
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    const Triangle& tri = mesh.triangles[static_cast<size_t>(t)];
    for (int k = 0; k < 3; ++k) directed[{tri[k], tri[(k + 1) % 3]}] = {t, tri[(k + 2) % 3]};
  }
  std::vector<Hinge> out;
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    const Triangle& tri = mesh.triangles[static_cast<size_t>(t)];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      const auto twin = directed.find({b, a});
      if (twin == directed.end() || twin->second.first < t) continue;  // border edge, or listed from the twin
      Hinge h;
      h.nodes = {a, b, tri[(k + 2) % 3], twin->second.second};
      h.triangle_a = t;
      h.triangle_b = twin->second.first;
      out.push_back(h);
    }
  }
  return out;
}

}  // namespace

TriMesh FlatDiscretization::prepare_flat_mesh(const std::string& method, const TriMesh& mesh, const LogFn& log) {
  check_triangles(mesh);
  (void)Topology(mesh.num_vertices(), mesh.triangles);  // throws MeshError for a non-manifold mesh
  if (log)
    log("mesh: " + method + " uses the mesh as given (" + std::to_string(mesh.num_vertices()) + " vertices, " +
        std::to_string(mesh.num_triangles()) + " triangles; no refinement)");
  return mesh;
}

FlatDiscretization::FlatDiscretization(std::string method, const TriMesh& mesh,
                                       const std::vector<BoundaryCondition>& boundary, const ShellMaterial& material)
    : method_(std::move(method)), mesh_(mesh), material_(material), rest_(to_flat(mesh.vertices)),
      status_(3 * static_cast<size_t>(mesh.num_vertices()), DofStatus::free) {
  check_triangles(mesh_);
  (void)Topology(mesh_.num_vertices(), mesh_.triangles);
  for (size_t i = 0; i < boundary.size(); ++i) {
    const BoundaryCondition& bc = boundary[i];
    const std::string name = method_ + ": boundary condition " + std::to_string(i);
    if (bc.clamped || bc.symmetric)
      throw std::runtime_error(name + ": rotation \"" + (bc.clamped ? "clamped" : "symmetry") +
                               "\" is not supported by the " + method_ + " method (its nodes have no rotational degrees of "
                               "freedom and its borders are hinged); use \"free\", or hold a slope by fixing two rows "
                               "of vertices");
    for (int v : bc.vertices) {
      if (v < 0 || v >= mesh_.num_vertices())
        throw std::runtime_error(name + ": vertex " + std::to_string(v) + " is not a vertex of the mesh");
      for (int c = 0; c < 3; ++c)
        if (bc.fix[static_cast<size_t>(c)]) status_[3 * static_cast<size_t>(v) + static_cast<size_t>(c)] = DofStatus::fixed;
    }
  }
  hinges_ = find_hinges(mesh_);
  std::vector<std::vector<int>> groups;
  groups.reserve(mesh_.triangles.size() + hinges_.size());
  for (const Triangle& t : mesh_.triangles) groups.push_back({t[0], t[1], t[2]});
  for (const Hinge& h : hinges_) groups.push_back({h.nodes[0], h.nodes[1], h.nodes[2], h.nodes[3]});
  blocks_ = NodeBlockPattern(mesh_.num_vertices(), groups);
}

std::vector<std::string> FlatDiscretization::unrestrained_rigid_motions() const {
  // A rigid motion r = t + ω × (X − centroid)/size leaves every fixed component at rest exactly
  // when r vanishes there. Collect r at the fixed components for the six basis motions; the
  // null space of their Gram matrix is the rigid motions left free (the words and thresholds of
  // ShellModel::unrestrained_rigid_motions, without its ghosts and tied components).
  const Eigen::MatrixX3d& x = mesh_.vertices;
  const Eigen::RowVector3d centroid = x.colwise().mean();
  const double size = std::max((x.rowwise() - centroid).rowwise().norm().maxCoeff(), 1e-300);
  Eigen::Matrix<double, 6, 6> gram = Eigen::Matrix<double, 6, 6>::Zero();
  for (int v = 0; v < mesh_.num_vertices(); ++v) {
    const Eigen::Vector3d p = (x.row(v) - centroid).transpose() / size;
    for (int c = 0; c < 3; ++c) {
      if (status(3 * v + c) != DofStatus::fixed) continue;
      Eigen::Matrix<double, 6, 1> r;
      for (int i = 0; i < 3; ++i) {
        r(i) = i == c ? 1.0 : 0.0;
        r(3 + i) = Eigen::Vector3d::Unit(i).cross(p)(c);
      }
      gram += r * r.transpose();
    }
  }
  return free_rigid_motions(gram);
}

Eigen::VectorXd FlatDiscretization::lumped_mass(double areal_density) const {
  return lumped_vertex_mass(mesh_, areal_density);
}

Eigen::VectorXd FlatDiscretization::traction_load(
    const std::function<Eigen::Vector3d(const Eigen::Vector3d& normal)>& traction) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(mesh_.num_vertices()));
  for (const Triangle& t : mesh_.triangles) {
    const Eigen::Vector3d x0 = mesh_.vertices.row(t[0]), x1 = mesh_.vertices.row(t[1]), x2 = mesh_.vertices.row(t[2]);
    const Eigen::Vector3d n = (x1 - x0).cross(x2 - x0);
    const double area = 0.5 * n.norm();
    const Eigen::Vector3d share = (area / 3.0) * traction(n.normalized());  // ∫ N_I dA = A/3
    for (int v : t) f.segment<3>(3 * v) += share;
  }
  return f;
}

std::unique_ptr<ForceTerm> LinearFeDiscretization::elastic_term(bool corotational, bool /*tension_stiffening*/) const {
  return std::make_unique<LinearFeElastic>(*this, corotational);
}

SurfaceOperator FlatDiscretization::node_points(const std::vector<int>& nodes) const {
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t i = 0; i < nodes.size(); ++i) {
    const int v = nodes[i];
    if (v < 0 || v >= mesh_.num_vertices())
      throw std::out_of_range("node_points: node " + std::to_string(v) + " is not a vertex of the mesh (" +
                              std::to_string(mesh_.num_vertices()) + " vertices)");
    entries.emplace_back(static_cast<int>(i), v, 1.0);
  }
  SurfaceOperator op;
  op.position.resize(static_cast<Eigen::Index>(nodes.size()), mesh_.num_vertices());
  op.position.setFromTriplets(entries.begin(), entries.end());
  return op;
}

SurfaceOperator FlatDiscretization::samples(const std::vector<SurfaceSample>& points) const {
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t p = 0; p < points.size(); ++p) {
    const SurfaceSample& sp = points[p];
    if (sp.triangle < 0 || sp.triangle >= mesh_.num_triangles())
      throw std::invalid_argument("surface samples: point " + std::to_string(p) + " names triangle " +
                                  std::to_string(sp.triangle) + ", not a triangle of the mesh");
    const Triangle& t = mesh_.triangles[static_cast<size_t>(sp.triangle)];
    const double weights[3] = {1.0 - sp.v - sp.w, sp.v, sp.w};
    for (int k = 0; k < 3; ++k)
      if (weights[k] != 0.0) entries.emplace_back(static_cast<int>(p), t[k], weights[k]);
  }
  SurfaceOperator op;
  op.position.resize(static_cast<Eigen::Index>(points.size()), mesh_.num_vertices());
  op.position.setFromTriplets(entries.begin(), entries.end());
  return op;
}

SurfaceOperator FlatDiscretization::display(int levels) const {
  return midpoint_display(mesh_, levels, mesh_.num_vertices());
}

SurfaceOperator FlatDiscretization::loop_limit_display(int levels) const {
  if (levels < 0) throw std::invalid_argument("display: levels must be >= 0");
  // loop_kl's construction on the same mesh: the ghost layer, then the limit refinement of the
  // extended mesh, composed with the map from the nodes to the extended mesh's vertices (each
  // ghost by the free-border rule of a DofMap without conditions, x_g = x_a + x_b − x_c).
  const ExtendedMesh ext = [&] {
    try {
      return build_ghost_layer(mesh_);
    } catch (const MeshError& e) {
      throw MeshError(std::string("the Loop limit surface over the ") + method_ + " nodes (\"render.surface\": "
                      "\"loop_limit\") cannot be built: " + e.what());
    }
  }();
  const DofMap free_borders(ext, {});
  std::vector<Eigen::Triplet<double>> g;
  for (int v = 0; v < ext.num_vertices(); ++v)
    for (const auto& [dof, w] : free_borders.combination(v, 0)) g.emplace_back(v, dof / 3, w);  // same for y, z
  Eigen::SparseMatrix<double, Eigen::RowMajor> expand(ext.num_vertices(), mesh_.num_vertices());
  expand.setFromTriplets(g.begin(), g.end());
  LimitRefinement r = build_limit_refinement(ext.rest, ext.triangles, ext.num_real_triangles, levels);
  SurfaceOperator op;
  op.position = r.position * expand;
  op.tangent1 = r.tangent1 * expand;
  op.tangent2 = r.tangent2 * expand;
  op.position.prune(0.0, 1e-14);
  op.tangent1.prune(0.0, 1e-14);
  op.tangent2.prune(0.0, 1e-14);
  op.triangles = std::move(r.triangles);
  op.levels = r.levels;
  return op;
}

double FlatDiscretization::max_membrane_strain(const Eigen::VectorXd& u) const {
  // Per triangle: the deformation gradient F (3 × 2) from an orthonormal frame of the rest
  // triangle's plane to the current positions, F = D_s D_m⁻¹ with D_m the rest edges (b − a,
  // c − a) in that frame and D_s the current ones; the Green–Lagrange strain ½(FᵀF − I) and its
  // principal values.
  double worst = 0.0;
  for (const Triangle& t : mesh_.triangles) {
    const Eigen::Vector3d xa = rest_.segment<3>(3 * t[0]), xb = rest_.segment<3>(3 * t[1]), xc = rest_.segment<3>(3 * t[2]);
    const Eigen::Vector3d e1 = (xb - xa).normalized();
    const Eigen::Vector3d e2 = ((xb - xa).cross(xc - xa)).cross(xb - xa).normalized();
    Eigen::Matrix2d dm;
    dm << e1.dot(xb - xa), e1.dot(xc - xa), e2.dot(xb - xa), e2.dot(xc - xa);
    Eigen::Matrix<double, 3, 2> ds;
    ds.col(0) = (xb + u.segment<3>(3 * t[1])) - (xa + u.segment<3>(3 * t[0]));
    ds.col(1) = (xc + u.segment<3>(3 * t[2])) - (xa + u.segment<3>(3 * t[0]));
    const Eigen::Matrix<double, 3, 2> f = ds * dm.inverse();
    const Eigen::Matrix2d green = 0.5 * (f.transpose() * f - Eigen::Matrix2d::Identity());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(0.5 * (green + green.transpose()), Eigen::EigenvaluesOnly);
    worst = std::max(worst, eig.eigenvalues().cwiseAbs().maxCoeff());
  }
  return worst;
}

void FlatDiscretization::add_point_forces(const SurfaceOperator& op, const Eigen::MatrixX3d& forces,
                                              Eigen::VectorXd& f) const {
  // Jᵀ F: the control net is the nodes, so each point's force goes to its nodes with the
  // operator's weights.
  for (Eigen::Index p = 0; p < op.position.rows(); ++p)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(op.position, p); it; ++it)
      for (int c = 0; c < 3; ++c) f(3 * it.col() + c) += it.value() * forces(p, c);
}

Eigen::SparseMatrix<double, Eigen::RowMajor> FlatDiscretization::point_jacobian(const SurfaceOperator& op) const {
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index p = 0; p < op.position.rows(); ++p)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(op.position, p); it; ++it)
      for (int c = 0; c < 3; ++c)
        entries.emplace_back(static_cast<int>(3 * p + c), static_cast<int>(3 * it.col() + c), it.value());
  Eigen::SparseMatrix<double, Eigen::RowMajor> j(3 * op.position.rows(), 3 * static_cast<Eigen::Index>(mesh_.num_vertices()));
  j.setFromTriplets(entries.begin(), entries.end());
  return j;
}

}  // namespace clothsim

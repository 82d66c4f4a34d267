#include "sim/shell/shell_model.hpp"

#include "sim/subdivision/loop.hpp"
#include "sim/subdivision/patch.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bitset>
#include <Eigen/Eigenvalues>

#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {

ShellElement make_element(const ExtendedMesh& ext, const DofMap& dofs, const Triangle& tri,
                          const std::vector<QuadraturePoint>& rule) {
  ShellElement el;
  el.triangle = tri;
  for (const QuadraturePoint& q : rule) {
    PatchEvaluation pe = evaluate_patch(ext.topology, tri, q.v, q.w);
    if (el.patch.empty()) el.patch = pe.vertices;
    if (pe.vertices != el.patch) throw std::logic_error("element patch changed between quadrature points");
    el.basis.push_back(std::move(pe.basis));
    el.weights.push_back(q.weight);
  }
  el.identity = std::all_of(el.patch.begin(), el.patch.end(), [&](int v) { return dofs.is_identity(v); });
  if (el.identity) {
    el.real = el.patch;
    return el;
  }
  for (int p : el.patch)
    for (int c = 0; c < 3; ++c)
      for (const auto& [dof, w] : dofs.combination(p, c)) {
        (void)w;
        el.real.push_back(dof / 3);
      }
  std::sort(el.real.begin(), el.real.end());
  el.real.erase(std::unique(el.real.begin(), el.real.end()), el.real.end());
  std::map<int, Eigen::Index> col;
  for (size_t i = 0; i < el.real.size(); ++i) col[el.real[i]] = static_cast<Eigen::Index>(i);
  const Eigen::Index np = static_cast<Eigen::Index>(el.patch.size()), nr = static_cast<Eigen::Index>(el.real.size());
  std::vector<Eigen::Triplet<double>> weights;
  for (Eigen::Index p = 0; p < np; ++p)
    for (int c = 0; c < 3; ++c)
      for (const auto& [dof, w] : dofs.combination(el.patch[p], c))
        weights.emplace_back(3 * p + c, 3 * col.at(dof / 3) + dof % 3, w);
  el.fold.resize(3 * np, 3 * nr);
  el.fold.setFromTriplets(weights.begin(), weights.end());
  return el;
}

// Tᵀ K T: a patch-coordinate matrix folded onto the element's real DOFs.
Eigen::MatrixXd fold_patch_matrix(const ShellElement& el, const Eigen::MatrixXd& k) {
  const Eigen::MatrixXd kt = k * el.fold;
  return el.fold.transpose() * kt;
}

Eigen::MatrixX3d patch_rows(const Eigen::MatrixX3d& x, const std::vector<int>& ids) {
  Eigen::MatrixX3d out(static_cast<Eigen::Index>(ids.size()), 3);
  for (size_t i = 0; i < ids.size(); ++i) out.row(static_cast<Eigen::Index>(i)) = x.row(ids[i]);
  return out;
}

}  // namespace

ShellModel::ShellModel(const TriMesh& mesh, const ShellMaterial& material,
                       const std::vector<BoundaryCondition>& conditions, Quadrature quadrature, RestShape rest)
    : ext_(build_ghost_layer(mesh)), dofs_(ext_, conditions), material_(material), rest_shape_(rest) {
  const std::vector<QuadraturePoint> rule = quadrature_points(quadrature);
  elements_.reserve(mesh.triangles.size());
  if (material.orthotropic() && mesh.warp.size() != mesh.triangles.size())
    throw std::invalid_argument("an orthotropic material needs a warp direction per triangle (the mesh has " +
                                std::to_string(mesh.warp.size()) + " for " + std::to_string(mesh.num_triangles()) +
                                " triangles)");
  std::optional<FlatRestLayout> layout;
  if (rest == RestShape::pattern) layout.emplace(mesh, ext_);
  for (int t = 0; t < mesh.num_triangles(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    if (irregular_vertex_count(ext_, tri) > 1)
      throw MeshError("triangle " + std::to_string(t) + " has more than one irregular vertex; refine the mesh first");
    elements_.push_back(make_element(ext_, dofs_, tri, rule));
    ShellElement& el = elements_.back();
    el.reference = layout ? layout->patch(t, el.patch) : patch_rows(ext_.rest, el.patch);
    if (material.orthotropic()) {
      el.warp = layout ? layout->to_layout(t, mesh.warp[static_cast<size_t>(t)]) : mesh.warp[static_cast<size_t>(t)];
      // Every quadrature point must see the grain (curvilinear_matrix throws otherwise).
      for (const BasisMatrix& b : el.basis) {
        const SurfacePoint s = surface_point(b, el.reference);
        const Eigen::Vector3d w = el.warp - el.warp.dot(s.a3) * s.a3;
        if (!(w.norm() > 1e-6 * el.warp.norm()))
          throw std::invalid_argument("triangle " + std::to_string(t) +
                                      ": its warp direction is normal to the surface (or zero)");
      }
    }
  }
  build_pattern();
  build_colors();
}

void ShellModel::build_pattern() {
  const int n = num_vertices();
  std::vector<std::vector<int>> nb(n);
  for (int v = 0; v < n; ++v) nb[v].push_back(v);
  for (const ShellElement& el : elements_)
    for (int j : el.real) nb[j].insert(nb[j].end(), el.real.begin(), el.real.end());
  for (auto& list : nb) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  std::vector<int> column_start(3 * n + 1, 0);
  block_stride_.resize(n);
  for (int j = 0; j < n; ++j) {
    block_stride_[j] = 3 * static_cast<int>(nb[j].size());
    for (int d = 0; d < 3; ++d) column_start[3 * j + d + 1] = column_start[3 * j + d] + block_stride_[j];
  }
  const int nnz = column_start[3 * n];
  pattern_ = Eigen::SparseMatrix<double>(3 * n, 3 * n);
  pattern_.makeCompressed();
  pattern_.resizeNonZeros(nnz);
  std::copy(column_start.begin(), column_start.end(), pattern_.outerIndexPtr());
  for (int j = 0; j < n; ++j)
    for (int d = 0; d < 3; ++d) {
      int pos = column_start[3 * j + d];
      for (int i : nb[j])
        for (int c = 0; c < 3; ++c) pattern_.innerIndexPtr()[pos++] = 3 * i + c;
    }
  std::fill(pattern_.valuePtr(), pattern_.valuePtr() + nnz, 0.0);
  slots_.resize(elements_.size());
  for (size_t e = 0; e < elements_.size(); ++e) {
    const std::vector<int>& real = elements_[e].real;
    const size_t m = real.size();
    slots_[e].resize(m * m);
    for (size_t b = 0; b < m; ++b) {
      const std::vector<int>& list = nb[real[b]];
      for (size_t a = 0; a < m; ++a) {
        const auto slot = std::lower_bound(list.begin(), list.end(), real[a]) - list.begin();
        slots_[e][a + m * b] = column_start[3 * real[b]] + 3 * static_cast<int>(slot);
      }
    }
  }
}

void ShellModel::build_colors() {
  // Greedy colouring: an element takes the lowest colour not yet used at any of its vertices.
  constexpr size_t kMaxColors = 256;
  std::vector<std::bitset<kMaxColors>> used(num_vertices());
  for (int e = 0; e < static_cast<int>(elements_.size()); ++e) {
    std::bitset<kMaxColors> taken;
    for (int v : elements_[e].real) taken |= used[v];
    size_t color = 0;
    while (color < kMaxColors && taken[color]) ++color;
    if (color == kMaxColors) throw std::logic_error("element colouring needs more than 256 colours");
    for (int v : elements_[e].real) used[v].set(color);
    if (color >= colors_.size()) colors_.resize(color + 1);
    colors_[color].push_back(e);
  }
}

template <class Matrix>
void ShellModel::scatter_matrix(int e, const Matrix& local, double* values) const {
  const std::vector<int>& real = elements_[e].real;
  const std::vector<int>& slots = slots_[e];
  const size_t m = real.size();
  for (size_t b = 0; b < m; ++b) {
    const int stride = block_stride_[real[b]];
    for (size_t a = 0; a < m; ++a) {
      double* block = values + slots[a + m * b];
      for (int d = 0; d < 3; ++d)
        for (int c = 0; c < 3; ++c)
          block[d * stride + c] += local(3 * static_cast<Eigen::Index>(a) + c, 3 * static_cast<Eigen::Index>(b) + d);
    }
  }
}

Eigen::MatrixXd ShellModel::folded_element_stiffness(int e) const {
  const ShellElement& el = elements_[e];
  const ElementMatrix k = element_stiffness(el.basis, el.weights, el.reference, material_, el.warp);
  if (el.identity) return k;
  return fold_patch_matrix(el, k);
}

Eigen::SparseMatrix<double> ShellModel::stiffness() const {
  Eigen::SparseMatrix<double> k = pattern_;
  double* values = k.valuePtr();
  // Colour by colour; elements of one colour share no vertex, so their scatters never collide
  // and the sum in every entry is taken in the same order on every run.
  for (const std::vector<int>& group : colors_)
    tbb::parallel_for(tbb::blocked_range<size_t>(0, group.size(), 64), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i != range.end(); ++i) {
        const int e = group[i];
        const ShellElement& el = elements_[e];
        if (el.identity)
          scatter_matrix(e, element_stiffness(el.basis, el.weights, el.reference, material_, el.warp), values);
        else
          scatter_matrix(e, folded_element_stiffness(e), values);
      }
    });
  return k;
}

Eigen::MatrixXd ShellModel::patch_stiffness(int e) const {
  const ShellElement& el = elements_[e];
  return element_stiffness(el.basis, el.weights, el.reference, material_, el.warp);
}

Eigen::VectorXd ShellModel::patch_vector(int e, const Eigen::VectorXd& real) const {
  const ShellElement& el = elements_[e];
  const Eigen::Index np = static_cast<Eigen::Index>(el.patch.size());
  Eigen::VectorXd out(3 * np);
  if (el.identity) {
    for (Eigen::Index p = 0; p < np; ++p) out.segment<3>(3 * p) = real.segment<3>(3 * el.patch[p]);
    return out;
  }
  Eigen::VectorXd local(3 * static_cast<Eigen::Index>(el.real.size()));
  for (size_t r = 0; r < el.real.size(); ++r) local.segment<3>(3 * static_cast<Eigen::Index>(r)) = real.segment<3>(3 * el.real[r]);
  return el.fold * local;
}

void ShellModel::add_patch_matrix(int e, const Eigen::MatrixXd& k_patch, Eigen::SparseMatrix<double>& global) const {
  const ShellElement& el = elements_[e];
  if (el.identity) {
    scatter_matrix(e, k_patch, global.valuePtr());
    return;
  }
  scatter_matrix(e, fold_patch_matrix(el, k_patch), global.valuePtr());
}

void ShellModel::restrict_to_free(Eigen::SparseMatrix<double>& k) const {
  for (Eigen::Index col = 0; col < k.outerSize(); ++col) {
    const bool col_free = dofs_.is_free(static_cast<int>(col / 3), static_cast<int>(col % 3));
    for (Eigen::SparseMatrix<double>::InnerIterator it(k, col); it; ++it) {
      const bool row_free = dofs_.is_free(static_cast<int>(it.row() / 3), static_cast<int>(it.row() % 3));
      if (!col_free || !row_free) it.valueRef() = it.row() == col ? 1.0 : 0.0;
    }
  }
}

void ShellModel::restrict_to_free(Eigen::VectorXd& f) const {
  for (Eigen::Index i = 0; i < f.size(); ++i)
    if (!dofs_.is_free(static_cast<int>(i / 3), static_cast<int>(i % 3))) f(i) = 0.0;
}

void ShellModel::scatter_vector(const ShellElement& el, const Eigen::VectorXd& local, Eigen::VectorXd& global) const {
  for (size_t p = 0; p < el.patch.size(); ++p)
    for (int c = 0; c < 3; ++c)
      for (const auto& [dof, w] : dofs_.combination(el.patch[p], c)) global(dof) += w * local(3 * static_cast<Eigen::Index>(p) + c);
}

Eigen::VectorXd ShellModel::area_load(const Eigen::Vector3d& q) const {
  return surface_traction_load([&](const SurfacePoint&) { return q; });
}

Eigen::VectorXd ShellModel::pressure_load(double p) const {
  return surface_traction_load([&](const SurfacePoint& s) -> Eigen::Vector3d { return p * s.a3; });
}

Eigen::VectorXd ShellModel::surface_traction_load(
    const std::function<Eigen::Vector3d(const SurfacePoint&)>& traction) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * num_vertices());
  for (const ShellElement& el : elements_) {
    // The traction's direction from the mesh's positions, the area from the rest state (the same
    // surface unless the rest state is a flat layout).
    const Eigen::MatrixX3d x = patch_rows(ext_.rest, el.patch);
    Eigen::VectorXd local = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(el.patch.size()));
    for (size_t k = 0; k < el.basis.size(); ++k) {
      const SurfacePoint s = surface_point(el.basis[k], x);
      const double j = rest_shape_ == RestShape::initial ? s.j : surface_point(el.basis[k], el.reference).j;
      const Eigen::Vector3d t = (el.weights[k] * j) * traction(s);
      for (Eigen::Index p = 0; p < static_cast<Eigen::Index>(el.patch.size()); ++p)
        local.segment<3>(3 * p) += el.basis[k](kValue, p) * t;
    }
    scatter_vector(el, local, f);
  }
  return f;
}

Eigen::VectorXd ShellModel::point_load(int v, const Eigen::Vector3d& force) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * num_vertices());
  const std::vector<int>& ring = ext_.topology.ring(v);
  const int valence = static_cast<int>(ring.size());
  const double w = limit_neighbour_weight(valence);
  auto add = [&](int vertex, double weight) {
    for (int c = 0; c < 3; ++c)
      for (const auto& [dof, cw] : dofs_.combination(vertex, c)) f(dof) += weight * cw * force(c);
  };
  add(v, 1.0 - valence * w);
  for (int r : ring) add(r, w);
  return f;
}

Eigen::MatrixX3d ShellModel::limit_points(const Eigen::MatrixX3d& x) const {
  Eigen::MatrixX3d out(num_vertices(), 3);
  for (int v = 0; v < num_vertices(); ++v) {
    const std::vector<int>& ring = ext_.topology.ring(v);
    const int valence = static_cast<int>(ring.size());
    const double w = limit_neighbour_weight(valence);
    Eigen::RowVector3d p = (1.0 - valence * w) * x.row(v);
    for (int r : ring) p += w * x.row(r);
    out.row(v) = p;
  }
  return out;
}

std::vector<std::string> free_rigid_motions(const Eigen::Matrix<double, 6, 6>& gram) {
  std::vector<std::string> out;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(gram);
  const double scale = std::max(1.0, eig.eigenvalues().maxCoeff());
  const char* axes = "xyz";
  for (int k = 0; k < 6; ++k) {
    if (eig.eigenvalues()(k) > 1e-9 * scale) continue;
    const Eigen::Matrix<double, 6, 1> mode = eig.eigenvectors().col(k);
    std::ostringstream s;
    bool first = true;
    for (int i = 0; i < 6; ++i) {
      if (std::abs(mode(i)) < 1e-6) continue;
      s << (first ? "" : " + ") << (i < 3 ? "translation along " : "rotation about ") << axes[i % 3];
      first = false;
    }
    out.push_back(s.str());
  }
  return out;
}

std::vector<std::string> ShellModel::unrestrained_rigid_motions() const {
  // A rigid motion r = t + ω × (X − centroid)/size moves the model without strain exactly when
  // every displacement the DOF map derives (fixed components: zero; tied components and ghosts:
  // their combinations of free components) agrees with r there. Collect those residuals for the
  // six basis motions and find the null space of their Gram matrix.
  const int n = num_vertices();
  const Eigen::MatrixX3d& x = ext_.rest;
  const Eigen::RowVector3d centroid = x.topRows(n).colwise().mean();
  const double size = std::max((x.topRows(n).rowwise() - centroid).rowwise().norm().maxCoeff(), 1e-300);
  auto rigid = [&](int v, int c) {  // the six basis motions' component c at vertex v
    const Eigen::Vector3d p = (x.row(v) - centroid).transpose() / size;
    Eigen::Matrix<double, 6, 1> r;
    for (int i = 0; i < 3; ++i) {
      r(i) = i == c ? 1.0 : 0.0;
      r(3 + i) = Eigen::Vector3d::Unit(i).cross(p)(c);
    }
    return r;
  };
  Eigen::Matrix<double, 6, 6> gram = Eigen::Matrix<double, 6, 6>::Zero();
  for (int v = 0; v < ext_.num_vertices(); ++v)
    for (int c = 0; c < 3; ++c) {
      if (v < n && dofs_.is_free(v, c)) continue;
      Eigen::Matrix<double, 6, 1> residual = rigid(v, c);
      if (v >= n || dofs_.status(v, c) == DofStatus::dependent)
        for (const auto& [dof, w] : dofs_.combination(v, c))
          if (dofs_.is_free(dof / 3, dof % 3)) residual -= w * rigid(dof / 3, dof % 3);
      gram += residual * residual.transpose();
    }
  return free_rigid_motions(gram);
}

}  // namespace clothsim

#include "sim/corotation/corotational_elements.hpp"

#include "sim/corotation/assembly_kernels.hpp"

#include "sim/shell/element.hpp"
#include "sim/subdivision/box_spline.hpp"
#include "sim/subdivision/patch.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace clothsim {

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// A patch vector (3·#patch) on the stack.
using PatchVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxPatchDofs, 1>;

using assembly_avx2::kLanes;

}  // namespace

namespace {

// Positive part of a symmetric 2 × 2 membrane force n = (n¹¹, n²², n¹²): zero without tension,
// n itself when both eigenvalues are ≥ 0, else high·v vᵀ = high (N − low I)/(high − low) with
// eigenvalues low < 0 < high (closed form; an eigensolver per element costs more).
Eigen::Matrix2d tensile_part(const Eigen::Vector3d& n) {
  const double mean = 0.5 * (n(0) + n(1)), half = 0.5 * (n(0) - n(1));
  const double radius = std::sqrt(half * half + n(2) * n(2));
  const double high = mean + radius, low = mean - radius;
  if (!(high > 0.0)) return Eigen::Matrix2d::Zero();
  Eigen::Matrix2d positive;
  positive << n(0), n(2), n(2), n(1);
  if (low < 0.0) {
    positive.diagonal().array() -= low;
    positive *= high / (high - low);
  }
  return positive;
}

// Vertices of a regular patch (three vertices of valence 6): the common case, with fixed sizes.
constexpr int kRegularPatch = 12;

// kd = K_e d = Σ_q w_q (Mᵀ (K_m H) M d + Bᵀ (D_b H) B d) over an element's `points` quadrature
// points (strain matrices one after the other from `strain`, 6·dofs values per point); with
// `tension`, also w_q times the tensile part of each point's membrane force (3 values each).
template <int Dofs>
void element_product(Eigen::Index dofs, int points, const double* strain, const Eigen::Matrix3d* membrane,
                     const Eigen::Matrix3d* bending, const double* weight, const double* d, double* kd, double* tension) {
  using StrainMap = Eigen::Map<const Eigen::Matrix<double, 3, Dofs>>;
  const Eigen::Map<const Eigen::Matrix<double, Dofs, 1>> dv(d, dofs);
  Eigen::Map<Eigen::Matrix<double, Dofs, 1>> out(kd, dofs);
  out.setZero();
  for (int q = 0; q < points; ++q, strain += 6 * dofs) {
    const StrainMap m(strain, 3, dofs), b(strain + 3 * dofs, 3, dofs);
    const Eigen::Vector3d n = membrane[q] * (m * dv);  // membrane force n¹¹, n²², n¹²
    const Eigen::Vector3d moment = bending[q] * (b * dv);
    out.noalias() += m.transpose() * (weight[q] * n);
    out.noalias() += b.transpose() * (weight[q] * moment);
    if (!tension) continue;
    const Eigen::Matrix2d positive = tensile_part(n);
    tension[3 * q] = weight[q] * positive(0, 0);
    tension[3 * q + 1] = weight[q] * positive(0, 1);
    tension[3 * q + 2] = weight[q] * positive(1, 1);
  }
}

// W with fold = W ⊗ I₃ when the element's fold treats the three components alike (free borders,
// borders fixed in every component); empty otherwise (clamped borders, partly fixed vertices).
Eigen::MatrixXd componentwise_fold(const ShellElement& el) {
  const Eigen::MatrixXd t = el.fold;
  Eigen::MatrixXd w(t.rows() / 3, t.cols() / 3);
  for (Eigen::Index p = 0; p < w.rows(); ++p)
    for (Eigen::Index i = 0; i < w.cols(); ++i) {
      w(p, i) = t(3 * p, 3 * i);
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d)
          if (t(3 * p + c, 3 * i + d) != (c == d ? w(p, i) : 0.0)) return {};
    }
  return w;
}

}  // namespace

bool extract_rotation(const Eigen::Vector3d& rest_a1, const Eigen::Vector3d& rest_a2, const Eigen::Vector3d& a1,
                      const Eigen::Vector3d& a2, Eigen::Matrix3d& r) {
  // Orthonormal rest frame (E1, E2, N) and the rest tangents in it.
  const Eigen::Vector3d e1 = rest_a1.normalized();
  const Eigen::Vector3d n = rest_a1.cross(rest_a2).normalized();
  const Eigen::Vector3d e2 = n.cross(e1);
  Eigen::Matrix2d rest_local;
  rest_local << rest_a1.dot(e1), rest_a2.dot(e1), rest_a1.dot(e2), rest_a2.dot(e2);
  // G = F [E1 E2]: the current images of the rest unit tangents (3 × 2).
  Eigen::Matrix<double, 3, 2> current;
  current << a1, a2;
  const Eigen::Matrix<double, 3, 2> g = current * rest_local.inverse();
  // Polar decomposition G = R₂ U with U = (GᵀG)^½ (eq. 30).
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig;
  eig.computeDirect(g.transpose() * g);  // closed form: the iterative solver dominated the rotation pass
  const Eigen::Vector2d lambda = eig.eigenvalues();
  if (!lambda.allFinite() || !(lambda(0) > 1e-12 * lambda(1)) || !(lambda(1) > 0)) return false;
  const Eigen::Matrix2d u_inv =
      eig.eigenvectors() * lambda.cwiseSqrt().cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
  const Eigen::Matrix<double, 3, 2> r2 = g * u_inv;  // orthonormal columns (eq. 31, R = F U⁻¹)
  Eigen::Matrix3d current_frame, rest_frame;
  current_frame << r2.col(0), r2.col(1), r2.col(0).cross(r2.col(1));
  rest_frame << e1, e2, n;
  r = current_frame * rest_frame.transpose();
  return true;
}

CorotationalElements::CorotationalElements(const ShellModel& model, bool corotational)
    : model_(model), corotational_(corotational) {
  const auto& elements = model.elements();
  const size_t count = elements.size();
  patch_offset_.assign(count + 1, 0);
  point_offset_.assign(count + 1, 0);
  for (size_t e = 0; e < count; ++e) {
    const size_t np = elements[e].patch.size();
    patch_offset_[e + 1] = patch_offset_[e] + 3 * static_cast<Eigen::Index>(np);
    point_offset_[e + 1] = point_offset_[e] + static_cast<int>(elements[e].basis.size());
  }
  const size_t points = static_cast<size_t>(point_offset_[count]);
  strain_offset_.assign(points + 1, 0);
  for (size_t e = 0; e < count; ++e)
    for (int q = point_offset_[e]; q < point_offset_[e + 1]; ++q)
      strain_offset_[q + 1] = strain_offset_[q] + 6 * static_cast<size_t>(patch_offset_[e + 1] - patch_offset_[e]);
  strain_.resize(strain_offset_[points]);
  membrane_material_.resize(points);
  bending_material_.resize(points);
  area_weight_.resize(points);
  tension_.assign(3 * points, 0.0);
  points_per_element_ = count > 0 ? static_cast<int>(elements[0].basis.size()) : 0;
  for (const ShellElement& el : elements)
    if (static_cast<int>(el.basis.size()) != points_per_element_) throw std::logic_error("elements with different quadrature rules");
  rest_patch_.resize(patch_offset_[count]);
  base_patch_.resize(patch_offset_[count]);
  x_patch_.resize(patch_offset_[count]);
  local_force_.resize(patch_offset_[count]);
  tangent_rows_.resize(2 * static_cast<size_t>(patch_offset_[count] / 3));
  patch_vertex_.resize(static_cast<size_t>(patch_offset_[count] / 3));
  identity_.resize(count);
  for (size_t e = 0; e < count; ++e) {
    identity_[e] = elements[e].identity;
    for (size_t p = 0; p < elements[e].patch.size(); ++p) patch_vertex_[static_cast<size_t>(patch_offset_[e] / 3) + p] = elements[e].patch[p];
  }
  rest_a1_.resize(count);
  rest_a2_.resize(count);
  rotation_.assign(count, Eigen::Matrix3d::Identity());
  turn_cosine_.assign(count, 1.0);
  local_energy_.assign(count, 0.0);
  // K_e for the assembly (see build_assembly): packed upper blocks of K_e, or of Tᵀ K_e T for a
  // componentwise fold T = W ⊗ I₃; the dense K_e of the other folded elements.
  std::vector<std::vector<double>> packed(count);
  std::vector<Eigen::MatrixXd> fold_weights(count);
  folded_stiffness_.resize(count);
  const Eigen::MatrixX3d& rest = model.extended().rest;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 16), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t e = range.begin(); e != range.end(); ++e) {
      const ShellElement& el = elements[e];
      Eigen::MatrixXd k = model.patch_stiffness(static_cast<int>(e));
      if (!el.identity) {
        fold_weights[e] = componentwise_fold(el);
        if (fold_weights[e].size() > 0)
          k = el.fold.transpose() * (k * el.fold);
        else
          folded_stiffness_[e] = std::move(k);
      }
      if (el.identity || fold_weights[e].size() > 0) {
        const Eigen::Index nb = k.rows() / 3;
        packed[e].reserve(static_cast<size_t>(9 * nb * (nb + 1) / 2));
        for (Eigen::Index b = 0; b < nb; ++b)
          for (Eigen::Index a = 0; a <= b; ++a)
            for (Eigen::Index j = 0; j < 3; ++j)
              for (Eigen::Index i = 0; i < 3; ++i) packed[e].push_back(k(3 * a + i, 3 * b + j));
      }
      const Eigen::Index np = static_cast<Eigen::Index>(el.patch.size());
      for (Eigen::Index p = 0; p < np; ++p) {
        base_patch_.segment<3>(patch_offset_[e] + 3 * p) = rest.row(el.patch[p]).transpose();
        rest_patch_.segment<3>(patch_offset_[e] + 3 * p) = el.reference.row(p).transpose();
      }
      // Tangent rows at the barycentre (the paper's choice for the element rotation).
      const PatchEvaluation centre = evaluate_patch(model.extended().topology, el.triangle, 1.0 / 3, 1.0 / 3);
      Eigen::Map<Eigen::Matrix<double, 2, Eigen::Dynamic>>(tangent_rows_.data() + 2 * (patch_offset_[e] / 3), 2, np) =
          centre.basis.middleRows(1, 2);  // kDv, kDw
      const Eigen::MatrixX3d& x = el.reference;
      rest_a1_[e] = (centre.basis.row(1) * x).transpose();
      rest_a2_[e] = (centre.basis.row(2) * x).transpose();
      for (size_t q = 0; q < el.basis.size(); ++q) {
        const size_t point = static_cast<size_t>(point_offset_[e]) + q;
        const SurfacePoint s = surface_point(el.basis[q], x);
        StrainMatrix m, b;
        strain_matrices(el.basis[q], s, m, b);
        double* strain = strain_.data() + strain_offset_[point];
        Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic>>(strain, 3, 3 * np) = m;
        Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic>>(strain + 9 * np, 3, 3 * np) = b;
        // (isotropic: K_m H and D_b H exactly as before; orthotropic: the law about el.warp)
        material_matrices(s, model.material(), el.warp, membrane_material_[point], bending_material_[point]);
        area_weight_[point] = el.weights[q] * s.j;
      }
    }
  });
  // Gather lists of the force scatter, in the order the element loop adds to each component.
  const DofMap& dofs = model.dofs();
  const int n3 = 3 * model.num_vertices();
  scatter_start_.assign(n3 + 1, 0);
  for (const ShellElement& el : elements)
    for (int v : el.patch)
      for (int c = 0; c < 3; ++c)
        for (const auto& [dof, w] : dofs.combination(v, c)) ++scatter_start_[dof + 1];
  for (int i = 0; i < n3; ++i) scatter_start_[i + 1] += scatter_start_[i];
  scatter_source_.resize(scatter_start_[n3]);
  scatter_weight_.resize(scatter_start_[n3]);
  std::vector<int> next(scatter_start_.begin(), scatter_start_.end() - 1);
  for (size_t e = 0; e < count; ++e)
    for (size_t p = 0; p < elements[e].patch.size(); ++p)
      for (int c = 0; c < 3; ++c)
        for (const auto& [dof, w] : dofs.combination(elements[e].patch[p], c)) {
          scatter_source_[next[dof]] = static_cast<int>(patch_offset_[e]) + 3 * static_cast<int>(p) + c;
          scatter_weight_[next[dof]++] = w;
        }
  build_assembly(packed, fold_weights);
  force_ = Eigen::VectorXd::Zero(n3);
}

void CorotationalElements::build_assembly(std::vector<std::vector<double>>& packed, const std::vector<Eigen::MatrixXd>& fold_weights) {
  const auto& elements = model_.elements();
  const Eigen::SparseMatrix<double>& pattern = model_.pattern();
  const int* outer = pattern.outerIndexPtr();
  const int* inner = pattern.innerIndexPtr();
  // The blocks (I, J), I ≤ J, column by column (rows ascend within a column).
  std::vector<int> block_of(static_cast<size_t>(pattern.nonZeros()), -1);
  for (int j = 0; j < model_.num_vertices(); ++j)
    for (int k = outer[3 * j]; k < outer[3 * j + 1] && inner[k] <= 3 * j; k += 3) {
      const int i = inner[k] / 3;
      block_of[k] = static_cast<int>(block_upper_.size());
      block_upper_.push_back(k);
      block_stride_upper_.push_back(model_.block_stride(j));
      block_lower_.push_back(static_cast<int>(std::lower_bound(inner + outer[3 * i], inner + outer[3 * i + 1], 3 * j) - inner));
      block_stride_lower_.push_back(model_.block_stride(i));
    }
  // Each gathered element's block (a, b), a ≤ b (indices into ShellElement::real), adds to one
  // of them: (real[a], real[b]) as it is, or transposed when real[a] > real[b]. Two passes
  // (count, fill) in element order. A componentwise fold T = W ⊗ I₃ commutes with the rotation,
  // Tᵀ R K_e Rᵀ T = R (Tᵀ K_e T) Rᵀ per block, and folds G ⊗ I₃ to (Wᵀ G W) ⊗ I₃: such an element
  // is gathered like an identity one, with Tᵀ K_e T and the basis rows N,α W.
  const size_t count = elements.size(), blocks = block_upper_.size();
  std::vector<int> contributions(blocks, 0);
  constexpr size_t lanes = kLanes;
  auto for_each_block = [&](auto&& add) {
    for (size_t e = 0; e < count; ++e) {
      if (packed[e].empty()) continue;
      const std::vector<int>& real = elements[e].real;
      const int* slots = model_.block_slots(static_cast<int>(e));
      const size_t m = real.size();
      for (size_t b = 0; b < m; ++b)
        for (size_t a = 0; a <= b; ++a) {
          const bool transpose = real[a] > real[b];
          add(e, a, b, transpose, block_of[slots[transpose ? b + m * a : a + m * b]]);
        }
    }
  };
  for_each_block([&](size_t, size_t, size_t, bool, int u) { ++contributions[u]; });
  block_groups_.assign(blocks + 1, 0);
  for (size_t u = 0; u < blocks; ++u) block_groups_[u + 1] = block_groups_[u] + (contributions[u] + kLanes - 1) / kLanes;
  const size_t groups = static_cast<size_t>(block_groups_[blocks]);
  const size_t rows_per_group = 3 * lanes * static_cast<size_t>(points_per_element_);
  group_element_.assign(lanes * groups, -1);
  group_stiffness_.assign(9 * lanes * groups, 0.0);
  group_rows_.assign(rows_per_group * groups, 0.0);
  std::fill(contributions.begin(), contributions.end(), 0);
  Eigen::Matrix<double, 2, Eigen::Dynamic> rows;
  for_each_block([&](size_t e, size_t a, size_t b, bool transpose, int u) {
    const int k = contributions[u]++;
    const size_t slot = lanes * static_cast<size_t>(block_groups_[u] + k / kLanes) + static_cast<size_t>(k % kLanes);
    const size_t group = slot / lanes, lane = slot % lanes;
    group_element_[slot] = static_cast<int>(e);
    const Eigen::Index ia = static_cast<Eigen::Index>(a), ib = static_cast<Eigen::Index>(b);
    for (int q = 0; q < points_per_element_; ++q) {
      rows = elements[e].basis[static_cast<size_t>(q)].middleRows(1, 2);  // N,1 and N,2
      if (fold_weights[e].size() > 0) rows = rows * fold_weights[e];
      double* products = group_rows_.data() + rows_per_group * group + 3 * lanes * static_cast<size_t>(q) + lane;
      products[0] = rows(0, ia) * rows(0, ib);
      products[lanes] = rows(0, ia) * rows(1, ib) + rows(1, ia) * rows(0, ib);
      products[2 * lanes] = rows(1, ia) * rows(1, ib);
    }
    const Eigen::Map<const Eigen::Matrix3d> block(packed[e].data() + 9 * (b * (b + 1) / 2 + a));
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) group_stiffness_[lanes * (9 * group + i + 3 * j) + lane] = transpose ? block(j, i) : block(i, j);
    if (a + 1 == elements[e].real.size() && b == a) std::vector<double>().swap(packed[e]);  // its last block
  });
  for (size_t g = 0; g < groups; ++g)
    for (size_t l = 1; l < lanes; ++l)
      if (group_element_[lanes * g + l] < 0) group_element_[lanes * g + l] = group_element_[lanes * g];  // zero block
  // The other folded elements (folded_stiffness_ set) add after the gather, colour by colour.
  for (const std::vector<int>& group : model_.color_groups()) {
    std::vector<int> folded;
    for (int e : group)
      if (folded_stiffness_[e].size() > 0) folded.push_back(e);
    if (!folded.empty()) folded_groups_.push_back(std::move(folded));
  }
}

void CorotationalElements::stiffness_product(size_t e, const double* d, double* kd, double* tension) const {
  const Eigen::Index dofs = patch_offset_[e + 1] - patch_offset_[e];
  const int first = point_offset_[e], points = point_offset_[e + 1] - first;
  const double* strain = strain_.data() + strain_offset_[static_cast<size_t>(first)];
  const Eigen::Matrix3d* membrane = membrane_material_.data() + first;
  const Eigen::Matrix3d* bending = bending_material_.data() + first;
  const double* weight = area_weight_.data() + first;
  if (dofs == 3 * kRegularPatch)
    element_product<3 * kRegularPatch>(dofs, points, strain, membrane, bending, weight, d, kd, tension);
  else
    element_product<Eigen::Dynamic>(dofs, points, strain, membrane, bending, weight, d, kd, tension);
}

void CorotationalElements::evaluate(const Eigen::VectorXd& u) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t count = model_.elements().size();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 32), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t e = range.begin(); e != range.end(); ++e) {
      // Flat per-patch-vertex arrays in element order (not the ShellElement objects): a stream.
      const Eigen::Index offset = patch_offset_[e], np = (patch_offset_[e + 1] - offset) / 3;
      auto x = x_patch_.segment(offset, 3 * np);
      const int* vertex = patch_vertex_.data() + offset / 3;
      if (identity_[e])
        for (Eigen::Index p = 0; p < np; ++p)
          x.segment<3>(3 * p) = base_patch_.segment<3>(offset + 3 * p) + u.segment<3>(3 * static_cast<Eigen::Index>(vertex[p]));
      else
        x = base_patch_.segment(offset, 3 * np) + model_.patch_vector(static_cast<int>(e), u);
      if (!corotational_ || frozen_rotations_) continue;
      const double* rows = tangent_rows_.data() + 2 * (offset / 3);
      Eigen::Vector3d a1 = Eigen::Vector3d::Zero(), a2 = Eigen::Vector3d::Zero();
      for (Eigen::Index p = 0; p < np; ++p) {
        a1 += rows[2 * p] * x.segment<3>(3 * p);
        a2 += rows[2 * p + 1] * x.segment<3>(3 * p);
      }
      const Eigen::Matrix3d previous = rotation_[e];
      extract_rotation(rest_a1_[e], rest_a2_[e], a1, a2, rotation_[e]);  // keeps the last R if degenerate
      // cos of the angle of Rₒₗ𝒹ᵀ R: (trace − 1) / 2.
      turn_cosine_[e] = 0.5 * (previous.cwiseProduct(rotation_[e]).sum() - 1.0);
    }
  });
  double cosine = 1.0;
  if (corotational_ && !frozen_rotations_)
    for (size_t e = 0; e < count; ++e) cosine = std::min(cosine, turn_cosine_[e]);
  rotation_change_ = std::acos(std::clamp(cosine, -1.0, 1.0));
  rotate_ms_ = ms_since(t0);
  total_rotate_ms_ += rotate_ms_;
  const auto t1 = std::chrono::steady_clock::now();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 32), [&](const tbb::blocked_range<size_t>& range) {
    PatchVector d, kd;
    for (size_t e = range.begin(); e != range.end(); ++e) {
      const Eigen::Matrix3d& r = rotation_[e];
      const Eigen::Matrix3d rt = r.transpose();
      const Eigen::Index offset = patch_offset_[e], dofs = patch_offset_[e + 1] - offset, np = dofs / 3;
      d.resize(dofs);
      kd.resize(dofs);
      for (Eigen::Index p = 0; p < np; ++p)
        d.segment<3>(3 * p) = rt * x_patch_.segment<3>(offset + 3 * p) - rest_patch_.segment<3>(offset + 3 * p);
      // With the tension stiffening: the tensile membrane force of the corotated strain.
      stiffness_product(e, d.data(), kd.data(), tension_stiffening_ ? tension_.data() + 3 * static_cast<size_t>(point_offset_[e]) : nullptr);
      local_energy_[e] = 0.5 * d.dot(kd);
      for (Eigen::Index p = 0; p < np; ++p) local_force_.segment<3>(offset + 3 * p) = -(r * kd.segment<3>(3 * p));
    }
  });
  // Each component sums its element contributions in element order: deterministic, and the
  // same sums as a serial element loop.
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, force_.size(), 512), [&](const tbb::blocked_range<Eigen::Index>& range) {
    for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
      double sum = 0.0;
      for (int k = scatter_start_[i]; k < scatter_start_[i + 1]; ++k) sum += scatter_weight_[k] * local_force_(scatter_source_[k]);
      force_(i) = sum;
    }
  });
  energy_ = 0.0;
  for (size_t e = 0; e < count; ++e) energy_ += local_energy_[e];  // element order: deterministic sum
  force_ms_ = ms_since(t1);
}

Eigen::SparseMatrix<double> CorotationalElements::assemble_stiffness() const {
  Eigen::SparseMatrix<double> k;
  assemble_stiffness(k);
  return k;
}

void CorotationalElements::assemble_stiffness(Eigen::SparseMatrix<double>& k) const {
  const Eigen::SparseMatrix<double>& pattern = model_.pattern();
  if (k.rows() != pattern.rows() || k.cols() != pattern.cols() || !k.isCompressed() || k.nonZeros() != pattern.nonZeros())
    k = pattern;
  else
    std::fill(k.valuePtr(), k.valuePtr() + k.nonZeros(), 0.0);
  add_stiffness(1.0, k);
}

void CorotationalElements::add_stiffness(double scale, Eigen::SparseMatrix<double>& k) const {
  if (folded_groups_.empty()) {  // the gather alone: each block summed once, added scaled
    accumulate_stiffness(scale, /*overwrite=*/false, k.valuePtr());
    return;
  }
  // With folded elements the blocks are completed (gather, then folded contributions) before
  // they are scaled, in a scratch copy of the values: the same sums, in the same order, whatever
  // the scale.
  scratch_.resize(static_cast<size_t>(k.nonZeros()));
  accumulate_stiffness(1.0, /*overwrite=*/true, scratch_.data());
  double* values = k.valuePtr();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, scratch_.size(), 1 << 14), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) values[i] += scale * scratch_[i];
  });
}

void CorotationalElements::set_stiffness(double scale, Eigen::SparseMatrix<double>& k) const {
  if (folded_groups_.empty()) {
    accumulate_stiffness(scale, /*overwrite=*/true, k.valuePtr());
    return;
  }
  scratch_.resize(static_cast<size_t>(k.nonZeros()));
  accumulate_stiffness(1.0, /*overwrite=*/true, scratch_.data());
  double* values = k.valuePtr();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, scratch_.size(), 1 << 14), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) values[i] = scale * scratch_[i];
  });
}

void CorotationalElements::accumulate_stiffness(double scale, bool overwrite, double* values) const {
  const auto sum = assembly_avx2::supported() ? assembly_avx2::sum_block : assembly_avx2::sum_block_portable;
  const double* rotations = rotation_.empty() ? nullptr : rotation_.front().data();  // Matrix3d: 9 contiguous values each
  const double* tension = tension_stiffening_ ? tension_.data() : nullptr;
  // The gather covers the whole pattern: each block is summed once and added, scaled, once.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, block_upper_.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t u = range.begin(); u != range.end(); ++u) {
      double acc[9];
      const size_t first = static_cast<size_t>(block_groups_[u]);
      sum(block_groups_[u + 1] - block_groups_[u], group_element_.data() + kLanes * first, rotations,
          group_stiffness_.data() + 9 * kLanes * first, group_rows_.data() + 3 * kLanes * static_cast<size_t>(points_per_element_) * first,
          tension, point_offset_.data(), points_per_element_, acc);
      double* upper = values + block_upper_[u];
      double* lower = values + block_lower_[u];
      const int su = block_stride_upper_[u], sl = block_stride_lower_[u];
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
          const double value = scale * acc[i + 3 * j];
          if (overwrite) {
            upper[j * su + i] = value;
            if (lower != upper) lower[i * sl + j] = value;  // a diagonal block is written once, as summed
          } else {
            upper[j * su + i] += value;
            if (lower != upper) lower[i * sl + j] += value;
          }
        }
    }
  });
  // Folded elements: A = R K_e Rᵀ in patch coordinates, folded to Tᵀ A T on the real vertices
  // (T = ShellElement::fold, mostly unit columns) and added block by block, colour by colour:
  // the elements of one colour share no vertex, so every entry sums in a fixed order.
  for (const std::vector<int>& group : folded_groups_)
    tbb::parallel_for(tbb::blocked_range<size_t>(0, group.size(), 4), [&](const tbb::blocked_range<size_t>& range) {
      Eigen::MatrixXd rotated, half, folded;  // A, A T, Tᵀ A T
      for (size_t i = range.begin(); i != range.end(); ++i) {
        const int e = group[i];
        const Eigen::Matrix3d& r = rotation_[e];
        const Eigen::MatrixXd& ke = folded_stiffness_[e];
        const Eigen::Index nb = ke.rows() / 3;
        const ShellElement& el = model_.elements()[e];
        rotated.resize(ke.rows(), ke.cols());
        for (Eigen::Index b = 0; b < nb; ++b)
          for (Eigen::Index a = 0; a <= b; ++a) {
            Eigen::Matrix3d block = r * ke.block<3, 3>(3 * a, 3 * b) * r.transpose();
            if (tension_stiffening_)
              for (int q = point_offset_[e]; q < point_offset_[e + 1]; ++q) {
                const auto rows = el.basis[static_cast<size_t>(q - point_offset_[e])].middleRows(1, 2);
                const double* t = tension_.data() + 3 * static_cast<size_t>(q);
                block.diagonal().array() += rows(0, a) * rows(0, b) * t[0] +
                                            (rows(0, a) * rows(1, b) + rows(1, a) * rows(0, b)) * t[1] +
                                            rows(1, a) * rows(1, b) * t[2];
              }
            rotated.block<3, 3>(3 * a, 3 * b) = block;
            rotated.block<3, 3>(3 * b, 3 * a) = block.transpose();
          }
        const Eigen::SparseMatrix<double>& fold = el.fold;
        half.setZero(rotated.rows(), fold.cols());
        for (Eigen::Index j = 0; j < fold.cols(); ++j)
          for (Eigen::SparseMatrix<double>::InnerIterator it(fold, j); it; ++it) half.col(j) += it.value() * rotated.col(it.row());
        folded.setZero(fold.cols(), fold.cols());
        for (Eigen::Index row = 0; row < fold.cols(); ++row)
          for (Eigen::SparseMatrix<double>::InnerIterator it(fold, row); it; ++it) folded.row(row) += it.value() * half.row(it.row());
        for (size_t b = 0; b < el.real.size(); ++b)
          for (size_t a = 0; a < el.real.size(); ++a)
            model_.add_block(e, a, b, scale * folded.block<3, 3>(3 * static_cast<Eigen::Index>(a), 3 * static_cast<Eigen::Index>(b)), values);
      }
    });
}

Eigen::VectorXd CorotationalElements::tension_force(const Eigen::VectorXd& u) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(u.size());
  const std::vector<ShellElement>& elements = model_.elements();
  for (size_t e = 0; e < elements.size(); ++e) {
    const Eigen::Index np = (patch_offset_[e + 1] - patch_offset_[e]) / 3;
    const Eigen::VectorXd x = base_patch_.segment(patch_offset_[e], 3 * np) + model_.patch_vector(static_cast<int>(e), u);
    Eigen::VectorXd local = Eigen::VectorXd::Zero(3 * np);
    for (int q = point_offset_[e]; q < point_offset_[e + 1]; ++q) {
      const BasisMatrix& basis = elements[e].basis[static_cast<size_t>(q - point_offset_[e])];
      Eigen::Vector3d a1 = Eigen::Vector3d::Zero(), a2 = Eigen::Vector3d::Zero();
      for (Eigen::Index p = 0; p < np; ++p) {
        a1 += basis(1, p) * x.segment<3>(3 * p);
        a2 += basis(2, p) * x.segment<3>(3 * p);
      }
      const double* t = tension_.data() + 3 * static_cast<size_t>(q);  // w j n₊¹¹, n₊¹², n₊²²
      const Eigen::Vector3d s1 = t[0] * a1 + t[1] * a2, s2 = t[1] * a1 + t[2] * a2;
      for (Eigen::Index p = 0; p < np; ++p) local.segment<3>(3 * p) -= basis(1, p) * s1 + basis(2, p) * s2;
    }
    model_.add_patch_vector(static_cast<int>(e), local, f);
  }
  return f;
}

Eigen::MatrixX2d CorotationalElements::membrane_principal_strains(const Eigen::VectorXd& u) const {
  const size_t count = model_.elements().size();
  Eigen::MatrixX2d out(static_cast<Eigen::Index>(count), 2);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 64), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t e = range.begin(); e != range.end(); ++e) {
      const Eigen::VectorXd x =
          base_patch_.segment(patch_offset_[e], patch_offset_[e + 1] - patch_offset_[e]) + model_.patch_vector(static_cast<int>(e), u);
      const double* rows = tangent_rows_.data() + 2 * (patch_offset_[e] / 3);
      Eigen::Vector3d a1 = Eigen::Vector3d::Zero(), a2 = Eigen::Vector3d::Zero();
      for (Eigen::Index p = 0; p < x.size() / 3; ++p) {
        a1 += rows[2 * p] * x.segment<3>(3 * p);
        a2 += rows[2 * p + 1] * x.segment<3>(3 * p);
      }
      Eigen::Matrix2d g, rest;
      g << a1.dot(a1), a1.dot(a2), a1.dot(a2), a2.dot(a2);
      rest << rest_a1_[e].dot(rest_a1_[e]), rest_a1_[e].dot(rest_a2_[e]), rest_a1_[e].dot(rest_a2_[e]),
          rest_a2_[e].dot(rest_a2_[e]);
      // Eigenvalues of G⁻¹E: the symmetric problem L⁻¹ E L⁻ᵀ with G = L Lᵀ.
      const Eigen::Matrix2d l = rest.llt().matrixL();
      const Eigen::Matrix2d l_inv = l.inverse();
      const Eigen::Matrix2d strain = 0.5 * l_inv * (g - rest) * l_inv.transpose();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(0.5 * (strain + strain.transpose()),
                                                               Eigen::EigenvaluesOnly);
      out.row(static_cast<Eigen::Index>(e)) = eig.eigenvalues().transpose();
    }
  });
  return out;
}

double CorotationalElements::element_energy(int e, const Eigen::Matrix3d& r, const Eigen::VectorXd& x_patch) const {
  const Eigen::Matrix3d rt = r.transpose();
  PatchVector d(x_patch.size()), kd(x_patch.size());
  for (Eigen::Index i = 0; i < x_patch.size(); i += 3)
    d.segment<3>(i) = rt * x_patch.segment<3>(i) - rest_patch_.segment<3>(patch_offset_[e] + i);
  stiffness_product(static_cast<size_t>(e), d.data(), kd.data());
  return 0.5 * d.dot(kd);
}

Eigen::VectorXd CorotationalElements::element_force(int e, const Eigen::Matrix3d& r, const Eigen::VectorXd& x_patch) const {
  const Eigen::Matrix3d rt = r.transpose();
  PatchVector d(x_patch.size()), kd(x_patch.size());
  for (Eigen::Index i = 0; i < x_patch.size(); i += 3)
    d.segment<3>(i) = rt * x_patch.segment<3>(i) - rest_patch_.segment<3>(patch_offset_[e] + i);
  stiffness_product(static_cast<size_t>(e), d.data(), kd.data());
  Eigen::VectorXd f(x_patch.size());
  for (Eigen::Index i = 0; i < x_patch.size(); i += 3) f.segment<3>(i) = -(r * kd.segment<3>(i));
  return f;
}

}  // namespace clothsim

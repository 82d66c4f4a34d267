#include "sim/dynamics/corotation.hpp"

#include "sim/shell/element.hpp"
#include "sim/subdivision/box_spline.hpp"
#include "sim/subdivision/patch.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>

namespace clothsim {

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Applies R (or Rᵀ) to every 3-vector of a patch vector.
Eigen::VectorXd rotate_blocks(const Eigen::Matrix3d& r, const Eigen::VectorXd& x) {
  Eigen::VectorXd out(x.size());
  for (Eigen::Index i = 0; i < x.size(); i += 3) out.segment<3>(i) = r * x.segment<3>(i);
  return out;
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
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(g.transpose() * g);
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
  stiffness_.resize(count);
  rest_patch_.resize(count);
  tangent_rows_.resize(count);
  rest_a1_.resize(count);
  rest_a2_.resize(count);
  rotation_.assign(count, Eigen::Matrix3d::Identity());
  membrane_.resize(count);
  membrane_material_.resize(count);
  area_weight_.resize(count);
  geometric_stiffness_.resize(count);
  local_force_.resize(count);
  local_energy_.assign(count, 0.0);
  const Eigen::MatrixX3d& rest = model.extended().rest;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 16), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t e = range.begin(); e != range.end(); ++e) {
      const ShellElement& el = elements[e];
      stiffness_[e] = model.patch_stiffness(static_cast<int>(e));
      const Eigen::Index np = static_cast<Eigen::Index>(el.patch.size());
      rest_patch_[e].resize(3 * np);
      for (Eigen::Index p = 0; p < np; ++p) rest_patch_[e].segment<3>(3 * p) = rest.row(el.patch[p]).transpose();
      // Tangent rows at the barycentre (the paper's choice for the element rotation).
      const PatchEvaluation centre = evaluate_patch(model.extended().topology, el.triangle, 1.0 / 3, 1.0 / 3);
      tangent_rows_[e] = centre.basis.middleRows(1, 2);  // kDv, kDw
      Eigen::MatrixX3d x(np, 3);
      for (Eigen::Index p = 0; p < np; ++p) x.row(p) = rest.row(el.patch[p]);
      rest_a1_[e] = (tangent_rows_[e].row(0) * x).transpose();
      rest_a2_[e] = (tangent_rows_[e].row(1) * x).transpose();
      for (size_t q = 0; q < el.basis.size(); ++q) {
        const SurfacePoint s = surface_point(el.basis[q], x);
        StrainMatrix m, b;
        strain_matrices(el.basis[q], s, m, b);
        membrane_[e].push_back(m);
        membrane_material_[e].push_back(model.material().membrane_stiffness() * material_matrix(s, model.material().poisson_ratio));
        area_weight_[e].push_back(el.weights[q] * s.j);
      }
      geometric_stiffness_[e] = Eigen::MatrixXd::Zero(np, np);
    }
  });
  force_ = Eigen::VectorXd::Zero(3 * model.num_vertices());
}

void CorotationalElements::evaluate(const Eigen::VectorXd& u) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t count = stiffness_.size();
  std::vector<Eigen::VectorXd> x_patch(count);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 32), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t e = range.begin(); e != range.end(); ++e) {
      x_patch[e] = rest_patch_[e] + model_.patch_vector(static_cast<int>(e), u);
      if (!corotational_) continue;
      const Eigen::Index np = x_patch[e].size() / 3;
      Eigen::Vector3d a1 = Eigen::Vector3d::Zero(), a2 = Eigen::Vector3d::Zero();
      for (Eigen::Index p = 0; p < np; ++p) {
        a1 += tangent_rows_[e](0, p) * x_patch[e].segment<3>(3 * p);
        a2 += tangent_rows_[e](1, p) * x_patch[e].segment<3>(3 * p);
      }
      extract_rotation(rest_a1_[e], rest_a2_[e], a1, a2, rotation_[e]);  // keeps the last R if degenerate
    }
  });
  rotate_ms_ = ms_since(t0);
  const auto t1 = std::chrono::steady_clock::now();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 32), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t e = range.begin(); e != range.end(); ++e) {
      const Eigen::Matrix3d& r = rotation_[e];
      const Eigen::VectorXd d = rotate_blocks(r.transpose(), x_patch[e]) - rest_patch_[e];
      const Eigen::VectorXd kd = stiffness_[e] * d;
      local_energy_[e] = 0.5 * d.dot(kd);
      local_force_[e] = -rotate_blocks(r, kd);
      if (!geometric_) continue;
      // Tension stiffening from the membrane force of the corotated strain.
      const ShellElement& el = model_.elements()[e];
      Eigen::MatrixXd& g = geometric_stiffness_[e];
      g.setZero();
      for (size_t q = 0; q < membrane_[e].size(); ++q) {
        const Eigen::Vector3d n = membrane_material_[e][q] * (membrane_[e][q] * d);  // n¹¹, n²², n¹²
        Eigen::Matrix2d stress;
        stress << n(0), n(2), n(2), n(1);
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(stress);
        const Eigen::Vector2d tension = eig.eigenvalues().cwiseMax(0.0);
        if (tension.maxCoeff() <= 0.0) continue;
        const Eigen::Matrix2d positive = eig.eigenvectors() * tension.asDiagonal() * eig.eigenvectors().transpose();
        const Eigen::Matrix<double, 2, Eigen::Dynamic> rows = el.basis[q].middleRows(1, 2);  // N,1 and N,2
        g.noalias() += area_weight_[e][q] * (rows.transpose() * positive * rows);
      }
    }
  });
  force_.setZero();
  energy_ = 0.0;
  for (size_t e = 0; e < count; ++e) {  // element order: deterministic sums
    model_.add_patch_vector(static_cast<int>(e), local_force_[e], force_);
    energy_ += local_energy_[e];
  }
  force_ms_ = ms_since(t1);
}

Eigen::SparseMatrix<double> CorotationalElements::assemble_stiffness() const {
  Eigen::SparseMatrix<double> k = model_.zero_matrix();
  for (const std::vector<int>& group : model_.color_groups())
    tbb::parallel_for(tbb::blocked_range<size_t>(0, group.size(), 16), [&](const tbb::blocked_range<size_t>& range) {
      Eigen::MatrixXd rotated;
      double* values = k.valuePtr();
      for (size_t i = range.begin(); i != range.end(); ++i) {
        const int e = group[i];
        const Eigen::Matrix3d& r = rotation_[e];
        const Eigen::MatrixXd& ke = stiffness_[e];
        const Eigen::Index nb = ke.rows() / 3;
        const bool direct = model_.elements()[e].identity;
        if (!direct) rotated.resize(ke.rows(), ke.cols());
        // R K_e Rᵀ block by block, using the symmetry of K_e.
        const Eigen::MatrixXd& geo = geometric_stiffness_[e];
        for (Eigen::Index b = 0; b < nb; ++b)
          for (Eigen::Index a = 0; a <= b; ++a) {
            Eigen::Matrix3d block = r * ke.block<3, 3>(3 * a, 3 * b) * r.transpose();
            if (geometric_) block.diagonal().array() += geo(a, b);
            if (direct) {
              model_.add_block(e, static_cast<size_t>(a), static_cast<size_t>(b), block, values);
              if (a != b) model_.add_block(e, static_cast<size_t>(b), static_cast<size_t>(a), block.transpose(), values);
            } else {
              rotated.block<3, 3>(3 * a, 3 * b) = block;
              rotated.block<3, 3>(3 * b, 3 * a) = block.transpose();
            }
          }
        if (!direct) model_.add_patch_matrix(e, rotated, k);
      }
    });
  return k;
}

Eigen::MatrixX2d CorotationalElements::membrane_principal_strains(const Eigen::VectorXd& u) const {
  const size_t count = stiffness_.size();
  Eigen::MatrixX2d out(static_cast<Eigen::Index>(count), 2);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 64), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t e = range.begin(); e != range.end(); ++e) {
      const Eigen::VectorXd x = rest_patch_[e] + model_.patch_vector(static_cast<int>(e), u);
      Eigen::Vector3d a1 = Eigen::Vector3d::Zero(), a2 = Eigen::Vector3d::Zero();
      for (Eigen::Index p = 0; p < x.size() / 3; ++p) {
        a1 += tangent_rows_[e](0, p) * x.segment<3>(3 * p);
        a2 += tangent_rows_[e](1, p) * x.segment<3>(3 * p);
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
  const Eigen::VectorXd d = rotate_blocks(r.transpose(), x_patch) - rest_patch_[e];
  return 0.5 * d.dot(stiffness_[e] * d);
}

Eigen::VectorXd CorotationalElements::element_force(int e, const Eigen::Matrix3d& r, const Eigen::VectorXd& x_patch) const {
  const Eigen::VectorXd d = rotate_blocks(r.transpose(), x_patch) - rest_patch_[e];
  return -rotate_blocks(r, stiffness_[e] * d);
}

}  // namespace clothsim

#include "sim/shell/element.hpp"

#include "sim/subdivision/box_spline.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <stdexcept>

namespace clothsim {

SurfacePoint surface_point(const BasisMatrix& basis, const Eigen::MatrixX3d& x) {
  SurfacePoint s;
  s.a1 = (basis.row(kDv) * x).transpose();
  s.a2 = (basis.row(kDw) * x).transpose();
  s.a11 = (basis.row(kDvv) * x).transpose();
  s.a12 = (basis.row(kDvw) * x).transpose();
  s.a22 = (basis.row(kDww) * x).transpose();
  const Eigen::Vector3d n = s.a1.cross(s.a2);
  s.j = n.norm();
  s.a3 = n / s.j;
  return s;
}

Eigen::Matrix3d material_matrix(const SurfacePoint& s, double nu) {
  Eigen::Matrix2d metric;
  metric << s.a1.dot(s.a1), s.a1.dot(s.a2), s.a1.dot(s.a2), s.a2.dot(s.a2);
  const Eigen::Matrix2d inv = metric.inverse();
  const double c11 = inv(0, 0), c22 = inv(1, 1), c12 = inv(0, 1);
  Eigen::Matrix3d h;
  h << c11 * c11, nu * c11 * c22 + (1 - nu) * c12 * c12, c11 * c12,  //
      0, c22 * c22, c22 * c12,                                       //
      0, 0, 0.5 * ((1 - nu) * c11 * c22 + (1 + nu) * c12 * c12);
  h(1, 0) = h(0, 1);
  h(2, 0) = h(0, 2);
  h(2, 1) = h(1, 2);
  return h;
}

Eigen::Matrix3d curvilinear_matrix(const SurfacePoint& s, const Eigen::Vector3d& warp, const Eigen::Matrix3d& law) {
  const Eigen::Vector3d in_plane = warp - warp.dot(s.a3) * s.a3;
  if (!(in_plane.norm() > 1e-6 * warp.norm()))
    throw std::invalid_argument("the warp direction is normal to the surface (or zero): no grain to measure from");
  const Eigen::Vector3d g1 = in_plane.normalized(), g2 = s.a3.cross(g1);
  Eigen::Matrix2d metric;
  metric << s.a1.dot(s.a1), s.a1.dot(s.a2), s.a1.dot(s.a2), s.a2.dot(s.a2);
  const Eigen::Matrix2d inv = metric.inverse();
  const Eigen::Vector3d dual1 = inv(0, 0) * s.a1 + inv(0, 1) * s.a2, dual2 = inv(1, 0) * s.a1 + inv(1, 1) * s.a2;
  Eigen::Matrix2d t;  // t(α, i) = a^α · g_i
  t << dual1.dot(g1), dual1.dot(g2), dual2.dot(g1), dual2.dot(g2);
  return voigt_transform(t, law);
}

void material_matrices(const SurfacePoint& s, const ShellMaterial& material, const Eigen::Vector3d& warp,
                       Eigen::Matrix3d& membrane, Eigen::Matrix3d& bending) {
  if (!material.orthotropic()) {
    const Eigen::Matrix3d h = material_matrix(s, material.poisson_ratio);
    membrane = material.membrane_stiffness() * h;
    bending = material.bending_stiffness() * h;
    return;
  }
  membrane = curvilinear_matrix(s, warp, material.membrane_law());
  bending = curvilinear_matrix(s, warp, material.bending_law());
}

void strain_matrices(const BasisMatrix& basis, const SurfacePoint& s, StrainMatrix& membrane, StrainMatrix& bending) {
  const Eigen::Index n = basis.cols();
  membrane.resize(3, 3 * n);
  bending.resize(3, 3 * n);
  const double inv_j = 1.0 / s.j;
  const Eigen::Vector3d a2xa3 = s.a2.cross(s.a3), a3xa1 = s.a3.cross(s.a1);
  const Eigen::Vector3d* second[3] = {&s.a11, &s.a22, &s.a12};
  const int row_of[3] = {kDvv, kDww, kDvw};
  for (Eigen::Index i = 0; i < n; ++i) {
    const double n1 = basis(kDv, i), n2 = basis(kDw, i);
    membrane.block<1, 3>(0, 3 * i) = n1 * s.a1.transpose();
    membrane.block<1, 3>(1, 3 * i) = n2 * s.a2.transpose();
    membrane.block<1, 3>(2, 3 * i) = (n2 * s.a1 + n1 * s.a2).transpose();
    for (int r = 0; r < 3; ++r) {
      const Eigen::Vector3d& aab = *second[r];
      const Eigen::Vector3d row = -basis(row_of[r], i) * s.a3 +
                                  inv_j * (n1 * aab.cross(s.a2) + n2 * s.a1.cross(aab)) +
                                  (s.a3.dot(aab) * inv_j) * (n1 * a2xa3 + n2 * a3xa1);
      bending.block<1, 3>(r, 3 * i) = (r == 2 ? 2.0 : 1.0) * row.transpose();
    }
  }
}

Eigen::Matrix<double, 6, 1> nonlinear_strains(const BasisMatrix& basis, const Eigen::MatrixX3d& rest,
                                              const Eigen::MatrixX3d& deformed) {
  const SurfacePoint r = surface_point(basis, rest), d = surface_point(basis, deformed);
  Eigen::Matrix<double, 6, 1> e;
  e(0) = 0.5 * (d.a1.dot(d.a1) - r.a1.dot(r.a1));
  e(1) = 0.5 * (d.a2.dot(d.a2) - r.a2.dot(r.a2));
  e(2) = d.a1.dot(d.a2) - r.a1.dot(r.a2);
  e(3) = r.a11.dot(r.a3) - d.a11.dot(d.a3);
  e(4) = r.a22.dot(r.a3) - d.a22.dot(d.a3);
  e(5) = 2.0 * (r.a12.dot(r.a3) - d.a12.dot(d.a3));
  return e;
}

ElementMatrix element_stiffness(const std::vector<BasisMatrix>& basis, const std::vector<double>& weights,
                                const Eigen::MatrixX3d& rest, const ShellMaterial& material,
                                const Eigen::Vector3d& warp) {
  const Eigen::Index dofs = 3 * rest.rows();
  ElementMatrix k = ElementMatrix::Zero(dofs, dofs);
  StrainMatrix m, b;
  Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxPatchDofs> hm_m, hb_b;
  for (size_t q = 0; q < basis.size(); ++q) {
    const SurfacePoint s = surface_point(basis[q], rest);
    if (material.orthotropic()) {
      Eigen::Matrix3d hm, hb;
      material_matrices(s, material, warp, hm, hb);
      strain_matrices(basis[q], s, m, b);
      const double scale = weights[q] * s.j;
      hm_m.noalias() = (scale * hm) * m;
      hb_b.noalias() = (scale * hb) * b;
      k.noalias() += m.transpose() * hm_m;
      k.noalias() += b.transpose() * hb_b;
      continue;
    }
    const Eigen::Matrix3d h = material_matrix(s, material.poisson_ratio);
    strain_matrices(basis[q], s, m, b);
    const double scale = weights[q] * s.j;
    hm_m.noalias() = ((scale * material.membrane_stiffness()) * h) * m;
    hb_b.noalias() = ((scale * material.bending_stiffness()) * h) * b;
    k.noalias() += m.transpose() * hm_m;
    k.noalias() += b.transpose() * hb_b;
  }
  return k;
}

}  // namespace clothsim

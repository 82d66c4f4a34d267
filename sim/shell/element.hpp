// The linear Kirchhoff–Love subdivision shell element (Cirak et al. 2000 eqs. 21–22; paper
// §4.2 eqs. 24–27; docs/formulas.md §5 Kirchhoff–Love strains, §6 Material law).
//
// At a point of an element with patch vertices I = 0 .. n−1 (basis rows from patch.hpp) and
// rest positions X_I, the linearised membrane and bending strains in Voigt order
// [ε₁₁, ε₂₂, 2ε₁₂] are α = Σ M_I u_I and β = Σ B_I u_I (local DOF order [x0 y0 z0 x1 y1 z1 ...]).
// The element stiffness is K_e = Σ_q w_q j (K_m Mᵀ H M + D_b Bᵀ H B), with H the isotropic
// material matrix in the curvilinear frame, K_m = E t/(1 − ν²), D_b = E t³/(12(1 − ν²)); for an
// orthotropic material K_m H and D_b H are replaced by the laws of docs/materials.md turned into
// the curvilinear frame about the element's warp direction (curvilinear_matrix).
#pragma once

#include "sim/shell/material.hpp"

#include <Eigen/Core>

namespace clothsim {

// Largest patch: an irregular vertex of valence 12 has 12 + 6 control vertices.
constexpr int kMaxPatchVertices = 18;
constexpr int kMaxPatchDofs = 3 * kMaxPatchVertices;

using BasisMatrix = Eigen::Matrix<double, 6, Eigen::Dynamic>;  // rows: BasisRow of box_spline.hpp
// 3 × 3n, stack-allocated.
using StrainMatrix = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxPatchDofs>;
// 3n × 3n element matrix, stack-allocated.
using ElementMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxPatchDofs, kMaxPatchDofs>;

// Geometry of the reference surface at one point.
struct SurfacePoint {
  Eigen::Vector3d a1, a2, a3;     // covariant tangents and unit normal
  Eigen::Vector3d a11, a12, a22;  // second derivatives of the position
  double j = 0.0;                 // area element |a1 × a2| (dA = j dθ¹ dθ²)
};

SurfacePoint surface_point(const BasisMatrix& basis, const Eigen::MatrixX3d& x);

// Isotropic constitutive matrix in Voigt form in the curvilinear frame (docs/formulas.md §6,
// Material law).
Eigen::Matrix3d material_matrix(const SurfacePoint& s, double poisson_ratio);

// Constitutive matrix in Voigt form in the curvilinear frame for a plane-stress matrix `law` given
// in the orthonormal frame (g₁, g₂ = a₃ × g₁), g₁ the `warp` direction projected into the tangent
// plane and normalised (docs/materials.md, transform to curvilinear components):
// H^{αβγδ} = Σ law_{ijkl} (a^α·g_i)(a^β·g_j)(a^γ·g_k)(a^δ·g_l), a^α the dual (contravariant) basis.
// Throws std::invalid_argument when `warp` is (nearly) normal to the surface.
Eigen::Matrix3d curvilinear_matrix(const SurfacePoint& s, const Eigen::Vector3d& warp, const Eigen::Matrix3d& law);

// The membrane and bending matrices (stiffness included) at a point: for an isotropic material
// K_m·material_matrix(s, ν) and D_b·material_matrix(s, ν) (bit for bit as always; `warp` unused),
// for an orthotropic one curvilinear_matrix with the material's membrane_law() and bending_law().
void material_matrices(const SurfacePoint& s, const ShellMaterial& material, const Eigen::Vector3d& warp,
                       Eigen::Matrix3d& membrane, Eigen::Matrix3d& bending);

// Strain–displacement matrices (3 × 3n) of the linearised membrane and bending strains.
void strain_matrices(const BasisMatrix& basis, const SurfacePoint& s, StrainMatrix& membrane, StrainMatrix& bending);

// Exact (nonlinear) membrane and bending strains of the deformed positions x relative to the
// rest positions X, [α₁₁, α₂₂, 2α₁₂, β₁₁, β₂₂, 2β₁₂] with α_αβ = ½(a_α·a_β − A_α·A_β) and
// β_αβ = A_αβ·A₃ − a_αβ·a₃. Their derivative at x = X is the linear strain: used to test it.
Eigen::Matrix<double, 6, 1> nonlinear_strains(const BasisMatrix& basis, const Eigen::MatrixX3d& rest,
                                              const Eigen::MatrixX3d& deformed);

// Σ_q weight_q · j (K_m Mᵀ H M + D_b Bᵀ H B) over the given quadrature points (3n × 3n); for an
// orthotropic material Σ_q weight_q · j (Mᵀ H_m M + Bᵀ H_b B) with material_matrices and the
// element's rest `warp` direction.
ElementMatrix element_stiffness(const std::vector<BasisMatrix>& basis, const std::vector<double>& weights,
                                const Eigen::MatrixX3d& rest, const ShellMaterial& material,
                                const Eigen::Vector3d& warp = Eigen::Vector3d::Zero());

}  // namespace clothsim

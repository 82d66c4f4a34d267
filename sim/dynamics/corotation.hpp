// Corotational subdivision elements (paper §4.3, eqs. 21 and 29–31).
//
// Each element gets one rotation R, taken at its barycentre from the deformation gradient of the
// mid-surface: with rest tangents A_α and current tangents a_α, F maps the rest tangent plane to
// the current one; its 2D polar decomposition F = R U (U the 2 × 2 stretch in the rest plane,
// eq. 30) gives the in-plane rotation, completed by the normals (eq. 31). The rest stiffness K_e
// (patch coordinates) is computed once; with R frozen,
//     energy  E_e = ½ dᵀ K_e d,  d = Rᵀ x_e − X_e   (R applied per vertex),
//     force   f_e = −R K_e d,
//     Hessian R K_e Rᵀ   (the "frozen-R" linearisation: the derivative of R itself is dropped,
//                         which keeps the system linear and symmetric, as in the paper).
// f_e is exactly −∂E_e/∂x_e for fixed R (tested against finite differences of E_e).
// With `corotational` off, R = I: the plain linear element.
//
// Tension stiffening. Freezing R drops the change of the rotation from the Jacobian; for an
// element under membrane tension that dropped term is the geometric ("string") stiffness,
// which is then integrated explicitly and can set taut regions into a step-to-step oscillation
// (measured: a sleeve twisted 90° in 0.5 s between rims at a fixed distance, dt = 2 ms). The
// assembled matrix therefore also carries the membrane geometric stiffness of the tensile part
// of the stress, G_IJ = Σ_q w_q j (N_I,α n₊^{αβ} N_J,β) I₃, with n the membrane force from the
// corotated strain and n₊ its positive part (compression adds nothing, so the matrix stays
// positive definite). It changes the linearisation only, not the forces or the equilibrium.
#pragma once

#include "sim/shell/shell_model.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace clothsim {

// Rotation taking the rest frame to the current one from the barycentre tangents (eqs. 29–31).
// Returns false (and leaves `r` alone) when the current tangents are degenerate.
bool extract_rotation(const Eigen::Vector3d& rest_a1, const Eigen::Vector3d& rest_a2, const Eigen::Vector3d& a1,
                      const Eigen::Vector3d& a2, Eigen::Matrix3d& r);

class CorotationalElements {
 public:
  CorotationalElements(const ShellModel& model, bool corotational);

  // Rotations, internal forces and strain energy for real displacements u (3·#V, tied
  // components already consistent).
  void evaluate(const Eigen::VectorXd& u);
  const Eigen::VectorXd& force() const { return force_; }  // internal force f_int (3·#V) [N]
  double energy() const { return energy_; }                 // strain energy [J]
  const std::vector<Eigen::Matrix3d>& rotations() const { return rotation_; }
  // Σ R K_e Rᵀ (folded, 3·#V square) with the rotations of the last evaluate().
  Eigen::SparseMatrix<double> assemble_stiffness() const;
  // Energy and force of one element for a given rotation (patch coordinates): for tests.
  double element_energy(int e, const Eigen::Matrix3d& r, const Eigen::VectorXd& x_patch) const;
  Eigen::VectorXd element_force(int e, const Eigen::Matrix3d& r, const Eigen::VectorXd& x_patch) const;

  // Principal Green–Lagrange membrane strains of the limit surface at each element's barycentre
  // for real displacements u (3·#V, tied components consistent): the eigenvalues of G⁻¹ E with
  // E = ½ (g − G), g_αβ = a_α·a_β and G_αβ = A_α·A_β from the current and rest limit tangents.
  // #elements × 2, ascending per row [-]. A uniform stretch by λ gives ½(λ² − 1); any rigid
  // motion gives 0. Computed on demand (a pass over the elements), not by evaluate().
  Eigen::MatrixX2d membrane_principal_strains(const Eigen::VectorXd& u) const;

  // Include the tension-stiffening term (default true).
  void set_geometric_stiffness(bool on) { geometric_ = on; }

  double last_rotate_ms() const { return rotate_ms_; }
  double last_force_ms() const { return force_ms_; }

 private:
  const ShellModel& model_;
  bool corotational_;
  std::vector<Eigen::MatrixXd> stiffness_;      // K_e, 3·#patch square
  std::vector<Eigen::VectorXd> rest_patch_;     // X_e, 3·#patch
  std::vector<Eigen::Matrix<double, 2, Eigen::Dynamic>> tangent_rows_;  // ∂N/∂v, ∂N/∂w at the barycentre
  std::vector<Eigen::Vector3d> rest_a1_, rest_a2_;
  std::vector<Eigen::Matrix3d> rotation_;
  std::vector<Eigen::VectorXd> local_force_;
  // Per element and quadrature point: membrane strain matrix (3 × 3·#patch) at rest, K_m·H,
  // weight·j and the first-derivative rows; and the current geometric stiffness (#patch square).
  std::vector<std::vector<Eigen::MatrixXd>> membrane_;
  std::vector<std::vector<Eigen::Matrix3d>> membrane_material_;
  std::vector<std::vector<double>> area_weight_;
  std::vector<Eigen::MatrixXd> geometric_stiffness_;
  bool geometric_ = true;
  std::vector<double> local_energy_;
  Eigen::VectorXd force_;
  double energy_ = 0.0;
  double rotate_ms_ = 0.0, force_ms_ = 0.0;
};

}  // namespace clothsim

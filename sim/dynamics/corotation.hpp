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
  std::vector<double> local_energy_;
  Eigen::VectorXd force_;
  double energy_ = 0.0;
  double rotate_ms_ = 0.0, force_ms_ = 0.0;
};

}  // namespace clothsim

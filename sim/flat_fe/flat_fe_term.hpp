// The elastic force term of the linear_fe discretisation (sim/flat_fe/flat_fe.hpp):
//
// Membrane (Etzmuss, Keckeisen & Straßer 2003). Each triangle is a linear constant-strain
// element in plane stress, in its rest frame: 2D rest coordinates X̂ᵢ, the 6 × 6 stiffness
//     K_e = A Bᵀ C B,   C = E t/(1 − ν²) [[1, ν, 0], [ν, 1, 0], [0, 0, (1 − ν)/2]]
// (B the strain–displacement matrix of the linear shape functions, engineering shear strain;
// E·t and ν are ShellMaterial's stretch_modulus and poisson_ratio). Corotation: R (3 × 2, an
// orthonormal frame of the deformed triangle's plane) is the rotation of the polar
// decomposition F = R S of the deformation gradient F = [x₁ − x₀, x₂ − x₀] D⁻¹ (3 × 2,
// D = [X̂₁ − X̂₀, X̂₂ − X̂₀]); with d = Rᵀxᵢ − X̂ᵢ (in-plane, 2 per node)
//     f = −R K_e d,   E = ½ dᵀ K_e d,   matrix R K_e Rᵀ (R frozen).
// For the polar rotation and an isotropic C, −R K_e d is the exact gradient of E (the terms from
// ∂R vanish because the stress commutes with S). An orthotropic material (docs/materials.md §4)
// uses its plane-stress law turned into the triangle's rest frame about the triangle's warp
// direction (TriMesh::warp) as C; −R K_e d is then the corotational force without the ∂R terms
// (exact with the rotations frozen), and each hinge's B is the directional rigidity of bending
// across its edge. `corotational` false: R is the rest frame, the
// linear element (in-plane displacements only). Tension stiffening (the geometric stiffness of
// the membrane stress) is not part of this method and is ignored.
//
// Bending (discrete shells: Grinspun et al. 2003; Bridson, Marino & Fedkiw 2003). On every
// interior edge e, E_e = k_e (θ_e − θ̄_e)² with θ the signed dihedral angle
// (sim/flat_fe/dihedral.hpp), θ̄ its rest value and
//     k_e = B |ē|² / (2 Ā_e),
// |ē| the rest edge length, Ā_e the sum of the two rest triangle areas, B the bending rigidity
// [N·m]. This makes a flat mesh of equilateral triangles bent isometrically into a cylinder of
// curvature κ store B κ²/2 per unit area as the mesh is refined, in any direction; on the grid
// primitive's right triangles it does so across x or y, and up to 3 times that across the cells'
// diagonal (derivation in docs/linear_fe.md; the often quoted 3|e|²/(2A_e) is the sphere's
// calibration and stores three times B κ²/2 on a cylinder). Force −2k (θ − θ̄) ∇θ; matrix 2k ∇θ ∇θᵀ (Gauss–Newton: symmetric, positive
// semidefinite), or with set_exact_bending_hessian(true) the exact 2k (∇θ ∇θᵀ + (θ − θ̄) ∇²θ)
// (derivative checks).
//
// No damping of its own (Kelvin–Voigt damping wraps it, sim/forces/damping.hpp). Units: [m], [N],
// [J], matrix [N/m].
#pragma once

#include "sim/flat_fe/dihedral.hpp"
#include "sim/core/force_term.hpp"

#include <Eigen/Core>

#include <vector>

namespace clothsim {

class LinearFeDiscretization;

class LinearFeElastic final : public ForceTerm {
 public:
  // Refers to `d`, which must outlive the term.
  LinearFeElastic(const LinearFeDiscretization& d, bool corotational);

  std::string name() const override {
    return corotational_ ? "linear FE (corotated membrane, hinge bending)" : "linear FE (linear membrane, hinge bending)";
  }
  // Evaluates rotations, forces and energies at x; a call with the same x as the last one
  // (exactly) reuses them.
  void update(const Eigen::VectorXd& x, const Eigen::VectorXd& u, double t) override;
  bool has_energy() const override { return true; }
  double energy() const override { return membrane_energy_ + bending_energy_; }
  void add_force(Eigen::VectorXd& f) const override { f += force_; }
  bool has_matrix() const override { return true; }
  // a += w.stiffness · (Σ R K_e Rᵀ + Σ hinge matrices); the term has no damping matrix.
  void add_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const override;

  // The two parts of energy() [J].
  double membrane_energy() const { return membrane_energy_; }
  double bending_energy() const { return bending_energy_; }
  // Keep the current membrane rotations in later updates (the frozen-R forces, whose exact
  // Jacobian is the membrane matrix: for derivative checks). Switching it off re-extracts them at
  // the next update.
  void freeze_rotations(bool on);
  // The exact hinge Hessian in the matrix instead of the Gauss–Newton one (for derivative checks;
  // it may be indefinite).
  void set_exact_bending_hessian(bool on) { exact_hessian_ = on; }
  // The rest stiffness of each triangle (#triangles, 6 × 6 over the in-plane components of its
  // three nodes in its rest frame) [N/m], and each hinge's k_e [J/rad²] and rest angle θ̄ [rad]:
  // for tests.
  const std::vector<Eigen::Matrix<double, 6, 6>>& triangle_stiffness() const { return k_; }
  const std::vector<double>& hinge_stiffness() const { return hinge_k_; }
  const std::vector<double>& hinge_rest_angle() const { return rest_angle_; }

 private:
  using Frame = Eigen::Matrix<double, 3, 2>;
  HingePositions hinge_positions(size_t h, const Eigen::VectorXd& x) const;

  const LinearFeDiscretization& d_;
  bool corotational_;
  bool frozen_ = false;
  bool exact_hessian_ = false;
  // Rest data per triangle: stiffness, 2D rest coordinates (a 2 × 3 matrix, one column per node),
  // D⁻¹, rest frame.
  std::vector<Eigen::Matrix<double, 6, 6>> k_;
  std::vector<Eigen::Matrix<double, 2, 3>> rest2d_;
  std::vector<Eigen::Matrix2d> inverse_edges_;
  std::vector<Frame> rest_frame_;
  // Rest data per hinge.
  std::vector<double> hinge_k_, rest_angle_;
  // The state of the last update.
  bool evaluated_ = false;
  Eigen::VectorXd x_;
  std::vector<Frame> rotation_;     // per triangle
  std::vector<double> angle_;       // per hinge θ
  std::vector<HingeVector> gradient_;  // per hinge ∇θ
  Eigen::VectorXd force_;
  double membrane_energy_ = 0.0, bending_energy_ = 0.0;
};

}  // namespace clothsim

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
  // The same into `k`, reusing its storage: `k` is empty or was filled by an earlier call (only
  // its values are rewritten when its pattern matches the model's).
  void assemble_stiffness(Eigen::SparseMatrix<double>& k) const;
  // k += scale · Σ R K_e Rᵀ (with the tension stiffening when on); `k` has the model's pattern.
  void add_stiffness(double scale, Eigen::SparseMatrix<double>& k) const;
  // k = scale · Σ R K_e Rᵀ (every value written; no clearing pass needed).
  void set_stiffness(double scale, Eigen::SparseMatrix<double>& k) const;
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
  void set_geometric_stiffness(bool on) { tension_stiffening_ = on; }
  // Keep the rotations of the last evaluate() in later ones (default false): the forces are then
  // those of the frozen-R linearisation, whose exact Jacobian is the assembled Σ R K_e Rᵀ (for
  // derivative checks).
  void set_frozen_rotations(bool on) { frozen_rotations_ = on; }

  // The tension force of the last evaluate()'s tensile membrane forces n₊ held fixed, at
  // displacements u (3·#V): f_T = −∂Φ/∂x with Φ = ½ Σ_q w_q j n₊^{αβ} a_α·a_β, a_α = Σ N_I,α x_I.
  // Its exact Jacobian is minus the tension-stiffening matrix G (for derivative checks) [N].
  Eigen::VectorXd tension_force(const Eigen::VectorXd& u) const;

  // The largest angle by which an element's rotation turned in the last evaluate() against the
  // one before it [rad] (0 without corotation or with frozen rotations).
  double last_rotation_change() const { return rotation_change_; }

  double last_rotate_ms() const { return rotate_ms_; }
  double total_rotate_ms() const { return total_rotate_ms_; }  // over every evaluate() so far
  double last_force_ms() const { return force_ms_; }

 private:
  // K_e d for element e (d and kd: 3·#patch), from the strain matrices: K_e = Σ_q w_q (Mᵀ K_m H M
  // + Bᵀ D_b H B) applied factor by factor (a third of the work of the dense product). With
  // `tension` (3 per quadrature point), also the point's tension stiffening (see tension_).
  void stiffness_product(size_t e, const double* d, double* kd, double* tension = nullptr) const;
  // values += scale · (gathered blocks + folded elements), or = with `overwrite` (the gather
  // covers the whole pattern).
  void accumulate_stiffness(double scale, bool overwrite, double* values) const;
  // Lays out the gather from the elements' packed upper blocks (emptied) and fold weights W.
  void build_assembly(std::vector<std::vector<double>>& packed, const std::vector<Eigen::MatrixXd>& fold_weights);

  const ShellModel& model_;
  bool corotational_;
  // Per-element patch vectors (3·#patch each) in flat buffers from patch_offset_[e]: X_e (the
  // patch at rest, ShellElement::reference), the mesh's positions that displacements are measured
  // from (equal to X_e unless the rest state is a flat layout), the current x_e and the local
  // force, so that evaluate() allocates nothing.
  std::vector<Eigen::Index> patch_offset_;
  Eigen::VectorXd rest_patch_, base_patch_, x_patch_, local_force_;
  // Per patch vertex (element e's from patch_offset_[e] / 3): ∂N/∂v, ∂N/∂w at the barycentre
  // (2 each) and the extended-mesh vertex; per element, whether its patch is the identity map.
  std::vector<double> tangent_rows_;
  std::vector<int> patch_vertex_;
  std::vector<char> identity_;
  std::vector<Eigen::Vector3d> rest_a1_, rest_a2_;
  std::vector<Eigen::Matrix3d> rotation_;
  std::vector<double> turn_cosine_;  // per element, cos of its rotation's turn in the last evaluate()
  double rotation_change_ = 0.0;
  // Per quadrature point (element e's from point_offset_[e]): membrane and bending strain
  // matrices at rest (3 × 3·#patch each, column-major, one after the other from
  // strain_offset_), K_m·H, D_b·H and weight·j.
  std::vector<int> point_offset_;
  std::vector<size_t> strain_offset_;
  std::vector<double> strain_;
  std::vector<Eigen::Matrix3d> membrane_material_, bending_material_;
  std::vector<double> area_weight_;
  // Tension stiffening of the last evaluate(): per quadrature point, weight·j times the positive
  // part of the membrane force (n₊¹¹, n₊¹², n₊²²; zero without tension). An element's geometric
  // stiffness G_ab = Σ_q w (N_a,α n₊^{αβ} N_b,β) is formed from these where it is assembled.
  std::vector<double> tension_;
  bool tension_stiffening_ = true;
  bool frozen_rotations_ = false;
  // Assembly as a gather (identity elements, and folded ones whose fold treats the three
  // components alike: see build_assembly). Every block (I, J), I ≤ J, of the matrix
  // pattern sums its element blocks R K_ab Rᵀ (K_ab stored already oriented as (I, J)) in
  // registers and is written once, with its transpose at (J, I): no zeroing and no scattered
  // read-modify-write per element block, and each sum has a fixed order (deterministic in
  // parallel). The contributions come in groups of four (vector lanes, sim/dynamics/
  // assembly_kernels.hpp, where the layout is described; a short group is padded with zero blocks):
  // the elements, their K blocks interleaved and, per quadrature point, the basis-row products
  // that turn tension_ into G_ab.
  std::vector<int> block_upper_, block_lower_;  // value offsets of (I, J) and (J, I) per block
  std::vector<int> block_stride_upper_, block_stride_lower_;  // column strides of J and I
  std::vector<int> block_groups_;  // contribution groups of block u: [block_groups_[u], block_groups_[u + 1])
  std::vector<int> group_element_;      // 4 per group
  std::vector<double> group_stiffness_;  // 36 per group
  std::vector<double> group_rows_;       // 12 per group and quadrature point
  int points_per_element_ = 0;           // the same rule for every element
  // The other folded elements (clamped borders, partly fixed vertices): K_e (3·#patch square)
  // and their colour groups; folded and added after the gather.
  std::vector<Eigen::MatrixXd> folded_stiffness_;  // by element, empty for identity elements
  std::vector<std::vector<int>> folded_groups_;
  // The force scatter as a gather: per global component (CSR from scatter_start_) the local
  // force entries and fold weights it sums, in element order, so a parallel pass over the
  // components adds exactly what the serial element loop did, in the same order.
  std::vector<int> scatter_start_, scatter_source_;
  std::vector<double> scatter_weight_;
  std::vector<double> local_energy_;
  mutable std::vector<double> scratch_;  // add_stiffness with folded elements: the unscaled values
  Eigen::VectorXd force_;
  double energy_ = 0.0;
  double rotate_ms_ = 0.0, force_ms_ = 0.0, total_rotate_ms_ = 0.0;
};

}  // namespace clothsim

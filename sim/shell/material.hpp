// Material of a Kirchhoff–Love shell (paper §3.2, eq. 17; docs/formulas.md §6, Material law;
// docs/materials.md for the orthotropic law): linear, with membrane (stretch) stiffness and
// bending rigidity set independently, as measured fabrics do not obey D = E t³ / 12. Isotropic by
// default; woven cloth is orthotropic (`orthotropy`), with its warp direction given per triangle
// of the mesh (TriMesh::warp).
#pragma once

#include <Eigen/Core>

#include <optional>
#include <string>

namespace clothsim {

// The orthotropic (woven) law in the orthonormal frame of the warp direction g₁ and the weft
// direction g₂ = n × g₁ (docs/materials.md). Plane stress, Voigt order (11, 22, 12) with the
// engineering shear γ₁₂ = 2ε₁₂:
//   membrane  n = Q ε,  Q₁₁ = E_w/(1 − ν_wf ν_fw), Q₂₂ = E_f/(1 − ν_wf ν_fw), Q₁₂ = ν_wf Q₂₂,
//             Q₆₆ = G  (n₁₂ = G γ₁₂), with ν_fw = ν_wf E_f/E_w;
//   bending   m = D κ,  the same law with (B_w, B_f, D_t, ν_wf): D₆₆ = D_t (m₁₂ = D_t · 2κ₁₂).
struct Orthotropy {
  double warp_stretch = 5000.0;  // E_w·t [N/m], along the warp
  double weft_stretch = 5000.0;  // E_f·t [N/m], along the weft
  double shear_stretch = 2000.0; // G·t [N/m], in-plane shear (n₁₂ = G t γ₁₂)
  double poisson = 0.25;         // ν_wf [-]: weft contraction under warp stress; ν_fw = ν_wf E_f/E_w
  double warp_bending = 1e-5;    // B_w [N·m]: bending about the weft (curvature along the warp)
  double weft_bending = 1e-5;    // B_f [N·m]
  double twist = 4e-6;           // D_t [N·m]: m₁₂ = D_t · 2κ₁₂ (isotropic: B/(2(1 + ν)))
};

// The default twist rigidity: the isotropic value of the geometric-mean rigidity,
// D_t = √(B_w B_f) / (2 (1 + ν̄)) with ν̄ = √(ν_wf ν_fw^b) = ν_wf √(B_f/B_w) the geometric mean of
// the bending law's two Poisson ratios. Equal rigidities B give B/(2(1 + ν_wf)), the isotropic
// plate's twist.
double default_twist(double warp_bending, double weft_bending, double poisson);

// Plane-stress matrix in the (warp, weft) frame, Voigt (11, 22, 12) with engineering shear:
// [[Q₁₁, Q₁₂, 0], [Q₁₂, Q₂₂, 0], [0, 0, Q₆₆]] for moduli E₁, E₂ (along g₁, g₂), shear G and ν₁₂.
Eigen::Matrix3d plane_stress_matrix(double e1, double e2, double shear, double nu12);

// `law` (plane-stress matrix in the (g₁, g₂) frame) written in another orthonormal frame
// (e₁, e₂) of the same plane, where g₁ = c e₁ + s e₂ (c² + s² = 1): Voigt (11, 22, 12) with
// engineering shear, H = T law Tᵀ with the tensor rotation T (docs/materials.md).
Eigen::Matrix3d law_in_frame(const Eigen::Matrix3d& law, double c, double s);

// `law` (Voigt (11, 22, 12), engineering shear, in the frame g₁, g₂) in the components of another
// basis, given t(α, i) = e^α · g_i (e^α that basis's dual vectors, or an orthonormal frame's own):
// H = T law Tᵀ with T's row (α, β) the products t_αi t_βj summed over the pairs (i, j) of each
// Voigt index (both orders for the shear). Shared by law_in_frame and the element's curvilinear
// components.
Eigen::Matrix3d voigt_transform(const Eigen::Matrix2d& t, const Eigen::Matrix3d& law);

// The uniaxial modulus of a plane-stress law (in the (g₁, g₂) frame) along the direction
// c g₁ + s g₂: 1 / (the compliance's (1,1) entry rotated there), that is
// 1/E_θ = c⁴/E₁ + s⁴/E₂ + (1/G − 2ν₁₂/E₁) s²c² for an orthotropic law. The same with the bending
// law gives the rigidity of a strip bent along that direction with its other moments free.
double directional_modulus(const Eigen::Matrix3d& law, double c, double s);

struct ShellMaterial {
  double stretch_modulus = 5000.0;   // E·t [N/m]; membrane stiffness K_m = E t / (1 − ν²)
  double bending_rigidity = 1e-5;    // E·t³/12 [N·m]; bending stiffness D_b = E t³ / (12 (1 − ν²))
  double poisson_ratio = 0.25;       // ν [-], in [0, 0.5)
  double areal_density = 0.1;        // ρ·t [kg/m²]
  // When set, the membrane and bending laws are these (the fields above then hold the geometric
  // means, set by set_orthotropy, for code that needs one representative scalar: step-size and
  // load-magnitude checks, studies). Unset: isotropic.
  std::optional<Orthotropy> orthotropy;

  bool orthotropic() const { return orthotropy.has_value(); }
  double membrane_stiffness() const { return stretch_modulus / (1.0 - poisson_ratio * poisson_ratio); }
  double bending_stiffness() const { return bending_rigidity / (1.0 - poisson_ratio * poisson_ratio); }
  // The plane-stress membrane and bending matrices in the (warp, weft) frame: the orthotropic
  // law, or the isotropic one (K_m [[1, ν, 0], [ν, 1, 0], [0, 0, (1 − ν)/2]] and the same with D_b).
  Eigen::Matrix3d membrane_law() const;
  Eigen::Matrix3d bending_law() const;

  // From Young's modulus E [Pa], thickness t [m] and density ρ [kg/m³].
  static ShellMaterial from_solid(double youngs_modulus, double poisson_ratio, double thickness, double density) {
    ShellMaterial m;
    m.stretch_modulus = youngs_modulus * thickness;
    m.bending_rigidity = youngs_modulus * thickness * thickness * thickness / 12.0;
    m.poisson_ratio = poisson_ratio;
    m.areal_density = density * thickness;
    return m;
  }
};

// Makes `m` orthotropic with law `o` and sets its representative isotropic fields to the geometric
// means: stretch_modulus = √(E_w E_f), bending_rigidity = √(B_w B_f), poisson_ratio =
// min(√(ν_wf ν_fw), 0.49).
void set_orthotropy(ShellMaterial& m, const Orthotropy& o);

// The orthotropic law equal to an isotropic material (E_w = E_f = E·t, G = E t/(2(1 + ν)),
// B_w = B_f = B, D_t = B/(2(1 + ν))).
Orthotropy isotropic_orthotropy(const ShellMaterial& m);

// Empty string when valid, else a message naming the bad field.
std::string validate(const ShellMaterial& m);
// The same for an orthotropic law alone (moduli > 0, ν_wf ≥ 0 with ν_wf² < E_w/E_f and
// ν_wf² < B_w/B_f, so that both laws are positive definite).
std::string validate(const Orthotropy& o);

}  // namespace clothsim

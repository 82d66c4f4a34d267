// The mass–spring method, "mass_spring": cloth as the popular tools model it, on the flat
// discretisation of linear_fe (sim/flat_fe/flat_fe.hpp: the same nodes, DOFs, lumped mass, loads,
// pattern and surface operators). Linear springs, energy ½ k (l − L₀)² each, in the layout of
// Provot (1995) carried over to triangle meshes:
//  - stretch/shear springs on every mesh edge, with Van Gelder's (1998) stiffness
//        k_e = E·t Σ_{T ∋ e} A_T / |e|²,
//    A_T the rest areas of the edge's one or two triangles, |e| its rest length, E·t the
//    material's stretch modulus [N/m]. On a mesh of equilateral triangles this network is the
//    plane-stress membrane with the stretch modulus E·t and Poisson ratio 1/3, whatever the
//    material's ν (a network of central springs on that lattice has ν = 1/3 for any stiffness);
//    on other triangles it is anisotropic. The material's ν is not used.
//  - bending springs between the two apexes x2, x3 of every interior edge (Hinge::nodes), with
//        k_b = (24576/35) · B Ā_e / (κ_ref² L₀⁶),
//    Ā_e the rest area of the edge's two triangles, L₀ = |x3 − x2| at rest, B the bending rigidity
//    [N·m] and κ_ref the reference curvature [1/m]. A bending spring's length changes only at
//    second order in the curvature, δ ≈ −κ² L₀³ cos⁴ψ / 24 (ψ between the spring and the
//    curvature direction), so its energy is quartic in κ; k_b makes a flat sheet bent into a
//    cylinder of curvature κ_ref store B κ_ref²/2 per unit area, averaged over the bending
//    direction (the energy at curvature κ is (κ/κ_ref)² times B κ²/2). docs/mass_spring.md has
//    both derivations and what they leave out.
//
// κ_ref, unless given, is the inverse of the material's bending length (Peirce 1930),
// c = (B / (ρ_A g))^(1/3) with g = 9.80665 m/s²: the curvature at which the cloth's own weight and
// its bending stiffness balance, the scale of draping folds.
#pragma once

#include "sim/flat_fe/flat_fe.hpp"

#include <vector>

namespace clothsim {

// A linear spring between nodes i and j: energy ½ k (|x_i − x_j| − L₀)².
struct Spring {
  int i = 0, j = 0;             // nodes
  int group = 0, a = 0, b = 0;  // the pattern group holding both nodes (FlatDiscretization::blocks)
                                // and their places in its node list: node i = group_node(group, a)
  double stiffness = 0.0;       // k [N/m]
  double rest_length = 0.0;     // L₀ [m]
};

class MassSpringDiscretization final : public FlatDiscretization {
 public:
  // FlatDiscretization::prepare_flat_mesh for "mass_spring".
  static TriMesh prepare_mesh(const TriMesh& mesh, const LogFn& log) { return prepare_flat_mesh("mass_spring", mesh, log); }

  // The inverse bending length (ρ_A g / B)^(1/3) [1/m] of a material (g = 9.80665 m/s²); NaN
  // when it has no positive areal density or bending rigidity.
  static double bending_length_curvature(const ShellMaterial& material);

  // See FlatDiscretization's constructor. `reference_curvature` κ_ref [1/m] of the bending
  // springs; 0 takes bending_length_curvature(material). Throws std::runtime_error for an
  // orthotropic material (a spring network cannot take it: docs/materials.md), when κ_ref is
  // not a positive finite number (0 given and a material without mass), or when two nodes of a
  // spring coincide at rest.
  MassSpringDiscretization(const TriMesh& mesh, const std::vector<BoundaryCondition>& boundary, const ShellMaterial& material,
                           double reference_curvature = 0.0);

  // The springs (MassSpringElastic). `corotational` has no meaning for springs — their forces
  // are already invariant under rotation — and is ignored. `tension_stiffening` keeps the
  // transverse part k (1 − L₀/l)(I − n nᵀ) of stretched springs in the matrix (the geometric
  // stiffness of their tension); false leaves only k n nᵀ.
  std::unique_ptr<ForceTerm> elastic_term(bool corotational, bool tension_stiffening) const override;

  // One stretch spring per mesh edge (ordered by the first triangle that has the edge, then by the
  // edge's place in it, i → j as the edge runs there), one bending spring per hinge (in hinges()
  // order, i = x2, j = x3).
  const std::vector<Spring>& stretch_springs() const { return stretch_; }
  const std::vector<Spring>& bending_springs() const { return bending_; }
  double reference_curvature() const { return reference_curvature_; }  // κ_ref [1/m]

 private:
  double reference_curvature_;
  std::vector<Spring> stretch_, bending_;
};

}  // namespace clothsim

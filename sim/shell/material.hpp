// Material of a Kirchhoff–Love shell (paper §3.2, eq. 17; docs/formulas.md §6, Material law):
// isotropic, linear, with membrane (stretch) stiffness and bending rigidity set independently, as
// measured fabrics do not obey D = E t³ / 12.
#pragma once

#include <string>

namespace clothsim {

struct ShellMaterial {
  double stretch_modulus = 5000.0;   // E·t [N/m]; membrane stiffness K_m = E t / (1 − ν²)
  double bending_rigidity = 1e-5;    // E·t³/12 [N·m]; bending stiffness D_b = E t³ / (12 (1 − ν²))
  double poisson_ratio = 0.25;       // ν [-], in [0, 0.5)
  double areal_density = 0.1;        // ρ·t [kg/m²]

  double membrane_stiffness() const { return stretch_modulus / (1.0 - poisson_ratio * poisson_ratio); }
  double bending_stiffness() const { return bending_rigidity / (1.0 - poisson_ratio * poisson_ratio); }

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

// Empty string when valid, else a message naming the bad field.
std::string validate(const ShellMaterial& m);

}  // namespace clothsim

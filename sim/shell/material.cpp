#include "sim/shell/material.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace clothsim {

double default_twist(double warp_bending, double weft_bending, double poisson) {
  const double mean = std::sqrt(warp_bending * weft_bending);
  const double nu = poisson * std::sqrt(weft_bending / warp_bending);
  return mean / (2.0 * (1.0 + nu));
}

Eigen::Matrix3d plane_stress_matrix(double e1, double e2, double shear, double nu12) {
  const double nu21 = nu12 * e2 / e1;
  const double d = 1.0 - nu12 * nu21;
  Eigen::Matrix3d q = Eigen::Matrix3d::Zero();
  q(0, 0) = e1 / d;
  q(1, 1) = e2 / d;
  q(0, 1) = q(1, 0) = nu12 * e2 / d;
  q(2, 2) = shear;
  return q;
}

Eigen::Matrix3d law_in_frame(const Eigen::Matrix3d& law, double c, double s) {
  // t(α, i) = e_α · g_i with g₁ = (c, s), g₂ = (−s, c) in the (e₁, e₂) frame.
  Eigen::Matrix2d t;
  t << c, -s, s, c;
  return voigt_transform(t, law);
}

Eigen::Matrix3d voigt_transform(const Eigen::Matrix2d& t, const Eigen::Matrix3d& law) {
  Eigen::Matrix3d m;
  const int first[3] = {0, 1, 0}, second[3] = {0, 1, 1};
  for (int p = 0; p < 3; ++p) {
    const int a = first[p], b = second[p];
    m(p, 0) = t(a, 0) * t(b, 0);
    m(p, 1) = t(a, 1) * t(b, 1);
    m(p, 2) = t(a, 0) * t(b, 1) + t(a, 1) * t(b, 0);
  }
  return m * law * m.transpose();
}

double directional_modulus(const Eigen::Matrix3d& law, double c, double s) {
  // The law in a frame whose first axis is the direction: g₁ = c' e₁ + s' e₂ with the direction
  // d = c g₁ + s g₂ as e₁, so g₁ = c e₁ − s e₂.
  const Eigen::Matrix3d h = law_in_frame(law, c, -s);
  return 1.0 / h.inverse()(0, 0);
}

Eigen::Matrix3d ShellMaterial::membrane_law() const {
  if (orthotropy)
    return plane_stress_matrix(orthotropy->warp_stretch, orthotropy->weft_stretch, orthotropy->shear_stretch,
                               orthotropy->poisson);
  return plane_stress_matrix(stretch_modulus, stretch_modulus, stretch_modulus / (2.0 * (1.0 + poisson_ratio)),
                             poisson_ratio);
}

Eigen::Matrix3d ShellMaterial::bending_law() const {
  if (orthotropy)
    return plane_stress_matrix(orthotropy->warp_bending, orthotropy->weft_bending, orthotropy->twist,
                               orthotropy->poisson);
  return plane_stress_matrix(bending_rigidity, bending_rigidity, bending_rigidity / (2.0 * (1.0 + poisson_ratio)),
                             poisson_ratio);
}

void set_orthotropy(ShellMaterial& m, const Orthotropy& o) {
  m.orthotropy = o;
  m.stretch_modulus = std::sqrt(o.warp_stretch * o.weft_stretch);
  m.bending_rigidity = std::sqrt(o.warp_bending * o.weft_bending);
  m.poisson_ratio = std::min(o.poisson * std::sqrt(o.weft_stretch / o.warp_stretch), 0.49);
}

Orthotropy isotropic_orthotropy(const ShellMaterial& m) {
  Orthotropy o;
  o.warp_stretch = o.weft_stretch = m.stretch_modulus;
  o.shear_stretch = m.stretch_modulus / (2.0 * (1.0 + m.poisson_ratio));
  o.poisson = m.poisson_ratio;
  o.warp_bending = o.weft_bending = m.bending_rigidity;
  o.twist = m.bending_rigidity / (2.0 * (1.0 + m.poisson_ratio));
  return o;
}

std::string validate(const Orthotropy& o) {
  std::ostringstream s;
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(o.warp_stretch))
    s << "warp stretch modulus must be a finite number > 0 [N/m] (got " << o.warp_stretch << ")";
  else if (!positive(o.weft_stretch))
    s << "weft stretch modulus must be a finite number > 0 [N/m] (got " << o.weft_stretch << ")";
  else if (!positive(o.shear_stretch))
    s << "shear modulus must be a finite number > 0 [N/m] (got " << o.shear_stretch << ")";
  else if (!positive(o.warp_bending))
    s << "warp bending rigidity must be a finite number > 0 [N·m] (got " << o.warp_bending << ")";
  else if (!positive(o.weft_bending))
    s << "weft bending rigidity must be a finite number > 0 [N·m] (got " << o.weft_bending << ")";
  else if (!positive(o.twist))
    s << "twist rigidity must be a finite number > 0 [N·m] (got " << o.twist << ")";
  else if (!(std::isfinite(o.poisson) && o.poisson >= 0))
    s << "Poisson ratio must be a finite number >= 0 (got " << o.poisson << ")";
  else if (!(o.poisson * o.poisson < o.warp_stretch / o.weft_stretch))
    s << "Poisson ratio " << o.poisson << " makes the membrane law indefinite: nu^2 must be < E_warp/E_weft = "
      << o.warp_stretch / o.weft_stretch << " (nu_warp,weft * nu_weft,warp < 1)";
  else if (!(o.poisson * o.poisson < o.warp_bending / o.weft_bending))
    s << "Poisson ratio " << o.poisson << " makes the bending law indefinite: nu^2 must be < B_warp/B_weft = "
      << o.warp_bending / o.weft_bending;
  return s.str();
}

std::string validate(const ShellMaterial& m) {
  std::ostringstream s;
  if (m.orthotropy) {
    if (std::string o = validate(*m.orthotropy); !o.empty()) return o;
    if (!(std::isfinite(m.areal_density) && m.areal_density >= 0))
      s << "areal density must be a finite number >= 0 [kg/m²] (got " << m.areal_density << ")";
    return s.str();
  }
  if (!(std::isfinite(m.stretch_modulus) && m.stretch_modulus > 0))
    s << "stretch modulus must be a finite number > 0 [N/m] (got " << m.stretch_modulus << ")";
  else if (!(std::isfinite(m.bending_rigidity) && m.bending_rigidity > 0))
    s << "bending rigidity must be a finite number > 0 [N·m] (got " << m.bending_rigidity << ")";
  else if (!(std::isfinite(m.poisson_ratio) && m.poisson_ratio >= 0 && m.poisson_ratio < 0.5))
    s << "Poisson ratio must lie in [0, 0.5) (got " << m.poisson_ratio << ")";
  else if (!(std::isfinite(m.areal_density) && m.areal_density >= 0))
    s << "areal density must be a finite number >= 0 [kg/m²] (got " << m.areal_density << ")";
  return s.str();
}

}  // namespace clothsim

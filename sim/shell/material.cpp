#include "sim/shell/material.hpp"

#include <cmath>
#include <sstream>

namespace clothsim {

std::string validate(const ShellMaterial& m) {
  std::ostringstream s;
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

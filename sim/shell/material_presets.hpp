// Named shell materials for scene files ("material": {"preset": "cotton"}): the paper's cotton
// and metal-like material, Kawabata-measured fabrics and the cloths measured by Wang et al. 2011
// (numbers and their published sources in material_presets.cpp), and orthotropic variants of the
// fabrics and cloths named "<name>_ortho" (docs/materials.md, Presets).
#pragma once

#include "sim/shell/material.hpp"

#include <optional>
#include <string>
#include <vector>

namespace clothsim {

// The preset called `name` (exact, case-sensitive), or std::nullopt if there is none.
std::optional<ShellMaterial> material_preset(const std::string& name);

// Every preset name, in a fixed order (paper materials, Kawabata fabrics, Wang et al. cloths,
// then the orthotropic variants).
std::vector<std::string> material_preset_names();

}  // namespace clothsim

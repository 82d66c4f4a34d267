// The material preset table. Every entry says where its numbers come from; all values SI:
// stretch modulus E·t [N/m], bending rigidity B [N·m], Poisson ratio ν [-], areal density [kg/m²].
#include "sim/shell/material_presets.hpp"

#include <cmath>
#include <utility>

namespace clothsim {
namespace {

struct Preset {
  std::string name;
  ShellMaterial material;
};

ShellMaterial make(double stretch_modulus, double bending_rigidity, double poisson_ratio, double areal_density) {
  ShellMaterial m;
  m.stretch_modulus = stretch_modulus;
  m.bending_rigidity = bending_rigidity;
  m.poisson_ratio = poisson_ratio;
  m.areal_density = areal_density;
  return m;
}

// The paper's cotton (§6: "E = 5000 N/m", ν = 0.25) is used as the stretch behaviour of the
// fabrics for which only bending was measured.
constexpr double kPaperCottonStretch = 5000.0;  // [N/m]
constexpr double kPaperCottonPoisson = 0.25;

// Wang, Ramamoorthi & O'Brien 2011 measured an orthotropic membrane; the isotropic preset uses
// the geometric mean of the two axial coefficients, E·t = √(c11·c22) [N/m], and ν = 0.25
// (their c12 is a fitting artefact for several cloths), with B [N·m] and the areal density
// [kg/m²] as measured.
ShellMaterial wang(double c11, double c22, double bending_rigidity, double areal_density) {
  return make(std::sqrt(c11 * c22), bending_rigidity, 0.25, areal_density);
}

std::vector<Preset> build_presets() {
  std::vector<Preset> p;
  // Paper §6 cotton: E·t = 5000 N/m, ν = 0.25 (the paper gives no bending rigidity or mass);
  // B = 1.157e-5 N·m and 0.1238 kg/m² from the Kawabata cotton broadcloth (Matsudaira et al.
  // 2015, Table 1).
  p.push_back({"cotton", make(kPaperCottonStretch, 1.157e-5, kPaperCottonPoisson, 0.1238)});
  // Paper §6, Fig. 11 "thin flexible metal": E·t = 100000 N/m, ν = 0.05, thickness 1 mm, so
  // B = E·t·t²/12 = 1e5 · (1e-3)² / 12 = 8.333e-3 N·m. The paper gives no density: 0.5 kg/m²
  // (ρ = 500 kg/m³ at t = 1 mm, about four times the cotton's mass per area) is our choice.
  p.push_back({"metal", make(100000.0, 100000.0 * 1e-3 * 1e-3 / 12.0, 0.05, 0.5)});

  // Kawabata KES-FB2 bending rigidity and areal density, Matsudaira et al. 2015, J. Textile
  // Eng. 61(6):69, Table 1 (1 gf·cm²/cm = 9.80665e-5 N·m, 1 mg/cm² = 0.01 kg/m²); stretch
  // modulus and ν are the paper's cotton values (not measured in that table).
  p.push_back({"cotton_broadcloth", make(kPaperCottonStretch, 1.157e-5, kPaperCottonPoisson, 0.1238)});
  p.push_back({"wool_tropical", make(kPaperCottonStretch, 6.57e-6, kPaperCottonPoisson, 0.1629)});
  p.push_back({"polyester_tropical", make(kPaperCottonStretch, 7.55e-6, kPaperCottonPoisson, 0.1165)});
  p.push_back({"polyester_faille", make(kPaperCottonStretch, 1.86e-6, kPaperCottonPoisson, 0.1043)});

  // Wang, Ramamoorthi & O'Brien 2011, "Data-driven elastic models for cloth": c11, c22 [N/m],
  // B [N·m] at small curvature along the first axis, areal density [kg/m²].
  p.push_back({"gray_interlock", wang(16.6, 34.5, 2.32e-5, 0.187)});           // t-shirt
  p.push_back({"black_denim", wang(205.4, 1013.9, 6.42e-5, 0.324)});          // 11 oz, jeans
  p.push_back({"royal_target", wang(2016.6, 2035.0, 1.25e-4, 0.220)});        // pants
  p.push_back({"ivory_rib_knit", wang(42.9, 65.2, 4.62e-5, 0.276)});
  p.push_back({"camel_ponte_roma", wang(31.1, 44.0, 3.63e-5, 0.284)});        // jacket
  p.push_back({"navy_sparkle_sweat", wang(12.5, 3.3, 5.95e-5, 0.224)});       // sweater
  p.push_back({"pink_ribbon_brown", wang(151.5, 244.8, 1.17e-4, 0.228)});     // blanket
  p.push_back({"tango_red_jet_set", wang(43.1, 171.4, 1.43e-5, 0.113)});      // jacket
  p.push_back({"white_dots_on_black", wang(2002.1, 2027.5, 5.17e-5, 0.128)});  // tablecloth
  p.push_back({"white_swim_solid", wang(48.0, 104.6, 6.02e-5, 0.204)});       // swimsuit
  return p;
}

const std::vector<Preset>& presets() {
  static const std::vector<Preset> table = build_presets();
  return table;
}

}  // namespace

std::optional<ShellMaterial> material_preset(const std::string& name) {
  for (const Preset& p : presets())
    if (p.name == name) return p.material;
  return std::nullopt;
}

std::vector<std::string> material_preset_names() {
  std::vector<std::string> names;
  names.reserve(presets().size());
  for (const Preset& p : presets()) names.push_back(p.name);
  return names;
}

}  // namespace clothsim

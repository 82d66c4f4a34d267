// The material preset table. Every entry says where its numbers come from; all values SI:
// stretch modulus E·t [N/m], bending rigidity B [N·m], Poisson ratio ν [-], areal density [kg/m²].
#include "sim/shell/material_presets.hpp"

#include <algorithm>
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

// The orthotropic fit of a Wang, Ramamoorthi & O'Brien 2011 cloth (docs/materials.md, Presets)
// from its small-strain stretching row [c11, c12, c22, c33] [N/m] (the stress–strain matrix of
// the Green strain with the tensor shear strain ε₁₂, first material axis = warp, as ARCSim's
// materials/*.json give it) and its bending at the smallest curvature for fold lines along the
// first axis (b0), at 45° (b45) and along the second axis (b90) [N·m]:
//   ν_wf = max(c12, 0)/c22 (a negative c12 is a fitting artefact: ν = 0), c12' = ν_wf c22,
//   E_w = c11 − c12'²/c22, E_f = c22 − c12'²/c11, G = c33/2 (n₁₂ = c33 ε₁₂ = (c33/2) γ₁₂);
//   B_w = b90 (curvature along the warp: fold lines along the weft), B_f = b0, and the twist from
//   the 45° rigidity, 1/D_t = 4/b45 − 1/B_w − 1/B_f + 2ν_wf/B_w (positive for all ten cloths).
ShellMaterial wang_orthotropic(double c11, double c12, double c22, double c33, double b0, double b45, double b90,
                               double areal_density) {
  Orthotropy o;
  o.poisson = std::max(c12, 0.0) / c22;
  const double coupling = o.poisson * c22;
  o.warp_stretch = c11 - coupling * coupling / c22;
  o.weft_stretch = c22 - coupling * coupling / c11;
  o.shear_stretch = 0.5 * c33;
  o.warp_bending = b90;
  o.weft_bending = b0;
  o.twist = 1.0 / (4.0 / b45 - 1.0 / b90 - 1.0 / b0 + 2.0 * o.poisson / b90);
  ShellMaterial m;
  set_orthotropy(m, o);
  m.areal_density = areal_density;
  return m;
}

// 1 gf/cm/deg (Kawabata KES-FB1 shear stiffness G) in N/m per radian: 9.80665e-3 N / 0.01 m per
// (π/180) rad = 56.19 N/m.
constexpr double kGfPerCmPerDeg = 9.80665e-3 / 0.01 / (3.14159265358979323846 / 180.0);

// A Kawabata fabric of Matsudaira et al. 2015 as an orthotropic shell: its measured B (the same
// along warp and weft: Table 1 gives one value) and areal density, the paper's cotton stretch
// (E·t = 5000 N/m along warp and weft, ν = 0.25: not measured in that table), and a shear
// modulus G [gf/cm/deg] that is assumed, not measured (see build_presets); default twist.
ShellMaterial kawabata_orthotropic(double bending_rigidity, double areal_density, double shear_gf_cm_deg) {
  Orthotropy o;
  o.warp_stretch = o.weft_stretch = kPaperCottonStretch;
  o.poisson = kPaperCottonPoisson;
  o.shear_stretch = shear_gf_cm_deg * kGfPerCmPerDeg;
  o.warp_bending = o.weft_bending = bending_rigidity;
  o.twist = default_twist(bending_rigidity, bending_rigidity, o.poisson);
  ShellMaterial m;
  set_orthotropy(m, o);
  m.areal_density = areal_density;
  return m;
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

  // Orthotropic (woven-cloth) variants; the isotropic presets above keep their names and values.
  // Kawabata fabrics of Matsudaira et al. 2015 (B and areal density as above) with soft shear:
  // G = 1.0 gf/cm/deg = 56.2 N/m assumed for all four, the middle of the 0.5–2 gf/cm/deg that
  // KES-FB1 gives for woven cotton, wool and polyester (their G is not in that table).
  p.push_back({"cotton_broadcloth_ortho", kawabata_orthotropic(1.157e-5, 0.1238, 1.0)});
  p.push_back({"wool_tropical_ortho", kawabata_orthotropic(6.57e-6, 0.1629, 1.0)});
  p.push_back({"polyester_tropical_ortho", kawabata_orthotropic(7.55e-6, 0.1165, 1.0)});
  p.push_back({"polyester_faille_ortho", kawabata_orthotropic(1.86e-6, 0.1043, 1.0)});
  // Wang, Ramamoorthi & O'Brien 2011, fitted by wang_orthotropic: the first row of "stretching"
  // and the first column of the three "bending" rows (0°, 45°, 90°) of ARCSim's materials/*.json
  // (the published data of that paper), areal density [kg/m²] from the same files.
  p.push_back({"gray_interlock_ortho", wang_orthotropic(16.593832, -14.69599, 34.477123, 36.860302, 2.3191698e-05,
                                                        2.4749964e-05, 1.4267624e-05, 0.187)});
  p.push_back({"black_denim_ortho", wang_orthotropic(205.352005, 10.234077, 1013.88629, 53.387184, 6.4196457e-05,
                                                     7.3384567e-05, 9.6951576e-05, 0.324)});
  p.push_back({"royal_target_ortho", wang_orthotropic(2016.55456, 9.170511, 2034.97644, 104.759674, 1.25409805e-4,
                                                      1.07997696e-4, 1.25409805e-4, 0.220)});
  p.push_back({"ivory_rib_knit_ortho", wang_orthotropic(42.871021, -0.234556, 65.166023, 83.175644, 4.6237591e-05,
                                                        3.001593e-05, 3.2243889e-05, 0.276)});
  p.push_back({"camel_ponte_roma_ortho", wang_orthotropic(31.146198, -12.802702, 44.028667, 31.896357, 3.6348366e-05,
                                                          3.3013252e-05, 3.7157593e-05, 0.284)});
  p.push_back({"navy_sparkle_sweat_ortho", wang_orthotropic(12.486332, -19.875324, 3.272434, 17.616289, 5.9469658e-05,
                                                            4.0072277e-05, 4.5625023e-05, 0.224)});
  p.push_back({"pink_ribbon_brown_ortho", wang_orthotropic(151.503906, 106.02816, 244.830673, 30.250183, 1.17070122e-4,
                                                           8.7509773e-05, 5.9774277e-05, 0.228)});
  p.push_back({"tango_red_jet_set_ortho", wang_orthotropic(43.067627, 54.373299, 171.424835, 14.3147, 1.4293814e-05,
                                                           2.19517e-05, 2.0345654e-05, 0.113)});
  p.push_back({"white_dots_on_black_ortho", wang_orthotropic(2002.08618, 0.345588, 2027.48559, 19.189022, 5.1713814e-05,
                                                             4.065947e-05, 3.1282822e-05, 0.128)});
  p.push_back({"white_swim_solid_ortho", wang_orthotropic(47.971176, 6.834521, 104.615456, 60.773663, 6.0237942e-05,
                                                          5.8803211e-05, 5.1018833e-05, 0.204)});
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

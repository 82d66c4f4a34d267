// The standard fabric tests run virtually (`clothsim fabric-test`, docs/fabric_test.md): the
// cantilever bending test (ASTM D1388), uniaxial tensile tests along the warp, the weft and the
// bias (45°) at small strain, and the Cusick drape test (ISO 9073-9). This file builds each test's
// scene from a material (the scene file's "material" object) and measures its result; the
// command (app/fabric_test.cpp) runs them, writes the table and draws the pictures.
//
// Every scene here is y-up with gravity along −y, like the shipped drape scenes.
#pragma once

#include "sim/scene/scene.hpp"
#include "sim/study/drape_measure.hpp"

#include <nlohmann/json.hpp>

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace clothsim {

// ---- Measured values of a fabric, where its source gives them ----------------------------------

struct FabricMeasurement {
  std::string fabric;                        // e.g. "cotton broadcloth"
  double bending_rigidity = 0.0;             // B [N·m] (KES-FB2, the mean of warp and weft)
  double areal_density = 0.0;                // [kg/m²]
  std::optional<double> drape_coefficient;   // Cusick DC [-]
  std::optional<int> nodes;                  // Cusick nodes
  std::string source;
};

// The measurements behind preset `preset` (a Kawabata fabric of Matsudaira et al. 2015, under its
// isotropic or its "_ortho" name), or none.
std::optional<FabricMeasurement> fabric_measurement(const std::string& preset);

// ---- The material under test ---------------------------------------------------------------------

struct FabricUnderTest {
  std::string label;             // the preset's name, or the scene file's name
  nlohmann::json material;       // the scene's "material" object (without "grain": each test sets it)
  ShellMaterial law;             // as read
  std::optional<FabricMeasurement> measured;
};

// The material of `preset_or_scene`: a preset name, or a scene file (.json) whose "material" is
// taken. Throws SceneError / std::runtime_error naming the preset or the file.
FabricUnderTest fabric_under_test(const std::string& preset_or_scene);

// The bending rigidity of a strip cut at `angle_deg` to the warp (the directional rigidity of the
// bending law with the other moments free; B for an isotropic material) [N·m].
double strip_bending_rigidity(const ShellMaterial& m, double angle_deg);
// The stretch modulus of a strip cut at `angle_deg` to the warp, free to contract (E_θ) [N/m].
double strip_stretch_modulus(const ShellMaterial& m, double angle_deg);
// The in-plane shear modulus G (G·t, N/m): the law's Q₆₆.
double shear_modulus(const ShellMaterial& m);

// ---- Cantilever bending test (ASTM D1388) ------------------------------------------------------

struct CantileverSettings {
  double width = 0.025;          // strip width [m] (the standard's 25 mm)
  int cells_along = 40;          // mesh cells along the overhang
  int cells_across = 6;
  double incline_deg = 41.5;     // the standard's incline
  double dt = 0.005;             // [s]
  double settle = 4.0;           // simulated time to rest [s]
  double mass_damping = 5.0;     // [1/s]
  double tolerance_deg = 0.02;   // the overhang is found when the chord angle is this close
  int max_runs = 12;
};

// The scene of a strip of `overhang` [m] cut at `angle_deg` to the warp, clamped at x = 0 (the
// platform's edge, where the ruler holds it flat) and hanging under gravity over +x; with
// `apparatus_obj` (a file name relative to the scene) the platform and incline as an obstacle.
nlohmann::json cantilever_scene(const FabricUnderTest& fabric, double angle_deg, double overhang,
                                const CantileverSettings& settings, const std::string& apparatus_obj = "");
// The platform and the incline as a closed OBJ (a prism across the strip): the platform's top
// `gap` [m] under the strip, its edge at x = 0, the incline face going down from it at
// `incline_deg`.
std::string cantilever_apparatus_obj(double incline_deg, double gap, double width);

struct CantileverRun {
  double overhang = 0.0;     // [m]
  double chord_deg = 0.0;    // angle below the horizontal of the chord from the edge to the tip [deg]
  double tip_speed = 0.0;    // the tip's speed at the end [m/s] (at rest: ≪ 1 mm/s)
  double seconds = 0.0;      // wall time
};
// Runs the scene of `overhang` to rest in this process and measures the chord angle.
CantileverRun run_cantilever(const FabricUnderTest& fabric, double angle_deg, double overhang,
                             const CantileverSettings& settings);

struct CantileverResult {
  double angle_deg = 0.0;           // strip direction to the warp
  double overhang = 0.0;            // L at which the tip reaches the incline [m]
  double bending_length = 0.0;      // c = L / 2 [m]
  double flexural_rigidity = 0.0;   // G = w c³ with w = ρ_A g [N·m] (per unit width)
  double expected_length = 0.0;     // (B_θ / (ρ_A g))^(1/3) of the law [m]
  std::vector<CantileverRun> runs;  // every run of the search, in order
};
// Finds the overhang whose tip reaches the incline (chord angle = incline) by the secant method on
// log L, starting from twice the law's bending length ± 10 %. `log` gets a line per run.
CantileverResult cantilever_test(const FabricUnderTest& fabric, double angle_deg, const CantileverSettings& settings,
                                 const std::function<void(const std::string&)>& log = {});

// ---- Tensile tests at small strain ----------------------------------------------------------------

struct TensileSettings {
  double length = 0.2, width = 0.05;  // specimen [m] (the free length between the grips)
  int cells_along = 40, cells_across = 10;
  double strain = 0.005;              // nominal strain the load aims at (E_θ of the law × strain × width)
};
// A static scene: the strip cut at `angle_deg`, its left end on rollers (free to contract), pulled
// along x by a force spread over its right end.
nlohmann::json tensile_scene(const FabricUnderTest& fabric, double angle_deg, const TensileSettings& settings);
struct TensileResult {
  double angle_deg = 0.0;
  double force = 0.0;          // [N]
  double strain = 0.0;         // mean axial strain between x = ±L/4 (limit surface)
  double modulus = 0.0;        // (force / width) / strain [N/m]
  double expected = 0.0;       // E_θ of the law [N/m]
  double shear_strain = 0.0;   // the warp–weft angle change in the middle [rad] (bias: ≈ the strain)
};
TensileResult tensile_test(const FabricUnderTest& fabric, double angle_deg, const TensileSettings& settings);
// G from the bias modulus and the warp and weft ones: 1/G = 4/E₄₅ − 1/E_w − 1/E_f + 2ν_wf/E_w.
double shear_from_bias(double e45, double e_warp, double e_weft, double poisson);

// ---- Cusick drape test (ISO 9073-9) -----------------------------------------------------------------

// The default meshes: clamped 12, 16, 24 rings across the annulus (1,875 to 6,831 vertices; the
// four Kawabata fabrics took 5–7 minutes each on 2 cores), loose 16, 24, 32 rings of the disc
// (817 to 3,169 vertices).
std::vector<int> default_cusick_rings(bool clamped);

struct CusickSettings {
  double specimen_radius = 0.15, support_radius = 0.09;  // [m]
  double height = 0.2;         // the specimen's plane [m]
  // The standard holds the specimen between the support disc and a disc of the same diameter on
  // top: the specimen is then an annulus whose vertices up to the support's rim are fixed
  // (`clamped_rings` rings inside the rim, so that the drawn surface is flat up to about one
  // element inside it). false: the whole disc lies loose on the support (no upper disc).
  bool clamped = true;
  int clamped_rings = 2;
  // Meshes, coarse to fine: clamped, the rings across the hanging annulus (graded, the finest at
  // the rim; annulus_obj); loose, the rings of the disc (disc_obj). Default: default_cusick_rings.
  std::vector<int> rings = default_cusick_rings(true);
  double end = 3.0;            // simulated time [s]
  double dt = 0.002;           // [s]
  double thickness = 0.001;    // contact thickness [m]
  double imperfection = 0.0;   // [m] a seeded imperfection of the specimen (scene key imperfection, seed 1); 0: none
  // [s] gravity grows linearly from zero over this time (loads.ramp_time), the specimen lowered
  // slowly onto its drape; the run lasts ramp + end. 0: the full weight at once (a drop).
  double ramp = 0.0;
};
// The loose specimen: a disc of `rings` rings (1 + 3N(N+1) vertices, ring k of 6k), in the x–z
// plane with normal +y, texture coordinates u = (x/R + 1)/2, v = (1 − z/R)/2 (warp along +x).
std::string disc_obj(double radius, int rings);
// The clamped specimen: an annulus from `inner` to `outer` [m] of `rings` rings across, ring k at
// radius inner·q^k (q = (outer/inner)^(1/rings)), plus `inner_rings` rings inside `inner` (the
// clamped part), each of annulus_around() vertices, every ring turned by half a step from the one
// inside: nearly equilateral triangles whose size grows with the radius (the finest at the rim,
// where the folds start). The same plane, normal and texture coordinates as disc_obj.
std::string annulus_obj(double inner, double outer, int rings, int inner_rings);
// The vertices per ring of annulus_obj: round(√3 π / (q − 1)).
int annulus_around(double inner, double outer, int rings);
// The specimen of `settings` with `rings` rings (annulus_obj or disc_obj) and its vertex count.
std::string cusick_specimen_obj(const CusickSettings& settings, int rings);
int cusick_vertices(const CusickSettings& settings, int rings);
// The scene (the specimen `disc_file`, relative to the scene, placed on the support; clamped: its
// vertices within the support's radius fixed).
nlohmann::json cusick_scene(const FabricUnderTest& fabric, const std::string& disc_file, const CusickSettings& settings);

}  // namespace clothsim

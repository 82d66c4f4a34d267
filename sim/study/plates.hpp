// Square Kirchhoff plates with analytic centre deflections (docs/formulas.md §9, Analytic
// references; Timoshenko & Woinowsky-Krieger, "Theory of plates and shells", tables for the
// square plate), built through the public static-analysis API. Shared by the convergence study
// (sim/study/convergence.hpp), the plate tests and bench/plate_convergence.
//
// The plate: side a [m] centred at the origin in the z = 0 plane, E = 1e7 Pa, ν = 0.3,
// t = 0.01 m, all four edges hinged (simply supported) or clamped; loaded by a uniform
// pressure q = 1 N/m² or a centre point force P = 1 N, both along −z.
#pragma once

#include "sim/mesh/mesh.hpp"
#include "sim/shell/quadrature.hpp"
#include "sim/static/static_solve.hpp"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace clothsim {

// One of the four classical square-plate cases.
struct AnalyticPlate {
  const char* id;     // short name for tables and CSV files, e.g. "plate_ss_uniform"
  const char* label;  // e.g. "simply supported, uniform load"
  bool clamped;       // false: hinged edges (simply supported)
  bool point_load;    // false: uniform load q; true: centre point force P
  double coefficient;  // centre deflection w = c q a⁴ / D (uniform) or w = c P a² / D (point)
  double last_digit;   // the unit of the coefficient's last given digit: it is known to ± ½ of it

  // Relative uncertainty of the reference from rounding the coefficient [-].
  constexpr double relative_precision() const { return 0.5 * last_digit / coefficient; }
};

// Simply supported / clamped × uniform / point load, in that order (coefficients:
// docs/formulas.md §9, Analytic references).
// The clamped point-load coefficient has 4 digits only (± 9e-5 relative): finer errors than that
// cannot be told apart from the reference's rounding.
inline constexpr std::array<AnalyticPlate, 4> kAnalyticPlates{{
    {"plate_ss_uniform", "simply supported, uniform load", false, false, 0.00406235, 1e-8},
    {"plate_clamped_uniform", "clamped, uniform load", true, false, 0.00126532, 1e-8},
    {"plate_ss_point", "simply supported, centre point load", false, true, 0.0116008, 1e-7},
    {"plate_clamped_point", "clamped, centre point load", true, true, 0.005612, 1e-6},
}};

inline constexpr double kPlatePressure = 1.0;  // q [N/m²]
inline constexpr double kPlateForce = 1.0;     // P [N]

// Control vertices of `mesh` whose rest position (a 1 × 3 row [m]) satisfies `pred`, ascending.
template <class Pred>
std::vector<int> select_vertices(const TriMesh& mesh, Pred pred) {
  std::vector<int> out;
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (pred(mesh.vertices.row(v))) out.push_back(v);
  return out;
}

// The control vertex nearest to `point` [m] (ties → lowest index).
int nearest_vertex(const TriMesh& mesh, const Eigen::Vector3d& point);

// Unloaded square plate: side `side` [m], divisions × divisions cells (make_grid), E = 1e7 Pa,
// ν = 0.3, t = 0.01 m, all border vertices hinged (clamped = false) or clamped, the given
// quadrature rule.
Problem square_plate(int divisions, bool clamped, Quadrature rule, double side = 1.0);

// Flexural rigidity D = E t³ / (12 (1 − ν²)) of the problem's material [N·m].
double plate_rigidity(const Problem& problem);

// square_plate with the case's load: q = kPlatePressure on the whole plate, or P = kPlateForce
// at the control vertex nearest to the centre (the vertex at the centre for even divisions).
Problem plate_problem(const AnalyticPlate& plate, int divisions, Quadrature rule, double side = 1.0);

// The analytic downward centre deflection [m] of `plate` for the material and side of
// `problem` (as built by plate_problem with that side).
double plate_reference_deflection(const AnalyticPlate& plate, const Problem& problem, double side = 1.0);

}  // namespace clothsim

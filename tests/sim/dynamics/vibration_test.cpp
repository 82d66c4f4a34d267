// Free vibration against closed-form natural frequencies (small amplitudes, so the corotational
// element is linear). A load applied suddenly at t = 0 sets the structure oscillating about its
// static deflection; the period is read from the times of the maxima of one vertex's
// displacement (parabola through the three samples around each). References:
// - simply supported square plate, side a: ω₁₁ = 2π²/a² · √(D/ρh), D = E t³ / (12 (1 − ν²))
//   (Leissa, Vibration of Plates, NASA SP-160, 1969, §4.1);
// - cantilever strip (ν = 0, so a beam of EI = D·b), length L: ω₁ = (1.8751041)² √(EI/(μ L⁴)),
//   μ = ρh·b (Euler–Bernoulli; the first root of 1 + cos βL cosh βL = 0).
// Implicit Euler with step h turns an undamped oscillator of frequency ω into a damped one of
// frequency atan(ωh)/h (eigenvalues 1/(1 ∓ iωh) of the step map), so the discrete reference
// period is 2πh / atan(ωh); the step also damps the higher modes the sudden load excites.
#include "sim/dynamics/simulator.hpp"
#include "sim/scene/scene.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/shell/material.hpp"

#include <Eigen/QR>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <vector>

namespace clothsim {
namespace {

// The mode that remains in a signal sampled every h seconds, recovered from the step map: once the
// higher modes have died out, the samples satisfy w_{n+1} = p w_n + q w_{n−1} + c (c from the
// static part), with the step map's eigenvalues λ, λ̄ the roots of λ² − p λ − q (least squares over
// the samples). Implicit Euler maps a mode e^{st} to λ = 1/(1 − s h), so
// s = (1 − 1/λ)/h = −ζω + iω√(1 − ζ²): the frequency ω = |s| and the damping ratio
// ζ = −Re(s)/|s| of the space-discretised system, free of the time step's own error.
struct Mode {
  double omega;  // undamped natural frequency [rad/s]
  double zeta;   // damping ratio
};

Mode fitted_mode(const std::vector<double>& w, double h, std::size_t skip) {
  const Eigen::Index rows = static_cast<Eigen::Index>(w.size() - skip - 2);
  Eigen::MatrixX3d a(rows, 3);
  Eigen::VectorXd b(rows);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const std::size_t n = skip + 1 + static_cast<std::size_t>(r);
    a.row(r) << w[n], w[n - 1], 1.0;
    b(r) = w[n + 1];
  }
  const Eigen::Vector3d pqc = a.colPivHouseholderQr().solve(b);
  const double p = pqc(0), q = pqc(1);
  const std::complex<double> lambda(p / 2, std::sqrt(std::max(-q - p * p / 4, 0.0)));
  const std::complex<double> s = (1.0 - 1.0 / lambda) / h;
  return {std::abs(s), -s.real() / std::abs(s)};
}

struct Vibration {
  Mode mode;         // measured
  double reference;  // analytic frequency [rad/s]
  double error() const { return mode.omega / reference - 1; }
};

// The signal: z-displacement of `probe`, one sample per step.
std::vector<double> run(const Problem& p, int probe) {
  Simulator sim(p);
  std::vector<double> w;
  w.reserve(sim.num_steps());
  for (int i = 0; i < sim.num_steps(); ++i) {
    sim.step();
    w.push_back(-(sim.state().positions()(probe, 2) - p.mesh.vertices(probe, 2)));
  }
  return w;
}

Vibration simply_supported_plate(int n, DampingSettings damping = {}) {
  const double a = 1.0, t = 0.01, rho = 1000.0, young = 1e7, nu = 0.3;
  Problem p;
  p.mesh = make_grid(a, a, n, n);
  p.material = ShellMaterial::from_solid(young, nu, t, rho);
  BoundaryCondition edge;  // hinged: displacements held, rotation free
  int centre = -1;
  for (int v = 0; v < p.mesh.num_vertices(); ++v) {
    const double x = p.mesh.vertices(v, 0), y = p.mesh.vertices(v, 1);
    if (std::abs(std::abs(x) - a / 2) < 1e-9 || std::abs(std::abs(y) - a / 2) < 1e-9) edge.vertices.push_back(v);
    if (std::abs(x) < 1e-9 && std::abs(y) < 1e-9) centre = v;
  }
  p.boundary = {edge};
  p.damping = damping;
  p.surface_load = Eigen::Vector3d(0, 0, -0.01);  // static centre deflection 4.4e-5 m = 0.4 % of t
  p.time.dt = 0.01;
  const double d = young * t * t * t / (12 * (1 - nu * nu));
  const double omega = 2 * std::numbers::pi * std::numbers::pi / (a * a) * std::sqrt(d / (rho * t));
  p.time.end = 4.0 * 2 * std::numbers::pi / omega;  // four periods
  p.solver.preconditioner = PreconditionerType::cholesky;
  p.solver.tolerance = 1e-10;
  return {fitted_mode(run(p, centre), p.time.dt, static_cast<std::size_t>(1.0 / p.time.dt)), omega};
}

Vibration cantilever(int along, int across) {
  const double length = 0.2, width = 0.02, rigidity = 1e-4, areal_density = 0.1;  // B [N·m], ρh [kg/m²]
  Problem p;
  p.mesh = make_grid(length, width, along, across);
  p.material.stretch_modulus = 1e4;
  p.material.bending_rigidity = rigidity;
  p.material.poisson_ratio = 0.0;
  p.material.areal_density = areal_density;
  BoundaryCondition clamp;
  clamp.clamped = true;
  int tip = -1;
  for (int v = 0; v < p.mesh.num_vertices(); ++v) {
    const double x = p.mesh.vertices(v, 0), y = p.mesh.vertices(v, 1);
    if (x < -length / 2 + 1e-9) clamp.vertices.push_back(v);
    if (x > length / 2 - 1e-9 && std::abs(y) < 1e-9) tip = v;
  }
  p.boundary = {clamp};
  p.surface_load = Eigen::Vector3d(0, 0, -1e-4);  // tip deflection 2e-4 m = 0.1 % of L
  p.time.dt = 0.01;
  const double omega = std::pow(1.8751040687, 2) * std::sqrt(rigidity * width / (areal_density * width * std::pow(length, 4)));
  p.time.end = 4.0 * 2 * std::numbers::pi / omega;
  p.solver.preconditioner = PreconditionerType::cholesky;
  p.solver.tolerance = 1e-10;
  return {fitted_mode(run(p, tip), p.time.dt, static_cast<std::size_t>(2.0 / p.time.dt)), omega};
}

TEST(Vibration, SimplySupportedPlateMatchesTheFundamentalFrequency) {
  double previous = 1.0;
  for (int n : {8, 16, 32}) {
    const Vibration r = simply_supported_plate(n);
    std::printf("simply supported plate %d x %d: omega %.6f rad/s, reference %.6f, error %+.3f %%, damping ratio %.1e\n",
                n, n, r.mode.omega, r.reference, 100 * r.error(), r.mode.zeta);
    EXPECT_LT(std::abs(r.error()), 0.8 * previous);  // converges under refinement
    EXPECT_LT(std::abs(r.mode.zeta), 5e-4);           // no damping but the time step's
    previous = std::abs(r.error());
  }
  EXPECT_LT(previous, 0.005);  // 32 × 32 within 0.5 %
}

// The same plate through the shipped scene file (scene format, probe at the centre).
TEST(Vibration, ShippedPlateVibrationSceneMatchesTheFundamentalFrequency) {
  const Scene scene = load_scene(std::string(CLOTHSIM_SOURCE_DIR) + "/scenes/plate_vibration.json", nullptr);
  const double d = 1e7 * 1e-6 / (12 * (1 - 0.3 * 0.3));
  const double omega = 2 * std::numbers::pi * std::numbers::pi * std::sqrt(d / (1000 * 0.01));
  const Problem& p = scene.problem;
  const Mode m = fitted_mode(run(p, scene.probes.at(0).vertex), p.time.dt, static_cast<std::size_t>(1.0 / p.time.dt));
  std::printf("plate_vibration.json: omega %.6f rad/s, reference %.6f, error %+.3f %%\n", m.omega, omega,
              100 * (m.omega / omega - 1));
  EXPECT_NEAR(m.omega / omega, 1.0, 0.005);
  EXPECT_LT(std::abs(m.zeta), 5e-4);
}

// Refined along and across together (the across resolution alone leaves an error that does not
// vanish when only the length is refined: 2, 4, 8 cells across at 80 along gave −2.2, −0.59,
// −0.18 %).
TEST(Vibration, CantileverStripMatchesTheFirstBendingFrequency) {
  double previous = 1.0;
  for (auto [along, across] : {std::pair{20, 4}, {40, 8}, {80, 16}}) {
    const Vibration r = cantilever(along, across);
    std::printf("cantilever strip %d x %d: omega %.6f rad/s, reference %.6f, error %+.3f %%, damping ratio %.1e\n",
                along, across, r.mode.omega, r.reference, 100 * r.error(), r.mode.zeta);
    EXPECT_LT(std::abs(r.error()), 0.8 * previous);
    EXPECT_LT(std::abs(r.mode.zeta), 5e-4);
    previous = std::abs(r.error());
  }
  EXPECT_LT(previous, 0.002);  // 80 × 16 within 0.2 %
}

// Kelvin–Voigt damping C = c K gives a mode of frequency ω the damping ratio ζ = c ω / 2, mass
// damping C = m M the ratio ζ = m / (2 ω) (Rayleigh damping); compared at the frequency the
// undamped run of the same mesh measured.
TEST(Vibration, RayleighDampingGivesTheModalDampingRatio) {
  const double omega = simply_supported_plate(16).mode.omega;
  DampingSettings stiffness, mass;
  stiffness.stiffness = 0.01;  // [s]
  mass.mass = 0.2;             // [1/s]
  const Mode with_stiffness = simply_supported_plate(16, stiffness).mode;
  const Mode with_mass = simply_supported_plate(16, mass).mode;
  std::printf("damping ratio: stiffness-proportional %.5f (c w / 2 = %.5f), mass-proportional %.5f (m / 2w = %.5f)\n",
              with_stiffness.zeta, 0.01 * omega / 2, with_mass.zeta, 0.2 / (2 * omega));
  EXPECT_NEAR(with_stiffness.zeta, 0.01 * omega / 2, 0.02 * 0.01 * omega / 2);
  EXPECT_NEAR(with_mass.zeta, 0.2 / (2 * omega), 0.02 * 0.2 / (2 * omega));
  EXPECT_NEAR(with_stiffness.omega, omega, 1e-3 * omega);  // damping does not change ω
  EXPECT_NEAR(with_mass.omega, omega, 1e-3 * omega);
}

}  // namespace
}  // namespace clothsim

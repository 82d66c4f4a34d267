// The contact stage's response after the step's solve (the fail-safe, and with collision.method
// "constraints" all of contact): the pairs found to respond to (`Found`: a constraint on the node
// velocities, the distance it had, and a key that names it from step to step, so its multipliers
// start from the last step's), the implicit response that solves the step's system with the
// constraints in it (an augmented Lagrangian, docs/contact.md), and the impact zones of the last
// resort: nodes joined by pairs that still collide, each zone moved as one rigid map over the step
// (sim/contact/impact_zones.hpp).
//
// Per-step inputs (the step's system, start positions and velocities) are arguments; what lasts
// across steps (the last step's multipliers, the Newton matrix's factor) is kept here.
#pragma once

#include "sim/contact/collision_surface.hpp"
#include "sim/contact/contact_stage.hpp"
#include "sim/contact/impact_zones.hpp"
#include "sim/contact/pair_types.hpp"
#include "sim/solver/cholesky_preconditioner.hpp"
#include "sim/solver/coupled_matrix.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <tuple>
#include <utility>
#include <vector>

namespace clothsim::contact {

// What a constraint stands for, to start its multipliers from the last step's.
struct ConstraintKey {
  std::uint8_t source = 0;  // 0 proximity, 1 CCD
  std::uint8_t kind = 0;    // the Candidate's kind, or 255 for a plane (a: the plane, b: the point)
  int a = 0, b = 0;
  bool operator<(const ConstraintKey& o) const { return std::tie(source, kind, a, b) < std::tie(o.source, o.kind, o.a, o.b); }
  bool operator==(const ConstraintKey& o) const { return source == o.source && kind == o.kind && a == o.a && b == o.b; }
};
inline ConstraintKey key_of(const Candidate& c, std::uint8_t source) {
  return {source, static_cast<std::uint8_t>(c.kind), c.a, c.b};
}

// A pair to respond to: its constraint, and the distance it had where it was found.
struct Found {
  Constraint constraint;
  double distance = 0.0;
  double separation = 0.0;  // CCD: the separation the pair must keep [m]
  ConstraintKey key{};
};

// The multipliers of the last step's constraints with an impulse, by key.
class KeptMultipliers {
 public:
  // Starts each constraint whose key had an impulse last step from that step's multipliers.
  void warm_start(std::vector<Found>& found) const;
  // Keeps the multipliers of the constraints with an impulse (a pair found twice keeps its
  // first entry).
  void keep(const std::vector<Found>& found);

 private:
  std::vector<std::pair<ConstraintKey, std::pair<double, Eigen::Vector3d>>> last_;  // sorted by key
};

// The implicit response: the new velocities v solve
//     min ½ (v − v*)ᵀ A (v − v*) + Σᵢ μᵢ λᵢ |wᵢ(v)|   subject to   targetᵢ − nᵢ·uᵢ(v) ≤ 0
// for the step's system A (ResponseSystem), the solve's velocities v* and each constraint's
// relative velocity uᵢ, tangential part wᵢ and normal impulse λᵢ (fail_safe.cpp has the method:
// an augmented Lagrangian with Newton inside). Keeps the Cholesky factor of its Newton matrix
// across calls.
class ImplicitResponse {
 public:
  explicit ImplicitResponse(const ContactParameters& parameters) : params_(parameters) {}

  // Solves for v (in place, free DOFs only) from v* = `base`, to `tolerance` [m/s], with the
  // step's system and its diagonal (per DOF), the free-DOF mask and the collision surface (for
  // the constraints' node form). The multipliers stay in the constraints (the next call starts
  // from them). Adds its iterations, factorisations, impulses and time to `report`.
  void solve(std::vector<Found>& found, const Eigen::VectorXd& base, Eigen::VectorXd& v, const ResponseSystem& system,
             const Eigen::VectorXd& diagonal, const std::vector<char>& free, double tolerance, CollisionSurface& surface,
             ContactReport& report);

 private:
  ContactParameters params_;
  std::unique_ptr<CholeskyPreconditioner> newton_factor_;  // of the Newton matrix
  // That matrix: A's pattern and the node couplings of the constraints it was made for.
  CoupledMatrix newton_pattern_;
};

// Merges the nodes of each colliding pair into one zone and marks them in `zone_obstacle` (per
// node: −2 in no zone, −1 a cloth zone, else the highest obstacle index among its pairs).
void merge_zones(const std::vector<Found>& hits, Zones& zones, std::vector<int>& zone_obstacle);

// Moves each impact zone (the nodes with zone_obstacle ≠ −2, grouped by their root) as one map
// over the step from start positions x at time t by h: the obstacle's motion when the zone holds
// one, else the rigid map fitted to its prescribed nodes' motion, else the rigid velocity field
// with the zone's linear and angular momentum (node masses `node_mass`); v changes on free DOFs
// only. Sets report.impact_zones and adds the time to report.response_ms.
void move_impact_zones(Zones& zones, const std::vector<int>& zone_obstacle, const Eigen::VectorXd& x, double t, double h,
                       const std::vector<char>& free, const Eigen::VectorXd& node_mass, const std::vector<Obstacle>& obstacles,
                       Eigen::VectorXd& v, ContactReport& report);

}  // namespace clothsim::contact

// The pairs the contact stage works with: candidate pairs of primitives from the broad phase,
// distance bounds over a list of them, the geometry of a pair at one instant, and a pair's
// constraint on the node velocities (sim/contact/contact_stage.hpp has how they are used).
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <utility>
#include <vector>

namespace clothsim::contact {

// A narrow-phase pair. Points and triangles index the collision surface ("cloth") or the
// obstacles' combined mesh ("obstacle"); edges likewise.
enum class Kind : std::uint8_t {
  cloth_point_cloth_triangle,
  cloth_edge_cloth_edge,
  cloth_point_obstacle_triangle,
  obstacle_point_cloth_triangle,
  cloth_edge_obstacle_edge,
};

struct Candidate {
  Kind kind;
  int a, b;  // point and triangle, or edge and edge, in the order of the kind's name
  bool near = false;  // from triangles near each other at rest: CCD only, at a tiny separation
  bool operator<(const Candidate& o) const {
    return std::tie(kind, a, b) < std::tie(o.kind, o.a, o.b);
  }
  bool operator==(const Candidate& o) const { return kind == o.kind && a == o.a && b == o.b; }
};

// Lower bounds of the distances of a list of candidate pairs at some configuration
// (BarrierPotential::reference_bounds, sim/contact/barrier_potential.hpp), and the candidates whose
// bound is below each of a few reaches, so that a pass that needs only the pairs that can come
// within some distance visits the shortest list that holds them (a resting drape's step bound
// visits none of its tens of thousands of candidates, its linearisation those within the barrier's
// reach).
struct Bounds {
  // A list of candidates: index[0 .. size), or every candidate (`all`).
  struct List {
    bool all = true;
    const size_t* index = nullptr;
    size_t size = 0;
    size_t operator[](size_t j) const { return index[j]; }
  };
  std::vector<double> lower;    // per candidate [m]
  std::vector<double> reaches;  // increasing [m]
  // The candidates with a bound below the largest reach, those below the smallest first, then
  // those below the next, and so on (each part in increasing order); ends[k] counts those below
  // reaches[k].
  std::vector<size_t> close;
  std::vector<size_t> ends;
  // Makes the lists for `reaches` (any order), in two passes over the bounds.
  void make_close(std::vector<double> r) {
    std::sort(r.begin(), r.end());
    reaches = std::move(r);
    const size_t levels = reaches.size();
    level_.resize(lower.size());
    std::vector<size_t> count(levels + 1, 0);
    for (size_t i = 0; i < lower.size(); ++i) {
      unsigned char k = 0;
      for (double reach : reaches) k = static_cast<unsigned char>(k + (lower[i] >= reach));
      level_[i] = k;
      ++count[k];
    }
    ends.assign(levels, 0);
    std::vector<size_t> next(levels + 1, 0);
    for (size_t k = 0, sum = 0; k < levels; ++k) {
      next[k] = sum;
      sum += count[k];
      ends[k] = sum;
    }
    close.resize(levels > 0 ? ends.back() : 0);
    for (size_t i = 0; i < lower.size(); ++i)
      if (level_[i] < levels) close[next[level_[i]]++] = i;
  }
  // The shortest list that holds every candidate whose distance may be below `threshold` after
  // each pair's distance changed by at most `motion` [m]; `all` when that may be any candidate.
  List within(double threshold, double motion) const {
    for (size_t k = 0; k < reaches.size(); ++k)
      if (reaches[k] - motion >= threshold) return List{false, close.data(), ends[k]};
    return List{};
  }
  // The bounds less `motion` (at least 0): the bounds after every point moved by at most that.
  std::vector<double> less(double motion) const {
    std::vector<double> out(lower.size());
    for (size_t i = 0; i < lower.size(); ++i) out[i] = std::max(0.0, lower[i] - motion);
    return out;
  }

 private:
  std::vector<unsigned char> level_;  // (make_close's scratch)
};

// Geometry of one pair at one instant: up to four points on each side with coefficients
// (relative position = Σ c_k p_k, cloth points first), a unit normal from the second primitive
// to the first, and their distance.
struct PairGeometry {
  int num = 0;                        // points in use
  std::array<int, 4> point{};         // point index (cloth or obstacle, see `obstacle`)
  std::array<bool, 4> obstacle{};     // whether the point is an obstacle vertex
  std::array<double, 4> coef{};       // +1 / weights on the first primitive, −weights on the second
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double distance = 0.0;
};

// A contact constraint in DOF space: the relative velocity of the pair is
// u = Σ_dof B[dof] v[dof] + u_obstacle (3-vectors B), so an impulse λ along a unit direction e
// changes v[dof] by W[dof] λ (B[dof]·e).
struct Constraint {
  std::vector<std::pair<int, Eigen::Vector3d>> b;  // (dof, B[dof])
  Eigen::Vector3d obstacle_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double target = 0.0;    // wanted normal relative velocity [m/s]
  double mu = 0.0;        // friction coefficient
  double lambda = 0.0;    // accumulated normal impulse [N·s]
  Eigen::Vector3d friction = Eigen::Vector3d::Zero();  // accumulated tangential impulse [N·s]
  int obstacle = -1;      // obstacle involved, or −1
};

}  // namespace clothsim::contact

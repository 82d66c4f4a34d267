// The states the force-term tests check a term at (tests/support/fd_check.hpp): rest, seeded random
// states, a strong in-plane compression, a fold and a large rotation with strain; rigid motions and
// the isometric bending of a flat sheet into a cylinder.
#pragma once

#include "sim/discretization/discretization.hpp"
#include "tests/support/fd_check.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <string>
#include <vector>

namespace clothsim::testing {

// The rotation by `angle` [rad] about `axis` (any length).
inline Eigen::Matrix3d rotation(double angle, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// Node positions x = R X + c (3·#nodes), X the rest positions.
inline Eigen::VectorXd rigidly_moved(const Discretization& d, const Eigen::Matrix3d& r, const Eigen::Vector3d& c) {
  Eigen::VectorXd x = d.rest();
  for (int v = 0; v < d.num_nodes(); ++v) x.segment<3>(3 * v) = r * x.segment<3>(3 * v) + c;
  return x;
}

struct State {
  std::string name;
  Eigen::VectorXd x;
};

// Which states `states` makes: how many random ones, and the fold.
struct StateOptions {
  unsigned random_states = 2;                // seeds 1, 2, …
  double fold_degrees = 150.0;               // the part with x > fold_from turned about the y axis
  double fold_from = 0.001;                  // [m]
  std::string fold_name = "folded 150 deg";  // the folded state's name
};

// Rest; seeded random states (rest perturbed by up to 2 mm); a strong compression (30 % shorter
// along x, with a little noise to leave the symmetric state); a fold (the part with x > fold_from
// turned about the y axis: a crease across x); a large rotation (1.2 rad about a skew axis) plus
// a small strain. Fixed components are moved too: the terms do not care which are prescribed.
inline std::vector<State> states(const Discretization& d, const StateOptions& options = {}) {
  std::vector<State> out;
  out.push_back({"rest", d.rest()});
  for (unsigned seed = 1; seed <= options.random_states; ++seed)
    out.push_back({"random " + std::to_string(seed), perturbed_rest(d, 2e-3, seed)});
  Eigen::VectorXd compressed = perturbed_rest(d, 2e-4, 7);
  for (int v = 0; v < d.num_nodes(); ++v) compressed(3 * v) *= 0.7;
  out.push_back({"compressed 30 %", compressed});
  Eigen::VectorXd folded = perturbed_rest(d, 2e-4, 11);
  const Eigen::Matrix3d fold = rotation(options.fold_degrees * M_PI / 180.0, Eigen::Vector3d::UnitY());
  for (int v = 0; v < d.num_nodes(); ++v)
    if (folded(3 * v) > options.fold_from) folded.segment<3>(3 * v) = fold * folded.segment<3>(3 * v);
  out.push_back({options.fold_name, folded});
  Eigen::VectorXd turned = rigidly_moved(d, rotation(1.2, Eigen::Vector3d(1, 2, -0.5)), Eigen::Vector3d(0.01, -0.02, 0.03));
  turned += perturbed_rest(d, 1e-3, 13) - d.rest();
  out.push_back({"large rotation", turned});
  return out;
}

// The rest positions of a flat sheet in the plane z = 0 bent isometrically into a cylinder of
// curvature κ [1/m] towards +z, the curvature direction at `angle` [rad] from the x axis: the
// coordinate s along it goes to sin(κs)/κ along it and (1 − cos(κs))/κ along z.
inline Eigen::VectorXd bent_into_cylinder(const Discretization& d, double angle, double kappa) {
  const Eigen::Vector3d dir(std::cos(angle), std::sin(angle), 0.0), up(0, 0, 1);
  Eigen::VectorXd x = d.rest();
  for (int v = 0; v < d.num_nodes(); ++v) {
    const Eigen::Vector3d p = d.rest().segment<3>(3 * v);
    const double s = p.dot(dir);
    x.segment<3>(3 * v) = p - s * dir + std::sin(kappa * s) / kappa * dir + (1.0 - std::cos(kappa * s)) / kappa * up;
  }
  return x;
}

}  // namespace clothsim::testing

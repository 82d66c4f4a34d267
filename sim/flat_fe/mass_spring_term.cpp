#include "sim/flat_fe/mass_spring_term.hpp"

#include "sim/flat_fe/mass_spring.hpp"

#include <stdexcept>
#include <string>

namespace clothsim {

MassSpringElastic::MassSpringElastic(const MassSpringDiscretization& d, bool tension_stiffening)
    : d_(d), tension_stiffening_(tension_stiffening) {
  update(d.rest(), Eigen::VectorXd::Zero(d.rest().size()), 0.0);  // the rest state until the first update
}

double MassSpringElastic::evaluate(const std::vector<Spring>& springs, const Eigen::VectorXd& x,
                                   std::vector<SpringState>& state) {
  state.resize(springs.size());
  double energy = 0.0;
  for (size_t s = 0; s < springs.size(); ++s) {
    const Spring& spring = springs[s];
    const Eigen::Vector3d d = x.segment<3>(3 * spring.i) - x.segment<3>(3 * spring.j);
    const double l = d.norm();
    if (!(l > 0)) {
      evaluated_ = false;
      throw std::runtime_error("mass-spring: the nodes " + std::to_string(spring.i) + " and " + std::to_string(spring.j) +
                               " of a spring coincide, so its direction is undefined");
    }
    const Eigen::Vector3d n = d / l;
    const double stretch = l - spring.rest_length;
    energy += 0.5 * spring.stiffness * stretch * stretch;
    const Eigen::Vector3d f = -spring.stiffness * stretch * n;  // on node i
    force_.segment<3>(3 * spring.i) += f;
    force_.segment<3>(3 * spring.j) -= f;
    state[s] = {l, n};
  }
  return energy;
}

void MassSpringElastic::update(const Eigen::VectorXd& x, const Eigen::VectorXd& /*u*/, double /*t*/) {
  if (evaluated_ && x.size() == x_.size() && x == x_) return;
  force_ = Eigen::VectorXd::Zero(x.size());
  stretch_energy_ = evaluate(d_.stretch_springs(), x, stretch_state_);
  bending_energy_ = evaluate(d_.bending_springs(), x, bending_state_);
  x_ = x;
  evaluated_ = true;
}

void MassSpringElastic::add_springs(const std::vector<Spring>& springs, const std::vector<SpringState>& state,
                                    double weight, double* values) const {
  const NodeBlockPattern& blocks = d_.blocks();
  for (size_t s = 0; s < springs.size(); ++s) {
    const Spring& spring = springs[s];
    const Eigen::Vector3d& n = state[s].direction;
    const Eigen::Matrix3d nn = n * n.transpose();
    // k (1 − L₀/l): the transverse (geometric) stiffness; negative when compressed.
    double transverse = spring.stiffness * (1.0 - spring.rest_length / state[s].length);
    if (!exact_hessian_ && (transverse < 0.0 || !tension_stiffening_)) transverse = 0.0;
    const Eigen::Matrix3d h =
        weight * (spring.stiffness * nn + transverse * (Eigen::Matrix3d::Identity() - nn));
    blocks.add_block(spring.group, spring.a, spring.a, h, values);
    blocks.add_block(spring.group, spring.b, spring.b, h, values);
    blocks.add_block(spring.group, spring.a, spring.b, -h, values);
    blocks.add_block(spring.group, spring.b, spring.a, -h, values);
  }
}

void MassSpringElastic::add_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const {
  if (w.stiffness == 0.0) return;
  add_springs(d_.stretch_springs(), stretch_state_, w.stiffness, a.valuePtr());
  add_springs(d_.bending_springs(), bending_state_, w.stiffness, a.valuePtr());
}

}  // namespace clothsim

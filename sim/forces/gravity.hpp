// Gravity, a constant acceleration g [m/s²] acting on the cloth's mass, in one of two named
// models (docs/architecture.md says which analysis uses which):
//  - lumped: f_v = m_v g with the discretisation's lumped node mass. Consistent with the lumped
//    mass matrix of the dynamics, so a free fall is exact: the dynamic analysis uses it;
//  - consistent: f_I = ∫ N_I ρ_A g dA over the rest surface (ρ_A the areal density), the work-
//    equivalent load of the shape functions, like any surface load: the static analysis uses it
//    (it converges with the element's order under refinement).
// Energy: E = −Σ f_I · u_I (a constant force: the potential of the load, relative to the rest).
#pragma once

#include "sim/discretization/discretization.hpp"
#include "sim/core/force_term.hpp"

namespace clothsim {

enum class GravityModel { lumped, consistent };

// A force that does not depend on the state (gravity, surface loads, point loads): f₀ = F,
// energy −F·u.
class ConstantForce : public ForceTerm {
 public:
  ConstantForce(std::string name, Eigen::VectorXd force) : name_(std::move(name)), force_(std::move(force)) {}
  std::string name() const override { return name_; }
  void update(const Eigen::VectorXd&, const Eigen::VectorXd& u, double) override { energy_ = -force_.dot(u); }
  bool has_energy() const override { return true; }
  double energy() const override { return energy_; }
  void add_force(Eigen::VectorXd& f) const override { f += force_; }
  // The nodal force (3·#nodes) [N].
  const Eigen::VectorXd& force() const { return force_; }

 private:
  std::string name_;
  Eigen::VectorXd force_;
  double energy_ = 0.0;
};

// Gravity g [m/s²] on a discretisation with areal density `areal_density` [kg/m²].
std::unique_ptr<ConstantForce> make_gravity(const Discretization& d, double areal_density, const Eigen::Vector3d& g,
                                            GravityModel model);

}  // namespace clothsim

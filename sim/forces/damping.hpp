// Damping force terms (paper §4.2: "a damping term proportional to the velocities"), both linear
// in the velocity, f = −D v, and integrated implicitly:
//  - Kelvin–Voigt (stiffness-proportional, Rayleigh β) damping of an elastic term, D = c·K with K
//    that term's (rotated) stiffness: a viscosity of the material that damps strain rates and
//    leaves rigid motion alone. It wraps the elastic term and stands in for it, so the term's
//    matrix is assembled once per step with the weight (w_K + c·w_D);
//  - mass-proportional (Rayleigh α) damping, D = c·M with the lumped mass: a drag on every
//    velocity, rigid motion included.
// Damping ratio of a mode of angular frequency ω: ζ = c_K ω / 2 + c_M / (2ω).
#pragma once

#include "sim/core/sparse_pattern.hpp"
#include "sim/core/force_term.hpp"

#include <memory>
#include <vector>

namespace clothsim {

class KelvinVoigtDamping final : public ForceTerm {
 public:
  // `coefficient` c_K >= 0 [s].
  KelvinVoigtDamping(std::unique_ptr<ForceTerm> elastic, double coefficient);

  std::string name() const override;
  void update(const Eigen::VectorXd& x, const Eigen::VectorXd& u, double t) override { elastic_->update(x, u, t); }
  bool has_energy() const override { return elastic_->has_energy(); }
  double energy() const override { return elastic_->energy(); }  // the elastic term's [J]
  void add_force(Eigen::VectorXd& f) const override { elastic_->add_force(f); }
  double frame_turn() const override { return elastic_->frame_turn(); }
  bool has_matrix() const override { return true; }
  // a += (w_K + c w_D) K + w_D D_elastic.
  void add_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const override;
  void set_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const override;

  ForceTerm& elastic() { return *elastic_; }
  const ForceTerm& elastic() const { return *elastic_; }
  double coefficient() const { return coefficient_; }

 private:
  std::unique_ptr<ForceTerm> elastic_;
  double coefficient_;
};

class MassDamping final : public ForceTerm {
 public:
  // `node_mass`: lumped mass per node [kg]; `coefficient` c_M >= 0 [1/s]. `pattern`: the
  // system matrix pattern (every diagonal entry present).
  MassDamping(const Eigen::VectorXd& node_mass, double coefficient, const Eigen::SparseMatrix<double>& pattern);

  std::string name() const override { return "mass damping"; }
  void update(const Eigen::VectorXd&, const Eigen::VectorXd&, double) override {}
  void add_force(Eigen::VectorXd&) const override {}  // f₀ = 0; the force is −D v
  bool has_matrix() const override { return true; }
  void add_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const override;

 private:
  Eigen::VectorXd dof_mass_;             // 3·#nodes [kg]
  double coefficient_;
  std::vector<Eigen::Index> diagonal_;   // value offsets of the diagonal entries
};

}  // namespace clothsim

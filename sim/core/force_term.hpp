// One force model of the simulation: its force, its contribution to the system matrix in the
// discretisation's fixed sparsity pattern and, where one exists, its energy. The integrator only
// sees this interface (sim/integrator/implicit_euler.hpp); adding a force model means adding a
// ForceTerm, never editing the integrator. docs/architecture.md shows how, with its test.
//
// Every force has the form
//     f(x, v, t) = f₀(x, t) − D(x) v,
// f₀ the position-dependent part (elastic forces, loads) and D v a damping force linear in the
// velocity, which the integrator treats implicitly. Around the state x where update() was called,
//     K = −∂f₀/∂x   (stiffness),     D   (damping),
// both symmetric and sharing the pattern of the discretisation's system matrix
// (Discretization::matrix_pattern()). A term whose force is integrated explicitly (a follower
// couple, whose Jacobian is neither symmetric nor in the pattern) reports no matrix.
//
// Units: positions [m], forces [N], energy [J], K [N/m], D [N·s/m]. Vectors are flat over the
// discretisation's nodes (sim/core/layout.hpp): [x0 y0 z0 x1 ...], 3·#nodes.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <algorithm>
#include <string>

namespace clothsim {

// Weights of the matrix a term adds: a += stiffness · K + damping · D. Implicit Euler with the
// velocities as unknowns uses stiffness = h², damping = h (the integrator owns them).
struct MatrixWeights {
  double stiffness = 0.0;
  double damping = 0.0;
};

class ForceTerm {
 public:
  virtual ~ForceTerm() = default;

  // A short name for logs and test output ("corotated shell", "gravity (lumped)", ...).
  virtual std::string name() const = 0;

  // Evaluates the term at positions x [m], with u = x − X the displacements from the rest state
  // [m] (both 3·#nodes, every component consistent with the discretisation's constraints; the
  // integrator computes u once and hands the same values to every term), at time t [s].
  // Everything energy(), add_force() and add_matrix() report refers to this state until the next
  // call. Throws std::runtime_error when the state cannot carry the term (the message names it).
  virtual void update(const Eigen::VectorXd& x, const Eigen::VectorXd& u, double t) = 0;

  // Whether energy() is meaningful: f₀ = −∂E/∂x. Loads that do not derive from a potential
  // (follower couples) have none.
  virtual bool has_energy() const { return false; }
  virtual double energy() const { return 0.0; }  // [J]

  // The largest turn of a local frame the term is linearised about (a corotated element's
  // rotation) from the update() before the last one to the last [rad]; 0 for a term without such
  // frames or when the last update() reused the state before it. The integrator re-linearises a
  // step in contact while it exceeds the solver's tolerance (sim/integrator/implicit_euler.hpp).
  virtual double frame_turn() const { return 0.0; }

  // f += f₀ at the last update() [N].
  virtual void add_force(Eigen::VectorXd& f) const = 0;

  // Whether add_matrix() adds anything (false: the term is integrated explicitly).
  virtual bool has_matrix() const { return false; }
  // a += w.stiffness · K + w.damping · D at the last update(). `a` has the discretisation's
  // pattern (compressed, column-major); only its values are touched.
  virtual void add_matrix(const MatrixWeights& /*w*/, Eigen::SparseMatrix<double>& /*a*/) const {}
  // a = w.stiffness · K + w.damping · D: the same as setting every value of `a` to zero and calling
  // add_matrix(). The integrator asks the first term for this; a term whose matrix fills the
  // whole pattern overrides it to save the clearing pass (the corotated shell: 4 % of a step).
  virtual void set_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const {
    std::fill(a.valuePtr(), a.valuePtr() + a.nonZeros(), 0.0);
    add_matrix(w, a);
  }
};

}  // namespace clothsim

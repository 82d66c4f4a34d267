#include "sim/dynamics/simulator.hpp"

#include "sim/dynamics/corotation.hpp"
#include "sim/shell/shell_model.hpp"
#include "sim/solver/cholesky_preconditioner.hpp"
#include "sim/solver/direct_solver.hpp"
#include "sim/solver/pcg.hpp"

#include <Eigen/Geometry>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <sstream>

namespace clothsim {

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

Eigen::VectorXd flat(const Eigen::MatrixX3d& m) {
  Eigen::VectorXd out(3 * m.rows());
  for (Eigen::Index v = 0; v < m.rows(); ++v) out.segment<3>(3 * v) = m.row(v).transpose();
  return out;
}

Eigen::MatrixX3d unflat(const Eigen::VectorXd& f) {
  return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(f.data(), f.size() / 3, 3);
}

void check_problem(const DynamicProblem& p) {
  if (const std::string bad = validate(p.material); !bad.empty()) throw std::runtime_error("material: " + bad);
  if (!(p.material.areal_density > 0))
    throw std::runtime_error("material: a dynamic analysis needs a positive areal density (mass) [kg/m²]");
  if (!(std::isfinite(p.time.dt) && p.time.dt > 0)) throw std::runtime_error("time.dt must be > 0 [s]");
  if (!(std::isfinite(p.time.end) && p.time.end > 0)) throw std::runtime_error("time.end must be > 0 [s]");
  if (!(p.damping.stiffness >= 0 && p.damping.mass >= 0)) throw std::runtime_error("damping must be >= 0");
  if (!(p.ramp_time >= 0)) throw std::runtime_error("loads.ramp_time must be >= 0 [s]");
  for (size_t i = 0; i < p.moments.size(); ++i) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * p.mesh.num_vertices());
    if (!add_moment_forces(p.moments[i], p.mesh.vertices, f))
      throw std::runtime_error("moment " + std::to_string(i) + ": its vertices lie on a line parallel to the moment");
  }
  if (!(p.solver.tolerance > 0 && p.solver.tolerance < 1)) throw std::runtime_error("solver.tolerance must lie in (0, 1)");
  if (p.solver.max_iterations < 1 || p.solver.newton_iterations < 1)
    throw std::runtime_error("solver.max_iterations and solver.newton_iterations must be >= 1");
  for (size_t i = 0; i < p.boundary.size(); ++i) {
    if (p.boundary[i].clamped && !p.boundary[i].motion.empty())
      throw std::runtime_error("boundary[" + std::to_string(i) +
                               "]: a clamped border cannot follow a motion yet; use a hinged one");
    for (size_t k = 0; k < p.boundary[i].motion.size(); ++k)
      if (const std::string bad = validate(p.boundary[i].motion[k]); !bad.empty())
        throw std::runtime_error("boundary[" + std::to_string(i) + "].motion[" + std::to_string(k) + "]: " + bad);
  }
  const int n = p.mesh.num_vertices();
  for (const PointLoad& l : p.point_loads)
    if (l.vertex < 0 || l.vertex >= n) throw std::runtime_error("point load at vertex " + std::to_string(l.vertex) + ": no such vertex");
}

}  // namespace

struct Simulator::Impl {
  DynamicProblem problem;
  ShellModel model;
  int n = 0;
  Eigen::VectorXd rest;     // 3n rest positions
  Eigen::VectorXd mass;     // 3n lumped mass per DOF [kg]
  Eigen::VectorXd mass_per_vertex;
  Eigen::VectorXd f_ext;    // 3n constant external force [N] (before the ramp; no couples)
  CorotationalElements elements;
  std::vector<char> solve_free;            // 3n: unknown in the linear solve
  std::vector<int> prescribed_dof;         // fixed components: DOF ids
  std::vector<const std::vector<Motion>*> prescribed_motion;  // their motion chain (may be empty)
  std::vector<int> dependent_dof;          // tied components (clamped borders)
  DirectSolver direct;                // solver.type "cholmod"
  CholeskyPreconditioner factor;      // "pcg" with the "cholesky" preconditioner
  // When to refresh `factor` (counted in conjugate-gradient iterations, see step()).
  int solves_since_factor = 0;
  double iterations_since_factor = 0.0;
  bool refactor_next = false;
  Eigen::VectorXd v_previous;  // velocity at the start of the previous step (extrapolated start)
  DynamicState state;
  Eigen::MatrixX3d limit_rest;
  double work = 0.0;           // external_work()
  double boundary_work = 0.0;  // boundary_work()
  double bbox = 1.0;
  Eigen::SparseMatrix<double> system;  // the step's matrix, its storage reused from step to step
  std::vector<Eigen::Index> diagonal;  // value offsets of its diagonal entries

  explicit Impl(const DynamicProblem& p)
      : problem(p),
        model(p.mesh, p.material, p.boundary, p.quadrature),
        n(p.mesh.num_vertices()),
        elements(model, p.corotational),
        direct(/*supernodal=*/3 * p.mesh.num_vertices() > 3000) {}

  // Real displacement vector with the tied components derived from the others.
  Eigen::VectorXd consistent(const Eigen::VectorXd& x) const {
    Eigen::VectorXd u = x - rest;
    for (int dof : dependent_dof) {
      double value = 0.0;
      for (const auto& [d, w] : model.dofs().combination(dof / 3, dof % 3)) value += w * u(d);
      u(dof) = value;
    }
    return u;
  }
};

Simulator::Simulator(const DynamicProblem& problem) {
  check_problem(problem);
  impl_ = std::make_unique<Impl>(problem);
  Impl& m = *impl_;
  const int n = m.n;
  m.rest = flat(problem.mesh.vertices);
  m.bbox = std::max((problem.mesh.vertices.colwise().maxCoeff() - problem.mesh.vertices.colwise().minCoeff()).norm(), 1e-12);

  // Lumped mass: a third of each incident triangle's rest area.
  m.mass_per_vertex = Eigen::VectorXd::Zero(n);
  for (const Triangle& t : problem.mesh.triangles) {
    const Eigen::Vector3d x0 = problem.mesh.vertices.row(t[0]), x1 = problem.mesh.vertices.row(t[1]),
                          x2 = problem.mesh.vertices.row(t[2]);
    const double area = 0.5 * (x1 - x0).cross(x2 - x0).norm();
    for (int v : t) m.mass_per_vertex(v) += problem.material.areal_density * area / 3.0;
  }
  m.mass.resize(3 * n);
  for (int v = 0; v < n; ++v) m.mass.segment<3>(3 * v).setConstant(m.mass_per_vertex(v));

  // External loads: lumped gravity (consistent with the lumped mass, so free fall is exact),
  // consistent surface loads and point loads.
  m.f_ext = Eigen::VectorXd::Zero(3 * n);
  for (int v = 0; v < n; ++v) m.f_ext.segment<3>(3 * v) = m.mass_per_vertex(v) * problem.gravity;
  if (problem.surface_load.squaredNorm() > 0) m.f_ext += m.model.area_load(problem.surface_load);
  if (problem.pressure != 0.0) m.f_ext += m.model.pressure_load(problem.pressure);
  for (const PointLoad& l : problem.point_loads) m.f_ext += m.model.point_load(l.vertex, l.force);

  // Which components the linear solve treats as unknown.
  static const std::vector<Motion> kHold;
  // (Pointers into the simulator's own copy of the problem: the caller's may not outlive it.)
  std::vector<const std::vector<Motion>*> motion_of(3 * n, nullptr);
  for (const BoundaryCondition& bc : m.problem.boundary)
    for (int v : bc.vertices)
      for (int c = 0; c < 3; ++c)
        if (bc.fix[c]) motion_of[3 * v + c] = &bc.motion;
  m.solve_free.assign(3 * n, 1);
  for (int v = 0; v < n; ++v)
    for (int c = 0; c < 3; ++c) {
      const int dof = 3 * v + c;
      switch (m.model.dofs().status(v, c)) {
        case DofStatus::free:
          break;
        case DofStatus::fixed:
          m.solve_free[dof] = 0;
          m.prescribed_dof.push_back(dof);
          m.prescribed_motion.push_back(motion_of[dof] ? motion_of[dof] : &kHold);
          break;
        case DofStatus::dependent:
          m.solve_free[dof] = 0;
          m.dependent_dof.push_back(dof);
          break;
      }
    }

  // Initial state: rest positions, rigid initial velocity field.
  m.state.x = problem.mesh.vertices;
  m.state.v.resize(n, 3);
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d x = problem.mesh.vertices.row(v);
    m.state.v.row(v) = (problem.initial.velocity + problem.initial.angular_velocity.cross(x - problem.initial.center)).transpose();
  }
  m.elements.set_geometric_stiffness(problem.solver.tension_stiffening);
  m.limit_rest = m.model.limit_points(m.model.extended().rest);
  m.elements.evaluate(m.consistent(flat(m.state.x)));
}

Simulator::~Simulator() = default;

const DynamicState& Simulator::state() const { return impl_->state; }
int Simulator::num_vertices() const { return impl_->n; }
int Simulator::num_steps() const {
  return static_cast<int>(std::ceil(impl_->problem.time.end / impl_->problem.time.dt - 1e-9));
}
const Eigen::MatrixX3d& Simulator::limit_rest() const { return impl_->limit_rest; }
double Simulator::kinetic_energy() const {
  const Eigen::VectorXd v = flat(impl_->state.v);
  return 0.5 * v.dot(impl_->mass.cwiseProduct(v));
}
double Simulator::elastic_energy() const { return impl_->elements.energy(); }
double Simulator::external_work() const { return impl_->work; }
double Simulator::boundary_work() const { return impl_->boundary_work; }
double Simulator::max_membrane_strain() const {
  const Eigen::MatrixX2d strains = impl_->elements.membrane_principal_strains(impl_->consistent(flat(impl_->state.x)));
  return strains.size() > 0 ? strains.cwiseAbs().maxCoeff() : 0.0;
}
const Eigen::VectorXd& Simulator::vertex_mass() const { return impl_->mass_per_vertex; }

const ExtendedMesh& Simulator::extended_mesh() const { return impl_->model.extended(); }

Eigen::MatrixX3d Simulator::extended_positions() const {
  const Impl& m = *impl_;
  return m.model.extended().rest + m.model.dofs().expand(unflat(m.consistent(flat(m.state.x))));
}

Eigen::MatrixX3d Simulator::limit_positions() const {
  const Impl& m = *impl_;
  const Eigen::MatrixX3d u = unflat(m.consistent(flat(m.state.x)));
  return m.model.limit_points(m.model.extended().rest + m.model.dofs().expand(u));
}

StepStats Simulator::step() {
  Impl& m = *impl_;
  const DynamicProblem& p = m.problem;
  const double h = p.time.dt;
  const int step_number = m.state.step + 1;
  const double t_next = (m.state.step + 1) * h;
  StepStats stats;
  stats.step = step_number;
  stats.t = t_next;

  const Eigen::VectorXd x = flat(m.state.x), v = flat(m.state.v);
  // Prescribed velocities put scripted components exactly on their motion at t + h.
  Eigen::VectorXd target = x;
  for (size_t i = 0; i < m.prescribed_dof.size(); ++i) {
    const int dof = m.prescribed_dof[i];
    target(dof) = apply_motions(*m.prescribed_motion[i], m.rest.segment<3>(3 * (dof / 3)), t_next)(dof % 3);
  }
  // The iterative solver's start: v + (v − v_prev) on the free components (a constant-acceleration
  // guess: on the 2542-vertex sleeve 7 % fewer PCG iterations and 2 of 23 factorisations less than
  // starting from v, on sleeve_twist 15 % fewer), v in the first step or with
  // solver.warm_start = "last_velocity". The solution does not depend on it beyond the tolerance.
  Eigen::VectorXd v_next = v;
  if (p.solver.extrapolated_start && m.v_previous.size() == v.size())
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (m.solve_free[i]) v_next(i) = v(i) + (v(i) - m.v_previous(i));
  m.v_previous = v;
  for (int dof : m.prescribed_dof) v_next(dof) = (target(dof) - x(dof)) / h;
  for (int dof : m.dependent_dof) v_next(dof) = 0.0;

  const double c_mass = 1.0 + h * p.damping.mass;
  const double c_stiff = h * p.damping.stiffness + h * h;
  // The first solve is linearised at the current state x (rotations and forces from the end of
  // the previous step); further Newton iterations at x + h v_k.
  Eigen::VectorXd v_k = Eigen::VectorXd::Zero(3 * m.n);
  // External loads at this step: ramped; the follower couples act on the linearisation point
  // (re-evaluated with each Newton iteration).
  const double ramp = p.ramp_time > 0 ? std::min(1.0, t_next / p.ramp_time) : 1.0;
  Eigen::VectorXd f_ext;
  auto external_force = [&](const Eigen::VectorXd& at) {
    f_ext = m.f_ext;
    for (size_t i = 0; i < p.moments.size(); ++i)
      if (!add_moment_forces(p.moments[i], unflat(at), f_ext))
        throw SimulationError(step_number, t_next,
                              "moment " + std::to_string(i) + ": its vertices have come to lie on a line parallel to the moment");
    f_ext *= ramp;
  };
  // The prescribed rows of the last solve's system (A's columns, by symmetry) and right-hand side,
  // kept before the Dirichlet form: (A v⁺ − b)_p is the support's impulse (boundary_work()).
  std::vector<std::vector<std::pair<Eigen::Index, double>>> prescribed_rows(m.prescribed_dof.size());
  Eigen::VectorXd prescribed_rhs(static_cast<Eigen::Index>(m.prescribed_dof.size()));
  for (int k = 0; k < p.solver.newton_iterations; ++k) {
    auto t0 = std::chrono::steady_clock::now();
    external_force(x + h * v_k);
    if (k > 0) {  // re-extract rotations at x + h v_k
      m.elements.evaluate(m.consistent(x + h * v_k));
      stats.rotate_ms += m.elements.last_rotate_ms();
      stats.assemble_ms += m.elements.last_force_ms();
    }
    t0 = std::chrono::steady_clock::now();
    // The matrix keeps its pattern and storage from step to step; only its values are rewritten.
    Eigen::SparseMatrix<double>& a = m.system;
    m.elements.assemble_stiffness(a);
    Eigen::VectorXd b = m.mass.cwiseProduct(v) + h * (m.elements.force() + f_ext);
    if (k > 0) b += h * h * (a * v_k);
    if (m.diagonal.empty())  // value offsets of the diagonal entries, found once (all are in the pattern)
      for (Eigen::Index i = 0; i < 3 * m.n; ++i) {
        Eigen::Index at = a.outerIndexPtr()[i];
        while (a.innerIndexPtr()[at] != i) ++at;
        m.diagonal.push_back(at);
      }
    // a = c_stiff a + c_mass M in one parallel pass over the columns (the same operations, in
    // the same order per entry, as a *= c_stiff followed by the diagonal).
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, a.outerSize(), 256), [&](const tbb::blocked_range<Eigen::Index>& range) {
      double* values = a.valuePtr();
      for (Eigen::Index col = range.begin(); col != range.end(); ++col) {
        for (Eigen::Index entry = a.outerIndexPtr()[col]; entry < a.outerIndexPtr()[col + 1]; ++entry) values[entry] *= c_stiff;
        values[m.diagonal[col]] += c_mass * m.mass(col);
      }
    });
    for (size_t i = 0; i < m.prescribed_dof.size(); ++i) {
      const int dof = m.prescribed_dof[i];
      prescribed_rows[i].clear();
      for (Eigen::SparseMatrix<double>::InnerIterator it(a, dof); it; ++it) prescribed_rows[i].emplace_back(it.row(), it.value());
      prescribed_rhs(static_cast<Eigen::Index>(i)) = b(dof);
    }
    stats.assemble_ms += ms_since(t0);

    t0 = std::chrono::steady_clock::now();
    // Dirichlet form of the system for CHOLMOD: prescribed columns moved to the right-hand side,
    // unit diagonal in their rows and columns.
    auto dirichlet = [&](Eigen::SparseMatrix<double>& matrix, Eigen::VectorXd& rhs) {
      Eigen::VectorXd fixed_values = Eigen::VectorXd::Zero(3 * m.n);
      for (Eigen::Index i = 0; i < 3 * m.n; ++i)
        if (!m.solve_free[i]) fixed_values(i) = v_next(i);
      rhs -= matrix * fixed_values;
      for (Eigen::Index i = 0; i < 3 * m.n; ++i)
        if (!m.solve_free[i]) rhs(i) = fixed_values(i);
      set_dirichlet_identity(matrix, m.solve_free);
    };
    auto refactor = [&] {
      const auto f0 = std::chrono::steady_clock::now();
      m.factor.factorize(a, &m.solve_free);  // of the Dirichlet form
      ++stats.factorizations;
      stats.factor_ms += ms_since(f0);
      m.solves_since_factor = 0;
      m.iterations_since_factor = 0.0;
    };
    if (p.solver.type == LinearSolverType::pcg) {
      const bool cholesky = p.solver.preconditioner == PreconditionerType::cholesky;
      if (cholesky && (!m.factor.ready() || m.refactor_next)) {
        m.refactor_next = false;
        refactor();
      }
      const Preconditioner factor = [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) { m.factor.apply(r, z); };
      const Eigen::VectorXd start = v_next;
      PcgResult r = solve_pcg(a, b, m.solve_free, v_next, p.solver.tolerance, p.solver.max_iterations,
                              cholesky && m.factor.ready() ? factor : Preconditioner());
      if (cholesky) {
        // The factor is of an earlier matrix, and the iterations grow as the matrix drifts from it
        // (about one more per step in the buckling sleeve). Refactor when this solve cost more
        // than the average per solve since the last factorisation, the factorisation included
        // (for a cost that grows steadily this minimises the long-run average), or when it
        // exceeded refresh_iterations. The new factor is of the next step's matrix (taken at the
        // start of that step), not of this one, which is solved already: a factor of the matrix
        // being solved needs 3–4 iterations (half-precision solves), one a step old 5–6 in the
        // sleeve's slow phases and 9–60 while it snaps into folds. The factorisation's cost in iterations is estimated
        // from its flop count against the flops of one iteration (two triangular solves and a
        // product with A), scaled by 0.17, fitted on the 2542-vertex sleeve (2 cores): first with
        // single-precision solves (factorisation 22 ms ≙ 21 iterations of 1.05 ms), checked again
        // with half-precision solves (21.5 ms, 0.75 ms per iteration). The optimum is flat:
        // 0.12 / 0.17 / 0.25 / 0.35 / 0.5 model to 11.4 / 11.3 / 11.7 / 12.0 / 12.5 ms of solve
        // per step (docs/performance.md). Decided on counts, never on timings: runs are repeatable.
        ++m.solves_since_factor;
        m.iterations_since_factor += r.iterations;
        const double iteration_work = 4.0 * static_cast<double>(m.factor.factor_entries()) + 2.0 * static_cast<double>(a.nonZeros());
        const double factor_cost = 0.17 * m.factor.factor_flops() / std::max(iteration_work, 1.0);
        const bool pays = r.iterations * m.solves_since_factor > factor_cost + m.iterations_since_factor;
        if (!r.converged) {  // refactor now and solve again from the same start
          refactor();
          if (m.factor.ready()) {
            stats.solver_iterations += r.iterations;
            v_next = start;
            r = solve_pcg(a, b, m.solve_free, v_next, p.solver.tolerance, p.solver.max_iterations, factor);
          }
        } else if (r.iterations > p.solver.refresh_iterations || pays) {
          m.refactor_next = true;
        }
      }
      stats.solver_iterations += r.iterations;
      stats.residual = r.residual;
      if (!r.converged) {
        std::ostringstream s;
        s << "the conjugate gradient solver did not converge: relative residual " << r.residual << " after "
          << r.iterations << " iterations (tolerance " << p.solver.tolerance
          << "); try a smaller time step, more iterations or \"solver\": {\"type\": \"cholmod\"}";
        throw SimulationError(step_number, t_next, s.str(), SimulationError::Kind::solver);
      }
    } else {
      dirichlet(a, b);
      const auto f0 = std::chrono::steady_clock::now();
      const bool factored = m.direct.refactorize(a);
      ++stats.factorizations;
      stats.factor_ms += ms_since(f0);
      if (!factored)
        throw SimulationError(step_number, t_next, "the system matrix is not positive definite (CHOLMOD)",
                              SimulationError::Kind::solver);
      v_next = m.direct.solve(b);
      stats.solver_iterations += 1;
      stats.residual = (a * v_next - b).norm() / std::max(b.norm(), 1e-300);
    }
    stats.solve_ms += ms_since(t0);
    if (k > 0) stats.newton_change = (v_next - v_k).norm() / std::max(v_next.norm(), 1e-300);
    v_k = v_next;
  }

  // Advance; scripted components land exactly on their motion, tied ones follow their rule.
  Eigen::VectorXd x_next = x + h * v_next;
  for (int dof : m.prescribed_dof) x_next(dof) = target(dof);
  const Eigen::VectorXd u_next = m.consistent(x_next);
  x_next = m.rest + u_next;
  for (int dof : m.dependent_dof) v_next(dof) = (x_next(dof) - x(dof)) / h;
  if (!x_next.allFinite() || !v_next.allFinite())
    throw SimulationError(step_number, t_next, "the state became NaN or infinite (numerical instability)",
                          SimulationError::Kind::nan);
  if ((x_next - m.rest).cwiseAbs().maxCoeff() > 1e3 * m.bbox)
    throw SimulationError(step_number, t_next, "the simulation diverged (a vertex moved more than 1000 times the mesh size)",
                          SimulationError::Kind::diverged);

  // Forces and energy at the new state (reused by the next step's linearisation).
  m.elements.evaluate(u_next);
  stats.rotate_ms += m.elements.last_rotate_ms();
  stats.assemble_ms += m.elements.last_force_ms();

  for (Eigen::Index i = 0; i < 3 * m.n; ++i)
    if (m.solve_free[i]) stats.external_work += f_ext(i) * (x_next(i) - x(i));
  // Work of the supports (and of the loads on the supported components): (R_p + f_ext,p) Δx_p
  // with h R_p = (A v⁺ − b)_p and Δx_p = h v⁺_p.
  for (size_t i = 0; i < m.prescribed_dof.size(); ++i) {
    const int dof = m.prescribed_dof[i];
    double impulse = -prescribed_rhs(static_cast<Eigen::Index>(i));
    for (const auto& [row, value] : prescribed_rows[i]) impulse += value * v_next(row);
    stats.boundary_work += (impulse + h * f_ext(dof)) * v_next(dof);
  }
  m.work += stats.external_work;
  m.boundary_work += stats.boundary_work;
  m.state.x = unflat(x_next);
  m.state.v = unflat(v_next);
  m.state.t = t_next;
  m.state.step = step_number;
  stats.kinetic_energy = kinetic_energy();
  stats.elastic_energy = elastic_energy();
  return stats;
}

}  // namespace clothsim

#include "sim/dynamics/simulator.hpp"

#include "sim/contact/contact_stage.hpp"
#include "sim/forces/corotated_shell.hpp"
#include "sim/forces/damping.hpp"
#include "sim/integrator/implicit_euler.hpp"
#include "sim/integrator/scripted_boundary.hpp"
#include "sim/problem/validate.hpp"
#include "sim/setup/setup.hpp"
#include "sim/solver/linear_solver.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {

// The contact stage as the integrator's step potential (proximity inside the step) and velocity
// filter (the fail-safe after it).
class ContactFilter final : public VelocityFilter, public StepPotential {
 public:
  ContactFilter(const Discretization& d, const Eigen::VectorXd& mass, const std::vector<char>& free,
                const CollisionSettings& settings, const std::vector<Obstacle>& obstacles, const ContactParameters& p)
      : stage_(d, mass, free, settings, obstacles, p) {
    if (settings.barrier) stage_.enable_potential();
  }
  bool inside_step() const { return stage_.potential_enabled(); }
  long long joined_at_rest() const { return stage_.joined_at_rest(); }
  void begin_step(const Eigen::VectorXd& x, const Eigen::VectorXd& v_guess, double t, double h,
                  const Eigen::VectorXd& diagonal) override {
    stage_.begin_step(x, v_guess, t, h, diagonal);
  }
  void linearise(const Eigen::VectorXd& v, PotentialLinearisation& out) override { stage_.linearise(v, out); }
  void end_step(const Eigen::VectorXd& v, PotentialReport& report) override { stage_.end_step(v, report); }
  double velocity_tolerance(double h) const override { return stage_.velocity_tolerance(h); }
  double step_bound(const Eigen::VectorXd& from, const Eigen::VectorXd& to) override { return stage_.step_bound(from, to); }
  void filter(const Eigen::VectorXd& x, double t, double h, Eigen::VectorXd& v, const StepSystem& system,
              StepStats& stats) override {
    const ContactReport r = stage_.filter(x, t, h, v, ResponseSystem{system.matrix, system.inverse});
    stats.contact += r;  // (its time is the integrator's to add, as contact.ms)
  }

 private:
  ContactStage stage_;
};

}  // namespace

struct Simulator::Impl {
  Problem problem;
  SettleReport settle;
  std::shared_ptr<const Discretization> discretization;
  Eigen::VectorXd node_mass;
  std::vector<std::unique_ptr<ForceTerm>> internal;
  std::unique_ptr<ExternalLoads> loads;
  const CorotatedShell* shell = nullptr;  // the elastic term when it is the corotated shell (timings, strains)
  ScriptedBoundary boundary;
  LinearSolver solver;
  DynamicState state;
  std::unique_ptr<ImplicitEuler> integrator;
  std::unique_ptr<ContactFilter> contact;  // only when the problem has contact
  Eigen::MatrixX3d node_points_rest;
  double shell_rotate_ms = 0.0;  // rotation time of the shell's updates so far

  explicit Impl(const Problem& p)
      : problem(p),
        discretization(make_discretization(p)),
        boundary(*discretization, p.boundary),
        solver(p.solver, 3 * static_cast<Eigen::Index>(p.mesh.num_vertices())) {}

  void build_integrator() {
    std::vector<ForceTerm*> terms;
    for (const auto& t : internal) terms.push_back(t.get());
    IntegratorSettings settings;
    settings.dt = problem.time.dt;
    settings.newton_iterations = problem.solver.newton_iterations;
    settings.extrapolated_start = problem.solver.extrapolated_start;
    settings.rotation_tolerance = problem.solver.rotation_tolerance_deg * std::numbers::pi / 180.0;
    integrator = std::make_unique<ImplicitEuler>(settings, *discretization, node_mass, terms, loads->empty() ? nullptr : loads.get(),
                                                 boundary, solver, state);
    if (problem.has_contact()) {
      if (!contact) {
        ContactParameters parameters;
        parameters.surface_level = problem.collision_level;
        contact = std::make_unique<ContactFilter>(*discretization, node_mass, integrator->free_dofs(), problem.collision,
                                                  problem.obstacles, parameters);
      }
      integrator->set_velocity_filter(contact.get());
      if (contact->inside_step()) integrator->set_step_potential(contact.get());
    }
    skip_rotation_time();
  }

  // The rotation time of evaluations outside step() (the integrator's set-up, a restore) is not
  // any step's: without this the first step's assemble_ms (update minus rotation) could go negative.
  void skip_rotation_time() { shell_rotate_ms = shell ? shell->elements().total_rotate_ms() : 0.0; }
};

namespace {

// The largest excess of a control edge's length at `x` (#V × 3) over its length in the texture
// coordinates (the pattern) [m]; 0 without texture coordinates.
double largest_seam_gap(const TriMesh& mesh, const Eigen::MatrixX3d& x) {
  if (mesh.uv.size() != mesh.triangles.size()) return 0.0;
  double gap = 0.0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      const double rest = (mesh.uv[t][(k + 1) % 3] - mesh.uv[t][k]).norm();
      gap = std::max(gap, (x.row(a) - x.row(b)).norm() - rest);
    }
  return gap;
}

// The settling phase (Simulator's constructor): the problem with the loads off, the obstacles
// held, no boundary conditions, strong mass damping, run for settle.time from rest; returns the
// problem whose mesh starts where the settling ended.
Problem settled(const Problem& p, SettleReport& report) {
  Problem s = p;
  s.settle = SettleSettings{};
  s.gravity.setZero();
  s.surface_load.setZero();
  s.pressure = 0.0;
  s.point_loads.clear();
  s.moments.clear();
  s.ramp_time = 0.0;
  s.initial = InitialState{};
  for (Obstacle& o : s.obstacles) o.motion.clear();
  // Pins and other boundary conditions act from t = 0, where the settling leaves their vertices:
  // held at the pieces' placed positions they would keep the seams next to them open.
  s.boundary.clear();
  s.damping.mass = std::max(s.damping.mass, p.settle.damping);
  s.time.end = p.settle.time;
  Problem out = p;
  try {
    Simulator sim(s);
    report.strain_start = sim.max_membrane_strain();
    report.gap_start = largest_seam_gap(p.mesh, p.mesh.vertices);
    report.steps = sim.num_steps();
    for (int k = 0; k < report.steps; ++k) {
      const StepStats st = sim.step();
      report.step_ms += st.step_ms;
      report.solver_iterations += st.solver_iterations;
      report.factorizations += st.factorizations;
      report.contact += st.contact;
    }
    report.strain_end = sim.max_membrane_strain();
    out.mesh.vertices = sim.state().positions();
    report.gap_end = largest_seam_gap(p.mesh, out.mesh.vertices);
  } catch (const std::exception& e) {
    throw std::runtime_error("while settling (the " + std::to_string(p.settle.time) + " s before t = 0): " + e.what());
  }
  return out;
}

}  // namespace

Simulator::Simulator(const Problem& problem) {
  check_problem(problem, Analysis::dynamics);
  if (problem.settle.time > 0) {
    SettleReport report;
    init(settled(problem, report));
    impl_->settle = report;
  } else {
    init(problem);
  }
}

const SettleReport& Simulator::settle_report() const { return impl_->settle; }

void Simulator::init(const Problem& problem) {
  impl_ = std::make_unique<Impl>(problem);
  Impl& m = *impl_;
  const Discretization& d = *m.discretization;
  const int n = d.num_nodes();
  m.node_mass = d.lumped_mass(problem.material.areal_density);

  // Internal terms: the elastic shell (Kelvin–Voigt damped), mass damping.
  std::unique_ptr<ForceTerm> elastic = d.elastic_term(problem.corotational, problem.solver.tension_stiffening);
  m.shell = dynamic_cast<const CorotatedShell*>(elastic.get());
  if (problem.damping.stiffness > 0) elastic = std::make_unique<KelvinVoigtDamping>(std::move(elastic), problem.damping.stiffness);
  m.internal.push_back(std::move(elastic));
  if (problem.damping.mass > 0)
    m.internal.push_back(std::make_unique<MassDamping>(m.node_mass, problem.damping.mass, d.matrix_pattern()));

  // External loads: lumped gravity (consistent with the lumped mass, so free fall is exact),
  // consistent surface loads, point loads at limit points, follower couples.
  m.loads = make_external_loads(d, problem, GravityModel::lumped, problem.ramp_time);

  // Initial state: rest positions, rigid initial velocity field.
  m.state.x = d.rest();
  m.state.v.resize(3 * n);
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d x = m.state.x.segment<3>(3 * v);
    m.state.v.segment<3>(3 * v) = problem.initial.velocity + problem.initial.angular_velocity.cross(x - problem.initial.center);
  }
  std::vector<int> all(static_cast<size_t>(n));
  for (int v = 0; v < n; ++v) all[static_cast<size_t>(v)] = v;
  m.node_points_rest = d.node_points(all).positions(d.control_net(d.rest()));
  m.build_integrator();
}

Simulator::~Simulator() = default;

void Simulator::add_term(std::unique_ptr<ForceTerm> term) {
  Impl& m = *impl_;
  if (!term) throw std::invalid_argument("Simulator::add_term: no term");
  if (m.state.step > 0) throw std::logic_error("Simulator::add_term: only before the first step");
  m.internal.push_back(std::move(term));
  m.build_integrator();
}

const DynamicState& Simulator::state() const { return impl_->state; }
int Simulator::num_vertices() const { return impl_->discretization->num_nodes(); }
int Simulator::num_steps() const {
  return static_cast<int>(std::ceil(impl_->problem.time.end / impl_->problem.time.dt - 1e-9));
}

StepStats Simulator::step() {
  Impl& m = *impl_;
  StepStats stats = m.integrator->step(m.state);
  // The shell's rotation pass apart from the rest of the term updates (stats.csv's rotate_ms;
  // assemble_ms counts the element forces, as it always has).
  const double rotate = m.shell ? m.shell->elements().total_rotate_ms() - m.shell_rotate_ms : 0.0;
  m.shell_rotate_ms += rotate;
  stats.rotate_ms = rotate;
  stats.assemble_ms += stats.update_ms - rotate;
  return stats;
}

const Discretization& Simulator::discretization() const { return *impl_->discretization; }
std::shared_ptr<const Discretization> Simulator::shared_discretization() const { return impl_->discretization; }

Eigen::MatrixX3d Simulator::surface_points(const SurfaceOperator& op) const {
  return impl_->discretization->surface_positions(op, impl_->state.x);
}
Eigen::MatrixX3d Simulator::rest_surface_points(const SurfaceOperator& op) const {
  return impl_->discretization->surface_positions(op, impl_->discretization->rest());
}
Eigen::MatrixX3d Simulator::node_points() const {
  const Discretization& d = *impl_->discretization;
  std::vector<int> all(static_cast<size_t>(d.num_nodes()));
  for (int v = 0; v < d.num_nodes(); ++v) all[static_cast<size_t>(v)] = v;
  return surface_points(d.node_points(all));
}
const Eigen::MatrixX3d& Simulator::node_points_rest() const { return impl_->node_points_rest; }

double Simulator::kinetic_energy() const { return impl_->integrator->kinetic_energy(impl_->state); }
double Simulator::elastic_energy() const { return impl_->integrator->elastic_energy(); }
double Simulator::external_work() const { return impl_->integrator->external_work(); }
double Simulator::boundary_work() const { return impl_->integrator->boundary_work(); }
double Simulator::contact_energy() const { return impl_->integrator->potential_energy(); }
long long Simulator::contact_joined_at_rest() const { return impl_->contact ? impl_->contact->joined_at_rest() : 0; }
double Simulator::max_membrane_strain() const {
  return impl_->discretization->max_membrane_strain(impl_->integrator->displacement());
}
const Eigen::VectorXd& Simulator::vertex_mass() const { return impl_->node_mass; }

SimulatorCheckpoint Simulator::checkpoint() const {
  const Impl& m = *impl_;
  return {m.state, m.integrator->checkpoint(), m.solver.checkpoint()};
}

void Simulator::restore(const SimulatorCheckpoint& c) {
  Impl& m = *impl_;
  const Eigen::Index n3 = 3 * static_cast<Eigen::Index>(m.discretization->num_nodes());
  if (c.state.x.size() != n3 || c.state.v.size() != n3 || c.state.step < 0 || !(c.state.t >= 0.0))
    throw std::invalid_argument("the checkpoint's state does not fit the mesh (" + std::to_string(n3 / 3) + " nodes)");
  m.state = c.state;
  m.integrator->restore(m.state, c.integrator);
  m.skip_rotation_time();
  m.solver.restore(c.solver, m.integrator->system_matrix(), m.integrator->free_dofs());
}

}  // namespace clothsim

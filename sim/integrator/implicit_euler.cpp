#include "sim/integrator/implicit_euler.hpp"

#include "sim/core/sparse_pattern.hpp"
#include "sim/solver/pcg.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>

namespace clothsim {

namespace {
double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Sets every value of a (its pattern kept) to zero, in parallel.
void clear_values(Eigen::SparseMatrix<double>& a) {
  double* values = a.valuePtr();
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, a.nonZeros(), 1 << 16), [&](const tbb::blocked_range<Eigen::Index>& r) {
    std::fill(values + r.begin(), values + r.end(), 0.0);
  });
}
}  // namespace

ImplicitEuler::ImplicitEuler(const IntegratorSettings& settings, const Discretization& discretization,
                             const Eigen::VectorXd& node_mass, std::vector<ForceTerm*> internal, ForceTerm* loads,
                             const ScriptedBoundary& boundary, LinearSolver& solver, const DynamicState& state)
    : settings_(settings),
      discretization_(discretization),
      internal_(std::move(internal)),
      loads_(loads),
      boundary_(boundary),
      solver_(solver) {
  all_ = internal_;
  if (loads_) all_.push_back(loads_);
  const int n = discretization.num_nodes();
  mass_.resize(3 * n);
  for (int v = 0; v < n; ++v) mass_.segment<3>(3 * v).setConstant(node_mass(v));
  free_.assign(3 * static_cast<size_t>(n), 1);
  for (int dof = 0; dof < 3 * n; ++dof) {
    const DofStatus s = discretization.status(dof);
    if (s != DofStatus::free) free_[static_cast<size_t>(dof)] = 0;
    if (s == DofStatus::dependent) dependent_.push_back(dof);
  }
  const Eigen::MatrixX3d& rest = discretization.mesh().vertices;
  size_ = std::max((rest.colwise().maxCoeff() - rest.colwise().minCoeff()).norm(), 1e-12);
  system_ = discretization.matrix_pattern();
  diagonal_ = diagonal_offsets(system_);
  u_ = state.x - discretization.rest();
  discretization.make_consistent(u_);
  update_terms(state.x, u_, state.t);
}

void ImplicitEuler::restore(const DynamicState& state, const IntegratorCheckpoint& c) {
  const Eigen::Index n3 = 3 * static_cast<Eigen::Index>(discretization_.num_nodes());
  if (state.x.size() != n3 || state.v.size() != n3 || c.u.size() != n3 ||
      (c.v_previous.size() != 0 && c.v_previous.size() != n3))
    throw std::invalid_argument("ImplicitEuler::restore: the checkpoint's state does not fit the mesh (" +
                                std::to_string(n3 / 3) + " nodes)");
  if (c.coupled_pattern.empty()) {
    coupled_in_use_ = false;
  } else {
    coupled_.restore(system_, c.coupled_pattern);
    coupled_in_use_ = true;
  }
  u_ = c.u;
  v_previous_ = c.v_previous;
  work_ = c.external_work;
  boundary_work_ = c.boundary_work;
  contact_last_step_ = c.contact_last_step;
  update_terms(state.x, u_, state.t);
}

IntegratorCheckpoint ImplicitEuler::checkpoint() const {
  IntegratorCheckpoint c{u_, v_previous_, work_, boundary_work_, {}, contact_last_step_};
  if (coupled_in_use_) c.coupled_pattern = coupled_.adjacency();
  return c;
}

LinearSolveReport ImplicitEuler::solve_with_potential(Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& b,
                                                      const Eigen::VectorXd& x, const Eigen::VectorXd& v_now, double t,
                                                      double h, bool first, Eigen::VectorXd& v, StepStats& stats,
                                                      const std::function<bool(const Eigen::VectorXd&)>* turned) {
  newton_turned_ = false;
  const Eigen::Index n3 = v.size();
  auto clock = [] { return std::chrono::steady_clock::now(); };
  auto t0 = clock();
  auto from_velocities = [&] {
    for (Eigen::Index i = 0; i < n3; ++i)
      if (free_[static_cast<size_t>(i)]) v(i) = v_now(i);
  };
  // (Where contact acted in the last step Newton starts from the step's velocities, below: the
  // potential makes its candidates for that start's motion, not the guess's.)
  if (first && contact_last_step_) from_velocities();
  if (first) potential_->begin_step(x, v, t, h, a.diagonal());
  // Newton starts where the surfaces have not passed through each other: the start's move of the
  // free components from the step's start positions is cut at the first crossing (the positions
  // at the start of the step are free of crossings; prescribed components move as scripted).
  auto feasible = [&](Eigen::VectorXd& w) {
    Eigen::VectorXd held = w;
    for (Eigen::Index i = 0; i < n3; ++i)
      if (free_[static_cast<size_t>(i)]) held(i) = 0.0;
    const auto t_bound = clock();
    const double alpha = potential_->step_bound(held, w);
    stats.contact.line_search_ms += ms_since(t_bound);
    if (alpha < 1.0) w = held + 0.9 * alpha * (w - held);
  };
  // From the caller's start (the extrapolated guess) where the potential is nothing there: the
  // first solve is then the step's solve without contact, bit for bit. Where it is something, from
  // the step's velocities: extrapolating a contact's motion linearises the barrier where the cloth
  // is not going (Newton iterations per step on sheet_on_sphere's first 0.5 s / sleeve_on_arm's
  // first 0.2 s: always from the guess 4.20 / 3.03, always from the velocities 3.52 / 2.79, this
  // rule 3.80 / 3.02). Where it was something in the last step, straight from the velocities,
  // without trying the guess (the same start wherever the guess would have met contact too, one
  // cut and one linearisation less: sleeve_on_arm's contact 8.0 -> 7.1 s, same Newton iterations).
  PotentialLinearisation lin;
  if (first) feasible(v);
  potential_->linearise(v, lin);
  if (!lin.empty()) potential_acted_ = true;
  if (first && !contact_last_step_ && !lin.empty()) {
    from_velocities();
    feasible(v);
    potential_->linearise(v, lin);
  }
  double potential_ms = ms_since(t0);
  // Φ(v) = ½ vᵀ A v − bᵀ v + E(x + h v) + h Ψ(v) (step_potential.hpp).
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(n3);
  Eigen::VectorXd product(n3);
  // (`product` holds A w after a call; product_at_v: it holds A v for the current iterate v.)
  bool product_at_v = false;
  auto merit = [&](const Eigen::VectorXd& w, const PotentialLinearisation& l, bool product_known = false) {
    if (!product_known) symmetric_product(a, w, ones, product);
    return 0.5 * w.dot(product) - b.dot(w) + l.energy + h * l.dissipation;
  };
  double phi = 0.0;
  bool phi_known = false;  // (Φ is needed once the potential is something at either end of a step)
  LinearSolveReport total;
  total.converged = true;
  Eigen::VectorXd rhs(n3), v_new(n3), trial(n3), initial_residual(n3);
  PotentialLinearisation next;
  const double tolerance = potential_->velocity_tolerance(h);
  constexpr int kMaxNewton = 12;
  // (After the second Newton step: checked after the first, the T-shirt drop's landing took 227
  // Newton solves instead of 214, re-linearising as often.)
  constexpr int kTurnCheck = 2;
  // Inexact Newton (Eisenstat & Walker 1996, their second choice of forcing term): each Newton
  // system is solved until its residual is η_k of its start's, ‖∇Φ(v_k)‖, with
  // η_k = γ (‖∇Φ(v_k)‖ / ‖∇Φ(v_{k−1})‖)², γ = 0.9, kept from falling faster than γ η_{k−1}² while
  // that is above 0.1, at most kEtaMax and at least the linear solver's own tolerance (relative to
  // the right-hand side, as without contact). The first system of a call: kEtaFirst.
  constexpr double kEtaFirst = 0.25, kEtaMax = 0.5;
  double eta = kEtaFirst, gradient_norm_previous = 0.0;
  double b_norm = 0.0;  // ‖b‖ on the free components
  for (Eigen::Index i = 0; i < n3; ++i)
    if (free_[static_cast<size_t>(i)]) b_norm += b(i) * b(i);
  b_norm = std::sqrt(b_norm);
  int iterations = 0;
  for (;;) {
    // The potential's blocks, weighted by h² (energy) or h (dissipation), merged by row
    // (sim/solver/block_sum.hpp).
    blocks_.build(lin, h);
    // The Newton matrix A + Σ Bᵀ (h² H) B. Its blocks each couple every node of their rows' stencils
    // (12–50 nodes per pair on a level-2 surface), so with the conjugate-gradient solver it is applied
    // as A x + Σ Bᵀ (h² H (B x)) and assembled only when the preconditioner needs a new factor (the
    // crushed sleeve's step with 1,500 active pairs: the assembly cost more than the rest of the step).
    // The pattern: A's and the couplings of the blocks; rebuilt only when a block needs a coupling it
    // lacks (then the solver analyses the new pattern).
    auto newton_matrix = [&]() -> Eigen::SparseMatrix<double>& {
      const std::vector<std::pair<NodeRow, Eigen::Matrix3d>> node_blocks = blocks_.node_blocks();
      std::vector<std::vector<int>> groups;
      groups.reserve(node_blocks.size());
      for (const auto& [row, hw] : node_blocks) groups.push_back(row.node_list());
      std::sort(groups.begin(), groups.end());  // (many rows share their nodes: each list is checked once)
      groups.erase(std::unique(groups.begin(), groups.end()), groups.end());
      if (!coupled_.covers(a, groups)) coupled_.rebuild(a, groups, /*keep_previous=*/true);
      coupled_.set_base(a);
      coupled_.add_blocks(node_blocks);
      coupled_in_use_ = true;
      return coupled_.matrix();
    };
    rhs = b;
    Eigen::VectorXd hv = Eigen::VectorXd::Zero(n3);  // (h² ∇²E + h ∇²Ψ) v
    blocks_.add_product(v, hv);
    if (lin.energy_gradient.size() == n3) rhs -= h * lin.energy_gradient;
    if (lin.dissipation_gradient.size() == n3) rhs -= h * lin.dissipation_gradient;
    rhs += hv;
    v_new = v;
    LinearSolveReport r;
    const auto t_solve = clock();
    if (!blocks_.empty() && solver_.solves_operators()) {
      const LinearOperator newton_product = [&](const Eigen::VectorXd& w, Eigen::VectorXd& y) {
        symmetric_product(a, w, ones, y);
        blocks_.add_product(w, y);
      };
      // The start's residual rhs − (A + Σ) v from A v (the merit's, which Φ needs anyway) and the
      // blocks' Σ v = hv made for the right-hand side: the solver need not apply the operator to
      // the start (a product per Newton iteration less).
      if (!product_at_v) symmetric_product(a, v, ones, product);
      product_at_v = true;
      initial_residual = rhs - (product + hv);
      double gradient_norm = 0.0;
      for (Eigen::Index i = 0; i < n3; ++i)
        if (free_[static_cast<size_t>(i)]) gradient_norm += initial_residual(i) * initial_residual(i);
      gradient_norm = std::sqrt(gradient_norm);
      if (gradient_norm_previous > 0) {
        const double floor = 0.9 * eta * eta;
        eta = 0.9 * std::pow(gradient_norm / gradient_norm_previous, 2);
        if (floor > 0.1) eta = std::max(eta, floor);
        eta = std::min(eta, kEtaMax);
      }
      gradient_norm_previous = gradient_norm;
      r = solver_.solve(newton_product, static_cast<double>(a.nonZeros()) + blocks_.product_entries(), newton_matrix, rhs, free_,
                        v_new, &initial_residual, eta);
    } else if (blocks_.empty() && solver_.solves_operators() && (coupled_.empty() || coupled_.matrix().nonZeros() == a.nonZeros())) {
      // No blocks, and no couplings in the pattern: A itself (the conjugate-gradient solver leaves
      // it as it is), without copying its values (a quarter of a millisecond per step on the
      // 494-vertex sleeve).
      r = solver_.solve(a, rhs, free_, v_new);
    } else {
      r = solver_.solve(newton_matrix(), rhs, free_, v_new);
    }
    // (The step's first solve is the elastic step's, with the potential where it acts at the start;
    // the others are Newton's cost of contact.)
    (first && iterations == 0 ? stats.contact.first_solve_ms : stats.contact.newton_solve_ms) += ms_since(t_solve);
    total.iterations += r.iterations;
    total.residual = r.residual;
    total.factorizations += r.factorizations;
    total.factor_ms += r.factor_ms;
    total.direct_fallbacks += r.direct_fallbacks;
    if (total.fallback_reason.empty()) total.fallback_reason = r.fallback_reason;
    ++iterations;
    if (!r.converged) {
      total.converged = false;
      total.failure = r.failure;
      break;
    }
    // The Newton step's largest velocity change, before it is cut (the stopping rule below).
    double direction = 0.0;
    for (Eigen::Index i = 0; i < n3; ++i)
      if (free_[static_cast<size_t>(i)]) direction = std::max(direction, std::abs(v_new(i) - v(i)));
    // A step is cut before the first crossing it would make (0.9 of the way to it), so the
    // iterates stay free of crossings.
    t0 = clock();
    const double alpha = potential_->step_bound(v, v_new);
    if (alpha < 1.0) v_new = v + 0.9 * alpha * (v_new - v);
    const double bound_ms = ms_since(t0);
    potential_ms += bound_ms;
    stats.contact.line_search_ms += bound_ms;
    // A step that raises Φ is shortened (halved up to eight times); one that still raises it is
    // not taken, and Newton stops where it is (the fail-safe after the step keeps it free of
    // crossings).
    t0 = clock();
    potential_->linearise(v_new, next);
    if (!lin.empty() || !next.empty()) potential_acted_ = true;
    if (lin.empty() && next.empty()) {
      // Nothing at either end: the solve minimised Φ, which is the step's quadratic there.
      potential_ms += ms_since(t0);
      v = v_new;
      break;
    }
    if (!phi_known) phi = merit(v, lin, product_at_v);
    phi_known = true;
    product_at_v = false;  // (merit is called at v_new from here on)
    double phi_new = merit(v_new, next);
    auto raises = [&](double value) { return value > phi + 1e-12 * std::abs(phi); };
    for (int halve = 0; halve < 8 && raises(phi_new); ++halve) {
      trial = 0.5 * (v + v_new);
      v_new = trial;
      potential_->linearise(v_new, next);
      phi_new = merit(v_new, next);
    }
    potential_ms += ms_since(t0);
    if (raises(phi_new)) {
      potential_->linearise(v, next);  // (lin was made at v; the potential's scratch follows the last call)
      std::swap(lin, next);
      break;
    }
    // Converged when the Newton step just solved for (before any cut) changes no velocity by
    // more than the tolerance: the step is taken, and what remains is smaller still; or when the
    // gradient of Φ at the new iterate is within the linear solver's tolerance of the right-hand
    // side, as accurate as a step without contact is solved (the next solve would take no
    // iteration: a linearisation and a solve less).
    const double change = direction;
    double gradient_norm = 0.0;
    if (change > tolerance && r.iterations > 0) {
      for (Eigen::Index i = 0; i < n3; ++i) {
        if (!free_[static_cast<size_t>(i)]) continue;
        double g = product(i) - b(i);  // (product = A v_new: merit() was last called at v_new)
        if (next.energy_gradient.size() == n3) g += h * next.energy_gradient(i);
        if (next.dissipation_gradient.size() == n3) g += h * next.dissipation_gradient(i);
        gradient_norm += g * g;
      }
      gradient_norm = std::sqrt(gradient_norm);
    }
    const bool at_floor = r.iterations > 0 && change > tolerance && gradient_norm <= solver_.settings().tolerance * b_norm;
    v = v_new;
    product_at_v = true;  // (merit() was last called at v_new)
    std::swap(lin, next);
    phi = phi_new;
    // (A solve that took no iteration changed nothing at the linear solver's tolerance: Newton
    // cannot get closer than that.)
    if (change <= tolerance || at_floor || r.iterations == 0 || iterations >= kMaxNewton) break;
    // (Rotations that turned within the step: the linearisation is discarded anyway, so Newton
    // continues from a new one rather than converging this one.)
    if (turned != nullptr && iterations == kTurnCheck && (*turned)(v)) {
      newton_turned_ = true;
      break;
    }
  }
  stats.contact.newton_iterations += iterations;
  stats.contact_active_pairs = lin.active;
  stats.contact_energy = lin.energy;
  stats.contact.potential_ms += potential_ms;
  stats.contact.ms += potential_ms;
  stats.solve_ms -= potential_ms;  // (the caller times the whole call as the solve)
  return total;
}

void ImplicitEuler::finish_potential(const Eigen::VectorXd& v, StepStats& stats) {
  const auto t0 = std::chrono::steady_clock::now();
  PotentialReport report;
  report.newton_iterations = static_cast<int>(stats.contact.newton_iterations);
  report.active_pairs = stats.contact_active_pairs;
  report.energy = stats.contact_energy;
  potential_->end_step(v, report);
  stats.contact_friction_pairs = report.friction_pairs;
  stats.contact.candidates_ms += report.candidates_ms;
  const double ms = ms_since(t0);
  stats.contact.potential_ms += ms;
  stats.contact.ms += ms;
}

void ImplicitEuler::update_terms(const Eigen::VectorXd& x, const Eigen::VectorXd& u, double t) {
  for (ForceTerm* term : all_) term->update(x, u, t);
}

void ImplicitEuler::assemble(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const {
  bool set = false;  // the first term with a matrix sets the values, the others add to them
  for (const ForceTerm* term : all_) {
    if (!term->has_matrix()) continue;
    if (set) term->add_matrix(w, a);
    else term->set_matrix(w, a);
    set = true;
  }
  if (!set) clear_values(a);
}

double ImplicitEuler::kinetic_energy(const DynamicState& state) const { return 0.5 * state.v.dot(mass_.cwiseProduct(state.v)); }

double ImplicitEuler::elastic_energy() const {
  double e = 0.0;
  for (const ForceTerm* term : internal_)
    if (term->has_energy()) e += term->energy();
  return e;
}

void ImplicitEuler::end_positions(const Eigen::VectorXd& x, const Eigen::VectorXd& v, const Eigen::VectorXd& target,
                                 Eigen::VectorXd& x_end, Eigen::VectorXd& u_end) const {
  const double h = settings_.dt;
  const std::vector<int>& prescribed = boundary_.dofs();
  x_end = x + h * v;
  for (size_t i = 0; i < prescribed.size(); ++i) x_end(prescribed[i]) = target(static_cast<Eigen::Index>(i));
  u_end = x_end - discretization_.rest();
  discretization_.make_consistent(u_end);
  x_end = discretization_.rest() + u_end;
}

StepStats ImplicitEuler::step(DynamicState& state) {
  const auto step_start = std::chrono::steady_clock::now();
  const double h = settings_.dt;
  const int step_number = state.step + 1;
  const double t_next = (state.step + 1) * h;
  const int n3 = static_cast<int>(state.x.size());
  const Eigen::VectorXd& rest = discretization_.rest();
  const std::vector<int>& prescribed = boundary_.dofs();
  StepStats stats;
  stats.step = step_number;
  stats.t = t_next;

  const Eigen::VectorXd& x = state.x;
  const Eigen::VectorXd& v = state.v;
  // Prescribed positions at t + h: the scripted components land exactly on their motion.
  Eigen::VectorXd target(static_cast<Eigen::Index>(prescribed.size()));
  for (size_t i = 0; i < prescribed.size(); ++i) target(static_cast<Eigen::Index>(i)) = boundary_.position(i, t_next);
  // The iterative solver's start: v + (v − v_prev) on the free components (a constant-acceleration
  // guess: on the 2542-vertex sleeve 7 % fewer PCG iterations and 2 of 23 factorisations less than
  // starting from v, on sleeve_twist 15 % fewer), v in the first step or with
  // extrapolated_start off. The solution does not depend on it beyond the tolerance.
  Eigen::VectorXd v_next = v;
  if (settings_.extrapolated_start && v_previous_.size() == v.size())
    for (Eigen::Index i = 0; i < v.size(); ++i)
      if (free_[i]) v_next(i) = v(i) + (v(i) - v_previous_(i));
  for (size_t i = 0; i < prescribed.size(); ++i)
    v_next(prescribed[i]) = (target(static_cast<Eigen::Index>(i)) - x(prescribed[i])) / h;
  for (int dof : dependent_) v_next(dof) = 0.0;

  const MatrixWeights weights{h * h, h};
  // The first solve is linearised at the current state x (terms evaluated at the end of the
  // previous step); further Newton iterations at x + h v_k.
  Eigen::VectorXd v_k = Eigen::VectorXd::Zero(n3);
  Eigen::VectorXd f(n3), f_ext = Eigen::VectorXd::Zero(n3);
  // The prescribed rows of the last solve's system (A's columns, by symmetry) and right-hand side,
  // kept before the solver may change them: (A v⁺ − b)_p is the support's impulse.
  std::vector<std::vector<std::pair<Eigen::Index, double>>> prescribed_rows(prescribed.size());
  Eigen::VectorXd prescribed_rhs(static_cast<Eigen::Index>(prescribed.size()));
  Eigen::VectorXd x_lin, u_lin;
  // Rotations follow the step where contact acts: once the requested iterations are done, the
  // terms are evaluated at the step's end positions (as the step's end does anyway); where a
  // frame turned by more than the tolerance against the one the step was linearised with, the
  // step is solved again, linearised there (a Newton iteration on the nonlinear step with the
  // potential in it), up to kMaxRelinearisations times.
  constexpr int kMaxRelinearisations = 4;
  bool relinearised = false;  // the terms are already evaluated where iteration k linearises
  potential_acted_ = false;
  for (int k = 0;; ++k) {
    auto t0 = std::chrono::steady_clock::now();
    try {
      if (relinearised) {
        // (evaluated below, at x_lin)
      } else if (k == 0) {
        update_terms(x, u_, t_next);  // (terms that depend on x alone reuse the last evaluation)
      } else {
        x_lin = x + h * v_k;
        u_lin = x_lin - rest;
        discretization_.make_consistent(u_lin);
        update_terms(x_lin, u_lin, t_next);
      }
    } catch (const SimulationError&) {
      throw;
    } catch (const std::exception& e) {
      throw SimulationError(step_number, t_next, e.what());
    }
    relinearised = false;
    stats.update_ms += ms_since(t0);

    t0 = std::chrono::steady_clock::now();
    // The matrix keeps its pattern and storage from step to step; only its values are rewritten.
    Eigen::SparseMatrix<double>& a = system_;
    assemble(weights, a);
    f.setZero();
    for (const ForceTerm* term : all_) term->add_force(f);
    Eigen::VectorXd b = mass_.cwiseProduct(v) + h * f;
    if (k > 0) {
      if (stiffness_.size() == 0) stiffness_ = discretization_.matrix_pattern();
      assemble({1.0, 0.0}, stiffness_);
      b += h * h * (stiffness_ * v_k);
    }
    double* values = a.valuePtr();
    for (Eigen::Index i = 0; i < n3; ++i) values[diagonal_[static_cast<size_t>(i)]] += mass_(i);
    for (size_t i = 0; i < prescribed.size(); ++i) {
      const int dof = prescribed[i];
      prescribed_rows[i].clear();
      for (Eigen::SparseMatrix<double>::InnerIterator it(a, dof); it; ++it) prescribed_rows[i].emplace_back(it.row(), it.value());
      prescribed_rhs(static_cast<Eigen::Index>(i)) = b(dof);
    }
    if (loads_) {
      f_ext.setZero();
      loads_->add_force(f_ext);
    }
    stats.assemble_ms += ms_since(t0);

    t0 = std::chrono::steady_clock::now();
    // Where a re-linearisation is still allowed, Newton asks early whether the frames turned.
    const std::function<bool(const Eigen::VectorXd&)> turned = [&](const Eigen::VectorXd& w) {
      const auto t1 = std::chrono::steady_clock::now();
      end_positions(x, w, target, x_lin, u_lin);
      try {
        update_terms(x_lin, u_lin, t_next);
      } catch (const std::exception& e) {
        throw SimulationError(step_number, t_next, e.what());
      }
      stats.update_ms += ms_since(t1);
      double turn = 0.0;
      for (const ForceTerm* term : all_) turn = std::max(turn, term->frame_turn());
      return turn > settings_.rotation_tolerance;
    };
    const bool may_relinearise = k + 1 >= settings_.newton_iterations &&
                                 k + 1 < settings_.newton_iterations + kMaxRelinearisations &&
                                 std::isfinite(settings_.rotation_tolerance);
    const LinearSolveReport report = potential_ ? solve_with_potential(a, b, x, v, state.t, h, k == 0, v_next, stats,
                                                                       may_relinearise ? &turned : nullptr)
                                                : solver_.solve(a, b, free_, v_next);
    if (!potential_) coupled_in_use_ = false;
    stats.solver_iterations += report.iterations;
    stats.residual = report.residual;
    stats.factorizations += report.factorizations;
    stats.factor_ms += report.factor_ms;
    stats.direct_fallbacks += report.direct_fallbacks;
    if (stats.direct_fallback_reason.empty()) stats.direct_fallback_reason = report.fallback_reason;
    stats.solve_ms += ms_since(t0);
    if (!report.converged) throw SimulationError(step_number, t_next, report.failure, SimulationError::Kind::solver);
    if (k > 0) stats.newton_change = (v_next - v_k).norm() / std::max(v_next.norm(), 1e-300);
    v_k = v_next;
    if (k + 1 < settings_.newton_iterations) continue;
    if (potential_ && newton_turned_) {  // (the terms are evaluated at the iterate's end positions)
      relinearised = true;
      ++stats.contact.relinearisations;
      continue;
    }
    if (!potential_acted_ || k + 1 >= settings_.newton_iterations + kMaxRelinearisations) break;
    if (!turned(v_next)) break;
    relinearised = true;
    ++stats.contact.relinearisations;
  }
  if (potential_) finish_potential(v_next, stats);

  if (filter_) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      const StepSystem system{system_, free_, solver_.preconditioner(system_, free_)};
      filter_->filter(x, state.t, h, v_next, system, stats);
    } catch (const SimulationError&) {
      throw;
    } catch (const std::exception& e) {
      throw SimulationError(step_number, t_next, e.what());
    }
    const double filter_ms = ms_since(t0);
    stats.contact.ms += filter_ms;
    stats.contact.failsafe_ms += filter_ms;
  }

  // Advance; scripted components land exactly on their motion, tied ones follow their rule.
  Eigen::VectorXd x_next, u_next;
  end_positions(x, v_next, target, x_next, u_next);
  for (int dof : dependent_) v_next(dof) = (x_next(dof) - x(dof)) / h;
  if (!x_next.allFinite() || !v_next.allFinite())
    throw SimulationError(step_number, t_next, "the state became NaN or infinite (numerical instability)",
                          SimulationError::Kind::nan);
  if (u_next.cwiseAbs().maxCoeff() > 1e3 * size_)
    throw SimulationError(step_number, t_next, "the simulation diverged (a vertex moved more than 1000 times the mesh size)",
                          SimulationError::Kind::diverged);

  for (Eigen::Index i = 0; i < n3; ++i)
    if (free_[i]) stats.external_work += f_ext(i) * (x_next(i) - x(i));
  // Work of the supports (and of the loads on the supported components): (R_p + f_ext,p) Δx_p
  // with h R_p = (A v⁺ − b)_p and Δx_p = h v⁺_p.
  for (size_t i = 0; i < prescribed.size(); ++i) {
    const int dof = prescribed[i];
    double impulse = -prescribed_rhs(static_cast<Eigen::Index>(i));
    for (const auto& [row, value] : prescribed_rows[i]) impulse += value * v_next(row);
    stats.boundary_work += (impulse + h * f_ext(dof)) * v_next(dof);
  }

  // The terms at the new state (energies now, the next step's linearisation).
  const auto t0 = std::chrono::steady_clock::now();
  try {
    update_terms(x_next, u_next, t_next);
  } catch (const std::exception& e) {
    throw SimulationError(step_number, t_next, e.what());
  }
  stats.update_ms += ms_since(t0);

  v_previous_ = v;
  potential_energy_ = stats.contact_energy;
  contact_last_step_ = potential_acted_;
  work_ += stats.external_work;
  boundary_work_ += stats.boundary_work;
  state.x = std::move(x_next);
  state.v = std::move(v_next);
  state.t = t_next;
  state.step = step_number;
  u_ = std::move(u_next);
  stats.kinetic_energy = kinetic_energy(state);
  stats.elastic_energy = elastic_energy();
  stats.step_ms = ms_since(step_start);
  if (potential_ || filter_) {
    const bool acted = potential_acted_ || stats.contact.impulses > 0 || stats.contact.impact_zones > 0;
    stats.contact.contact_steps += acted ? 1 : 0;
    (acted ? stats.contact.contact_step_ms : stats.contact.free_step_ms) += stats.step_ms;
  }
  return stats;
}

}  // namespace clothsim

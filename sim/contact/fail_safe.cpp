#include "sim/contact/fail_safe.hpp"

#include "sim/contact/pair_geometry.hpp"
#include "sim/solver/pcg.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

namespace clothsim::contact {

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }
}  // namespace

void KeptMultipliers::warm_start(std::vector<Found>& found) const {
  for (Found& f : found) {
    const auto it = std::lower_bound(last_.begin(), last_.end(), f.key,
                                     [](const auto& entry, const ConstraintKey& k) { return entry.first < k; });
    if (it == last_.end() || !(it->first == f.key)) continue;
    f.constraint.lambda = it->second.first;
    f.constraint.friction = it->second.second;
  }
}

void KeptMultipliers::keep(const std::vector<Found>& found) {
  last_.clear();
  for (const Found& f : found)
    if (f.constraint.lambda > 0) last_.push_back({f.key, {f.constraint.lambda, f.constraint.friction}});
  std::sort(last_.begin(), last_.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  // (a pair found twice in one step keeps its first entry: lower_bound finds it)
}

// The response is implicit, through the step's system: the new velocities solve
//     min ½ (v − v*)ᵀ A (v − v*) + Σᵢ μᵢ λᵢ |wᵢ(v)|   subject to   gᵢ(v) = targetᵢ − nᵢ·uᵢ(v) ≤ 0,
// v* the solve's velocities, A = M + h D + h² K its matrix, uᵢ = Σ B[dof] v[dof] + eᵢ the pair's
// relative velocity (B through J over the free DOFs, eᵢ the obstacle's and the prescribed DOFs'
// part), wᵢ its tangential part and λᵢ its normal impulse (Coulomb friction by maximal
// dissipation). This is implicit Euler with the contact in it, for the step's linearised
// forces: an impulse moves the cloth as the step's stiffness lets it (over a step of 10 ms, a
// whole stiff sleeve), where lumped masses alone would move a few nodes and strain the cloth
// around them. With targets ≤ 0 it cannot add energy (docs/contact.md).
//
// Solved by an augmented Lagrangian. For fixed multipliers (λᵢ, the friction impulses fᵢ),
// Newton on
//     ½ |v − v*|²_A + Σ (1 / 2κᵢ) max(0, λᵢ + κᵢ gᵢ)² + Σ Ψᵢ(wᵢ),   ∇Ψᵢ = Π(fᵢ + κᵢ wᵢ),
// Π the projection on the disc of radius μᵢ λᵢ (the Moreau envelope of μ λ |w|); the function is
// piecewise quadratic but for sliding pairs, and each Newton step solves
// (A + Σ κᵢ (normal and tangential blocks)) δ = −∇ by conjugate gradients preconditioned with a
// Cholesky factor of that matrix (on A's pattern; refreshed when the solves slow down). Then
// λᵢ ← max(0, λᵢ + κᵢ gᵢ), fᵢ ← Π(fᵢ + κᵢ wᵢ), the disc's radius μᵢ λᵢ following λᵢ for the
// first `friction_updates` updates only (lagged friction: then the problem is convex), until
// every constraint and every sticking pair is met to `tolerance`, in velocity. κᵢ =
// penalty_ratio / (Σ (B·n)² / D), D the diagonal of A. The multipliers stay in the constraints:
// the next pass starts from them.
void ImplicitResponse::solve(std::vector<Found>& found, const Eigen::VectorXd& base, Eigen::VectorXd& v, const ResponseSystem& system,
                             const Eigen::VectorXd& diagonal, const std::vector<char>& free, double tolerance,
                             CollisionSurface& surface, ContactReport& report) {
  const auto t0 = Clock::now();
  const Eigen::Index n3 = v.size();
  struct Row {
    // The pair's relative velocity u = Σ b · v(dof) + eᵢ over its free DOFs. Held in one of two
    // forms: `nodes`, when every node's three DOFs are free and b(3k + c) = w_k e_c (the collision
    // surface's Jacobian is S ⊗ I₃, the usual case), so u = Σ w_k v_k; else `b`, per DOF.
    // The node form is a third of the entries and of the arithmetic, with the same sums.
    NodeRow row;  // free DOFs (dofs empty in the node form; nodes: (node k, w_k))
    Eigen::Vector3d constant = Eigen::Vector3d::Zero();  // eᵢ
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity();  // I − n nᵀ
    double kappa = 0.0, target = 0.0, mu = 0.0;
    double radius = 0.0;  // of the friction disc, μ times a normal impulse
    Constraint* c = nullptr;
    // Newton's linearisation at the current v:
    bool normal_active = false;
    Eigen::Matrix3d friction_hessian = Eigen::Matrix3d::Zero();
    bool passive() const { return !normal_active && friction_hessian.isZero(0.0); }  // adds nothing to the matrix
  };
  std::vector<Row> rows;
  rows.reserve(found.size());
  for (Found& f : found) {
    Constraint& con = f.constraint;
    Row r;
    r.constant = con.obstacle_velocity;
    double w = 0.0;
    for (const auto& [dof, b] : con.b) {
      if (free[static_cast<size_t>(dof)]) {
        r.row.dofs.emplace_back(dof, b);
        w += std::pow(b.dot(con.normal), 2) / diagonal(dof);
      } else {
        r.constant += b * v(dof);
      }
    }
    if (!(w > 0)) {  // nothing on the cloth side can move along the normal
      con.lambda = 0.0;
      con.friction.setZero();
      continue;
    }
    surface.to_node_form(r.row.dofs, r.row.nodes);
    r.normal = con.normal;
    r.tangent -= con.normal * con.normal.transpose();
    r.kappa = params_.penalty_ratio / w;
    r.target = con.target;
    r.mu = con.mu;
    r.radius = con.mu * con.lambda;
    r.c = &con;
    con.friction = r.tangent * con.friction;
    rows.push_back(std::move(r));
  }
  if (rows.empty()) {
    report.response_ms += ms_since(t0);
    return;
  }
  auto relative = [&](const Row& r, const Eigen::VectorXd& x) { return r.row.apply(x); };  // uᵢ(x) without eᵢ
  auto scatter = [&](const Row& r, const Eigen::Vector3d& force, Eigen::VectorXd& y) { r.row.scatter(force, y); };  // y += Bᵢᵀ force
  auto disc = [](const Eigen::Vector3d& y, double radius) -> Eigen::Vector3d {
    const double norm = y.norm();
    if (norm <= radius) return y;
    return norm > 0 ? Eigen::Vector3d((radius / norm) * y) : Eigen::Vector3d::Zero();
  };
  const Eigen::VectorXd mask = clothsim::free_mask(free);
  Eigen::VectorXd gradient(n3), step(n3), change(n3), moved_by(n3);
  const Eigen::SparseMatrix<double>& a = system.matrix;
  auto penalised_product = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
    symmetric_product(a, x, mask, y);
    for (const Row& r : rows) {
      if (r.passive()) continue;
      const Eigen::Vector3d u = relative(r, x);
      Eigen::Vector3d force = r.friction_hessian * u;
      if (r.normal_active) force += r.kappa * r.normal.dot(u) * r.normal;
      scatter(r, force, y);
    }
    y = y.cwiseProduct(mask);
  };
  // The augmented Lagrangian's value at v for the current multipliers (up to a constant), and,
  // with `linearise`, its gradient and each row's Newton linearisation.
  auto merit = [&](const Eigen::VectorXd& x, bool linearise) {
    const Eigen::VectorXd ax = a * (x - base);
    double value = 0.5 * (x - base).dot(ax);
    if (linearise) gradient = ax;
    for (size_t i = 0; i < rows.size(); ++i) {
      Row& r = rows[i];
      const Eigen::Vector3d u = relative(r, x) + r.constant;
      const double s = r.c->lambda + r.kappa * (r.target - r.normal.dot(u));
      const double radius = r.radius;
      const Eigen::Vector3d y = r.c->friction + r.kappa * (r.tangent * u);
      const double excess = std::max(0.0, y.norm() - radius);
      value += (s > 0 ? s * s : 0.0) / (2.0 * r.kappa) + (y.squaredNorm() - excess * excess) / (2.0 * r.kappa);
      if (!linearise) continue;
      // −(impulse on the pair): the normal part pushes along n, friction opposes w.
      r.normal_active = s > 0;
      Eigen::Vector3d force = r.normal_active ? Eigen::Vector3d(-s * r.normal) : Eigen::Vector3d::Zero();
      const bool stick = excess == 0.0;
      if (!(radius > 0)) {  // no friction: the envelope of 0 is 0
        r.friction_hessian.setZero();
      } else if (stick) {
        r.friction_hessian = r.kappa * r.tangent;
      } else {
        const Eigen::Vector3d e = y.normalized();
        r.friction_hessian = r.kappa * (radius / y.norm()) * (r.tangent - e * e.transpose());
      }
      force += disc(y, radius);
      scatter(r, force, gradient);
    }
    if (linearise) gradient = gradient.cwiseProduct(mask);
    return value;
  };
  // The conjugate gradients' preconditioner: a Cholesky factor of the Newton matrix
  // A + Σ κᵢ Bᵢᵀ Hᵢ Bᵢ (Hᵢ the row's normal and friction blocks as last linearised) restricted
  // to A's pattern, made when a solve needs more than `refactor_iterations` and kept across
  // calls and steps while it serves (before the first one: the step's own preconditioner).
  auto precondition = [this, &system](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
    if (newton_factor_ && newton_factor_->ready())
      newton_factor_->apply(r, z);
    else
      system.inverse(r, z);
  };
  auto factor_newton_matrix = [&]() {
    // The pattern: A's and every coupling of the current constraints (two cloth parts in contact
    // couple nodes far apart in the mesh). It is rebuilt, with a new symbolic analysis, only when
    // a constraint needs a coupling it lacks.
    std::vector<std::vector<int>> row_nodes(rows.size());
    for (size_t k = 0; k < rows.size(); ++k) row_nodes[k] = rows[k].row.node_list();
    if (!newton_pattern_.covers(a, row_nodes)) {
      newton_pattern_.rebuild(a, row_nodes);
      newton_factor_ = std::make_unique<CholeskyPreconditioner>();
    }
    newton_pattern_.set_base(a);
    for (const Row& r : rows) {
      if (r.passive()) continue;
      Eigen::Matrix3d hessian = r.friction_hessian;
      if (r.normal_active) hessian += r.kappa * r.normal * r.normal.transpose();
      newton_pattern_.add_block(r.row, hessian);
    }
    const Eigen::SparseMatrix<double>& m = newton_pattern_.matrix();
    ++report.response_factorizations;
    if (!newton_factor_) newton_factor_ = std::make_unique<CholeskyPreconditioner>();
    if (!newton_factor_->factorize(m, &free)) newton_factor_.reset();  // then the step's own preconditioner
  };
  Eigen::VectorXd v_outer = v;
  for (int outer = 0; outer < params_.response_iterations; ++outer) {
    // Damped Newton on the (convex, once differentiable) function: the friction term is linear
    // along the sliding direction, so a full step can overshoot past w = 0.
    int newton = 0;
    for (; newton < 30; ++newton) {
      const double value = merit(v, true);
      if (newton > 0) {  // after a step: done when the preconditioner's estimate of the next is tiny
        precondition(-gradient, step);
        if (step.cwiseProduct(mask).cwiseAbs().maxCoeff() <= 0.01 * tolerance) break;
      }
      step.setZero();
      // A solve that needs many iterations has an out-of-date preconditioner: it is stopped,
      // the Newton matrix refactorised, and the solve goes on from where it stopped.
      const LinearOperator newton_operator(penalised_product);
      PcgResult result = solve_pcg(newton_operator, -gradient, free, step, params_.response_cg_tolerance,
                                   3 * params_.refactor_iterations, precondition);
      report.response_cg_iterations += result.iterations;
      if (!result.converged) {
        factor_newton_matrix();
        result = solve_pcg(newton_operator, -gradient, free, step, params_.response_cg_tolerance, 10 * static_cast<int>(n3) + 100,
                           precondition);
        report.response_cg_iterations += result.iterations;
      } else if (result.iterations > params_.refactor_iterations) {
        factor_newton_matrix();
      }
      const double slope = gradient.dot(step);
      if (step.cwiseAbs().maxCoeff() <= 0.1 * tolerance || !(slope < 0)) {
        if (slope < 0) v += step;
        break;
      }
      double alpha = 1.0;
      while (alpha > 1e-4 && merit(v + alpha * step, false) > value + 1e-4 * alpha * slope) alpha *= 0.5;
      v += alpha * step;
    }
    // Converged when no constraint is violated by more than the tolerance and the update of
    // the multipliers would change no DOF's velocity by more (estimated with the approximate
    // inverse of A).
    double worst = 0.0;
    change.setZero();
    for (Row& r : rows) {
      const Eigen::Vector3d u = relative(r, v) + r.constant;
      const double g = r.target - r.normal.dot(u);
      const double lambda = std::max(0.0, r.c->lambda + r.kappa * g);
      // The Coulomb disc follows the normal impulse for the first `friction_updates` updates,
      // then stays: the rest is a convex problem (friction with a given bound only dissipates).
      if (outer < params_.friction_updates) r.radius = r.mu * lambda;
      const Eigen::Vector3d updated = disc(r.c->friction + r.kappa * (r.tangent * u), r.radius);
      worst = std::max(worst, g);
      const Eigen::Vector3d impulse = (lambda - r.c->lambda) * r.normal - (updated - r.c->friction);
      scatter(r, impulse, change);
      r.c->lambda = lambda;
      r.c->friction = updated;
    }
    system.inverse(change.cwiseProduct(mask), moved_by);
    const double moves = moved_by.cwiseProduct(mask).cwiseAbs().maxCoeff();
    // (Multipliers can also change without moving anything: pairs that push on the same points
    // from two sides. Then the velocities have settled: they changed by less than the tolerance
    // over the last update.)
    const double settled = (v - v_outer).cwiseProduct(mask).cwiseAbs().maxCoeff();
    v_outer = v;
    worst = std::max(worst, outer > 0 ? std::min(moves, settled) : moves);
    ++report.response_iterations;
    if (worst <= tolerance) break;
  }
  report.impulses += static_cast<int>(std::count_if(rows.begin(), rows.end(), [](const Row& r) { return r.c->lambda > 0; }));
  report.response_ms += ms_since(t0);
}

void merge_zones(const std::vector<Found>& hits, Zones& zones, std::vector<int>& zone_obstacle) {
  for (const Found& f : hits) {
    const Constraint& c = f.constraint;
    int first = -1;
    for (const auto& entry : c.b) {
      const int node = entry.first / 3;
      if (first < 0) first = node;
      zones.unite(first, node);
    }
    if (first < 0) continue;
    for (const auto& entry : c.b) {
      const int node = entry.first / 3;
      int& zo = zone_obstacle[static_cast<size_t>(node)];
      if (zo == -2) zo = -1;
      if (c.obstacle >= 0) zo = std::max(zo, c.obstacle);
    }
  }
}

void move_impact_zones(Zones& zones, const std::vector<int>& zone_obstacle, const Eigen::VectorXd& x, double t, double h,
                       const std::vector<char>& free, const Eigen::VectorXd& node_mass, const std::vector<Obstacle>& obstacles,
                       Eigen::VectorXd& v, ContactReport& report) {
  const auto t0 = Clock::now();
  const int n = static_cast<int>(node_mass.size());
  // Members of each zone: the nodes marked by a colliding pair, grouped by their root.
  std::map<int, std::vector<int>> members;
  for (int i = 0; i < n; ++i)
    if (zone_obstacle[static_cast<size_t>(i)] != -2) members[zones.find(i)].push_back(i);
  report.impact_zones = 0;
  for (auto& [root, nodes] : members) {
    (void)root;
    ++report.impact_zones;
    auto pos = [&](int i) -> Eigen::Vector3d { return x.segment<3>(3 * i); };
    auto node_free = [&](int i) { return free[static_cast<size_t>(3 * i)] && free[static_cast<size_t>(3 * i + 1)] && free[static_cast<size_t>(3 * i + 2)]; };
    int obstacle = -1;  // the zone's obstacle (the highest index when it touches several)
    for (int i : nodes) obstacle = std::max(obstacle, zone_obstacle[static_cast<size_t>(i)]);
    std::vector<Eigen::Vector3d> from, to;
    for (int i : nodes)
      if (!node_free(i)) {
        from.push_back(pos(i));
        to.push_back(pos(i) + h * v.segment<3>(3 * i));
      }
    RigidMap map;
    bool have_map = false;
    if (obstacle >= 0) {
      map = obstacle_step_map(obstacles[static_cast<size_t>(obstacle)], t, h);
      have_map = true;
    } else if (!from.empty()) {
      map = fit_rigid(from, to);
      have_map = true;
    }
    if (have_map) {
      for (int i : nodes)
        for (int k = 0; k < 3; ++k)
          if (free[static_cast<size_t>(3 * i + k)]) v(3 * i + k) = (map(pos(i))[k] - pos(i)[k]) / h;
      continue;
    }
    // A free zone: the rigid velocity field with the zone's linear and angular momentum.
    double mass = 0.0;
    Eigen::Vector3d momentum = Eigen::Vector3d::Zero(), centre = Eigen::Vector3d::Zero();
    for (int i : nodes) {
      const double m = node_mass(i);
      mass += m;
      momentum += m * v.segment<3>(3 * i);
      centre += m * pos(i);
    }
    if (!(mass > 0)) continue;
    centre /= mass;
    Eigen::Vector3d angular = Eigen::Vector3d::Zero();
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
    for (int i : nodes) {
      const double m = node_mass(i);
      const Eigen::Vector3d r = pos(i) - centre;
      angular += m * r.cross(v.segment<3>(3 * i));
      inertia += m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
    }
    const Eigen::Vector3d omega = inertia.completeOrthogonalDecomposition().solve(angular);
    const Eigen::Vector3d velocity = momentum / mass;
    for (int i : nodes) v.segment<3>(3 * i) = velocity + omega.cross(pos(i) - centre);
  }
  report.response_ms += ms_since(t0);
}

}  // namespace clothsim::contact

#include "sim/contact/barrier_potential.hpp"

#include "sim/contact/narrow_phase.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>

namespace clothsim::contact {

BarrierPotential::BarrierPotential(CollisionSurface& surface, const PairPrimitives& pairs, const ObstacleSet& obstacle_set,
                                   const std::vector<Obstacle>& obstacles, CandidateSearch& search,
                                   const BarrierSettings& settings)
    : surf_(surface), pairs_(pairs), obs_(obstacle_set), obstacles_(obstacles), search_(search), settings_(settings) {}

// --- Rows --------------------------------------------------------------------------------------
Eigen::Vector3d BarrierPotential::Row::apply(const CollisionSurface& surf, const Eigen::VectorXd& v) const {
  return points.count > 0 ? points.apply(*surf.point_map(), v) : dofs.apply(v);
}
void BarrierPotential::Row::scatter(const CollisionSurface& surf, const Eigen::Vector3d& f, Eigen::VectorXd& y) const {
  if (points.count > 0) {
    points.scatter(*surf.point_map(), f, y);
  } else {
    dofs.scatter(f, y);
  }
}
void BarrierPotential::Row::put_in(PotentialLinearisation::Block& block) const {
  if (points.count > 0) {
    block.on_points = points;
  } else {
    block.row = dofs;
  }
}
BarrierPotential::Row BarrierPotential::pair_row(const PairGeometry& g) {
  Row r;
  if (surf_.point_map() != nullptr) {
    r.points = surf_.pair_points(g);
  } else {
    r.dofs = surf_.pair_row(g);
  }
  return r;
}
BarrierPotential::Row BarrierPotential::point_row(int p) {
  Row r;
  if (surf_.point_map() != nullptr) {
    r.points = surf_.point_alone(p);
  } else {
    r.dofs = surf_.point_row(p);
  }
  return r;
}

// The end points p0 + h J v (#P × 3) for velocities v.
Eigen::MatrixX3d BarrierPotential::end_points_of(const StepPositions& step, const Eigen::VectorXd& v) const {
  return surf_.end_points(step.p0, h_, v);
}

// The obstacle side's part of a pair's relative velocity over the step [m/s].
Eigen::Vector3d BarrierPotential::obstacle_side_velocity(const StepPositions& step, const PairGeometry& g) const {
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  for (int k = 0; k < g.num; ++k)
    if (g.obstacle[static_cast<size_t>(k)]) {
      const int p = g.point[static_cast<size_t>(k)];
      u += g.coef[static_cast<size_t>(k)] * (step.o1.row(p) - step.o0.row(p)).transpose() / h_;
    }
  return u;
}
double BarrierPotential::pair_friction(const PairGeometry& g) const {
  const int o = pairs_.obstacle_of(g);
  return o >= 0 ? obstacles_[static_cast<size_t>(o)].friction : settings_.friction;
}

// --- Stiffness ---------------------------------------------------------------------------------
// The barrier's stiffness for a pair of cloth points: k h² = ratio × the smallest effective mass
// (with the step's stiffness, s_k) of its cloth points, so the barrier is as stiff as the step's
// own system is under it, whatever the material and step.
double BarrierPotential::pair_stiffness(const Candidate& c) {
  double m = std::numeric_limits<double>::infinity();
  for (int p : pairs_.cloth_points(c))
    if (p >= 0) m = std::min(m, mass_of_point(p));
  return settings_.barrier_ratio * m / (h_ * h_);
}
// Effective mass of surface point p through J, 1 / Σ_k J_k² / s_k, with each node's scale s_k the
// mean of its three diagonal entries of A (a rotation leaves the trace of a node's block
// unchanged). Made on first use in a step (few points are in pairs; all of them took a quarter of
// a millisecond per step on the 494-vertex sleeve); not for parallel callers.
double BarrierPotential::mass_of_point(int p) {
  double& m = point_mass_(p);
  if (!std::isnan(m)) return m;
  double sum = 0.0;
  if (const PointMap* map = surf_.point_map()) {
    for (int e = map->offsets[static_cast<size_t>(p)]; e < map->offsets[static_cast<size_t>(p) + 1]; ++e) {
      const double w = map->weights[static_cast<size_t>(e)];
      sum += w * w / node_scale_(map->nodes[static_cast<size_t>(e)]);
    }
  } else {
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(surf_.jacobian(), 3 * p); it; ++it)
      sum += it.value() * it.value() / node_scale_(it.col() / 3);
  }
  m = sum > 0 ? 1.0 / sum : std::numeric_limits<double>::infinity();
  return m;
}
double BarrierPotential::plane_stiffness(int p) { return settings_.barrier_ratio * mass_of_point(p) / (h_ * h_); }

// --- Candidates and when they serve ------------------------------------------------------------
// The potential's candidates: the broad phase over the motion p0 → p1 with boxes grown by twice
// the thickness. They serve every configuration, and every motion between two, whose points (and
// obstacle vertices) each stay within half the thickness of the straight path from the start to
// the end point they were made for: at any time of such a motion every point is within that of
// its swept box, so each pair that comes within the thickness at the end (the barrier), over the
// step (the fail-safe's CCD) or over a Newton step (step_bound) is among them. So they are kept
// from step to step while the cloth moves little (a resting drape), and from the held start to
// the guess and on through Newton's iterates within a step.
// (serve_radius is half the thickness. A radius of 1 or 2.5 thicknesses took 2.2 or 9.6 times the
// contact time on sleeve_on_arm's first 0.6 s: the candidates grow faster than their rebuilds get
// rarer.)

// The largest distance of a point p_i from the segment a_i → b_i [m] (infinite for other sizes;
// NaN where a point is NaN). One pass per point, in parallel: it runs several times per step, and
// as whole-matrix expressions its temporaries cost more than its arithmetic.
double BarrierPotential::sweep_distance(const Eigen::MatrixX3d& p, const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b) {
  if (p.rows() != a.rows() || p.rows() != b.rows()) return std::numeric_limits<double>::infinity();
  auto larger = [](double m, double d) { return std::isnan(m) ? m : (d > m || std::isnan(d)) ? d : m; };
  return tbb::parallel_reduce(
      tbb::blocked_range<Eigen::Index>(0, p.rows(), 2048), 0.0,
      [&](const tbb::blocked_range<Eigen::Index>& range, double m) {
        for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
          const double dx = b(i, 0) - a(i, 0), dy = b(i, 1) - a(i, 1), dz = b(i, 2) - a(i, 2);
          const double qx = p(i, 0) - a(i, 0), qy = p(i, 1) - a(i, 1), qz = p(i, 2) - a(i, 2);
          const double dd = dx * dx + dy * dy + dz * dz;
          const double s = dd > 0 ? std::min(std::max((qx * dx + qy * dy + qz * dz) / dd, 0.0), 1.0) : 0.0;
          const double rx = qx - s * dx, ry = qy - s * dy, rz = qz - s * dz;
          m = larger(m, std::sqrt(rx * rx + ry * ry + rz * rz));
        }
        return m;
      },
      larger);
}

bool BarrierPotential::serves(const Eigen::MatrixX3d& p, const Eigen::MatrixX3d& q, double& sp, double& sq) const {
  const double r = serve_radius();
  return obstacles_serve_ && (sp = sweep_distance(p, built_p0_, guess_)) <= r && (sq = sweep_distance(q, built_p0_, guess_)) <= r;
}

// (The step bound's end of a move is the next linearisation's point, and its start the last
// one's: the check is a few passes over all surface points, and it runs several times a step.)
bool BarrierPotential::served(const Eigen::VectorXd& v, const Eigen::MatrixX3d& p) {
  if (!obstacles_serve_) return false;
  if (served_known_ && v.size() == served_velocity_.size() && v == served_velocity_) return true;
  const double sweep = sweep_distance(p, built_p0_, guess_);
  if (!(sweep <= serve_radius())) return false;
  served_velocity_ = v;
  served_known_ = true;
  served_sweep_ = sweep;
  return true;
}

void BarrierPotential::check_obstacles_serve(const StepPositions& step) {
  if (settings_.obstacles_static && built_o0_.rows() == step.o0.rows()) {  // (o0 = o1 = built_o0 = built_o1)
    obstacles_serve_ = true;
    return;
  }
  const double r = serve_radius();
  obstacles_serve_ = sweep_distance(step.o0, built_o0_, built_o1_) <= r && sweep_distance(step.o1, built_o0_, built_o1_) <= r;
}

void BarrierPotential::make_candidates(StepPositions& step) {
  const auto t0 = std::chrono::steady_clock::now();
  start_sweep_ = 0.0;  // (p0 starts the paths made here)
  lin_bounds_valid_ = false;
  served_known_ = false;
  ContactCounters scratch;
  const double grow = settings_.thickness + 2.0 * serve_radius();
  // The paths are the points' moves p0 -> p1 carried on ahead, up to a thickness for the fastest
  // point (at most 8 times the move): a cloth in steady motion then stays on them for several more
  // steps (the crushed sleeve: a broad phase every 10 steps instead of every 5), while their boxes,
  // grown by two thicknesses anyway, grow little. (A cloth faster than a thickness per step: p1.)
  const double fastest = (p1_ - step.p0).rowwise().norm().maxCoeff();
  const double ahead = fastest > 0 ? std::clamp(settings_.thickness / fastest, 1.0, 8.0) : 1.0;
  guess_ = step.p0 + ahead * (p1_ - step.p0);
  cands_ = search_.find(step.p0, guess_, step.o0, step.o1, step.obstacle_boxes_current, grow, scratch);
  step.obstacle_boxes_current = true;
  // Boxes overlap where the primitives are far apart (a point over a flat face with a fan of long
  // triangles: cusick_drape's 72-wedge support top gave 72k pairs for 20k points). A pair whose
  // distance at the start, less how far its points move along the paths the candidates are made
  // for, is at least `grow` cannot come within the thickness anywhere they serve (each point within
  // serve_radius of its path), so it is dropped: every later pass over the candidates is shorter.
  {
    const Eigen::VectorXd path = (guess_ - step.p0).rowwise().norm();
    const double obstacle_path = step.o0.rows() > 0 ? (step.o1 - step.o0).rowwise().norm().maxCoeff() : 0.0;
    std::vector<char> keep(cands_.size(), 1);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, cands_.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i != range.end(); ++i) {
        const Candidate& c = cands_[i];
        const Corners corner = pairs_.corners(c, step.p0, step.o0);
        const double motion = pairs_.motion(c, path, obstacle_path);
        // (A box gap is a lower bound of the distance, and cheaper.)
        keep[i] = box_gap(corner, is_point_triangle(c.kind)) - motion < grow && pairs_.geometry(c, corner).distance - motion < grow;
      }
    });
    size_t n = 0;
    for (size_t i = 0; i < cands_.size(); ++i)
      if (keep[i]) cands_[n++] = cands_[i];
    cands_.resize(n);
  }
  ++builds_;
  near_reach_of_.assign(cands_.size(), -1.0);
  built_p0_ = step.p0;
  built_o0_ = step.o0;
  built_o1_ = step.o1;
  obstacles_serve_ = true;
  prepare_candidates(step);
  candidates_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Per step (and after a new broad phase): each candidate's distance bound and, where it may be
// within the thickness, geometry at the start of the step.
void BarrierPotential::prepare_candidates(const StepPositions& step) {
  // The last step's final linearisation holds bounds at its end points, the obstacles at its end:
  // this step's start (the same surface up to the fail-safe's changes and round-off, which the
  // points' moves from it account for).
  // (The step's start time and the last one's end, t + h, agree up to round-off; the obstacles'
  // vertices then may differ by round-off too, which their move from the last linearisation's
  // accounts for.)
  const bool carried = lin_bounds_valid_ && lin_bounds_.lower.size() == cands_.size() &&
                       std::abs(lin_time_ - t_) <= 1e-9 * h_ && lin_o1_.rows() == step.o0.rows();
  double motion = 0.0, obstacle_shift = 0.0;
  if (carried) {
    point_move_ = (step.p0 - lin_points_).rowwise().norm();
    if (step.o0.rows() > 0 && !settings_.obstacles_static)
      obstacle_shift = (step.o0 - lin_o1_).rowwise().norm().maxCoeff();
    const double largest = point_move_.size() > 0 ? point_move_.maxCoeff() : 0.0;
    motion = std::max(2.0 * largest, largest + obstacle_shift);
  }
  // Where the last linearisation was at this start up to round-off (the step's velocities are its
  // last iterate's, and the fail-safe changed nothing), its pairs' geometry is the start's: most
  // pairs of a resting cloth (the start's geometry then differs from its own by round-off only).
  const bool reuse = carried && motion <= 1e-9 * settings_.thickness && end_known_.size() == cands_.size();
  lin_bounds_valid_ = false;
  // Each pair's geometry at the start of the step: its side (the barrier's distance is signed by
  // it, see linearise) and, for pairs pressed at the start, lagged friction. (Computed here for
  // the pairs whose boxes are within the thickness at the start, the others when a linearisation
  // finds them within it at the end: start_geometry.)
  cand_start_.resize(cands_.size());
  cand_start_known_.assign(cands_.size(), 0);
  cand_start_close_.assign(cands_.size(), 0);
  std::vector<double>& lower = start_bounds_.lower;
  if (carried) {
    lower = lin_bounds_.less(motion);
  } else {
    lower.assign(cands_.size(), 0.0);
  }
  auto visit = [&](size_t i) {
    const Candidate& c = cands_[i];
    if (carried) {
      if (lin_bounds_.lower[i] - motion >= settings_.thickness) return;  // (without the pair's own motion)
      const double bound = lin_bounds_.lower[i] - pairs_.motion(c, point_move_, obstacle_shift);
      lower[i] = std::max(0.0, bound);
      if (bound >= settings_.thickness) return;
    }
    const Corners corner = pairs_.corners(c, step.p0, step.o0);
    const double gap = box_gap(corner, is_point_triangle(c.kind));
    lower[i] = std::max(lower[i], gap);
    if (c.near || !(gap < settings_.thickness)) return;
    // (The last linearisation's geometry, of this start up to round-off: its bound less that. Not
    // where linearise signed it negative by its own start, a crossing: a fresh geometry is unsigned.)
    if (reuse && end_known_[i] && end_geometry_[i].distance > 0) {
      cand_start_[i] = end_geometry_[i];
      cand_start_known_[i] = 1;
      lower[i] = std::max(0.0, cand_start_[i].distance - motion);
    } else {
      lower[i] = start_geometry(step, i).distance;
    }
    cand_start_close_[i] = cand_start_[i].distance < settings_.thickness && !pairs_.redundant_on_flat_face(c, cand_start_[i], corner);
  };
  const Bounds::List visited =
      carried ? for_candidates(&lin_bounds_, motion, settings_.thickness, visit) : for_candidates(nullptr, 0.0, 0.0, visit);
  start_close_ = flagged_among(visited, cand_start_close_);
  start_bounds_.make_close(close_reaches());
}

// Candidate i's geometry at the start of the step (computed once per step; each i by one thread).
const PairGeometry& BarrierPotential::start_geometry(const StepPositions& step, size_t i) {
  if (!cand_start_known_[i]) {
    cand_start_[i] = pairs_.geometry(cands_[i], pairs_.corners(cands_[i], step.p0, step.o0));
    cand_start_known_[i] = 1;
  }
  return cand_start_[i];
}

// Of the flagged cloth-point–obstacle-triangle candidates, keeps (flagged) the closest triangle
// per point and obstacle.
void BarrierPotential::keep_closest(const StepPositions& step, std::vector<char>& flagged,
                                    const std::vector<PairGeometry>& geometry_of, std::vector<size_t>& which) {
  const size_t num_obstacles = obstacles_.size();
  closest_.resize(static_cast<size_t>(step.p0.rows()) * num_obstacles, 0);
  for (size_t i : which) {
    const Candidate& c = cands_[i];
    if (!flagged[i] || c.kind != Kind::cloth_point_obstacle_triangle) continue;
    const int obstacle = obs_.obstacle_of_vertex[static_cast<size_t>(obs_.triangles[static_cast<size_t>(c.b)][0])];
    const size_t key = static_cast<size_t>(c.a) * num_obstacles + static_cast<size_t>(obstacle);
    if (closest_[key] == 0) {
      closest_[key] = i + 1;
      closest_set_.push_back(key);
      continue;
    }
    const size_t best = closest_[key] - 1;
    if (geometry_of[i].distance < geometry_of[best].distance) {
      flagged[best] = 0;
      closest_[key] = i + 1;
    } else {
      flagged[i] = 0;
    }
  }
  for (size_t key : closest_set_) closest_[key] = 0;
  closest_set_.clear();
  which.erase(std::remove_if(which.begin(), which.end(), [&](size_t i) { return !flagged[i]; }), which.end());
}

// --- Distance bounds ---------------------------------------------------------------------------
// Lower bounds of the candidates' distances at a reference configuration, so that a pair whose
// points have moved less than its bound allows is known to be apart without looking at it: the
// step's start (p0 and the obstacles at t: start_bounds_), or the end points of the last
// linearisation (obstacles at t + h: lin_bounds_). Most candidates of a resting or slowly moving
// cloth are decided this way in each linearisation and each step bound; while every pair moves
// less than a quarter of the thickness from the reference, only the candidates whose bound is
// within 1.25 thicknesses (close_reach: Bounds::close) are visited at all.

// The barrier's reach for a near pair (parts near each other at rest, which CCD alone keeps from
// crossing): half the pair's distance at rest, at most the thickness, so that it exerts nothing
// at rest or anywhere the pair keeps half its rest distance, and resists a fold that presses
// neighbouring parts into each other (without it such a pair stops Newton only by cutting its
// steps: the crushed sleeve took 12 solves per step, each cut by an edge pair at 0.2 µm that had
// been 2 mm apart at rest). Computed once per candidate list, when first needed (each index by
// one thread).
double BarrierPotential::near_reach(size_t i) {
  double& r = near_reach_of_[i];
  if (r < 0.0) {
    const Candidate& c = cands_[i];
    r = std::min(settings_.thickness, 0.5 * pairs_.geometry(c, pairs_.corners(c, surf_.rest_points(), surf_.rest_points())).distance);
  }
  return r;
}

// Calls visit(i), in parallel, for every candidate, or only for the close ones of `bounds` when no
// pair can move from its bound to below `threshold` with moves of at most `motion` [m].
template <class Visit>
Bounds::List BarrierPotential::for_candidates(const Bounds* bounds, double motion, double threshold, Visit visit) {
  const Bounds::List list = bounds != nullptr ? bounds->within(threshold, motion) : Bounds::List{};
  const size_t n = !list.all ? list.size : cands_.size();
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t j = range.begin(); j != range.end(); ++j) visit(!list.all ? list[j] : j);
  });
  return list;
}

// The candidates of `visited` (all where it says so) that are flagged, in increasing order.
std::vector<size_t> BarrierPotential::flagged_among(const Bounds::List& visited, const std::vector<char>& flagged) const {
  std::vector<size_t> out;
  if (visited.all) {
    for (size_t i = 0; i < flagged.size(); ++i)
      if (flagged[i]) out.push_back(i);
    return out;
  }
  for (size_t j = 0; j < visited.size; ++j)
    if (flagged[visited[j]]) out.push_back(visited[j]);
  std::sort(out.begin(), out.end());
  return out;
}

// The reaches of the bounds' lists: the barrier's (the thickness) and the step bound's (the
// largest separation) each with a twentieth of the thickness to spare, and close_reach().
std::vector<double> BarrierPotential::close_reaches() const {
  const double dhat = settings_.thickness;
  const double separation = std::max(settings_.min_separation_ratio, settings_.near_separation_ratio) * dhat;
  return {separation + 0.05 * dhat, 1.05 * dhat, close_reach()};
}

// Fills point_move_ with each point's largest distance from the reference; the obstacles' move is
// 0 where the reference is the last linearisation and the obstacles stand at the end of the step.
ReferenceBounds BarrierPotential::reference_bounds(const StepPositions& step, const Eigen::MatrixX3d& points,
                                                   const Eigen::MatrixX3d* other, bool whole_step, const Eigen::VectorXd* moves) {
  const bool lin = lin_bounds_valid_;
  const Eigen::MatrixX3d& ref = lin ? lin_points_ : step.p0;
  if (moves != nullptr) {
    point_move_ = *moves;
  } else {
    point_move_ = (points - ref).rowwise().norm();
    if (other != nullptr) point_move_ = point_move_.cwiseMax((*other - ref).rowwise().norm());
  }
  const double obstacle = (lin && !whole_step) || step.o0.rows() == 0 ? 0.0 : (step.o1 - step.o0).rowwise().norm().maxCoeff();
  const double largest = point_move_.size() > 0 ? point_move_.maxCoeff() : 0.0;
  const double motion = std::max(2.0 * largest, largest + obstacle);
  return ReferenceBounds{lin ? lin_bounds_ : start_bounds_, point_move_, obstacle, motion};
}

// --- The step ----------------------------------------------------------------------------------
bool BarrierPotential::in_step(const Eigen::VectorXd& x, double t, double h) const {
  return step_start_ == std::pair{t, h} && x.size() == x_.size() && x == x_;
}

const Eigen::MatrixX3d* BarrierPotential::end_points(const Eigen::VectorXd& v) const {
  return v.size() == p1_velocity_.size() && v == p1_velocity_ ? &p1_ : nullptr;
}

double BarrierPotential::velocity_tolerance(double h) const {
  // collision.tolerance's velocity: a Newton step that moves no point by more than that fraction
  // of the thickness (docs/contact.md), measured on the step Newton solved for (before, 1 % of it,
  // estimated from the gradient through the preconditioner). On the T-shirt drop's landing ten
  // times this tolerance took 268 Newton solves against 303, the final energies the same to 1e-5.
  return settings_.tolerance * settings_.thickness / h;
}

void BarrierPotential::begin_step(StepPositions& step, const Eigen::VectorXd& x, const Eigen::VectorXd& v_guess, double t,
                                  double h, const Eigen::VectorXd& diagonal) {
  t_ = t;
  h_ = h;
  x_ = x;
  step_start_ = {t, h};
  p1_ = end_points_of(step, v_guess);
  p1_velocity_ = v_guess;
  // (The surface points' effective masses are made when a pair needs them: mass_of_point.)
  const int num_nodes = static_cast<int>(surf_.jacobian().cols() / 3);
  node_scale_.resize(num_nodes);
  for (int k = 0; k < num_nodes; ++k) node_scale_(k) = diagonal.segment<3>(3 * k).sum() / 3.0;
  point_mass_.setConstant(step.p0.rows(), std::numeric_limits<double>::quiet_NaN());
  check_obstacles_serve(step);
  served_known_ = false;  // (a new start)
  double start_sweep = 0.0, guess_sweep = 0.0;
  if (serves(step.p0, p1_, start_sweep, guess_sweep)) {
    const auto t0 = std::chrono::steady_clock::now();
    prepare_candidates(step);
    candidates_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  } else {
    make_candidates(step);  // (for the path from p0 through p1: both on it)
    start_sweep = guess_sweep = 0.0;
  }
  // (Either way the candidates serve the guess's end points: the first linearisation, which is
  // usually at the guess, need not check them again.)
  served_velocity_ = v_guess;
  served_known_ = true;
  served_sweep_ = guess_sweep;
  start_sweep_ = start_sweep;
  // Lagged friction: the pairs pressed at the start of the step, with their normal force and
  // tangent plane there (fixed over the step, so the friction potential is convex in v).
  friction_rows_.clear();
  keep_closest(step, cand_start_close_, cand_start_, start_close_);
  for (size_t i : start_close_) {
    const CubicBarrier barrier{settings_.thickness, pair_stiffness(cands_[i])};
    const PairGeometry& g = cand_start_[i];
    add_friction_row(g.normal, pair_friction(g), obstacle_side_velocity(step, g), -barrier.first(g.distance),
                     [&] { return pair_row(g); });
  }
  for (int k : obs_.planes) {
    const Obstacle& o = obstacles_[static_cast<size_t>(k)];
    Eigen::Vector3d q0, n0;
    plane_at(o, t, q0, n0);
    const RigidMap move = obstacle_step_map(o, t, h_);
    for (Eigen::Index p = 0; p < step.p0.rows(); ++p) {
      const Eigen::Vector3d a = step.p0.row(p).transpose();
      const double dist = n0.dot(a - q0);
      if (!(dist < settings_.thickness)) continue;
      const CubicBarrier barrier{settings_.thickness, plane_stiffness(static_cast<int>(p))};
      add_friction_row(n0, o.friction, -(move(a) - a) / h_, -barrier.first(dist), [&] { return point_row(static_cast<int>(p)); });
    }
  }
}

// A lagged friction row for a pair with normal n, friction coefficient mu, the obstacle side's
// velocity and normal force lambda [N]; `row` makes the pair's row (only when it is needed).
template <class MakeRow>
void BarrierPotential::add_friction_row(const Eigen::Vector3d& normal, double mu, const Eigen::Vector3d& obstacle_velocity,
                                        double lambda, MakeRow row) {
  if (!(mu > 0) || !(lambda > 0)) return;
  FrictionRow f;
  f.row = row();
  f.constant = obstacle_velocity;
  f.tangent -= normal * normal.transpose();
  f.bound = mu * lambda;
  friction_rows_.push_back(std::move(f));
}

void BarrierPotential::linearise(StepPositions& step, const Eigen::VectorXd& v, PotentialLinearisation& out) {
  const Eigen::Index n3 = v.size();
  out.blocks.clear();
  out.energy = out.dissipation = 0.0;
  out.active = 0;
  out.energy_gradient.setZero(n3);
  out.dissipation_gradient.setZero(n3);
  // (At the last step bound's end of the move, Newton's next iterate, from the linearisation
  // that is still the reference: its points and their moves are known.)
  const bool at_bound = v.size() == bound_to_velocity_.size() && v == bound_to_velocity_;
  const bool moves_known = at_bound && bound_move_lin_ == lin_serial_;
  if (!(v.size() == p1_velocity_.size() && v == p1_velocity_)) {
    if (at_bound) {
      std::swap(p1_, bound_to_points_);
      bound_to_velocity_.resize(0);  // (its points are p1_ now)
    } else {
      p1_ = end_points_of(step, v);
    }
    p1_velocity_ = v;
  }
  // Candidates made for other end points serve while no point is more than half the thickness
  // from the path they were made for (their boxes are grown by twice the thickness).
  if (!served(v, p1_)) make_candidates(step);
  const double dhat = settings_.thickness;
  // A pair whose distance at the reference (the start, or the last linearisation) exceeds the
  // thickness by more than its points have moved since cannot be within it now (most candidates
  // of a slow or resting cloth); the bound each candidate gets here serves the next call.
  const ReferenceBounds reference =
      reference_bounds(step, p1_, nullptr, false, moves_known && lin_bounds_valid_ ? &bound_move_ : nullptr);
  const Bounds& bounds = reference.bounds;
  const double obstacle_motion = reference.obstacle_motion, motion = reference.motion;
  // (The candidates not visited keep their bound less the largest motion.)
  Bounds next;
  next.lower = bounds.less(motion);
  std::vector<char> active(cands_.size(), 0);
  end_geometry_.resize(cands_.size());
  end_known_.assign(cands_.size(), 0);
  std::vector<PairGeometry>& end = end_geometry_;
  const Bounds::List visited = for_candidates(&bounds, motion, dhat, [&](size_t i) {
    const Candidate& c = cands_[i];
    if (bounds.lower[i] - motion >= dhat) return;  // (without the pair's own motion, below)
    const double bound = bounds.lower[i] - pairs_.motion(c, point_move_, obstacle_motion);
    next.lower[i] = std::max(0.0, bound);
    if (bound >= dhat) return;
    const Corners corner = pairs_.corners(c, p1_, step.o1);
    const double gap = box_gap(corner, is_point_triangle(c.kind));
    next.lower[i] = std::max(next.lower[i], gap);
    const double reach = c.near ? near_reach(i) : dhat;
    if (gap > reach) return;  // (most candidates: no exact distance)
    end[i] = pairs_.geometry(c, corner);
    end_known_[i] = 1;
    next.lower[i] = std::max(next.lower[i], end[i].distance);
    if (pairs_.redundant_on_flat_face(c, end[i], corner)) return;
    if (end[i].distance < reach) sign_by_start(start_geometry(step, i), end[i], is_point_triangle(c.kind));
    active[i] = end[i].distance < reach;
  });
  // (Before the bounds the visited list refers to are replaced.)
  std::vector<size_t> active_list = flagged_among(visited, active);
  next.make_close(close_reaches());
  lin_bounds_ = std::move(next);
  lin_points_ = p1_;
  ++lin_serial_;
  lin_velocity_ = v;
  lin_time_ = t_ + h_;
  if (settings_.obstacles_static) {
    lin_o1_.resize(step.o1.rows(), 3);  // (only its size is read: o1 is the same every step)
  } else {
    lin_o1_ = step.o1;
  }
  lin_bounds_valid_ = true;
  out.point_map = surf_.point_map();
  auto add_pair = [&](const Row& row, const Eigen::Vector3d& normal, double distance, double k, double reach) {
    const CubicBarrier barrier{reach, k};
    out.energy += barrier.value(distance);
    PotentialLinearisation::Block block;
    row.put_in(block);
    row.scatter(surf_, barrier.first(distance) * normal, out.energy_gradient);
    block.hessian = barrier.second(distance) * normal * normal.transpose();
    out.blocks.push_back(std::move(block));
    ++out.active;
  };
  // A cloth point against an obstacle keeps its closest triangle only: the barrier is of the
  // point's distance to the obstacle, the smallest over its triangles (one pair where a point over
  // a face has several triangles within the thickness, and none of them twice).
  keep_closest(step, active, end, active_list);
  if (const PointMap* map = surf_.point_map()) {
    // Rows on points: the pairs' blocks are made in parallel, their energies and gradients summed
    // in the pairs' order (bit for bit a serial pass; the crushed sleeve's 1,500 pairs took a
    // third of its linearisations serially). The stiffnesses first: the points' effective masses
    // are made on first use, by one thread.
    const size_t n = active_list.size(), first = out.blocks.size();
    pair_k_.resize(n);
    for (size_t j = 0; j < n; ++j) pair_k_[j] = pair_stiffness(cands_[active_list[j]]);
    pair_energy_.resize(n);
    pair_force_.resize(n);
    out.blocks.resize(first + n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 64), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t j = range.begin(); j != range.end(); ++j) {
        const size_t i = active_list[j];
        const PairGeometry& g = end[i];
        const CubicBarrier barrier{cands_[i].near ? near_reach(i) : dhat, pair_k_[j]};
        pair_energy_[j] = barrier.value(g.distance);
        pair_force_[j] = barrier.first(g.distance) * g.normal;
        PotentialLinearisation::Block& block = out.blocks[first + j];
        block.on_points = surf_.pair_points(g);
        block.hessian = barrier.second(g.distance) * g.normal * g.normal.transpose();
      }
    });
    for (size_t j = 0; j < n; ++j) {
      out.energy += pair_energy_[j];
      out.blocks[first + j].on_points.scatter(*map, pair_force_[j], out.energy_gradient);
    }
    out.active += static_cast<int>(n);
  } else {
    for (size_t i : active_list)
      add_pair(pair_row(end[i]), end[i].normal, end[i].distance, pair_stiffness(cands_[i]), cands_[i].near ? near_reach(i) : dhat);
  }
  for (int k : obs_.planes) {
    Eigen::Vector3d q1, n1;
    plane_at(obstacles_[static_cast<size_t>(k)], t_ + h_, q1, n1);
    for (Eigen::Index p = 0; p < p1_.rows(); ++p) {
      const double dist = n1.dot(p1_.row(p).transpose() - q1);
      if (dist < dhat) add_pair(point_row(static_cast<int>(p)), n1, dist, plane_stiffness(static_cast<int>(p)), dhat);
    }
  }
  const SmoothedFriction friction{friction_epsilon()};
  for (const FrictionRow& f : friction_rows_) {
    const Eigen::Vector3d w = f.tangent * (f.row.apply(surf_, v) + f.constant);
    out.dissipation += f.bound * friction.f0(w.norm());
    f.row.scatter(surf_, friction.gradient(w, f.bound), out.dissipation_gradient);
    PotentialLinearisation::Block block;
    f.row.put_in(block);
    block.hessian = friction.hessian(w, f.tangent, f.bound);
    block.dissipative = true;
    out.blocks.push_back(std::move(block));
  }
}

double BarrierPotential::step_bound(StepPositions& step, const Eigen::VectorXd& from, const Eigen::VectorXd& to) {
  const bool at_linearisation = lin_bounds_valid_ && from.size() == lin_velocity_.size() && from == lin_velocity_;
  // (End points known already are not made again: the last linearisation's, or those of the
  // velocities the step began with.)
  auto points_of = [&](const Eigen::VectorXd& w) {
    if (const Eigen::MatrixX3d* known = end_points(w)) return Eigen::MatrixX3d(*known);
    return end_points_of(step, w);
  };
  // (Velocities zero, as where Newton's start is checked from the held start with nothing
  // prescribed, end where the step starts: p0 + h J 0 = p0.)
  const bool from_start = !at_linearisation && from.size() == x_.size() && (from.array() == 0.0).all();
  // (References, not copies: the move's start is the last linearisation's or the step's, and its
  // end is kept as bound_to_points_ for the next linearisation.)
  Eigen::MatrixX3d pa_own;
  const Eigen::MatrixX3d& pa = at_linearisation ? lin_points_ : from_start ? step.p0 : (pa_own = points_of(from));
  if (const Eigen::MatrixX3d* known = end_points(to)) {
    bound_to_points_ = *known;
  } else {
    bound_to_points_ = end_points_of(step, to);
  }
  const Eigen::MatrixX3d& pb = bound_to_points_;
  bound_to_velocity_ = to;
  bound_move_ = (pb - pa).rowwise().norm();  // per point, over the move
  const Eigen::VectorXd& step_move = bound_move_;
  // (From the linearisation that is the reference, these are the moves from it: pa is lin_points_.)
  bound_move_lin_ = at_linearisation ? lin_serial_ : -1;
  // Candidates for the move pa → pb: the potential's where they serve it, else a broad phase over
  // this move. (pb is served when pa's sweep bound plus the largest point move is within the
  // serve radius: no pass over the points.)
  bool move_served = from_start && start_sweep_ >= 0.0 ? obstacles_serve_ && start_sweep_ <= serve_radius() : served(from, pa);
  if (move_served) {
    const double bound = (from_start && start_sweep_ >= 0.0 ? start_sweep_ : served_sweep_) + (step_move.size() > 0 ? step_move.maxCoeff() : 0.0);
    if (bound <= serve_radius()) {
      served_velocity_ = to;
      served_known_ = true;
      served_sweep_ = bound;
    } else {
      move_served = served(to, pb);
    }
  }
  const std::vector<Candidate>* cands = &cands_;
  std::vector<Candidate> own;
  if (!move_served) {
    // (This broad phase over the move is the line search's cost, not booked as candidates_ms_.)
    ContactCounters scratch;
    own = search_.find(pa, pb, step.o0, step.o1, step.obstacle_boxes_current, settings_.thickness, scratch);
    cands = &own;
  }
  // The obstacles stand where they are at the end of the step at both ends of the move.
  auto corner = [&](const Candidate& c, const Eigen::MatrixX3d& p) {
    const std::array<int, 4> cloth = pairs_.cloth_points(c);
    Corners x = pairs_.corners(c, p1_, step.o1);  // (obstacle points at t + h)
    // corners() puts the cloth points first for every kind but obstacle point–cloth triangle.
    if (c.kind == Kind::obstacle_point_cloth_triangle) {
      for (int k = 0; k < 3; ++k) x[static_cast<size_t>(k + 1)] = p.row(cloth[static_cast<size_t>(k)]).transpose();
    } else {
      for (size_t k = 0; k < 4; ++k)
        if (cloth[k] >= 0) x[k] = p.row(cloth[k]).transpose();
    }
    return x;
  };
  const double eta = settings_.min_separation_ratio * settings_.thickness;
  const double near_eta = settings_.near_separation_ratio * settings_.thickness;
  // With the potential's candidates, a pair whose distance bound at the reference exceeds the
  // separation by more than its points move (to either end of the move) is skipped.
  std::optional<ReferenceBounds> reference;
  if (cands == &cands_) reference.emplace(reference_bounds(step, pa, &pb, false, at_linearisation ? &bound_move_ : nullptr));
  const double obstacle_motion = reference ? reference->obstacle_motion : 0.0;
  const std::vector<double>* lower = reference ? &reference->bounds.lower : nullptr;
  // (Hits are rare: the smallest fraction is kept under a lock rather than per candidate.)
  double alpha = 1.0;
  std::mutex alpha_mutex;
  auto visit = [&](size_t i) {
    const Candidate& c = (*cands)[i];
    double separation = c.near ? near_eta : eta;
    if (lower != nullptr && ((*lower)[i] - reference->motion > separation ||
                             (*lower)[i] - pairs_.motion(c, point_move_, obstacle_motion) > separation))
      return;
    const Corners a = corner(c, pa), b = corner(c, pb);
    const bool pt = is_point_triangle(c.kind);
    // A quick reject: the boxes of the swept primitives farther apart than the separation.
    Corners lo, hi;
    for (size_t k = 0; k < 4; ++k) {
      lo[k] = a[k].cwiseMin(b[k]);
      hi[k] = a[k].cwiseMax(b[k]);
    }
    const size_t split = pt ? 1 : 2;  // the first primitive's corners, then the second's
    Eigen::Vector3d la = lo[0], ha = hi[0], lb = lo[split], hb = hi[split];
    for (size_t k = 1; k < split; ++k) {
      la = la.cwiseMin(lo[k]);
      ha = ha.cwiseMax(hi[k]);
    }
    for (size_t k = split + 1; k < 4; ++k) {
      lb = lb.cwiseMin(lo[k]);
      hb = hb.cwiseMax(hi[k]);
    }
    if (!(((la.array() - separation) <= hb.array()).all() && ((lb.array() - separation) <= ha.array()).all())) return;
    const double start_distance = pairs_.geometry(c, a).distance;
    if (!(start_distance > 0)) return;  // (touching already: nothing to bound)
    separation = std::min(separation, 0.5 * start_distance);
    // (A pair that does not move enough to lose what it has above the separation: most pairs
    // resting in contact between two Newton iterates.)
    if (start_distance - pairs_.motion(c, step_move, 0.0) > separation) return;
    const CcdResult r = pt ? point_triangle_ccd(a, b, separation) : edge_edge_ccd(a, b, separation);
    if (r.hit) {
      const std::lock_guard<std::mutex> lock(alpha_mutex);
      alpha = std::min(alpha, r.toi);
    }
  };
  if (reference) {
    for_candidates(&reference->bounds, reference->motion, std::max(eta, near_eta), visit);
  } else {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, cands->size(), 256), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i != range.end(); ++i) visit(i);
    });
  }
  for (int k : obs_.planes) {
    Eigen::Vector3d q1, n1;
    plane_at(obstacles_[static_cast<size_t>(k)], t_ + h_, q1, n1);
    for (Eigen::Index p = 0; p < pa.rows(); ++p) {
      const double da = n1.dot(pa.row(p).transpose() - q1), db = n1.dot(pb.row(p).transpose() - q1);
      if (!(da > 0) || db >= std::min(eta, 0.5 * da)) continue;
      const double separation = std::min(eta, 0.5 * da);
      alpha = std::min(alpha, (da - separation) / (da - db));
    }
  }
  return std::max(0.0, alpha);
}

}  // namespace clothsim::contact

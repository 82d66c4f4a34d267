#include "sim/contact/contact_stage.hpp"

#include "sim/contact/barrier.hpp"
#include "sim/contact/candidates.hpp"
#include "sim/contact/collision_surface.hpp"
#include "sim/contact/fail_safe.hpp"
#include "sim/contact/impact_zones.hpp"
#include "sim/contact/narrow_phase.hpp"
#include "sim/contact/obstacle_set.hpp"
#include "sim/contact/pair_geometry.hpp"
#include "sim/contact/pair_types.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>

namespace clothsim {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

using contact::box_gap;
using contact::Bounds;
using contact::Candidate;
using contact::Constraint;
using contact::Found;
using contact::key_of;
using contact::is_point_triangle;
using contact::Kind;
using contact::PairGeometry;
using contact::RigidMap;
using contact::sign_by_start;
using contact::Zones;

}  // namespace

struct ContactStage::Impl {
  const Discretization& d;
  CollisionSettings settings;
  ContactParameters params;
  std::vector<Obstacle> obstacles;

  contact::CollisionSurface surf;  // the collision surface (sim/contact/collision_surface.hpp)
  std::vector<char> free;
  Eigen::VectorXd node_mass;

  contact::ObstacleSet obs;  // the obstacles' meshes, combined (planes apart)
  contact::PairPrimitives pairs;  // the pairs' geometry over the surface and obs (sim/contact/pair_geometry.hpp)

  long long joined_pairs = 0;  // pairs of fine triangles joined at rest (CollisionSurface::find_near_at_rest)
  std::optional<contact::CandidateSearch> search;  // (made last in the constructor)

  // Per step.
  Eigen::MatrixX3d p0, p1;          // surface points at the start and end of the step
  bool obstacle_boxes_current = false;  // the search's obstacle boxes are those of o0 and o1
  Eigen::MatrixX3d o0, o1;          // obstacle vertices at t and t + h
  // No meshed obstacle moves: o0 = o1 and their boxes are the same every step (set at build).
  bool obstacles_static = false;
  double h = 0.0;

  // The parameters, once the settings read before the collision surface is built are checked.
  static const ContactParameters& checked(const CollisionSettings& settings, const ContactParameters& params) {
    if (!(settings.thickness > 0)) throw std::invalid_argument("collision: the thickness must be > 0 [m]");
    if (!(settings.friction >= 0)) throw std::invalid_argument("collision: the friction coefficient must be >= 0");
    if (!(settings.tolerance > 0 && settings.tolerance <= 0.1))
      throw std::invalid_argument("collision: the tolerance must be > 0 and at most 0.1");
    if (params.surface_level < 0) throw std::invalid_argument("collision: the surface level must be >= 0");
    return params;
  }

  Impl(const Discretization& disc, const Eigen::VectorXd& mass, const std::vector<char>& free_dofs,
       const CollisionSettings& s, std::vector<Obstacle> obstacle_list, const ContactParameters& p)
      : d(disc),
        settings(s),
        params(checked(s, p)),
        obstacles(std::move(obstacle_list)),
        surf(disc, params.surface_level),
        free(free_dofs),
        node_mass(mass),
        pairs(surf.triangles(), surf.edges(), obs) {
    const int n3 = 3 * d.num_nodes();
    if (static_cast<int>(free.size()) != n3 || node_mass.size() != d.num_nodes())
      throw std::invalid_argument("ContactStage: the masses and the free-DOF mask must cover every node");
    std::vector<std::vector<int>> near_at_rest, joined_at_rest;
    if (settings.self)
      joined_pairs = surf.find_near_at_rest(2.0 * settings.thickness, params.near_separation_ratio * settings.thickness,
                                            d.control_triangles(), near_at_rest, joined_at_rest);
    if (!(settings.flat_region_angle >= 0 && settings.flat_region_angle < 0.5 * M_PI))
      throw std::invalid_argument("collision: the flat-region angle must be >= 0 and < pi/2 [rad]");

    obs = contact::ObstacleSet(obstacles);
    obstacles_static = std::all_of(obstacles.begin(), obstacles.end(),
                                   [](const Obstacle& o) { return o.shape == Obstacle::Shape::plane || o.motion.empty(); });
    contact::CandidateSettings search_settings;
    search_settings.self = settings.self;
    search_settings.thickness = settings.thickness;
    search_settings.flat_region_angle = settings.flat_region_angle;
    search_settings.min_separation_ratio = params.min_separation_ratio;
    search_settings.near_separation_ratio = params.near_separation_ratio;
    search.emplace(contact::SearchSurface{surf.triangles(), surf.op().levels, surf.edges(), surf.triangle_edges(),
                                          surf.owned_points(), surf.owned_edges(), d.control_triangles(), d.num_nodes()},
                   std::move(near_at_rest), std::move(joined_at_rest), obs, search_settings);
  }

  // --- Positions -------------------------------------------------------------------------------
  bool end_points_current = false;  // p1 matches the velocities (no impulse since it was computed)

  void update_end_points(const Eigen::VectorXd& v) {
    if (end_points_current) return;
    end_points_current = true;
    p1 = end_points_of(v);
  }

  // The end points p0 + h J v (#P × 3) for velocities v.
  Eigen::MatrixX3d end_points_of(const Eigen::VectorXd& v) const { return surf.end_points(p0, h, v); }

  // --- Broad phase ----------------------------------------------------------------------------
  // The candidates of the motion p0 → p1 (and the obstacles' o0 → o1) with boxes grown by `grow`
  // [m] (sim/contact/candidates.hpp); the search keeps the obstacles' boxes until start_positions
  // moves the obstacles.
  std::vector<Candidate> candidates(ContactReport& report, double grow) {
    std::vector<Candidate> out = search->find(p0, p1, o0, o1, obstacle_boxes_current, grow, report);
    obstacle_boxes_current = true;
    return out;
  }

  // --- Pair geometry ---------------------------------------------------------------------------
  // The four points of a pair at the start (τ = 0) or end (τ = 1) of the step.
  std::array<Eigen::Vector3d, 4> corners(const Candidate& c, bool end) const {
    return end ? pairs.corners(c, p1, o1) : pairs.corners(c, p0, o0);
  }

  // The constraint of a pair's geometry: B over the DOFs through J, the obstacle side's velocity.
  Constraint constraint(const PairGeometry& g) {
    Constraint c;
    c.normal = g.normal;
    c.obstacle = pairs.obstacle_of(g);
    c.mu = c.obstacle >= 0 ? obstacles[static_cast<size_t>(c.obstacle)].friction : settings.friction;
    for (int k = 0; k < g.num; ++k) {
      const double coef = g.coef[static_cast<size_t>(k)];
      const int p = g.point[static_cast<size_t>(k)];
      if (coef == 0.0) continue;
      if (g.obstacle[static_cast<size_t>(k)]) c.obstacle_velocity += coef * (o1.row(p) - o0.row(p)).transpose() / h;
    }
    c.b = surf.rows(g);
    return c;
  }

  // --- Narrow phase ------------------------------------------------------------------------------
  // The pairs to respond to (contact::Found) come from proximity at the start of the step and from
  // continuous collision detection over it; the response and the impact zones are sim/contact/fail_safe.hpp's.

  // Planes: every surface point against every plane, at the start of the step (or, for
  // `end`, at its end: a plane that only translates has a distance linear in τ, so a point in
  // front at both ends is in front throughout).
  void plane_pairs(double t, bool end, double limit, std::vector<Found>& out, ContactReport& report) {
    for (int k : obs.planes) {
      const Obstacle& o = obstacles[static_cast<size_t>(k)];
      Eigen::Vector3d q0, n0, q1, n1;
      plane_at(o, t, q0, n0);
      plane_at(o, t + h, q1, n1);
      const RigidMap move = contact::obstacle_step_map(o, t, h);
      for (Eigen::Index p = 0; p < p0.rows(); ++p) {
        ++report.pairs_tested;
        const Eigen::Vector3d a = p0.row(p).transpose();
        const double d0 = n0.dot(a - q0);
        const double dist = end ? n1.dot(p1.row(p).transpose() - q1) : d0;
        if (dist >= limit) continue;
        PairGeometry g;
        g.num = 1;
        g.point[0] = static_cast<int>(p);
        g.coef[0] = 1.0;
        g.normal = n0;
        g.distance = d0;
        Found f{constraint(g), d0, limit, contact::ConstraintKey{static_cast<std::uint8_t>(end ? 1 : 0), 255, k, static_cast<int>(p)}};
        f.constraint.obstacle = k;
        f.constraint.mu = o.friction;
        f.constraint.obstacle_velocity = -(move(a) - a) / h;  // minus the plane's velocity at the point
        out.push_back(std::move(f));
      }
    }
  }

  // Pairs closer than the thickness at the start of the step.
  std::vector<Found> proximity(const std::vector<Candidate>& cands, double t, ContactReport& report) {
    const auto t0 = Clock::now();
    std::vector<Found> out;
    std::vector<char> close(cands.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, cands.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t i = range.begin(); i != range.end(); ++i)
        if (!cands[i].near) {  // neighbours in the material: only kept from crossing (collisions)
          const std::array<Eigen::Vector3d, 4> x = corners(cands[i], false);
          const PairGeometry g = pairs.geometry(cands[i], x);
          close[i] = g.distance < settings.thickness && !pairs.redundant_on_flat_face(cands[i], g, x);
        }
    });
    for (size_t i = 0; i < cands.size(); ++i) {
      if (!cands[i].near) ++report.pairs_tested;
      if (!close[i]) continue;
      const PairGeometry g = pairs.geometry(cands[i], corners(cands[i], false));
      out.push_back({constraint(g), g.distance, 0.0, key_of(cands[i], 0)});
    }
    plane_pairs(t, /*end=*/false, settings.thickness, out, report);
    report.narrow_ms += ms_since(t0);
    return out;
  }
  // Pairs whose distance may fall below the minimum separation during the step (CCD), with their
  // geometry at the (conservative) time of impact. With `moved` (per surface point: its end
  // position changed since the last test) and `last` (the pairs that collided then, sorted), only
  // pairs with a moved point or a previous collision are tested again: the others have the same
  // positions, so the same (negative) answer. With `bounds` (the potential's candidates' distance
  // bounds at a reference, from reference_bounds, which fills point_move and gives `motion`),
  // pairs that cannot come within the separation are not tested.
  std::vector<Found> collisions(const std::vector<Candidate>& cands, double t, ContactReport& report,
                                const std::vector<char>* moved = nullptr, const std::vector<Candidate>* last = nullptr,
                                std::vector<Candidate>* hit_pairs = nullptr, const Bounds* bounds = nullptr,
                                double obstacle_motion = 0.0, double motion = 0.0) {
    const auto t0 = Clock::now();
    const double eta = params.min_separation_ratio * settings.thickness;
    std::vector<Found> out;
    if (hit_pairs) hit_pairs->clear();
    // The CCD of every pair in parallel (each pair alone), then the hits in the pairs' order.
    std::vector<double> toi(cands.size(), -1.0);  // −1: not tested or no hit
    std::atomic<long long> tested{0};
    const std::vector<double>* lower = bounds != nullptr ? &bounds->lower : nullptr;
    const bool close_only = bounds != nullptr && bounds->reach - motion >= std::max(eta, params.near_separation_ratio * settings.thickness);
    const size_t n = close_only ? bounds->close.size() : cands.size();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& range) {
      long long count = 0;
      for (size_t j = range.begin(); j != range.end(); ++j) {
        const size_t i = close_only ? bounds->close[j] : j;
        const Candidate& c = cands[i];
        const double separation = c.near ? params.near_separation_ratio * settings.thickness : eta;
        if (lower != nullptr && (*lower)[i] - pairs.motion(c, point_move, obstacle_motion) > separation) continue;
        if (moved != nullptr) {
          bool any = false;
          for (int p : pairs.cloth_points(c)) any = any || (p >= 0 && (*moved)[static_cast<size_t>(p)]);
          if (!any && !std::binary_search(last->begin(), last->end(), c)) continue;
        }
        ++count;
        const std::array<Eigen::Vector3d, 4> a = corners(c, false), b = corners(c, true);
        const contact::CcdResult r = is_point_triangle(c.kind) ? contact::point_triangle_ccd(a, b, separation)
                                                               : contact::edge_edge_ccd(a, b, separation);
        if (r.hit) toi[i] = r.toi;
      }
      tested += count;
    });
    report.pairs_tested += tested.load();
    for (size_t i = 0; i < cands.size(); ++i) {
      if (toi[i] < 0) continue;
      const Candidate& c = cands[i];
      const std::array<Eigen::Vector3d, 4> a = corners(c, false), b = corners(c, true);
      const double separation = c.near ? params.near_separation_ratio * settings.thickness : eta;
      std::array<Eigen::Vector3d, 4> x;
      for (size_t k = 0; k < 4; ++k) x[k] = a[k] + toi[i] * (b[k] - a[k]);
      const PairGeometry g = pairs.geometry(c, x);
      if (pairs.redundant_on_flat_face(c, g, x)) continue;
      out.push_back({constraint(g), g.distance, separation, key_of(c, 1)});
      if (hit_pairs) hit_pairs->push_back(c);
    }
    if (hit_pairs) std::sort(hit_pairs->begin(), hit_pairs->end());
    plane_pairs(t, /*end=*/true, eta, out, report);
    report.narrow_ms += ms_since(t0);
    return out;
  }

  // --- Response (sim/contact/fail_safe.hpp) ----------------------------------------------------
  // The implicit response on the constraints `found` from the solve's velocities `base`, v in
  // place (the end points no longer match v).
  void implicit_response(std::vector<Found>& found, const Eigen::VectorXd& base, Eigen::VectorXd& v, ContactReport& report) {
    end_points_current = false;
    response.solve(found, base, v, *system, system_diagonal, free, settings.tolerance * settings.thickness / h, surf, report);
  }

  // --- The potential inside the step (docs/contact.md, "Contact inside the step") ---------------
  bool potential_on = false;
  double potential_t = 0.0;
  std::vector<Candidate> potential_cands;   // this step's candidates (boxes grown by 2 d̂)
  Eigen::MatrixX3d potential_guess;         // the end points they were made for
  // A row of the potential: on the surface's points where J's rows are in node form (so the
  // integrator applies it without merging the points' stencils), else over the DOFs.
  struct Row {
    PointRow points;
    NodeRow dofs;
    Eigen::Vector3d apply(const contact::CollisionSurface& surf, const Eigen::VectorXd& v) const {
      return points.count > 0 ? points.apply(*surf.point_map(), v) : dofs.apply(v);
    }
    void scatter(const contact::CollisionSurface& surf, const Eigen::Vector3d& f, Eigen::VectorXd& y) const {
      if (points.count > 0) {
        points.scatter(*surf.point_map(), f, y);
      } else {
        dofs.scatter(f, y);
      }
    }
    void put_in(PotentialLinearisation::Block& block) const {
      if (points.count > 0) {
        block.on_points = points;
      } else {
        block.row = dofs;
      }
    }
  };
  Row pair_row(const PairGeometry& g) {
    Row r;
    if (surf.point_map() != nullptr) {
      r.points = surf.pair_points(g);
    } else {
      r.dofs = surf.pair_row(g);
    }
    return r;
  }
  Row point_row(int p) {
    Row r;
    if (surf.point_map() != nullptr) {
      r.points = surf.point_alone(p);
    } else {
      r.dofs = surf.point_row(p);
    }
    return r;
  }
  struct FrictionRow {
    Row row;
    Eigen::Vector3d constant = Eigen::Vector3d::Zero();  // the obstacle side's part of u [m/s]
    Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity();
    double bound = 0.0;  // μ λ [N]
  };
  std::vector<FrictionRow> friction_rows;
  // Scratch of keep_closest: per (cloth point, obstacle), the closest candidate so far (+1; 0 for
  // none), and the entries set.
  std::vector<size_t> closest;
  std::vector<size_t> closest_set;
  Eigen::VectorXd potential_x;                    // the step's start positions (begin_potential)
  std::pair<double, double> potential_step_start{-1.0, 0.0};  // its t and h
  Eigen::VectorXd p1_velocity;                    // the velocities p1 was made from
  std::vector<PairGeometry> end_geometry;         // scratch of linearise_potential

  double barrier_ratio() const { return params.barrier_ratio; }
  // The obstacle side's part of a pair's relative velocity over the step [m/s].
  Eigen::Vector3d obstacle_side_velocity(const PairGeometry& g) const {
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (int k = 0; k < g.num; ++k)
      if (g.obstacle[static_cast<size_t>(k)]) {
        const int p = g.point[static_cast<size_t>(k)];
        u += g.coef[static_cast<size_t>(k)] * (o1.row(p) - o0.row(p)).transpose() / h;
      }
    return u;
  }
  double pair_friction(const PairGeometry& g) const {
    const int o = pairs.obstacle_of(g);
    return o >= 0 ? obstacles[static_cast<size_t>(o)].friction : settings.friction;
  }

  // The barrier's stiffness for a pair of cloth points: k h² = ratio × the smallest effective
  // mass (with the step's stiffness, s_k) of its cloth points, so the barrier is as stiff as the
  // step's own system is under it, whatever the material and step.
  double pair_stiffness(const Candidate& c) {
    double m = std::numeric_limits<double>::infinity();
    for (int p : pairs.cloth_points(c))
      if (p >= 0) m = std::min(m, mass_of_point(p));
    return barrier_ratio() * m / (h * h);
  }
  // Effective mass of surface point p through J, 1 / Σ_k J_k² / s_k, with each node's scale s_k
  // the mean of its three diagonal entries of A (a rotation leaves the trace of a node's block
  // unchanged). Made on first use in a step (few points are in pairs; all of them took a quarter
  // of a millisecond per step on the 494-vertex sleeve); not for parallel callers.
  Eigen::VectorXd node_scale;           // s_k of this step
  Eigen::VectorXd point_mass;           // per surface point [kg], NaN until made in this step
  double mass_of_point(int p) {
    double& m = point_mass(p);
    if (!std::isnan(m)) return m;
    double sum = 0.0;
    if (const PointMap* map = surf.point_map()) {
      for (int e = map->offsets[static_cast<size_t>(p)]; e < map->offsets[static_cast<size_t>(p) + 1]; ++e) {
        const double w = map->weights[static_cast<size_t>(e)];
        sum += w * w / node_scale(map->nodes[static_cast<size_t>(e)]);
      }
    } else {
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(surf.jacobian(), 3 * p); it; ++it)
        sum += it.value() * it.value() / node_scale(it.col() / 3);
    }
    m = sum > 0 ? 1.0 / sum : std::numeric_limits<double>::infinity();
    return m;
  }
  double plane_stiffness(int p) { return barrier_ratio() * mass_of_point(p) / (h * h); }

  // The potential's candidates: the broad phase over the motion p0 → p1 with boxes grown by twice
  // the thickness. They serve every configuration, and every motion between two, whose points
  // (and obstacle vertices) each stay within half the thickness of the straight path from the
  // start to the end point they were made for: at any time of such a motion every point is within
  // that of its swept box, so each pair that comes within the thickness at the end (the barrier),
  // over the step (the fail-safe's CCD) or over a Newton step (step_bound) is among them. So they
  // are kept from step to step while the cloth moves little (a resting drape), and from the
  // held start to the guess and on through Newton's iterates within a step.
  Eigen::MatrixX3d built_p0, built_o0, built_o1;  // the motion they were made for (and potential_guess)
  // (Half the thickness. A radius of 1 or 2.5 thicknesses took 2.2 or 9.6 times the contact time
  // on sleeve_on_arm's first 0.6 s: the candidates grow faster than their rebuilds get rarer.)
  double serve_radius() const { return 0.5 * settings.thickness; }
  // The largest distance of a point p_i from the segment a_i → b_i [m] (infinite for other sizes).
  static double sweep_distance(const Eigen::MatrixX3d& p, const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b) {
    if (p.rows() != a.rows() || p.rows() != b.rows()) return std::numeric_limits<double>::infinity();
    if (p.rows() == 0) return 0.0;
    // (Column by column, so that it vectorises: it runs several times per step.)
    const Eigen::ArrayX3d d = (b - a).array(), q = (p - a).array();
    const Eigen::ArrayXd dd = d.square().rowwise().sum();
    const Eigen::ArrayXd s = (dd > 0).select(((q * d).rowwise().sum() / dd).max(0.0).min(1.0), 0.0);
    return std::sqrt((q - d.colwise() * s).square().rowwise().sum().maxCoeff());
  }
  // Whether the candidates serve surface points p (and, when not null, q: any move between the
  // two) with the obstacles anywhere over this step (obstacles_serve, checked once per step).
  bool obstacles_serve = false;
  bool candidates_serve(const Eigen::MatrixX3d& p, const Eigen::MatrixX3d* q) const {
    const double r = serve_radius();
    return obstacles_serve && sweep_distance(p, built_p0, potential_guess) <= r &&
           (q == nullptr || sweep_distance(*q, built_p0, potential_guess) <= r);
  }
  bool candidates_serve() const { return candidates_serve(p0, &p1); }
  // The same for the end points p of velocities v, remembering the last velocities found served
  // (the step bound's end of a move is the next linearisation's point, and its start the last
  // one's): the check is a few passes over all surface points, and it runs several times a step.
  Eigen::VectorXd served_velocity;
  bool served_known = false;  // served_velocity's end points are served by the current candidates
  bool served(const Eigen::VectorXd& v, const Eigen::MatrixX3d& p) {
    if (!obstacles_serve) return false;
    if (served_known && v.size() == served_velocity.size() && v == served_velocity) return true;
    if (!(sweep_distance(p, built_p0, potential_guess) <= serve_radius())) return false;
    served_velocity = v;
    served_known = true;
    return true;
  }
  void check_obstacles_serve() {
    if (obstacles_static && built_o0.rows() == o0.rows()) {  // (o0 = o1 = built_o0 = built_o1)
      obstacles_serve = true;
      return;
    }
    const double r = serve_radius();
    obstacles_serve = sweep_distance(o0, built_o0, built_o1) <= r && sweep_distance(o1, built_o0, built_o1) <= r;
  }
  void make_potential_candidates(ContactReport& report) {
    lin_bounds_valid = false;
    served_known = false;
    potential_cands = candidates(report, settings.thickness + 2.0 * serve_radius());
    near_reach_of.assign(potential_cands.size(), -1.0);
    potential_guess = p1;
    built_p0 = p0;
    built_o0 = o0;
    built_o1 = o1;
    obstacles_serve = true;
    prepare_candidates();
  }
  // Per step (and after a new broad phase): each candidate's distance bound and, where it may be
  // within the thickness, geometry at the start of the step.
  void prepare_candidates() {
    // The last step's final linearisation holds bounds at its end points, the obstacles at its
    // end: this step's start (the same surface up to the fail-safe's changes and round-off, which
    // the points' moves from it account for).
    const bool carried = lin_bounds_valid && lin_bounds.lower.size() == potential_cands.size() && lin_time == potential_t;
    double motion = 0.0;
    if (carried) {
      point_move = (p0 - lin_points).rowwise().norm();
      motion = 2.0 * point_move.maxCoeff();
    }
    lin_bounds_valid = false;
    // Each pair's geometry at the start of the step: its side (the barrier's distance is signed
    // by it, see linearise_potential) and, for pairs pressed at the start, lagged friction.
    // (Computed here for the pairs whose boxes are within the thickness at the start, the others
    // when a linearisation finds them within it at the end: start_geometry.)
    cand_start.resize(potential_cands.size());
    cand_start_known.assign(potential_cands.size(), 0);
    cand_start_close.assign(potential_cands.size(), 0);
    std::vector<double>& lower = start_bounds.lower;
    if (carried) {
      lower = lin_bounds.less(motion);
    } else {
      lower.assign(potential_cands.size(), 0.0);
    }
    auto visit = [&](size_t i) {
      const Candidate& c = potential_cands[i];
      if (carried) {
        const double bound = lin_bounds.lower[i] - pairs.motion(c, point_move, 0.0);
        lower[i] = std::max(0.0, bound);
        if (bound >= settings.thickness) return;
      }
      const std::array<Eigen::Vector3d, 4> corner = corners(c, false);
      const double gap = box_gap(corner, is_point_triangle(c.kind));
      lower[i] = std::max(lower[i], gap);
      if (c.near || !(gap < settings.thickness)) return;
      lower[i] = start_geometry(i).distance;
      cand_start_close[i] = cand_start[i].distance < settings.thickness && !pairs.redundant_on_flat_face(c, cand_start[i], corner);
    };
    if (carried) {
      for_candidates(lin_bounds, motion, settings.thickness, visit);
    } else {
      for_candidates(nullptr, 0.0, 0.0, visit);
    }
    start_bounds.make_close(close_reach());
  }
  std::vector<char> cand_start_known;
  // Candidate i's geometry at the start of the step (computed once per step; each i by one thread).
  const PairGeometry& start_geometry(size_t i) {
    if (!cand_start_known[i]) {
      cand_start[i] = pairs.geometry(potential_cands[i], corners(potential_cands[i], false));
      cand_start_known[i] = 1;
    }
    return cand_start[i];
  }
  // Of the flagged cloth-point–obstacle-triangle candidates, keeps (flagged) the closest triangle
  // per point and obstacle.
  void keep_closest(std::vector<char>& flagged, const std::vector<PairGeometry>& geometry_of) {
    const size_t num_obstacles = obstacles.size();
    closest.resize(static_cast<size_t>(p0.rows()) * num_obstacles, 0);
    for (size_t i = 0; i < potential_cands.size(); ++i) {
      const Candidate& c = potential_cands[i];
      if (!flagged[i] || c.kind != Kind::cloth_point_obstacle_triangle) continue;
      const int obstacle = obs.obstacle_of_vertex[static_cast<size_t>(obs.triangles[static_cast<size_t>(c.b)][0])];
      const size_t key = static_cast<size_t>(c.a) * num_obstacles + static_cast<size_t>(obstacle);
      if (closest[key] == 0) {
        closest[key] = i + 1;
        closest_set.push_back(key);
        continue;
      }
      const size_t best = closest[key] - 1;
      if (geometry_of[i].distance < geometry_of[best].distance) {
        flagged[best] = 0;
        closest[key] = i + 1;
      } else {
        flagged[i] = 0;
      }
    }
    for (size_t key : closest_set) closest[key] = 0;
    closest_set.clear();
  }

  std::vector<PairGeometry> cand_start;  // per candidate, at the start of the step
  std::vector<char> cand_start_close;    // ... within the thickness there

  // Lower bounds of the candidates' distances at a reference configuration, so that a pair whose
  // points have moved less than its bound allows is known to be apart without looking at it: the
  // step's start (p0 and the obstacles at t: start_bounds), or the end points of the last
  // linearisation (obstacles at t + h: lin_bounds). Most candidates of a resting or slowly moving
  // cloth are decided this way in each linearisation and each step bound; while every pair moves
  // less than a quarter of the thickness from the reference, only the candidates whose bound is
  // within 1.25 thicknesses (`close`) are visited at all.
  Bounds start_bounds, lin_bounds;
  double close_reach() const { return 1.25 * settings.thickness; }
  // The barrier's reach for a near pair (parts near each other at rest, which CCD alone keeps
  // from crossing): half the pair's distance at rest, at most the thickness, so that it exerts
  // nothing at rest or anywhere the pair keeps half its rest distance, and resists a fold that
  // presses neighbouring parts into each other (without it such a pair stops Newton only by
  // cutting its steps: the crushed sleeve took 12 solves per step, each cut by an edge pair at
  // 0.2 µm that had been 2 mm apart at rest). Computed once per candidate list, when first
  // needed (each index by one thread).
  std::vector<double> near_reach_of;
  double near_reach(size_t i) {
    double& r = near_reach_of[i];
    if (r < 0.0) {
      const Candidate& c = potential_cands[i];
      r = std::min(settings.thickness, 0.5 * pairs.geometry(c, pairs.corners(c, surf.rest_points(), surf.rest_points())).distance);
    }
    return r;
  }
  // Calls visit(i), in parallel, for every candidate, or only for the close ones of `bounds` when
  // no pair can move from its bound to below `threshold` with moves of at most `motion` [m].
  template <class Visit>
  void for_candidates(const Bounds* bounds, double motion, double threshold, Visit visit) {
    const bool close_only = bounds != nullptr && bounds->reach - motion >= threshold;
    const size_t n = close_only ? bounds->close.size() : potential_cands.size();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t j = range.begin(); j != range.end(); ++j) visit(close_only ? bounds->close[j] : j);
    });
  }
  template <class Visit>
  void for_candidates(const Bounds& bounds, double motion, double threshold, Visit visit) {
    for_candidates(&bounds, motion, threshold, visit);
  }
  Eigen::MatrixX3d lin_points;      // the end points of the last linearisation
  Eigen::VectorXd lin_velocity;     // ... and the velocities they were made from
  bool lin_bounds_valid = false;    // lin_bounds hold for this step's candidates
  double lin_time = -1.0;           // the time of lin_points (the end of its step) [s]
  Eigen::VectorXd bound_to_velocity;  // the last step bound's velocities at the end of its move
  Eigen::MatrixX3d bound_to_points;   // ... and their end points
  Eigen::VectorXd point_move;       // scratch: per surface point, its move from the reference [m]

  // two), with the obstacles where they are at the end of the step or, with `whole_step`, anywhere
  // over it: fills `point_move` with each point's largest distance from the reference, returns the
  // bounds, sets `obstacle` to the obstacles' largest move from theirs and `motion` to the
  // largest change of any pair's distance that these moves allow.
  const Bounds& reference_bounds(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d* other, bool whole_step, double& obstacle,
                                 double& motion) {
    const bool lin = lin_bounds_valid;
    const Eigen::MatrixX3d& ref = lin ? lin_points : p0;
    point_move = (points - ref).rowwise().norm();
    if (other != nullptr) point_move = point_move.cwiseMax((*other - ref).rowwise().norm());
    obstacle = (lin && !whole_step) || o0.rows() == 0 ? 0.0 : (o1 - o0).rowwise().norm().maxCoeff();
    const double largest = point_move.size() > 0 ? point_move.maxCoeff() : 0.0;
    motion = std::max(2.0 * largest, largest + obstacle);
    return lin ? lin_bounds : start_bounds;
  }

  void begin_potential(const Eigen::VectorXd& x, const Eigen::VectorXd& v_guess, double t, double step,
                       const Eigen::VectorXd& diagonal) {
    h = step;
    start_positions(x, t);
    potential_x = x;
    potential_step_start = {t, step};
    end_points_current = false;
    update_end_points(v_guess);
    p1_velocity = v_guess;
    // (The surface points' effective masses are made when a pair needs them: mass_of_point.)
    node_scale.resize(d.num_nodes());
    for (int k = 0; k < d.num_nodes(); ++k) node_scale(k) = diagonal.segment<3>(3 * k).sum() / 3.0;
    point_mass.setConstant(p0.rows(), std::numeric_limits<double>::quiet_NaN());
    ContactReport scratch;
    check_obstacles_serve();
    served_known = false;  // (a new start)
    if (candidates_serve()) {
      prepare_candidates();
    } else {
      make_potential_candidates(scratch);
    }
    // Lagged friction: the pairs pressed at the start of the step, with their normal force and
    // tangent plane there (fixed over the step, so the friction potential is convex in v).
    friction_rows.clear();
    keep_closest(cand_start_close, cand_start);
    for (size_t i = 0; i < potential_cands.size(); ++i) {
      if (!cand_start_close[i]) continue;
      const contact::CubicBarrier barrier{settings.thickness, pair_stiffness(potential_cands[i])};
      const PairGeometry& g = cand_start[i];
      add_friction_row(g.normal, pair_friction(g), obstacle_side_velocity(g), -barrier.first(g.distance), [&] { return pair_row(g); });
    }
    for (int k : obs.planes) {
      const Obstacle& o = obstacles[static_cast<size_t>(k)];
      Eigen::Vector3d q0, n0;
      plane_at(o, t, q0, n0);
      const RigidMap move = contact::obstacle_step_map(o, t, h);
      for (Eigen::Index p = 0; p < p0.rows(); ++p) {
        const Eigen::Vector3d a = p0.row(p).transpose();
        const double dist = n0.dot(a - q0);
        if (!(dist < settings.thickness)) continue;
        const contact::CubicBarrier barrier{settings.thickness, plane_stiffness(static_cast<int>(p))};
        add_friction_row(n0, o.friction, -(move(a) - a) / h, -barrier.first(dist), [&] { return point_row(static_cast<int>(p)); });
      }
    }
  }

  // A lagged friction row for a pair with normal n, friction coefficient mu, the obstacle side's
  // velocity and normal force lambda [N]; `row` makes the pair's row (only when it is needed).
  template <class MakeRow>
  void add_friction_row(const Eigen::Vector3d& normal, double mu, const Eigen::Vector3d& obstacle_velocity, double lambda,
                        MakeRow row) {
    if (!(mu > 0) || !(lambda > 0)) return;
    FrictionRow f;
    f.row = row();
    f.constant = obstacle_velocity;
    f.tangent -= normal * normal.transpose();
    f.bound = mu * lambda;
    friction_rows.push_back(std::move(f));
  }

  double friction_epsilon() const { return settings.tolerance * settings.thickness / h; }

  void linearise_potential(const Eigen::VectorXd& v, double t, PotentialLinearisation& out) {
    const Eigen::Index n3 = v.size();
    out.blocks.clear();
    out.energy = out.dissipation = 0.0;
    out.active = 0;
    out.energy_gradient.setZero(n3);
    out.dissipation_gradient.setZero(n3);
    if (!(v.size() == p1_velocity.size() && v == p1_velocity)) {
      end_points_current = false;
      if (v.size() == bound_to_velocity.size() && v == bound_to_velocity) {
        p1 = bound_to_points;  // (the last step bound's end of the move: Newton's next iterate)
        end_points_current = true;
      } else {
        update_end_points(v);
      }
      p1_velocity = v;
    }
    // Candidates made for other end points serve while no point is more than half the
    // thickness from the path they were made for (their boxes are grown by twice the thickness).
    if (!served(v, p1)) {
      ContactReport scratch;
      make_potential_candidates(scratch);
    }
    const double dhat = settings.thickness;
    // A pair whose distance at the reference (the start, or the last linearisation) exceeds the
    // thickness by more than its points have moved since cannot be within it now (most candidates
    // of a slow or resting cloth); the bound each candidate gets here serves the next call.
    double obstacle_motion = 0.0, motion = 0.0;
    const Bounds& bounds = reference_bounds(p1, nullptr, false, obstacle_motion, motion);
    // (The candidates not visited keep their bound less the largest motion.)
    Bounds next;
    next.lower = bounds.less(motion);
    std::vector<char> active(potential_cands.size(), 0);
    end_geometry.resize(potential_cands.size());
    std::vector<PairGeometry>& end = end_geometry;
    for_candidates(bounds, motion, dhat, [&](size_t i) {
      const Candidate& c = potential_cands[i];
      const double bound = bounds.lower[i] - pairs.motion(c, point_move, obstacle_motion);
      next.lower[i] = std::max(0.0, bound);
      if (bound >= dhat) return;
      const std::array<Eigen::Vector3d, 4> corner = corners(c, true);
      const double gap = box_gap(corner, is_point_triangle(c.kind));
      next.lower[i] = std::max(next.lower[i], gap);
      const double reach = c.near ? near_reach(i) : dhat;
      if (gap > reach) return;  // (most candidates: no exact distance)
      end[i] = pairs.geometry(c, corner);
      next.lower[i] = std::max(next.lower[i], end[i].distance);
      if (pairs.redundant_on_flat_face(c, end[i], corner)) return;
      if (end[i].distance < reach) sign_by_start(start_geometry(i), end[i], is_point_triangle(c.kind));
      active[i] = end[i].distance < reach;
    });
    next.make_close(close_reach());
    lin_bounds = std::move(next);
    lin_points = p1;
    lin_velocity = v;
    lin_time = t + h;
    lin_bounds_valid = true;
    out.point_map = surf.point_map();
    auto add_pair = [&](const Row& row, const Eigen::Vector3d& normal, double distance, double k, double reach) {
      const contact::CubicBarrier barrier{reach, k};
      out.energy += barrier.value(distance);
      PotentialLinearisation::Block block;
      row.put_in(block);
      row.scatter(surf, barrier.first(distance) * normal, out.energy_gradient);
      block.hessian = barrier.second(distance) * normal * normal.transpose();
      out.blocks.push_back(std::move(block));
      ++out.active;
    };
    // A cloth point against an obstacle keeps its closest triangle only: the barrier is of the
    // point's distance to the obstacle, the smallest over its triangles (one pair where a point
    // over a face has several triangles within the thickness, and none of them twice).
    keep_closest(active, end);
    for (size_t i = 0; i < potential_cands.size(); ++i)
      if (active[i])
        add_pair(pair_row(end[i]), end[i].normal, end[i].distance, pair_stiffness(potential_cands[i]),
                 potential_cands[i].near ? near_reach(i) : dhat);
    for (int k : obs.planes) {
      Eigen::Vector3d q1, n1;
      plane_at(obstacles[static_cast<size_t>(k)], t + h, q1, n1);
      for (Eigen::Index p = 0; p < p1.rows(); ++p) {
        const double dist = n1.dot(p1.row(p).transpose() - q1);
        if (dist < dhat) add_pair(point_row(static_cast<int>(p)), n1, dist, plane_stiffness(static_cast<int>(p)), dhat);
      }
    }
    const contact::SmoothedFriction friction{friction_epsilon()};
    for (const FrictionRow& f : friction_rows) {
      const Eigen::Vector3d w = f.tangent * (f.row.apply(surf, v) + f.constant);
      out.dissipation += f.bound * friction.f0(w.norm());
      f.row.scatter(surf, friction.gradient(w, f.bound), out.dissipation_gradient);
      PotentialLinearisation::Block block;
      f.row.put_in(block);
      block.hessian = friction.hessian(w, f.tangent, f.bound);
      block.dissipative = true;
      out.blocks.push_back(std::move(block));
    }
  }

  // The end points p0 + h J v (#P × 3) for velocities v.

  double step_bound(const Eigen::VectorXd& from, const Eigen::VectorXd& to) {
    const bool at_linearisation = lin_bounds_valid && from.size() == lin_velocity.size() && from == lin_velocity;
    // (End points known already are not made again: the last linearisation's, or those of the
    // velocities the step began with.)
    auto points_of = [&](const Eigen::VectorXd& w) {
      if (end_points_current && w.size() == p1_velocity.size() && w == p1_velocity) return Eigen::MatrixX3d(p1);
      return end_points_of(w);
    };
    const Eigen::MatrixX3d pa = at_linearisation ? lin_points : points_of(from), pb = points_of(to);
    bound_to_velocity = to;
    bound_to_points = pb;
    // Candidates for the move pa → pb: the potential's where they serve it, else a broad phase
    // over this move.
    const std::vector<Candidate>* cands = &potential_cands;
    std::vector<Candidate> own;
    if (!(served(from, pa) && served(to, pb))) {
      ContactReport scratch;
      own = search->find(pa, pb, o0, o1, obstacle_boxes_current, settings.thickness, scratch);
      cands = &own;
    }
    // The obstacles stand where they are at the end of the step at both ends of the move.
    auto corner = [&](const Candidate& c, const Eigen::MatrixX3d& p) {
      const std::array<int, 4> cloth = pairs.cloth_points(c);
      std::array<Eigen::Vector3d, 4> x = corners(c, true);  // (obstacle points at t + h)
      // corners() puts the cloth points first for every kind but obstacle point–cloth triangle.
      if (c.kind == Kind::obstacle_point_cloth_triangle) {
        for (int k = 0; k < 3; ++k) x[static_cast<size_t>(k + 1)] = p.row(cloth[static_cast<size_t>(k)]).transpose();
      } else {
        for (size_t k = 0; k < 4; ++k)
          if (cloth[k] >= 0) x[k] = p.row(cloth[k]).transpose();
      }
      return x;
    };
    const double eta = params.min_separation_ratio * settings.thickness;
    const double near_eta = params.near_separation_ratio * settings.thickness;
    // With the potential's candidates, a pair whose distance bound at the reference exceeds the
    // separation by more than its points move (to either end of the move) is skipped.
    double obstacle_motion = 0.0, motion = 0.0;
    const Bounds* bounds = cands == &potential_cands ? &reference_bounds(pa, &pb, false, obstacle_motion, motion) : nullptr;
    const Eigen::VectorXd step_move = (pb - pa).rowwise().norm();  // per point, over the move
    const std::vector<double>* lower = bounds != nullptr ? &bounds->lower : nullptr;
    std::vector<double> bound(cands->size(), 1.0);
    auto visit = [&](size_t i) {
        const Candidate& c = (*cands)[i];
        double separation = c.near ? near_eta : eta;
        if (lower != nullptr && (*lower)[i] - pairs.motion(c, point_move, obstacle_motion) > separation) return;
        const std::array<Eigen::Vector3d, 4> a = corner(c, pa), b = corner(c, pb);
        const bool pt = is_point_triangle(c.kind);
        // A quick reject: the boxes of the swept primitives farther apart than the separation.
        std::array<Eigen::Vector3d, 4> lo, hi;
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
        const double start_distance = pairs.geometry(c, a).distance;
        if (!(start_distance > 0)) return;  // (touching already: nothing to bound)
        separation = std::min(separation, 0.5 * start_distance);
        // (A pair that does not move enough to lose what it has above the separation: most pairs
        // resting in contact between two Newton iterates.)
        if (start_distance - pairs.motion(c, step_move, 0.0) > separation) return;
        const contact::CcdResult r = pt ? contact::point_triangle_ccd(a, b, separation) : contact::edge_edge_ccd(a, b, separation);
        if (r.hit) bound[i] = r.toi;
    };
    if (bounds != nullptr) {
      for_candidates(*bounds, motion, std::max(eta, near_eta), visit);
    } else {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, cands->size(), 256), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) visit(i);
      });
    }
    double alpha = 1.0;
    for (double b : bound) alpha = std::min(alpha, b);
    for (int k : obs.planes) {
      Eigen::Vector3d q1, n1;
      plane_at(obstacles[static_cast<size_t>(k)], potential_t + h, q1, n1);
      for (Eigen::Index p = 0; p < pa.rows(); ++p) {
        const double da = n1.dot(pa.row(p).transpose() - q1), db = n1.dot(pb.row(p).transpose() - q1);
        if (!(da > 0) || db >= std::min(eta, 0.5 * da)) continue;
        const double separation = std::min(eta, 0.5 * da);
        alpha = std::min(alpha, (da - separation) / (da - db));
      }
    }
    return std::max(0.0, alpha);
  }

  // --- The stage ---------------------------------------------------------------------------------
  const ResponseSystem* system = nullptr;
  Eigen::VectorXd system_diagonal;  // of A, per DOF
  contact::ImplicitResponse response{params};  // (keeps its Newton matrix's factor across steps)
  contact::KeptMultipliers last_multipliers;   // of the last step's constraints with an impulse

  std::vector<Found> constraints;  // this step's, with their multipliers

  // The surface points and obstacle vertices at the start of the step (and the obstacles' at its
  // end); the end points are to be made from the velocities.
  void start_positions(const Eigen::VectorXd& x, double t) {
    p0 = surf.points(x);
    end_points_current = false;
    const bool placed = obstacles_static && o0.rows() == static_cast<Eigen::Index>(obs.obstacle_of_vertex.size());
    if (!placed) obstacle_boxes_current = false;
    if (!placed && !obs.obstacle_of_vertex.empty()) {
      o0.resize(static_cast<Eigen::Index>(obs.obstacle_of_vertex.size()), 3);
      o1.resize(o0.rows(), 3);
      for (size_t k = 0; k < obstacles.size(); ++k) {
        const Obstacle& o = obstacles[k];
        if (o.shape == Obstacle::Shape::plane) continue;
        o0.middleRows(obs.vertex_offset[k], o.mesh.num_vertices()) = mesh_at(o, t);
        o1.middleRows(obs.vertex_offset[k], o.mesh.num_vertices()) = mesh_at(o, t + h);
      }
    }
  }

  ContactReport filter(const Eigen::VectorXd& x, double t, double step, Eigen::VectorXd& v, const ResponseSystem& sys) {
    constraints.clear();
    const ContactReport report = run(x, t, step, v, sys);
    last_multipliers.keep(constraints);
    return report;
  }

  ContactReport run(const Eigen::VectorXd& x, double t, double step, Eigen::VectorXd& v, const ResponseSystem& sys) {
    ContactReport report;
    h = step;
    system = &sys;
    auto t0 = Clock::now();
    system_diagonal = sys.matrix.diagonal();
    const Eigen::VectorXd base = v;  // the solve's velocities, v*
    if (potential_on && potential_step_start == std::pair{t, step} && x.size() == potential_x.size() && x == potential_x) {
      // The potential's start positions of this step; its last end points when they are of v.
      end_points_current = v.size() == p1_velocity.size() && v == p1_velocity;
    } else {
      start_positions(x, t);
      if (potential_on) check_obstacles_serve();
    }
    update_end_points(v);
    report.narrow_ms += ms_since(t0);

    // Proximity at the start of the step: pairs within the thickness may not approach (target 0);
    // pairs that start closer than the minimum separation are pushed apart by a fraction of the
    // shortfall per step.
    const double eta = params.min_separation_ratio * settings.thickness;
    std::vector<Candidate> own;  // this step's own broad phase, where the potential's do not serve
    const std::vector<Candidate>* cands = &own;
    bool cands_current = true;  // made for the current end points
    bool use_bounds = false;    // cands are the potential's, with their distance bounds
    if (potential_on) {
      // Proximity is the potential's, inside the step (begin_potential / linearise); here only the
      // fail-safe, on the potential's candidates where they serve this step's motion
      // (candidates_serve).
      // (Within the potential's step its start is served: begin_potential checked it, or made the
      // candidates from it.)
      const bool same_step = potential_step_start == std::pair{t, step} && x.size() == potential_x.size() && x == potential_x;
      if (same_step ? served(v, p1) : candidates_serve()) {
        cands = &potential_cands;  // (read in place, not copied)
        use_bounds = true;
      } else {
        own = candidates(report, settings.thickness), cands = &own;
      }
    } else {
      own = candidates(report, settings.thickness), cands = &own;
      constraints = proximity(*cands, t, report);
      last_multipliers.warm_start(constraints);
      report.proximity_pairs = static_cast<int>(constraints.size());
      for (Found& f : constraints) f.constraint.target = params.repulsion_ratio * std::max(0.0, eta - f.distance) / h;
      if (!constraints.empty()) {
        implicit_response(constraints, base, v, report);
      }
    }

    // Continuous collision detection: each pass adds the pairs that collide to the constraints
    // and solves the response again from v*.
    std::vector<Found> hits;
    std::vector<Candidate> last_hits;
    std::vector<char> moved;
    Eigen::MatrixX3d p1_tested;  // end points of the last test
    for (int pass = 0; pass < params.ccd_passes; ++pass) {
      t0 = Clock::now();
      const bool changed = !end_points_current;  // impulses since the candidates were made
      update_end_points(v);
      report.narrow_ms += ms_since(t0);
      if (!cands_current || changed) own = candidates(report, settings.thickness), cands = &own;
      cands_current = false;  // the response below moves the end points
      if (pass == 0 && use_bounds) {
        double obstacle_motion = 0.0, motion = 0.0;
        const Bounds& bounds = reference_bounds(p0, &p1, true, obstacle_motion, motion);
        hits = collisions(*cands, t, report, nullptr, nullptr, &last_hits, &bounds, obstacle_motion, motion);
      } else if (pass == 0) {
        hits = collisions(*cands, t, report, nullptr, nullptr, &last_hits);
      } else {
        moved.assign(static_cast<size_t>(p1.rows()), 0);
        for (Eigen::Index p = 0; p < p1.rows(); ++p) moved[static_cast<size_t>(p)] = p1.row(p) != p1_tested.row(p);
        std::vector<Candidate> previous;
        previous.swap(last_hits);
        hits = collisions(*cands, t, report, &moved, &previous, &last_hits);
      }
      p1_tested = p1;
      report.ccd_collisions += static_cast<int>(hits.size());
      if (hits.empty()) return report;
      for (Found& f : hits) f.constraint.target = std::max(0.0, (f.separation - f.distance) / h);
      last_multipliers.warm_start(hits);
      constraints.insert(constraints.end(), hits.begin(), hits.end());
      implicit_response(constraints, base, v, report);
    }

    // Fail-safe: impact zones, merged until the step is free.
    const int n = d.num_nodes();
    Zones zones(n);
    std::vector<int> zone_obstacle(static_cast<size_t>(n), -2);  // −2: in no zone; −1: a cloth zone
    for (int round = 0; round < params.zone_rounds; ++round) {
      t0 = Clock::now();
      update_end_points(v);
      report.narrow_ms += ms_since(t0);
      if (round > 0) {
        own = candidates(report, settings.thickness), cands = &own;
        hits = collisions(*cands, t, report);
        if (hits.empty()) return report;
      }
      contact::merge_zones(hits, zones, zone_obstacle);
      end_points_current = false;
      contact::move_impact_zones(zones, zone_obstacle, x, t, h, free, node_mass, obstacles, v, report);
    }
    update_end_points(v);
    report.unresolved = static_cast<int>(collisions(candidates(report, settings.thickness), t, report).size());
    return report;
  }
};

ContactStage::ContactStage(const Discretization& discretization, const Eigen::VectorXd& node_mass,
                           const std::vector<char>& free, const CollisionSettings& settings, std::vector<Obstacle> obstacles,
                           const ContactParameters& parameters)
    : impl_(std::make_unique<Impl>(discretization, node_mass, free, settings, std::move(obstacles), parameters)) {}

ContactStage::~ContactStage() = default;

ContactReport ContactStage::filter(const Eigen::VectorXd& x, double t, double h, Eigen::VectorXd& v,
                                   const ResponseSystem& system) {
  return impl_->filter(x, t, h, v, system);
}

void ContactStage::enable_potential() {
  impl_->potential_on = true;
  impl_->surf.make_point_rows();
}
bool ContactStage::potential_enabled() const { return impl_->potential_on; }

void ContactStage::begin_step(const Eigen::VectorXd& x, const Eigen::VectorXd& v_guess, double t, double h,
                              const Eigen::VectorXd& diagonal) {
  impl_->potential_t = t;
  impl_->begin_potential(x, v_guess, t, h, diagonal);
}

void ContactStage::linearise(const Eigen::VectorXd& v, PotentialLinearisation& out) {
  impl_->linearise_potential(v, impl_->potential_t, out);
}

void ContactStage::end_step(const Eigen::VectorXd& v, PotentialReport& report) {
  (void)v;
  report.friction_pairs = static_cast<int>(impl_->friction_rows.size());
}

double ContactStage::step_bound(const Eigen::VectorXd& from, const Eigen::VectorXd& to) {
  return impl_->step_bound(from, to);
}

double ContactStage::velocity_tolerance(double h) const {
  // 1 % of collision.tolerance's velocity (a fraction of the thickness per step), as the
  // constraints' response stops its Newton steps: the energy error of the step then stays far
  // below the tolerance's own scale (docs/contact.md).
  return 0.01 * impl_->settings.tolerance * impl_->settings.thickness / h;
}

const SurfaceOperator& ContactStage::surface() const { return impl_->surf.op(); }
long long ContactStage::joined_at_rest() const { return impl_->joined_pairs; }
const std::vector<Obstacle>& ContactStage::obstacles() const { return impl_->obstacles; }

}  // namespace clothsim

#include "sim/contact/contact_stage.hpp"

#include "sim/contact/barrier_potential.hpp"
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
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace clothsim {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

using contact::Bounds;
using contact::Candidate;
using contact::Constraint;
using contact::Found;
using contact::key_of;
using contact::is_point_triangle;
using contact::PairGeometry;
using contact::RigidMap;
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
  std::optional<contact::CandidateSearch> search;  // (made in the constructor, after obs)
  // The contact potential inside the step (sim/contact/barrier_potential.hpp; made last in the
  // constructor), in use after enable_potential: potential_on.
  std::optional<contact::BarrierPotential> potential;
  bool potential_on = false;

  // Per step (shared with the potential).
  contact::StepPositions positions;  // surface points at its start, obstacle vertices at t and t + h
  Eigen::MatrixX3d p1;               // surface points at its end (the fail-safe's)
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
    potential.emplace(surf, pairs, obs, obstacles, *search,
                      contact::BarrierSettings{settings.thickness, settings.friction, settings.tolerance, params.barrier_ratio,
                                               params.min_separation_ratio, params.near_separation_ratio, obstacles_static});
  }

  // --- Positions -------------------------------------------------------------------------------
  bool end_points_current = false;  // p1 matches the velocities (no impulse since it was computed)
  bool start_checked = false;       // the first step's start was checked against the planes

  // A cloth that starts on the wrong side of a plane cannot be brought back by contact (the barrier
  // pushes a pair apart along the side it is on, and every move across the plane is a crossing):
  // it is an error in the scene, reported at the first step with the plane and how deep the cloth
  // is behind it. (A plane turned into a sheet, found by fuzzing, ran its first step for minutes
  // and grew to 2 GB.) Round-off below a hundredth of the thickness is let through.
  void check_start_against_planes(double t) const {
    for (size_t k = 0; k < obstacles.size(); ++k) {
      const Obstacle& o = obstacles[k];
      if (o.shape != Obstacle::Shape::plane) continue;
      Eigen::Vector3d q, n;
      plane_at(o, t, q, n);
      Eigen::Index deepest = -1;
      double depth = 0.01 * settings.thickness;
      for (Eigen::Index p = 0; p < positions.p0.rows(); ++p) {
        const double behind = -n.dot(positions.p0.row(p).transpose() - q);
        if (behind > depth) depth = behind, deepest = p;
      }
      if (deepest < 0) continue;
      Eigen::Index count = 0;
      for (Eigen::Index p = 0; p < positions.p0.rows(); ++p) count += n.dot(positions.p0.row(p).transpose() - q) < 0 ? 1 : 0;
      std::ostringstream what;
      what << std::setprecision(4) << "obstacles[" << k << "] \"" << o.name << "\": the cloth starts behind this plane, up to "
           << depth << " m deep (" << count << " of its " << positions.p0.rows() << " collision-surface points, the deepest at ("
           << positions.p0(deepest, 0) << ", " << positions.p0(deepest, 1) << ", " << positions.p0(deepest, 2)
           << ")); contact cannot bring it back: move the cloth or the plane so that the cloth starts on the side its normal "
              "points to";
      throw std::runtime_error(what.str());
    }
  }

  void update_end_points(const Eigen::VectorXd& v) {
    if (end_points_current) return;
    end_points_current = true;
    p1 = end_points_of(v);
  }

  // The end points p0 + h J v (#P × 3) for velocities v.
  Eigen::MatrixX3d end_points_of(const Eigen::VectorXd& v) const { return surf.end_points(positions.p0, h, v); }

  // --- Broad phase ----------------------------------------------------------------------------
  // The candidates of the motion p0 → p1 (and the obstacles' o0 → o1) with boxes grown by `grow`
  // [m] (sim/contact/candidates.hpp); the search keeps the obstacles' boxes until start_positions
  // moves the obstacles.
  std::vector<Candidate> candidates(ContactReport& report, double grow) {
    std::vector<Candidate> out =
        search->find(positions.p0, p1, positions.o0, positions.o1, positions.obstacle_boxes_current, grow, report);
    positions.obstacle_boxes_current = true;
    return out;
  }

  // --- Pair geometry ---------------------------------------------------------------------------
  // The four points of a pair at the start (τ = 0) or end (τ = 1) of the step.
  std::array<Eigen::Vector3d, 4> corners(const Candidate& c, bool end) const {
    return end ? pairs.corners(c, p1, positions.o1) : pairs.corners(c, positions.p0, positions.o0);
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
      if (g.obstacle[static_cast<size_t>(k)])
        c.obstacle_velocity += coef * (positions.o1.row(p) - positions.o0.row(p)).transpose() / h;
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
      for (Eigen::Index p = 0; p < positions.p0.rows(); ++p) {
        ++report.pairs_tested;
        const Eigen::Vector3d a = positions.p0.row(p).transpose();
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
  // positions, so the same (negative) answer. With `reference` (the potential's candidates' distance
  // bounds at a reference, BarrierPotential::reference_bounds), pairs that cannot come within the
  // separation are not tested.
  std::vector<Found> collisions(const std::vector<Candidate>& cands, double t, ContactReport& report,
                                const std::vector<char>* moved = nullptr, const std::vector<Candidate>* last = nullptr,
                                std::vector<Candidate>* hit_pairs = nullptr,
                                const contact::ReferenceBounds* reference = nullptr) {
    const auto t0 = Clock::now();
    const Bounds* bounds = reference != nullptr ? &reference->bounds : nullptr;
    const double obstacle_motion = reference != nullptr ? reference->obstacle_motion : 0.0;
    const double motion = reference != nullptr ? reference->motion : 0.0;
    const double eta = params.min_separation_ratio * settings.thickness;
    std::vector<Found> out;
    if (hit_pairs) hit_pairs->clear();
    // The CCD of every pair in parallel (each pair alone), then the hits in the pairs' order.
    // (Hits are rare: they are gathered under a lock and put in the pairs' order after.)
    std::vector<std::pair<size_t, double>> toi;  // (candidate, time of impact)
    std::mutex toi_mutex;
    std::atomic<long long> tested{0};
    const std::vector<double>* lower = bounds != nullptr ? &bounds->lower : nullptr;
    const Bounds::List list =
        bounds != nullptr ? bounds->within(std::max(eta, params.near_separation_ratio * settings.thickness), motion) : Bounds::List{};
    const size_t n = !list.all ? list.size : cands.size();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& range) {
      long long count = 0;
      for (size_t j = range.begin(); j != range.end(); ++j) {
        const size_t i = !list.all ? list[j] : j;
        const Candidate& c = cands[i];
        const double separation = c.near ? params.near_separation_ratio * settings.thickness : eta;
        if (lower != nullptr && ((*lower)[i] - motion > separation ||
                                 (*lower)[i] - pairs.motion(c, reference->point_move, obstacle_motion) > separation))
          continue;
        if (moved != nullptr) {
          bool any = false;
          for (int p : pairs.cloth_points(c)) any = any || (p >= 0 && (*moved)[static_cast<size_t>(p)]);
          if (!any && !std::binary_search(last->begin(), last->end(), c)) continue;
        }
        ++count;
        const std::array<Eigen::Vector3d, 4> a = corners(c, false), b = corners(c, true);
        const contact::CcdResult r = is_point_triangle(c.kind) ? contact::point_triangle_ccd(a, b, separation)
                                                               : contact::edge_edge_ccd(a, b, separation);
        if (r.hit) {
          const std::lock_guard<std::mutex> lock(toi_mutex);
          toi.emplace_back(i, r.toi);
        }
      }
      tested += count;
    });
    report.pairs_tested += tested.load();
    std::sort(toi.begin(), toi.end());
    for (const auto& [i, time] : toi) {
      const Candidate& c = cands[i];
      const std::array<Eigen::Vector3d, 4> a = corners(c, false), b = corners(c, true);
      const double separation = c.near ? params.near_separation_ratio * settings.thickness : eta;
      std::array<Eigen::Vector3d, 4> x;
      for (size_t k = 0; k < 4; ++k) x[k] = a[k] + time * (b[k] - a[k]);
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

  // --- The stage ---------------------------------------------------------------------------------
  const ResponseSystem* system = nullptr;
  Eigen::VectorXd system_diagonal;  // of A, per DOF
  contact::ImplicitResponse response{params};  // (keeps its Newton matrix's factor across steps)
  contact::KeptMultipliers last_multipliers;   // of the last step's constraints with an impulse

  std::vector<Found> constraints;  // this step's, with their multipliers

  // The surface points and obstacle vertices at the start of the step (and the obstacles' at its
  // end); the end points are to be made from the velocities.
  void start_positions(const Eigen::VectorXd& x, double t) {
    // (Through the point rows where they are in node form: the crushed sleeve's start points took
    // a twentieth of its contact time through the control net.)
    positions.p0 = surf.points_through_rows(x);
    if (!start_checked) check_start_against_planes(t);
    start_checked = true;
    end_points_current = false;
    const bool placed = obstacles_static && positions.o0.rows() == static_cast<Eigen::Index>(obs.obstacle_of_vertex.size());
    if (!placed) positions.obstacle_boxes_current = false;
    if (!placed && !obs.obstacle_of_vertex.empty()) {
      positions.o0.resize(static_cast<Eigen::Index>(obs.obstacle_of_vertex.size()), 3);
      positions.o1.resize(positions.o0.rows(), 3);
      for (size_t k = 0; k < obstacles.size(); ++k) {
        const Obstacle& o = obstacles[k];
        if (o.shape == Obstacle::Shape::plane) continue;
        positions.o0.middleRows(obs.vertex_offset[k], o.mesh.num_vertices()) = mesh_at(o, t);
        positions.o1.middleRows(obs.vertex_offset[k], o.mesh.num_vertices()) = mesh_at(o, t + h);
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
    const bool same_step = potential_on && potential->in_step(x, t, step);
    if (same_step) {
      // The potential's start positions of this step; its last end points when they are of v.
      const Eigen::MatrixX3d* known = potential->end_points(v);
      end_points_current = known != nullptr;
      if (known != nullptr) p1 = *known;
    } else {
      start_positions(x, t);
      if (potential_on) potential->check_obstacles_serve(positions);
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
      // Proximity is the potential's, inside the step (BarrierPotential::begin_step / linearise);
      // here only the fail-safe, on the potential's candidates where they serve this step's motion.
      // (Within the potential's step its start is served: begin_step checked it, or made the
      // candidates from it.)
      double start_sweep = 0.0, end_sweep = 0.0;
      if (same_step ? potential->served(v, p1) : potential->serves(positions.p0, p1, start_sweep, end_sweep)) {
        cands = &potential->candidates();  // (read in place, not copied)
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
        const contact::ReferenceBounds reference = potential->reference_bounds(positions, positions.p0, &p1, true);
        hits = collisions(*cands, t, report, nullptr, nullptr, &last_hits, &reference);
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
  impl_->h = h;
  impl_->start_positions(x, t);
  impl_->potential->begin_step(impl_->positions, x, v_guess, t, h, diagonal);
}

void ContactStage::linearise(const Eigen::VectorXd& v, PotentialLinearisation& out) {
  impl_->potential->linearise(impl_->positions, v, out);
}

void ContactStage::end_step(const Eigen::VectorXd& v, PotentialReport& report) {
  (void)v;
  impl_->potential->end_step(report);
}

double ContactStage::step_bound(const Eigen::VectorXd& from, const Eigen::VectorXd& to) {
  return impl_->potential->step_bound(impl_->positions, from, to);
}

double ContactStage::velocity_tolerance(double h) const { return impl_->potential->velocity_tolerance(h); }

const SurfaceOperator& ContactStage::surface() const { return impl_->surf.op(); }
long long ContactStage::joined_at_rest() const { return impl_->joined_pairs; }
const std::vector<Obstacle>& ContactStage::obstacles() const { return impl_->obstacles; }

}  // namespace clothsim

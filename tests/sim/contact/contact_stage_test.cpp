// The contact stage (sim/contact/contact_stage.hpp) through the Simulator, against independent
// expectations: the obstacles' tessellations (closed, outward, on the analytic surface, within
// 1 % of the analytic volume, chords within the documented 0.2 % of the radius); a far obstacle
// or an idle self-collision changes nothing (bit for bit); a cloth dropped on a plane rests on it
// inside the thickness band, and a flat landing stays flat; Coulomb friction on a tilted plane
// (stick below the friction angle, the closed-form slide above it); linear momentum conserved
// when two free cloth parts collide; mechanical energy never created by contact (the drop, the
// collision); and, checked with the independent exact CGAL test (tools/intersections), the drawn
// surface never intersects itself, the obstacles or the ground (a sheet falling on a sphere, a
// strip folded over itself, the sheet_on_sphere scene).
//
// Conventions: grids lie in z = 0 (sim/mesh/generators.hpp); gravity is along −z and the ground
// is the plane z = 0 with normal +z unless a test tilts it. Lengths [m], times [s], energies [J].
// Each test prints the figures it measured.
#include "tests/support/test_meshes.hpp"
#include "sim/contact/obstacle.hpp"
#include "sim/shell/material_presets.hpp"
#include "sim/dynamics/simulator.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/scene/scene.hpp"
#include "tools/intersections/surface_intersections.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace clothsim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;  // [m/s²]

// Whether contact acted in a step: the barrier inside the step held pairs, or the fail-safe after
// it gave impulses (with collision.method "constraints", every pair within the thickness).
int contact_acted(const StepStats& s) { return s.contact_active_pairs + static_cast<int>(s.contact.impulses); }

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The cotton preset (E·t = 5000 N/m, B = 1.157e-5 N·m, ν = 0.25, ρ_A = 0.1238 kg/m²).
ShellMaterial cotton() { return *material_preset("cotton"); }

// A dynamic problem on `mesh` with the cotton material, a direct solver, no damping, contact
// settings at their defaults but the collision surface refined once.
Problem cloth_problem(TriMesh mesh, double dt, double end) {
  Problem p;
  p.mesh = std::move(mesh);
  p.material = cotton();
  p.time.dt = dt;
  p.time.end = end;
  p.solver.type = LinearSolverType::cholmod;
  p.collision_level = 1;
  p.collision.thickness = 1e-3;
  return p;
}

Obstacle plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal, double friction) {
  Obstacle o;
  o.name = "plane";
  o.shape = Obstacle::Shape::plane;
  o.point = point;
  o.normal = normal.normalized();
  o.friction = friction;
  return o;
}

Obstacle ground(double friction) { return plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), friction); }

Obstacle sphere(const Eigen::Vector3d& center, double radius, double friction) {
  Obstacle o;
  o.name = "sphere";
  o.shape = Obstacle::Shape::sphere;
  o.center = center;
  o.radius = radius;
  o.friction = friction;
  o.mesh = tessellate(o);
  return o;
}

// The mesh's vertices mapped by p ↦ r p + c.
TriMesh transformed(TriMesh mesh, const Eigen::Matrix3d& r, const Eigen::Vector3d& c) {
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
    mesh.vertices.row(v) = (r * mesh.vertices.row(v).transpose() + c).transpose();
  return mesh;
}

check::Surface to_surface(const Eigen::MatrixX3d& points, const std::vector<Triangle>& triangles) {
  check::Surface s;
  s.vertices.resize(static_cast<size_t>(points.rows()));
  for (Eigen::Index i = 0; i < points.rows(); ++i) s.vertices[static_cast<size_t>(i)] = {points(i, 0), points(i, 1), points(i, 2)};
  s.triangles.assign(triangles.begin(), triangles.end());
  return s;
}

// The drawn surface at the current state: the display operator's points evaluated on the
// control net of x (what app/limit_surface_drawer draws).
Eigen::MatrixX3d drawn_points(const Simulator& sim, const SurfaceOperator& op) {
  Eigen::MatrixX3d positions, normals;
  op.evaluate(sim.discretization().control_net(sim.state().x), positions, normals);
  return positions;
}

Eigen::Vector3d momentum(const Simulator& sim) {
  return sim.state().velocities().transpose() * sim.vertex_mass();
}

Eigen::Vector3d centre_of_mass(const Simulator& sim) {
  return sim.state().positions().transpose() * sim.vertex_mass() / sim.vertex_mass().sum();
}

// ---------------------------------------------------------------------------------------------
// 1. Obstacle tessellation.

// Signed distance of q from the surface of a primitive [m] (negative inside), written here from
// the primitive's definition.
double signed_distance(const Obstacle& o, const Eigen::Vector3d& q) {
  switch (o.shape) {
    case Obstacle::Shape::sphere:
      return (q - o.center).norm() - o.radius;
    case Obstacle::Shape::capsule: {
      const Eigen::Vector3d d = o.to - o.from;
      const double s = std::clamp((q - o.from).dot(d) / d.squaredNorm(), 0.0, 1.0);
      return (q - (o.from + s * d)).norm() - o.radius;
    }
    case Obstacle::Shape::cylinder: {
      const Eigen::Vector3d d = o.to - o.from;
      const double length = d.norm();
      const Eigen::Vector3d a = d / length;
      const double s = (q - o.from).dot(a);
      const double rho = (q - o.from - s * a).norm();
      const double out_r = rho - o.radius, out_s = std::max(-s, s - length);
      if (out_r <= 0 && out_s <= 0) return std::max(out_r, out_s);
      return std::hypot(std::max(out_r, 0.0), std::max(out_s, 0.0));
    }
    case Obstacle::Shape::box: {
      const Eigen::Vector3d e = (q - o.center).cwiseAbs() - 0.5 * o.size;
      const double inside = std::min(e.maxCoeff(), 0.0);
      return e.cwiseMax(0.0).norm() + inside;
    }
    default:
      throw std::logic_error("signed_distance: not a primitive");
  }
}

double analytic_volume(const Obstacle& o) {
  const double r = o.radius;
  switch (o.shape) {
    case Obstacle::Shape::sphere: return 4.0 / 3.0 * kPi * r * r * r;
    case Obstacle::Shape::capsule: return kPi * r * r * (o.to - o.from).norm() + 4.0 / 3.0 * kPi * r * r * r;
    case Obstacle::Shape::cylinder: return kPi * r * r * (o.to - o.from).norm();
    case Obstacle::Shape::box: return o.size.prod();
    default: throw std::logic_error("analytic_volume: not a primitive");
  }
}

struct TessellationFigures {
  int open_edges = 0;             // undirected edges not in exactly two triangles
  int inconsistent_edges = 0;     // directed edges used more than once (neighbours disagree)
  double volume = 0.0;            // signed volume Σ a·(b × c) / 6 [m³]
  double vertex_off = 0.0;        // max |signed distance| of a vertex [m]
  double chord_depth = 0.0;       // max depth of an edge midpoint below the surface [m]
  double outside = 0.0;           // max distance of a vertex outside a face's plane (convexity) [m]
};

TessellationFigures measure(const Obstacle& o, const TriMesh& m) {
  TessellationFigures f;
  std::map<std::pair<int, int>, int> directed, undirected;
  for (const Triangle& t : m.triangles) {
    const Eigen::Vector3d a = m.vertices.row(t[0]), b = m.vertices.row(t[1]), c = m.vertices.row(t[2]);
    f.volume += a.dot(b.cross(c)) / 6.0;
    for (size_t k = 0; k < 3; ++k) {
      const int i = t[k], j = t[(k + 1) % 3];
      ++directed[{i, j}];
      ++undirected[std::minmax(i, j)];
      const Eigen::Vector3d mid = 0.5 * (Eigen::Vector3d(m.vertices.row(i)) + Eigen::Vector3d(m.vertices.row(j)));
      f.chord_depth = std::max(f.chord_depth, -signed_distance(o, mid));
    }
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    for (Eigen::Index v = 0; v < m.vertices.rows(); ++v)
      f.outside = std::max(f.outside, n.dot(Eigen::Vector3d(m.vertices.row(v)) - a));
  }
  for (const auto& [edge, count] : undirected)
    if (count != 2) ++f.open_edges;
  for (const auto& [edge, count] : directed)
    if (count != 1 || directed.count({edge.second, edge.first}) != 1) ++f.inconsistent_edges;
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v)
    f.vertex_off = std::max(f.vertex_off, std::abs(signed_distance(o, m.vertices.row(v).transpose())));
  return f;
}

// A sphere, an oblique capsule, a box and a cylinder along −x (the other branch of the frame
// choice in obstacle.cpp).
std::vector<Obstacle> primitives() {
  std::vector<Obstacle> shapes(4);
  shapes[0].shape = Obstacle::Shape::sphere;
  shapes[0].center = Eigen::Vector3d(0.1, -0.2, 0.3);
  shapes[0].radius = 0.12;
  shapes[1].shape = Obstacle::Shape::capsule;
  shapes[1].from = Eigen::Vector3d(0.1, 0.2, 0.3);
  shapes[1].to = Eigen::Vector3d(0.3, -0.1, 0.5);
  shapes[1].radius = 0.05;
  shapes[2].shape = Obstacle::Shape::box;
  shapes[2].center = Eigen::Vector3d(0.1, 0.2, -0.3);
  shapes[2].size = Eigen::Vector3d(0.2, 0.1, 0.4);
  shapes[3].shape = Obstacle::Shape::cylinder;
  shapes[3].from = Eigen::Vector3d(0.4, 0.05, 0.0);
  shapes[3].to = Eigen::Vector3d(-0.1, 0.05, 0.0);
  shapes[3].radius = 0.08;
  return shapes;
}

TEST(ContactObstacles, PrimitivesAreClosedOutwardAndOnTheirSurface) {
  const std::vector<Obstacle> shapes = primitives();
  for (const Obstacle& o : shapes) {
    SCOPED_TRACE(to_string(o.shape));
    const TriMesh m = tessellate(o);
    EXPECT_NO_THROW(check_triangles(m));
    const TessellationFigures f = measure(o, m);
    const double size = o.shape == Obstacle::Shape::box ? o.size.maxCoeff() : o.radius;
    const double exact = analytic_volume(o);
    std::printf("%-8s %5d triangles: volume %.6e m³ vs %.6e (%+.3f %%), vertices off %.1e m, chord depth %.4f %% of %s\n",
                to_string(o.shape), m.num_triangles(), f.volume, exact, 100.0 * (f.volume / exact - 1.0), f.vertex_off,
                100.0 * f.chord_depth / size, o.shape == Obstacle::Shape::box ? "the longest edge" : "r");
    EXPECT_EQ(f.open_edges, 0);
    EXPECT_EQ(f.inconsistent_edges, 0);
    EXPECT_GT(f.volume, 0.0);                           // outward (counter-clockwise seen from outside)
    EXPECT_LT(std::abs(f.volume / exact - 1.0), 0.01);  // within 1 % of the primitive
    EXPECT_LE(f.volume, exact * (1.0 + 1e-12));         // inscribed, so never larger
    EXPECT_LT(f.vertex_off, 1e-12);                     // every vertex on the true surface
    EXPECT_LT(f.outside, 1e-12);                        // convex: the mesh lies inside the primitive
  }
  // The sphere's vertices on the sphere to 1e-12 (the figure above covers it; stated on its own).
  const TriMesh ball = tessellate(shapes[0]);
  for (Eigen::Index v = 0; v < ball.vertices.rows(); ++v)
    ASSERT_NEAR((Eigen::Vector3d(ball.vertices.row(v)) - shapes[0].center).norm(), shapes[0].radius, 1e-12) << "vertex " << v;
}

TEST(ContactObstacles, ChordsStayWithinTheDocumentedSagitta) {
  // obstacle.hpp: "a tessellation fine enough that its chords are within 0.2 % of the radius of
  // the curved surface". Every edge's midpoint lies at most 0.002 r below the true surface (box:
  // on it). This bounds how far cloth resting on the mesh can sink into the drawn primitive.
  for (const Obstacle& o : primitives()) {
    SCOPED_TRACE(to_string(o.shape));
    const TessellationFigures f = measure(o, tessellate(o));
    if (o.shape != Obstacle::Shape::box)
      std::printf("%-8s deepest edge midpoint %.3e m = %.4f %% of r below the surface (allowed 0.2 %%)\n", to_string(o.shape),
                  f.chord_depth, 100.0 * f.chord_depth / o.radius);
    EXPECT_LE(f.chord_depth, o.shape == Obstacle::Shape::box ? 1e-12 : 0.002 * o.radius);
  }
}

TEST(ContactObstacles, TessellateRejectsPlanesMeshesAndBadSizes) {
  Obstacle o;
  o.shape = Obstacle::Shape::plane;
  EXPECT_THROW(tessellate(o), std::invalid_argument);
  o.shape = Obstacle::Shape::mesh;
  EXPECT_THROW(tessellate(o), std::invalid_argument);
  o.shape = Obstacle::Shape::sphere;
  o.radius = 0.0;
  EXPECT_THROW(tessellate(o), std::invalid_argument);
  o.shape = Obstacle::Shape::capsule;
  o.radius = 0.1;
  o.from = o.to;
  EXPECT_THROW(tessellate(o), std::invalid_argument);
  o.shape = Obstacle::Shape::box;
  o.size = Eigen::Vector3d(1.0, 0.0, 1.0);
  EXPECT_THROW(tessellate(o), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// 2. Nothing changes without contact.

// A square hinged along one edge, swinging down under gravity (it deforms and moves).
Problem swinging_square() {
  Problem p = cloth_problem(make_grid(0.1, 0.1, 6, 6), 1e-3, 0.02);
  BoundaryCondition hinge;
  for (int v = 0; v < p.mesh.num_vertices(); ++v)
    if (p.mesh.vertices(v, 0) < -0.05 + 1e-9) hinge.vertices.push_back(v);
  p.boundary = {hinge};
  p.gravity = Eigen::Vector3d(0, 0, -kG);
  p.initial.velocity = Eigen::Vector3d(0, 0.1, 0.0);  // irrelevant to the hinge, moves the rest
  return p;
}

TEST(ContactNoContact, NoCollisionReportsNoContactFigures) {
  const Problem p = swinging_square();
  ASSERT_FALSE(p.has_contact());
  Simulator sim(p);
  for (int i = 0; i < sim.num_steps(); ++i) {
    const StepStats s = sim.step();
    ASSERT_EQ(s.contact.pairs_tested, 0) << "step " << i + 1;
    ASSERT_EQ(s.contact.impulses, 0);
    ASSERT_EQ(s.contact.impact_zones, 0);
    ASSERT_EQ(s.contact.unresolved, 0);
    ASSERT_EQ(s.contact.ms, 0.0);
    ASSERT_EQ(s.contact.broad_ms, 0.0);
    ASSERT_EQ(s.contact.narrow_ms, 0.0);
    ASSERT_EQ(s.contact.response_ms, 0.0);
  }
  EXPECT_LT(sim.state().positions().col(2).minCoeff(), -1e-3);  // it did move
}

TEST(ContactNoContact, FarObstaclesLeaveTheRunBitIdentical) {
  const Problem reference = swinging_square();
  std::vector<std::pair<std::string, Problem>> variants;
  {
    Problem p = reference;
    p.obstacles = {sphere(Eigen::Vector3d(10.0, 0.0, 0.0), 0.1, 0.3)};  // 10 m off
    variants.emplace_back("sphere 10 m off", p);
  }
  {
    Problem p = reference;
    p.obstacles = {plane(Eigen::Vector3d(0, 0, -10.0), Eigen::Vector3d::UnitZ(), 0.3)};  // 10 m below
    variants.emplace_back("plane 10 m below", p);
  }
  {
    Problem p = reference;
    p.collision.self = true;  // a flat hinged square never comes near itself in 20 steps
    variants.emplace_back("self-collision on", p);
  }
  for (const auto& [name, p] : variants) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(p.has_contact());
    Simulator a(reference), b(p);
    long long impulses = 0;
    for (int i = 0; i < a.num_steps(); ++i) {
      a.step();
      impulses += b.step().contact.impulses;
      ASSERT_TRUE(a.state().x == b.state().x) << "step " << i + 1 << ": positions differ by "
                                              << (a.state().x - b.state().x).cwiseAbs().maxCoeff();
      ASSERT_TRUE(a.state().v == b.state().v) << "step " << i + 1 << ": velocities differ by "
                                              << (a.state().v - b.state().v).cwiseAbs().maxCoeff();
    }
    EXPECT_EQ(impulses, 0);
  }
}

// ---------------------------------------------------------------------------------------------
// 3. Resting on a plane (and 6: no energy created while it lands and rests).

// A free 0.1 m square of 8 × 8 cells, flat and level 3 mm above the ground (thickness 1 mm),
// dropped under gravity and run for 0.3 s (it lands after ~20 ms at ~0.2 m/s); friction μ on the
// ground.
struct DropRun {
  double thickness = 1e-3, drop = 3e-3;
  double mass = 0.0, dt = 0.0;
  double lowest = std::numeric_limits<double>::infinity();  // lowest drawn point over the run [m]
  int lowest_step = 0;
  double widest_spread = 0.0;  // largest (highest − lowest) drawn point in one step [m]
  int spread_step = 0;
  double end_low = 0.0, end_high = 0.0;  // drawn points at the end [m]
  double end_kinetic = 0.0, end_elastic = 0.0, fastest = 0.0;
  double most_elastic = 0.0;  // largest elastic energy over the run [J]
  int most_elastic_step = 0;
  double largest_rise = 0.0;  // of kinetic + elastic + gravity's potential from one step to the next [J]
  int rise_step = 0;
  long long impulses = 0, unresolved = 0;
  double seconds = 0.0;
  double drop_energy() const { return mass * kG * drop; }  // [J]
};

DropRun drop_on_ground(double friction, double tolerance = CollisionSettings{}.tolerance) {
  const auto t0 = std::chrono::steady_clock::now();
  DropRun run;
  Problem p = cloth_problem(
      transformed(make_grid(0.1, 0.1, 8, 8), Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, run.drop)), 1e-3, 0.3);
  p.gravity = Eigen::Vector3d(0, 0, -kG);
  p.collision.thickness = run.thickness;
  p.collision.tolerance = tolerance;
  p.obstacles = {ground(friction)};
  Simulator sim(p);
  const SurfaceOperator op = sim.discretization().display(p.collision_level);
  run.mass = sim.vertex_mass().sum();
  run.dt = p.time.dt;
  // Mechanical energy: kinetic + elastic + gravity's potential (minus the work gravity did).
  auto energy = [&] { return sim.kinetic_energy() + sim.elastic_energy() + sim.contact_energy() - sim.external_work(); };
  double previous = energy();
  for (int i = 0; i < sim.num_steps(); ++i) {
    const StepStats s = sim.step();
    run.impulses += contact_acted(s);
    run.unresolved += s.contact.unresolved;
    const Eigen::VectorXd z = drawn_points(sim, op).col(2);
    if (z.minCoeff() < run.lowest) {
      run.lowest = z.minCoeff();
      run.lowest_step = i + 1;
    }
    if (z.maxCoeff() - z.minCoeff() > run.widest_spread) {
      run.widest_spread = z.maxCoeff() - z.minCoeff();
      run.spread_step = i + 1;
    }
    const double e = energy();
    if (e - previous > run.largest_rise) {
      run.largest_rise = e - previous;
      run.rise_step = i + 1;
    }
    previous = e;
    if (sim.elastic_energy() > run.most_elastic) {
      run.most_elastic = sim.elastic_energy();
      run.most_elastic_step = i + 1;
    }
  }
  const Eigen::VectorXd z = drawn_points(sim, op).col(2);
  run.end_low = z.minCoeff();
  run.end_high = z.maxCoeff();
  run.end_kinetic = sim.kinetic_energy();
  run.end_elastic = sim.elastic_energy();
  run.fastest = sim.state().velocities().rowwise().norm().maxCoeff();
  run.seconds = seconds_since(t0);
  return run;
}

TEST(ContactPlane, DroppedClothComesToRestOnTheGround) {
  const DropRun run = drop_on_ground(0.5);
  const double t = run.thickness;
  std::printf("dropped cloth: lowest drawn point %.3e m (step %d; must be ≥ %.1e), at rest %.3e … %.3e m above the ground "
              "(band %.1e … %.1e), kinetic energy %.2e J (bound %.2e J), fastest node %.2e m/s (bound %.2e); %lld impulses; %.2f s\n",
              run.lowest, run.lowest_step, 0.1 * t, run.end_low, run.end_high, 0.1 * t, 2 * t, run.end_kinetic,
              0.5 * run.mass * std::pow(kG * run.dt, 2), run.fastest, kG * run.dt, run.impulses, run.seconds);
  EXPECT_GT(run.impulses, 0);
  EXPECT_EQ(run.unresolved, 0);
  // Never closer than CCD's minimum separation, 10 % of the thickness (rounding allowed).
  EXPECT_GE(run.lowest, 0.1 * t - 1e-12) << "at step " << run.lowest_step;
  // Resting in the band the contact keeps.
  EXPECT_GE(run.end_low, 0.1 * t);
  EXPECT_LE(run.end_high, 2.0 * t);
  // At rest: no node faster than one step of free fall makes (g h; it landed at ~0.2 m/s), so
  // the kinetic energy is below ½ M (g h)².
  EXPECT_LT(run.fastest, kG * run.dt);
  EXPECT_LT(run.end_kinetic, 0.5 * run.mass * std::pow(kG * run.dt, 2));
}

TEST(ContactPlane, FlatLandingStaysFlat) {
  // A flat, level, free square falling onto a level, frictionless plane: every point of it meets
  // the plane at the same instant and the problem is uniform across the sheet (the drawn surface
  // of a flat control net is flat), so the exact motion keeps it flat and unstrained. Allowed: a
  // spread in height of 1 % of the thickness (10 µm), elastic energy below 1e-6 of the drop
  // energy m g (3 mm).
  const DropRun run = drop_on_ground(0.0);
  std::printf("flat landing (μ = 0): widest height spread of the drawn surface %.3e m (step %d; allowed %.1e), largest "
              "elastic energy %.2e J (step %d; %.1e of the drop energy), at the end %.2e J\n",
              run.widest_spread, run.spread_step, 0.01 * run.thickness, run.most_elastic, run.most_elastic_step,
              run.most_elastic / run.drop_energy(), run.end_elastic);
  EXPECT_LE(run.widest_spread, 0.01 * run.thickness) << "at step " << run.spread_step;
  EXPECT_LE(run.most_elastic, 1e-6 * run.drop_energy()) << "at step " << run.most_elastic_step;
}

TEST(ContactEnergy, DroppedClothNeverGainsMechanicalEnergy) {
  // Kinetic + elastic + gravitational potential energy never rises from one step to the next:
  // contact is inelastic and the ground does no work; implicit Euler only dissipates. What is
  // allowed is the contact solver's error, which must go to zero with its tolerance
  // (collision.tolerance, in velocity, a fraction of the thickness per step). The barrier's energy
  // is part of the mechanical energy (a potential energy of the positions). Measured with the
  // barrier: 3.4e-21 J at both tolerances (round-off; its Newton iterations stop on the step solved
  // for, at the tolerance, or at the linear solver's floor); with the constraints method 7.3e-12 J at the default 1e-3 and 8.5e-14 J at 1e-5,
  // against a drop energy of 3.6e-5 J. Bounds: 1e-6 of the drop energy at 1e-3, 1e-8 at 1e-5.
  for (const auto& [tolerance, bound] : {std::pair{1e-3, 1e-6}, std::pair{1e-5, 1e-8}}) {
    const DropRun run = drop_on_ground(0.5, tolerance);
    std::printf("dropped cloth, contact tolerance %.0e: largest rise of the mechanical energy in a step %.2e J (%.1e of the "
                "drop energy %.2e J, step %d)\n",
                tolerance, run.largest_rise, run.largest_rise / run.drop_energy(), run.drop_energy(), run.rise_step);
    EXPECT_LE(run.largest_rise, bound * run.drop_energy()) << "tolerance " << tolerance << ", at step " << run.rise_step;
  }
}

// ---------------------------------------------------------------------------------------------
// 4. Friction on a tilted plane.

struct SlopeRun {
  double along = 0.0;      // displacement of the centre of mass down the slope [m]
  double across = 0.0;     // |displacement| across the slope within the plane [m]
  double lowest = 0.0;     // lowest distance of a drawn point from the plane over the run [m]
  double highest_end = 0.0;  // highest distance of a drawn point from the plane at the end [m]
};

// A 0.1 m square patch of 6 × 6 cells resting on a plane through the origin tilted by θ about
// the y axis (its normal R e_z, downhill R e_x, gravity −z), starting at the thickness above it
// (at the edge of the contact layer, where the barrier starts), at rest; friction μ on the plane
// and between cloth parts.
SlopeRun slide(double theta_deg, double mu, double duration) {
  const double thickness = 1e-3;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(theta_deg * kPi / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d normal = r * Eigen::Vector3d::UnitZ(), downhill = r * Eigen::Vector3d::UnitX();
  Problem p = cloth_problem(transformed(make_grid(0.1, 0.1, 6, 6), r, thickness * normal), 1e-3, duration);
  p.gravity = Eigen::Vector3d(0, 0, -kG);
  p.collision.thickness = thickness;
  p.collision.friction = mu;
  p.obstacles = {plane(Eigen::Vector3d::Zero(), normal, mu)};
  Simulator sim(p);
  const SurfaceOperator op = sim.discretization().display(p.collision_level);
  const Eigen::Vector3d c0 = centre_of_mass(sim);
  SlopeRun run;
  run.lowest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < sim.num_steps(); ++i) {
    const StepStats s = sim.step();
    EXPECT_EQ(s.contact.unresolved, 0) << "step " << i + 1;
    run.lowest = std::min(run.lowest, (drawn_points(sim, op) * normal).minCoeff());
  }
  const Eigen::Vector3d moved = centre_of_mass(sim) - c0;
  run.along = moved.dot(downhill);
  run.across = std::abs(moved.dot(normal.cross(downhill)));
  run.highest_end = (drawn_points(sim, op) * normal).maxCoeff();
  return run;
}

TEST(ContactFriction, PatchSticksBelowTheFrictionAngle) {
  // tan 10° = 0.176 < μ = 0.5: static friction holds the patch.
  const auto t0 = std::chrono::steady_clock::now();
  const SlopeRun run = slide(10.0, 0.5, 0.5);
  std::printf("stick (θ = 10°, μ = 0.5, 0.5 s): moved %.3e m down the slope, %.1e across; lowest point %.2e m, highest at "
              "the end %.2e m; %.2f s\n",
              run.along, run.across, run.lowest, run.highest_end, seconds_since(t0));
  EXPECT_LT(std::abs(run.along), 1e-3);
  EXPECT_LT(run.across, 1e-3);
  EXPECT_GE(run.lowest, 0.1e-3 - 1e-12);
}

TEST(ContactFriction, PatchSlidesAboveTheFrictionAngleWithCoulombDeceleration) {
  // tan 30° = 0.577 > μ = 0.2: the patch slides with a = g (sin θ − μ cos θ) = 3.206 m/s².
  // Expected distance ½ a T². Tolerance 2 %: implicit Euler's own error is (n + 1)/n − 1 = 0.3 %
  // for n = 300 steps, and the contact solver's tolerance (1e-4 thickness per step) moves the
  // friction impulse by far less.
  const auto t0 = std::chrono::steady_clock::now();
  const double theta = 30.0 * kPi / 180.0, mu = 0.2, duration = 0.3;
  const SlopeRun run = slide(30.0, mu, duration);
  const double expected = 0.5 * kG * (std::sin(theta) - mu * std::cos(theta)) * duration * duration;
  const double frictionless = 0.5 * kG * std::sin(theta) * duration * duration;
  std::printf("slide (θ = 30°, μ = 0.2, %.1f s): %.4f m down the slope vs %.4f m expected (%+.1f %%; frictionless %.4f m), "
              "%.1e across; lowest point %.2e m; %.2f s\n",
              duration, run.along, expected, 100.0 * (run.along / expected - 1.0), frictionless, run.across, run.lowest,
              seconds_since(t0));
  EXPECT_NEAR(run.along, expected, 0.02 * expected);
  EXPECT_LT(run.across, 1e-3);
  EXPECT_GE(run.lowest, 0.1e-3 - 1e-12);
}

TEST(ContactFriction, FlatClothRestingWithFrictionStaysUnstrained) {
  // The flat landing of ContactPlane.FlatLandingStaysFlat on ground with μ = 0.5: nothing moves
  // along the plane, so friction has nothing to resist and the exact motion stays unstrained.
  // Allowed: elastic energy below 1e-6 of the drop energy at every step.
  const DropRun run = drop_on_ground(0.5);
  std::printf("flat landing (μ = 0.5): largest elastic energy %.2e J (step %d; %.1e of the drop energy), at the end %.2e J\n",
              run.most_elastic, run.most_elastic_step, run.most_elastic / run.drop_energy(), run.end_elastic);
  EXPECT_LE(run.most_elastic, 1e-6 * run.drop_energy()) << "at step " << run.most_elastic_step;
}

// ---------------------------------------------------------------------------------------------
// 5, 6. Two free patches colliding: momentum and energy.

// Uniform accelerations, +a on the nodes before `first_b` and −a·M_A/M_B on the others, while
// t ≤ until: equal and opposite total forces (an internal push; Σ f = 0 up to rounding).
class PushTogether final : public ForceTerm {
 public:
  PushTogether(const Eigen::VectorXd& node_mass, int first_b, const Eigen::Vector3d& a, double until)
      : mass_(node_mass), first_b_(first_b), a_(a), until_(until) {
    const double m_a = mass_.head(first_b).sum(), m_b = mass_.tail(mass_.size() - first_b).sum();
    ratio_ = m_a / m_b;
  }
  std::string name() const override { return "push together"; }
  void update(const Eigen::VectorXd&, const Eigen::VectorXd&, double t) override { active_ = t <= until_ + 1e-12; }
  void add_force(Eigen::VectorXd& f) const override {
    if (!active_) return;
    for (Eigen::Index v = 0; v < mass_.size(); ++v)
      f.segment<3>(3 * v) += (v < first_b_ ? 1.0 : -ratio_) * mass_(v) * a_;
  }

 private:
  Eigen::VectorXd mass_;
  Eigen::Index first_b_;
  Eigen::Vector3d a_;
  double until_, ratio_ = 1.0;
  bool active_ = false;
};

// Patch A (0.06 m square, 6 × 6 cells) flat at z = +1 cm; patch B the same, tilted by 15° about
// x and shifted 1 cm along x, at z = −1 cm (gap ≥ 1.2 cm): one mesh of two parts. No gravity;
// self-collision on (thickness 1 mm, friction 0.3). An internal push for the first 10 ms
// (±25 m/s²) sends them towards each other at 0.25 m/s each; everything drifts at (0.3, 0.1, 0).
// Run for 0.1 s at h = 1 ms; B's raised edge meets A first.
struct CollisionRun {
  bool built = false;
  int first_contact = 0;   // step of the first impulse
  double dt = 0.0, push_until = 0.01;
  long long impulses = 0, zones = 0, unresolved = 0;
  double scale = 0.0;      // Σ m |v| when the push ends [kg·m/s]
  double p0 = 0.0;         // |Σ m v| at the start [kg·m/s]
  double worst_momentum = 0.0;  // max |Σ m v − p0| / scale after the push
  int worst_momentum_step = 0;
  double before_contact = 0.0, end_energy = 0.0;  // kinetic + elastic [J]
  double largest_rise = 0.0;  // from one step to the next, after the push [J]
  int rise_step = 0;
  double rise_kinetic = 0.0, rise_elastic = 0.0;  // the two parts of that step's change [J]
  long long self_pairs = 0;   // self-intersecting pairs of the drawn surface, summed over steps
  double seconds = 0.0;
};

CollisionRun collide_patches() {
  const auto t0 = std::chrono::steady_clock::now();
  CollisionRun run;
  const TriMesh a = transformed(make_grid(0.06, 0.06, 6, 6), Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 0.01));
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(15.0 * kPi / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const TriMesh b = transformed(make_grid(0.06, 0.06, 6, 6), tilt, Eigen::Vector3d(0.01, 0, -0.01));
  Problem p = cloth_problem(testing::concatenated(a, b), 1e-3, 0.1);
  p.collision.self = true;
  p.collision.friction = 0.3;
  p.initial.velocity = Eigen::Vector3d(0.3, 0.1, 0.0);
  run.dt = p.time.dt;
  std::unique_ptr<Simulator> made;
  try {
    made = std::make_unique<Simulator>(p);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "the Loop shell rejects a mesh of two parts: " << e.what();
    return run;
  }
  run.built = true;
  Simulator& sim = *made;
  EXPECT_EQ(sim.num_vertices(), a.num_vertices() + b.num_vertices());
  sim.add_term(std::make_unique<PushTogether>(sim.vertex_mass(), a.num_vertices(), Eigen::Vector3d(0, 0, -25.0), run.push_until));
  const SurfaceOperator op = sim.discretization().display(p.collision_level);
  const Eigen::Vector3d p0 = momentum(sim);
  run.p0 = p0.norm();
  double previous_kinetic = 0.0, previous_elastic = 0.0;
  for (int i = 0; i < sim.num_steps(); ++i) {
    const StepStats s = sim.step();
    run.unresolved += s.contact.unresolved;
    run.impulses += contact_acted(s);
    run.zones += s.contact.impact_zones;
    if (contact_acted(s) > 0 && run.first_contact == 0) run.first_contact = i + 1;
    // (the barrier's energy with the elastic: both are potential energies of the positions)
    const double kinetic = sim.kinetic_energy(), elastic = sim.elastic_energy() + sim.contact_energy();
    if (run.scale == 0.0 && sim.state().t > run.push_until + 1e-9) {
      run.scale = (sim.state().velocities().rowwise().norm().transpose() * sim.vertex_mass())(0);
      run.before_contact = kinetic + elastic;
    } else if (run.scale > 0.0) {
      const double change = (momentum(sim) - p0).norm() / run.scale;
      if (change > run.worst_momentum) {
        run.worst_momentum = change;
        run.worst_momentum_step = i + 1;
      }
      const double rise = (kinetic + elastic) - (previous_kinetic + previous_elastic);
      if (rise > run.largest_rise) {
        run.largest_rise = rise;
        run.rise_step = i + 1;
        run.rise_kinetic = kinetic - previous_kinetic;
        run.rise_elastic = elastic - previous_elastic;
      }
    }
    previous_kinetic = kinetic;
    previous_elastic = elastic;
    run.self_pairs += check::self_intersections(to_surface(drawn_points(sim, op), op.triangles)).intersecting_pairs;
  }
  run.end_energy = sim.kinetic_energy() + sim.elastic_energy() + sim.contact_energy();
  run.seconds = seconds_since(t0);
  return run;
}

TEST(ContactMomentum, CollidingClothPartsKeepTheirTotalMomentum) {
  // The push is internal (Σ f = 0) and the rest is contact between parts of the cloth, so
  // Σ m_v v_v stays what it was at the start, to 1e-9 of Σ m_v |v_v| (the size of the motion).
  const CollisionRun run = collide_patches();
  ASSERT_TRUE(run.built);
  std::printf("colliding patches: first impulse at step %d (t = %.3f s), %lld impulses, %lld impact zones, %lld unresolved; worst "
              "momentum change %.2e of Σ m|v| = %.3e kg·m/s (step %d; |p0| = %.3e); %lld self-intersecting pairs; %.2f s\n",
              run.first_contact, run.first_contact * run.dt, run.impulses, run.zones, run.unresolved, run.worst_momentum,
              run.scale, run.worst_momentum_step, run.p0, run.self_pairs, run.seconds);
  ASSERT_GT(run.first_contact, 0) << "the patches never met";
  EXPECT_GT(run.first_contact * run.dt, run.push_until);  // contact came after the push
  EXPECT_GT(run.impulses, 100);                            // and was substantial
  EXPECT_LT(run.worst_momentum, 1e-9) << "at step " << run.worst_momentum_step;
  EXPECT_EQ(run.unresolved, 0);
  EXPECT_EQ(run.self_pairs, 0);
}

TEST(ContactEnergy, CollidingClothPartsNeverGainEnergy) {
  // After the push, kinetic + elastic energy is constant in free flight and can only fall in an
  // inelastic collision (implicit Euler dissipates too): it never rises from one step to the next
  // by more than 1e-9 of the energy before contact, and ends below it.
  const CollisionRun run = collide_patches();
  ASSERT_TRUE(run.built);
  ASSERT_GT(run.first_contact, 0) << "the patches never met";
  std::printf("colliding patches: energy %.4e J before contact (step %d), %.4e J at the end; largest rise in a step %.2e J "
              "(%.1e of it) at step %d: kinetic %+.2e J, elastic %+.2e J\n",
              run.before_contact, run.first_contact, run.end_energy, run.largest_rise, run.largest_rise / run.before_contact,
              run.rise_step, run.rise_kinetic, run.rise_elastic);
  EXPECT_LE(run.largest_rise, 1e-9 * run.before_contact) << "at step " << run.rise_step;
  EXPECT_LT(run.end_energy, run.before_contact);
}

// A 0.3 m cotton square (12 × 12 cells) thrown at 2.4 m/s onto a ball of radius 5 cm with
// h = 10 ms: the ball turns the elements over it by up to 40° within a step. Nothing here adds
// energy (gravity's work is counted; contact and implicit Euler only dissipate), so kinetic +
// elastic + barrier energy never exceeds the start's kinetic energy plus gravity's work.
struct ImpactRun {
  double start_kinetic = 0.0;
  double largest_surplus = -std::numeric_limits<double>::infinity();  // max of energy − (KE₀ + work) [J]
  int surplus_step = 0;
  double most_elastic = 0.0;  // [J]
  long long relinearisations = 0, unresolved = 0;
  double seconds = 0.0;
};

ImpactRun throw_on_ball(double rotation_tolerance_deg) {
  const auto t0 = std::chrono::steady_clock::now();
  Problem p = cloth_problem(transformed(make_grid(0.3, 0.3, 12, 12), Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 0.06)),
                            0.01, 0.15);
  p.gravity = Eigen::Vector3d(0, 0, -kG);
  p.collision.thickness = 2e-3;
  p.obstacles = {sphere(Eigen::Vector3d::Zero(), 0.05, 0.0)};
  p.initial.velocity = Eigen::Vector3d(0, 0, -2.4);
  p.solver.rotation_tolerance_deg = rotation_tolerance_deg;
  Simulator sim(p);
  ImpactRun run;
  run.start_kinetic = sim.kinetic_energy();
  for (int i = 0; i < sim.num_steps(); ++i) {
    const StepStats s = sim.step();
    run.relinearisations += s.contact.relinearisations;
    run.unresolved += s.contact.unresolved;
    run.most_elastic = std::max(run.most_elastic, sim.elastic_energy());
    const double surplus =
        sim.kinetic_energy() + sim.elastic_energy() + sim.contact_energy() - run.start_kinetic - sim.external_work();
    if (surplus > run.largest_surplus) {
      run.largest_surplus = surplus;
      run.surplus_step = i + 1;
    }
  }
  run.seconds = seconds_since(t0);
  return run;
}

TEST(ContactEnergy, FastImpactStoresNoSpuriousStrain) {
  // With the rotations frozen over each step (rotation_tolerance_deg = 180: never re-linearised)
  // the elements turned by the ball keep their start-of-step frames and the step stores strain
  // the motion never put there; re-linearising at the end positions (the default, 6°) removes it.
  // Allowed surplus: 1 % of the start's kinetic energy.
  const ImpactRun frozen = throw_on_ball(180.0);
  const ImpactRun followed = throw_on_ball(6.0);
  for (const auto& [name, run] : {std::pair{"frozen", &frozen}, std::pair{"followed", &followed}})
    std::printf("ball impact at h = 10 ms, rotations %s: largest energy surplus %.3e J (step %d) against KE0 %.3e J, largest "
                "elastic energy %.3e J, %lld re-linearised steps, %lld unresolved; %.2f s\n",
                name, run->largest_surplus, run->surplus_step, run->start_kinetic, run->most_elastic, run->relinearisations,
                run->unresolved, run->seconds);
  EXPECT_GT(frozen.largest_surplus, 0.1 * frozen.start_kinetic);  // (the test can see the defect)
  EXPECT_EQ(frozen.relinearisations, 0);
  EXPECT_GT(followed.relinearisations, 0);
  EXPECT_LE(followed.largest_surplus, 0.01 * followed.start_kinetic) << "at step " << followed.surplus_step;
  EXPECT_EQ(followed.unresolved, 0);
}

// ---------------------------------------------------------------------------------------------
// 7, 8. The drawn surface never intersects itself, the obstacles or the ground.

struct IntersectionTally {
  int steps = 0;
  long long self_pairs = 0, obstacle_pairs = 0;
  int first_bad_step = 0;
  std::string first_bad;  // what was seen at the first bad step
  double lowest = std::numeric_limits<double>::infinity();  // lowest drawn point in front of a plane [m]
  long long unresolved = 0, impulses = 0, zones = 0;
  double contact_ms = 0.0, check_seconds = 0.0;
};

// Steps `sim` to its end; after every step evaluates the drawn surface at refinement `level` and
// checks it against itself and every obstacle mesh (exact CGAL test), and its points against
// every plane obstacle (signed distance in front of the plane at that time).
IntersectionTally run_and_check(Simulator& sim, const Problem& p, int level) {
  const SurfaceOperator op = sim.discretization().display(level);
  IntersectionTally tally;
  for (int i = 0; i < sim.num_steps(); ++i) {
    const StepStats s = sim.step();
    tally.unresolved += s.contact.unresolved;
    tally.impulses += contact_acted(s);
    tally.zones += s.contact.impact_zones;
    tally.contact_ms += s.contact.ms;
    const auto t0 = std::chrono::steady_clock::now();
    ++tally.steps;
    const double t = sim.state().t;
    const Eigen::MatrixX3d points = drawn_points(sim, op);
    const check::Surface cloth = to_surface(points, op.triangles);
    const check::IntersectionReport self = check::self_intersections(cloth);
    long long obstacle_pairs = 0;
    double lowest = std::numeric_limits<double>::infinity();
    std::string what;
    if (self.intersecting_pairs > 0)
      what += " self: " + std::to_string(self.intersecting_pairs) + " pairs, e.g. triangles " +
              std::to_string(self.examples.front().first) + " and " + std::to_string(self.examples.front().second) + ";";
    for (const Obstacle& o : p.obstacles) {
      if (o.shape == Obstacle::Shape::plane) {
        Eigen::Vector3d q, n;
        plane_at(o, t, q, n);
        const double d = ((points.rowwise() - q.transpose()) * n).minCoeff();
        lowest = std::min(lowest, d);
        if (d <= 0.0) what += " behind " + o.name + ": " + std::to_string(d) + " m;";
        continue;
      }
      const check::IntersectionReport r = check::intersections(cloth, to_surface(mesh_at(o, t), o.mesh.triangles));
      obstacle_pairs += r.intersecting_pairs;
      if (r.intersecting_pairs > 0)
        what += " " + o.name + ": " + std::to_string(r.intersecting_pairs) + " pairs, e.g. cloth triangle " +
                std::to_string(r.examples.front().first) + " with obstacle triangle " + std::to_string(r.examples.front().second) + ";";
    }
    tally.lowest = std::min(tally.lowest, lowest);
    tally.self_pairs += self.intersecting_pairs;
    tally.obstacle_pairs += obstacle_pairs;
    if (!what.empty() && tally.first_bad_step == 0) {
      tally.first_bad_step = i + 1;
      tally.first_bad = "step " + std::to_string(i + 1) + " (t = " + std::to_string(t) + " s):" + what;
    }
    tally.check_seconds += seconds_since(t0);
  }
  return tally;
}

void report(const char* name, const IntersectionTally& t, double seconds) {
  std::printf("%s: %d steps checked, self-intersecting pairs %lld, cloth–obstacle pairs %lld, lowest point %.3e m in front "
              "of the ground, %lld impulses, %lld impact zones, %lld unresolved; contact %.2f s, checks %.2f s, total %.2f s%s%s\n",
              name, t.steps, t.self_pairs, t.obstacle_pairs, t.lowest, t.impulses, t.zones, t.unresolved, 1e-3 * t.contact_ms,
              t.check_seconds, seconds, t.first_bad.empty() ? "" : "; first: ", t.first_bad.c_str());
}

// A square sheet (side `size`, n × n cells) held flat at (x, y, z) and dropped under gravity onto
// `obstacles`, with light damping, self-collision, 2 mm thickness and cloth friction 0.3.
Problem dropped_sheet(double size, int n, const Eigen::Vector3d& at, double end, std::vector<Obstacle> obstacles) {
  Problem p = cloth_problem(transformed(make_grid(size, size, n, n), Eigen::Matrix3d::Identity(), at), 2e-3, end);
  p.gravity = Eigen::Vector3d(0, 0, -kG);
  p.damping.stiffness = 0.001;
  p.damping.mass = 0.1;
  p.collision.self = true;
  p.collision.thickness = 2e-3;
  p.collision.friction = 0.3;
  p.obstacles = std::move(obstacles);
  return p;
}

// The run made contact and every step's drawn surface was free of intersections.
void expect_clean(const IntersectionTally& t) {
  EXPECT_GT(t.impulses, 0);
  EXPECT_EQ(t.self_pairs, 0) << t.first_bad;
  EXPECT_EQ(t.obstacle_pairs, 0) << t.first_bad;
  EXPECT_EQ(t.unresolved, 0);
}

TEST(ContactIntersections, SheetFallingOnASphereStaysIntersectionFree) {
  const auto t0 = std::chrono::steady_clock::now();
  // sheet_on_sphere, smaller: 0.3 m square of 12 × 12 cells held flat 0.2 m up, dropped over a
  // ball of radius 0.08 m resting on the ground.
  const Problem p =
      dropped_sheet(0.3, 12, Eigen::Vector3d(0, 0, 0.2), 0.4, {ground(0.5), sphere(Eigen::Vector3d(0, 0, 0.08), 0.08, 0.3)});
  Simulator sim(p);
  const IntersectionTally t = run_and_check(sim, p, p.collision_level);
  report("sheet on sphere (12 × 12, level 1, 0.4 s)", t, seconds_since(t0));
  expect_clean(t);
  EXPECT_GT(t.lowest, 0.0) << t.first_bad;
  // It draped: the sheet's centre rests on the ball's top (0.16 m + the thickness).
  const Eigen::MatrixX3d nodes = sim.node_points();
  EXPECT_NEAR(nodes(6 * 13 + 6, 2), 0.16 + p.collision.thickness, 2.0 * p.collision.thickness);
}

TEST(ContactIntersections, SheetDrapedOverABoxStaysIntersectionFree) {
  const auto t0 = std::chrono::steady_clock::now();
  // A 0.2 m square (10 × 10 cells) dropped from 3 cm over a 0.1 m cube on the ground: it lies on
  // the top face (two coplanar triangles: their shared diagonal makes no edge pairs) and folds
  // over the four sharp edges and corners.
  Obstacle box;
  box.name = "box";
  box.shape = Obstacle::Shape::box;
  box.center = Eigen::Vector3d(0, 0, 0.05);
  box.size = Eigen::Vector3d(0.1, 0.1, 0.1);
  box.friction = 0.3;
  box.mesh = tessellate(box);
  const Problem p = dropped_sheet(0.2, 10, Eigen::Vector3d(0.01, 0.02, 0.13), 0.3, {ground(0.5), box});
  Simulator sim(p);
  const IntersectionTally t = run_and_check(sim, p, p.collision_level);
  report("sheet over a box (10 × 10, 0.3 s)", t, seconds_since(t0));
  expect_clean(t);
  // It hangs over the edges: drawn points below the top face, the middle resting on it.
  const Eigen::MatrixX3d nodes = sim.node_points();
  EXPECT_LT(nodes.col(2).minCoeff(), 0.08);
  EXPECT_NEAR(nodes(5 * 11 + 5, 2), 0.1 + p.collision.thickness, 2.0 * p.collision.thickness);
}

// The flat-region cull (docs/contact.md) only drops pairs that cannot meet: the sheet draped over
// the ball (folds, self-contact) runs the same with and without it, while testing far fewer
// pairs. (With the constraints method, whose narrow phase tests every candidate in every step:
// with the barrier, distance bounds leave most candidates untested either way.)
TEST(ContactCulling, FlatRegionsDropPairsButChangeNothing) {
  struct Run {
    Eigen::VectorXd x;
    long long pairs = 0;
    int impulses = 0;
  };
  auto run = [](double angle) {
    Problem p = dropped_sheet(0.3, 12, Eigen::Vector3d(0, 0, 0.2), 0.4, {ground(0.5), sphere(Eigen::Vector3d(0, 0, 0.08), 0.08, 0.3)});
    p.collision.flat_region_angle = angle;
    p.collision.barrier = false;
    Simulator sim(p);
    Run r;
    for (int i = 0; i < sim.num_steps(); ++i) {
      const StepStats s = sim.step();
      r.pairs += s.contact.pairs_tested;
      r.impulses += contact_acted(s);
    }
    r.x = sim.state().x;
    return r;
  };
  const Run culled = run(CollisionSettings{}.flat_region_angle), all = run(0.0);
  const double difference = (culled.x - all.x).cwiseAbs().maxCoeff();
  std::printf("flat-region cull: %lld pairs tested (every pair: %lld), %d impulses (%d), largest position difference %.3e m\n",
              culled.pairs, all.pairs, culled.impulses, all.impulses, difference);
  EXPECT_GT(all.impulses, 0);
  EXPECT_LT(static_cast<double>(culled.pairs), 0.9 * static_cast<double>(all.pairs));  // most are pairs with the ball
  EXPECT_EQ(difference, 0.0);
  // The cone must stay narrower than a right angle.
  Problem bad = dropped_sheet(0.3, 4, Eigen::Vector3d(0, 0, 0.2), 0.01, {ground(0.5)});
  bad.collision.flat_region_angle = 0.5 * kPi;
  EXPECT_THROW(Simulator{bad}, std::invalid_argument);
}

// Smallest distance between drawn points whose rest positions are more than `apart` apart [m]:
// how close two layers of a fold come (a point pair is never closer than the surfaces).
double closest_layers(const Simulator& sim, const SurfaceOperator& op, double apart) {
  const Eigen::MatrixX3d x = drawn_points(sim, op), r = sim.rest_surface_points(op);
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    for (Eigen::Index j = i + 1; j < x.rows(); ++j)
      if ((r.row(i) - r.row(j)).squaredNorm() > apart * apart) best = std::min(best, (x.row(i) - x.row(j)).norm());
  return best;
}

TEST(ContactIntersections, StripFoldedOverItselfStaysIntersectionFree) {
  const auto t0 = std::chrono::steady_clock::now();
  // A 0.2 m × 0.05 m strip (20 × 5 cells) lying on the ground at 1.5 × thickness. Its end
  // x = +0.1 m is lifted and carried over like a towel being folded: rotated by 180° about the
  // y axis through (0.015, 0, 4 mm) in 0.5 s (ending at x = −0.07 m, 6.5 mm up), then pressed
  // down 4.5 mm in 0.1 s and held: the right half lies folded on the left half, in self-contact.
  const double thickness = 1e-3;
  Problem p = cloth_problem(
      transformed(make_grid(0.2, 0.05, 20, 5), Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 1.5 * thickness)), 1e-3, 0.8);
  p.gravity = Eigen::Vector3d(0, 0, -kG);
  p.collision.self = true;
  p.collision.thickness = thickness;
  p.collision.friction = 0.3;
  p.obstacles = {ground(0.5)};
  BoundaryCondition end;
  for (int v = 0; v < p.mesh.num_vertices(); ++v)
    if (p.mesh.vertices(v, 0) > 0.1 - 1e-9) end.vertices.push_back(v);
  Motion over;
  over.type = Motion::Type::rotate;
  over.axis = Eigen::Vector3d::UnitY();
  over.center = Eigen::Vector3d(0.015, 0, 0.004);
  over.angle_deg = -180.0;  // up first, then over to −x
  over.start = 0.0;
  over.end = 0.5;
  Motion press;
  press.type = Motion::Type::translate;
  press.displacement = Eigen::Vector3d(0, 0, -0.0045);
  press.start = 0.5;
  press.end = 0.6;
  end.motion = {over, press};
  p.boundary = {end};
  Simulator sim(p);
  const IntersectionTally t = run_and_check(sim, p, p.collision_level);
  const double layers = closest_layers(sim, sim.discretization().display(p.collision_level), 0.03);
  report("strip folded over itself (20 × 5, level 1, 0.8 s)", t, seconds_since(t0));
  std::printf("strip folded over itself: the layers end %.3e m apart (thickness %.1e)\n", layers, thickness);
  EXPECT_GT(t.impulses, 0);
  EXPECT_EQ(t.self_pairs, 0) << t.first_bad;
  EXPECT_GT(t.lowest, 0.0) << t.first_bad;
  EXPECT_EQ(t.unresolved, 0);
  // It is folded and the layers touch: parts of the cloth more than 3 cm apart in the material
  // lie within two thicknesses of each other, and no closer than CCD's 10 %.
  EXPECT_NEAR(sim.state().positions()(end.vertices.front(), 0), -0.07, 1e-9);
  EXPECT_LT(layers, 2.0 * thickness);
  EXPECT_GE(layers, 0.1 * thickness);
}

TEST(ContactIntersections, SheetOnSphereSceneStaysIntersectionFree) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::filesystem::path file = std::filesystem::path(CLOTHSIM_SOURCE_DIR) / "scenes" / "sheet_on_sphere.json";
  Scene scene = load_scene(file, nullptr);
  Problem& p = scene.problem;
  p.time.end = 0.2;  // the sheet reaches the ball well within this
  // (The scene is y-up: its ground is the plane y = 0.)
  Simulator sim(p);
  const IntersectionTally tally = run_and_check(sim, p, p.collision_level);
  const std::string name = "scene sheet_on_sphere (" + std::to_string(p.mesh.num_triangles()) + " triangles, collision level " + std::to_string(p.collision_level) + ", " +
                           std::to_string(sim.discretization().display(p.collision_level).triangles.size()) + " drawn triangles, to 0.2 s)";
  report(name.c_str(), tally, seconds_since(t0));
  EXPECT_GT(tally.impulses, 0);
  EXPECT_EQ(tally.self_pairs, 0) << tally.first_bad;
  EXPECT_EQ(tally.obstacle_pairs, 0) << tally.first_bad;
  EXPECT_GT(tally.lowest, 0.0) << tally.first_bad;
  EXPECT_EQ(tally.unresolved, 0);
}

TEST(ContactNewton, CrushedSleeveConvergesWithoutTheFailSafe) {
  // sleeve_compress (a cotton sleeve, self-collision on) crushed by 60 % of its length in 0.6 s on
  // a coarser mesh (18 × 13): folds are pressed onto folds, and in sharp folds neighbouring parts
  // of the surface (near each other at rest, kept from crossing by CCD alone until the barrier
  // held them at half their rest distance) are pressed into each other. Newton then converges in
  // a few solves per step, and the fail-safe has nothing to do. Measured: at most 4 solves in a
  // step, 830 in 700 steps, 0 impulses; without the near pairs' barrier 996 solves, 15 steps above
  // 4 and one at the cap of 12 (the full-size crush: 12 in every step from 0.8 s on). These are
  // the perfect sleeve's numbers; the shipped scene's 0.1 mm imperfection (2026-11-29) folds it
  // otherwise and is left out here. With it: 1388 solves in 700 steps, the cap of 12 reached at
  // step 550, still 0 impulses, 0 unresolved and no crossing.
  const auto t0 = std::chrono::steady_clock::now();
  const std::filesystem::path file = std::filesystem::path(CLOTHSIM_SOURCE_DIR) / "scenes" / "sleeve_compress.json";
  Scene scene = load_scene(file, nullptr,
                           {"boundary[1].motion[0].displacement=[0,-0.12,0]", "boundary[1].motion[0].end=0.6", "mesh.segments=18",
                            "mesh.rings=13", "time.end=0.7", "imperfection=null"});
  const Problem& p = scene.problem;
  Simulator sim(p);
  long long solves = 0, impulses = 0, unresolved = 0;
  int most = 0, most_step = 0;
  for (int i = 0; i < sim.num_steps(); ++i) {
    const StepStats s = sim.step();
    solves += s.contact.newton_iterations;
    impulses += s.contact.impulses;
    unresolved += s.contact.unresolved;
    if (s.contact.newton_iterations > most) {
      most = static_cast<int>(s.contact.newton_iterations);
      most_step = i + 1;
    }
  }
  const SurfaceOperator op = sim.discretization().display(p.collision_level);
  const long long crossing = check::self_intersections(to_surface(drawn_points(sim, op), op.triangles)).intersecting_pairs;
  std::printf("crushed sleeve (18 x 13, 60 %% in 0.6 s): %lld Newton solves in %d steps (at most %d, step %d), %lld fail-safe "
              "impulses, %lld unresolved, %lld crossing pairs of the drawn surface at the end; %.2f s\n",
              solves, sim.num_steps(), most, most_step, impulses, unresolved, crossing, seconds_since(t0));
  EXPECT_LE(most, 6) << "at step " << most_step;
  EXPECT_LE(static_cast<double>(solves), 1.3 * sim.num_steps());
  EXPECT_EQ(impulses, 0);
  EXPECT_EQ(unresolved, 0);
  EXPECT_EQ(crossing, 0);
}

}  // namespace
}  // namespace clothsim

// The contact stage's candidate search (sim/contact/candidates.hpp), built directly on small
// surfaces made with the public mesh and refinement functions, against independent references:
// a brute force over every point–triangle and edge–edge pair of two sheets gives exactly the
// pairs whose grown swept boxes overlap (near pairs and pairs joined at rest too), which hold
// every pair within the thickness and no point with its own triangle; a point moving into an
// obstacle over the step is found; a flat sheet makes no self pairs while a sharp fold keeps its
// pairs across the crease; and the list is the same, in the same order, every time.
//
// Conventions: grids lie in z = 0 (sim/mesh/generators.hpp), the thickness is 1 mm; lengths [m].
#include "tests/support/test_meshes.hpp"
#include "sim/contact/candidates.hpp"

#include "sim/contact/narrow_phase.hpp"
#include "sim/discretization/flat_refinement.hpp"
#include "sim/mesh/generators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <initializer_list>
#include <random>
#include <set>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

namespace clothsim::contact {
namespace {

constexpr double kThickness = 1e-3;
constexpr double kPi = 3.14159265358979323846;

// A collision surface over `mesh`: its triangles refined `levels` times (flat), with edges and
// ownership, and the points' rest positions. Holds what a SearchSurface refers to.
struct Cloth {
  TriMesh mesh;
  SurfaceOperator op;
  Eigen::MatrixX3d rest;
  std::vector<std::array<int, 2>> edges;
  std::vector<std::array<int, 3>> triangle_edges;
  std::vector<std::vector<int>> owned_points, owned_edges;
  std::vector<int> point_owner, edge_owner;  // the fine triangle that owns each

  Cloth(TriMesh m, int levels) : mesh(std::move(m)) {
    op = midpoint_display(mesh, levels, mesh.num_vertices());
    rest = op.position * mesh.vertices;
    build_edges(op.triangles, edges, triangle_edges);
    build_ownership(op.triangles, static_cast<int>(rest.rows()), triangle_edges, static_cast<int>(edges.size()), owned_points,
                    owned_edges);
    point_owner.assign(static_cast<size_t>(rest.rows()), -1);
    edge_owner.assign(edges.size(), -1);
    for (size_t t = 0; t < op.triangles.size(); ++t) {
      for (int v : owned_points[t]) point_owner[static_cast<size_t>(v)] = static_cast<int>(t);
      for (int e : owned_edges[t]) edge_owner[static_cast<size_t>(e)] = static_cast<int>(t);
    }
  }
  Cloth(const Cloth&) = delete;

  SearchSurface surface() const {
    return {op.triangles, op.levels, edges, triangle_edges, owned_points, owned_edges, mesh.triangles, mesh.num_vertices()};
  }
  int patch(int fine) const { return fine >> (2 * op.levels); }
  bool neighbours(int fine_a, int fine_b) const {
    return shares_vertex(mesh.triangles[static_cast<size_t>(patch(fine_a))], mesh.triangles[static_cast<size_t>(patch(fine_b))]);
  }
};

// Two 1 cm squares of 2 × 2 cells, the second `gap` above the first and shifted a little.
TriMesh two_sheets(double gap = 1.2e-3) {
  TriMesh lower = make_grid(0.01, 0.01, 2, 2);
  TriMesh upper = make_grid(0.01, 0.01, 2, 2);
  upper.vertices.col(0).array() += 0.0013;
  upper.vertices.col(2).array() += gap;
  return testing::concatenated(lower, upper);
}

CandidateSettings self_settings(double flat_region_angle) {
  CandidateSettings s;
  s.self = true;
  s.thickness = kThickness;
  s.flat_region_angle = flat_region_angle;
  return s;
}

// The rest points jittered by up to `amount` per coordinate (seeded).
Eigen::MatrixX3d jittered(const Eigen::MatrixX3d& p, double amount, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount, amount);
  Eigen::MatrixX3d out = p;
  for (Eigen::Index i = 0; i < out.rows(); ++i)
    for (int k = 0; k < 3; ++k) out(i, k) += u(rng);
  return out;
}

// A candidate with its near flag, comparable.
using Key = std::tuple<int, int, int, bool>;
Key key(const Candidate& c) { return {static_cast<int>(c.kind), c.a, c.b, c.near}; }
std::vector<Key> keys(const std::vector<Candidate>& cands) {
  std::vector<Key> out;
  for (const Candidate& c : cands) out.push_back(key(c));
  return out;
}
std::vector<Key> sorted_keys(const std::vector<Candidate>& cands) {
  std::vector<Key> out = keys(cands);
  std::sort(out.begin(), out.end());
  return out;
}

// The reference's boxes, written out here: the corners' start and end positions, grown by g.
struct RefBox {
  Eigen::Vector3d lo, hi;
};
RefBox ref_box(const Eigen::MatrixX3d& p0, const Eigen::MatrixX3d& p1, std::initializer_list<int> points, double g) {
  RefBox b{Eigen::Vector3d::Constant(1e300), Eigen::Vector3d::Constant(-1e300)};
  for (int v : points)
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = std::min({b.lo[k], p0(v, k), p1(v, k)});
      b.hi[k] = std::max({b.hi[k], p0(v, k), p1(v, k)});
    }
  b.lo.array() -= g;
  b.hi.array() += g;
  return b;
}
bool ref_overlap(const RefBox& a, const RefBox& b) {
  for (int k = 0; k < 3; ++k)
    if (a.lo[k] > b.hi[k] || b.lo[k] > a.hi[k]) return false;
  return true;
}

// Brute force over every point–triangle and edge–edge pair of fine triangles in different
// patches: the pairs the search is documented to return (obstacles aside). Patches with a control
// vertex in common, and fine triangle pairs `near_at_rest(i, j)` (i < j), are near pairs, their
// boxes grown by the near separation; near pairs `joined(i, j)` make no pairs.
std::vector<Key> brute_force(const Cloth& c, const Eigen::MatrixX3d& p0, const Eigen::MatrixX3d& p1, double grow,
                             const std::function<bool(int, int)>& near_at_rest = {},
                             const std::function<bool(int, int)>& joined = {}) {
  const double near_growth = 0.01 * kThickness;
  auto classify = [&](int i, int j, bool& near) {  // false: no pair
    if (c.patch(i) == c.patch(j)) return false;
    const int lo = std::min(i, j), hi = std::max(i, j);
    near = c.neighbours(i, j) || (near_at_rest && near_at_rest(lo, hi));
    return !(near && joined && joined(lo, hi));
  };
  std::vector<Key> out;
  const auto& tris = c.op.triangles;
  for (int v = 0; v < static_cast<int>(c.rest.rows()); ++v)
    for (int j = 0; j < static_cast<int>(tris.size()); ++j) {
      const Triangle& t = tris[static_cast<size_t>(j)];
      bool near = false;
      if (v == t[0] || v == t[1] || v == t[2] || !classify(c.point_owner[static_cast<size_t>(v)], j, near)) continue;
      if (ref_overlap(ref_box(p0, p1, {v}, near ? near_growth : grow), ref_box(p0, p1, {t[0], t[1], t[2]}, 0.0)))
        out.emplace_back(static_cast<int>(Kind::cloth_point_cloth_triangle), v, j, near);
    }
  for (int a = 0; a < static_cast<int>(c.edges.size()); ++a)
    for (int b = a + 1; b < static_cast<int>(c.edges.size()); ++b) {
      const auto& e = c.edges[static_cast<size_t>(a)];
      const auto& f = c.edges[static_cast<size_t>(b)];
      bool near = false;
      if (e[0] == f[0] || e[0] == f[1] || e[1] == f[0] || e[1] == f[1]) continue;
      if (!classify(c.edge_owner[static_cast<size_t>(a)], c.edge_owner[static_cast<size_t>(b)], near)) continue;
      const double g = 0.5 * (near ? near_growth : grow);
      if (ref_overlap(ref_box(p0, p1, {e[0], e[1]}, g), ref_box(p0, p1, {f[0], f[1]}, g)))
        out.emplace_back(static_cast<int>(Kind::cloth_edge_cloth_edge), a, b, near);
    }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<Candidate> search_once(const Cloth& c, const CandidateSettings& s, const Eigen::MatrixX3d& p0, const Eigen::MatrixX3d& p1,
                                   std::vector<std::vector<int>> near_at_rest = {}, std::vector<std::vector<int>> joined = {}) {
  const ObstacleSet none;
  CandidateSearch search(c.surface(), std::move(near_at_rest), std::move(joined), none, s);
  ContactCounters report;
  const Eigen::MatrixX3d no_obstacle(0, 3);
  std::vector<Candidate> out = search.find(p0, p1, no_obstacle, no_obstacle, false, s.thickness, report);
  EXPECT_GE(report.broad_ms, 0.0);
  return out;
}

TEST(CandidateSearch, TwoSheetsGiveExactlyThePairsWhoseGrownSweptBoxesOverlap) {
  const Cloth c(two_sheets(), 2);
  ASSERT_EQ(c.op.triangles.size(), 16u * 16u);
  // Both sheets crumpled by up to 0.4 mm at the start and the end of the step, the upper one
  // moving 0.6 mm down.
  const Eigen::MatrixX3d p0 = jittered(c.rest, 0.4e-3, 1);
  Eigen::MatrixX3d p1 = jittered(c.rest, 0.4e-3, 2);
  for (Eigen::Index i = 0; i < p1.rows(); ++i)
    if (c.rest(i, 2) > 0) p1(i, 2) -= 0.6e-3;
  const std::vector<Candidate> found = search_once(c, self_settings(0.0), p0, p1);
  const std::vector<Key> reference = brute_force(c, p0, p1, kThickness);
  const std::vector<Key> got = sorted_keys(found);
  EXPECT_EQ(std::adjacent_find(got.begin(), got.end()), got.end()) << "a pair is listed twice";
  EXPECT_EQ(got, reference);
  // Not a trivial comparison: both sorts of pairs, between the sheets and near pairs inside them.
  int across = 0, near = 0, edge_pairs = 0;
  const int sheet_points = static_cast<int>(c.rest.rows()) / 2;
  for (const Candidate& k : found) {
    near += k.near;
    edge_pairs += k.kind == Kind::cloth_edge_cloth_edge;
    if (k.kind == Kind::cloth_point_cloth_triangle)
      across += (k.a < sheet_points) != (c.op.triangles[static_cast<size_t>(k.b)][0] < sheet_points);
  }
  std::printf("%zu candidates: %d point-triangle across the sheets, %d edge-edge, %d near\n", found.size(), across, edge_pairs, near);
  EXPECT_GT(across, 50);
  EXPECT_GT(edge_pairs, 50);
  EXPECT_GT(near, 10);
}

TEST(CandidateSearch, HoldsEveryPairWithinTheThicknessAndNoPointWithItsOwnTriangle) {
  const Cloth c(two_sheets(), 1);
  const Eigen::MatrixX3d p0 = jittered(c.rest, 0.4e-3, 3);
  const Eigen::MatrixX3d p1 = jittered(c.rest, 0.4e-3, 4);
  const std::vector<Candidate> found = search_once(c, self_settings(0.0), p0, p1);
  std::set<Key> have;
  for (const Candidate& k : found) {
    have.insert(key(k));
    if (k.kind == Kind::cloth_point_cloth_triangle) {
      const Triangle& t = c.op.triangles[static_cast<size_t>(k.b)];
      EXPECT_TRUE(k.a != t[0] && k.a != t[1] && k.a != t[2]) << "point " << k.a << " with its own triangle " << k.b;
    } else {
      const auto& e = c.edges[static_cast<size_t>(k.a)];
      const auto& f = c.edges[static_cast<size_t>(k.b)];
      EXPECT_TRUE(e[0] != f[0] && e[0] != f[1] && e[1] != f[0] && e[1] != f[1]) << "edges " << k.a << ", " << k.b;
      EXPECT_LT(k.a, k.b);
    }
  }
  // Every pair of different patches closer than the thickness (neighbour patches: than the near
  // separation) at the start or the end of the step, by the narrow phase's exact distances.
  const double near_growth = 0.01 * kThickness;
  auto row = [](const Eigen::MatrixX3d& p, int i) -> Eigen::Vector3d { return p.row(i).transpose(); };
  int within = 0;
  for (int v = 0; v < static_cast<int>(c.rest.rows()); ++v)
    for (int j = 0; j < static_cast<int>(c.op.triangles.size()); ++j) {
      const Triangle& t = c.op.triangles[static_cast<size_t>(j)];
      const int i = c.point_owner[static_cast<size_t>(v)];
      if (v == t[0] || v == t[1] || v == t[2] || c.patch(i) == c.patch(j)) continue;
      const bool near = c.neighbours(i, j);
      double d = 1e300;
      for (const Eigen::MatrixX3d* p : {&p0, &p1}) d = std::min(d, point_triangle(row(*p, v), row(*p, t[0]), row(*p, t[1]), row(*p, t[2])).distance);
      if (d >= (near ? near_growth : kThickness)) continue;
      ++within;
      EXPECT_TRUE(have.count({static_cast<int>(Kind::cloth_point_cloth_triangle), v, j, near})) << "point " << v << ", triangle " << j;
    }
  for (int a = 0; a < static_cast<int>(c.edges.size()); ++a)
    for (int b = a + 1; b < static_cast<int>(c.edges.size()); ++b) {
      const auto& e = c.edges[static_cast<size_t>(a)];
      const auto& f = c.edges[static_cast<size_t>(b)];
      const int i = c.edge_owner[static_cast<size_t>(a)], j = c.edge_owner[static_cast<size_t>(b)];
      if (e[0] == f[0] || e[0] == f[1] || e[1] == f[0] || e[1] == f[1] || c.patch(i) == c.patch(j)) continue;
      const bool near = c.neighbours(i, j);
      double d = 1e300;
      for (const Eigen::MatrixX3d* p : {&p0, &p1}) d = std::min(d, edge_edge(row(*p, e[0]), row(*p, e[1]), row(*p, f[0]), row(*p, f[1])).distance);
      if (d >= (near ? near_growth : kThickness)) continue;
      ++within;
      EXPECT_TRUE(have.count({static_cast<int>(Kind::cloth_edge_cloth_edge), a, b, near})) << "edges " << a << ", " << b;
    }
  std::printf("%d pairs within the thickness, %zu candidates\n", within, found.size());
  EXPECT_GT(within, 20);
}

TEST(CandidateSearch, NearAtRestShrinksTheGrowthAndJoinedAtRestMakesNoPairs) {
  const Cloth c(two_sheets(0.2e-3), 1);  // crumpled by 0.4 mm, the sheets pass through each other
  const Eigen::MatrixX3d p0 = jittered(c.rest, 0.4e-3, 5);
  const Eigen::MatrixX3d p1 = jittered(c.rest, 0.4e-3, 6);
  const int n = static_cast<int>(c.op.triangles.size());
  const int sheet_triangles = n / 2;
  // Every fine triangle of the lower sheet near every one of the upper sheet at rest; the pairs of
  // the first upper patch's triangles also joined.
  auto near_at_rest = [&](int i, int j) { return i < sheet_triangles && j >= sheet_triangles; };
  auto joined = [&](int i, int j) { return near_at_rest(i, j) && c.patch(j) == c.patch(sheet_triangles); };
  std::vector<std::vector<int>> near_lists(static_cast<size_t>(n)), joined_lists(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      if (near_at_rest(i, j)) near_lists[static_cast<size_t>(i)].push_back(j);
      if (joined(i, j)) joined_lists[static_cast<size_t>(i)].push_back(j);
    }
  const std::vector<Key> plain = sorted_keys(search_once(c, self_settings(0.0), p0, p1));
  const std::vector<Key> with_near = sorted_keys(search_once(c, self_settings(0.0), p0, p1, near_lists));
  const std::vector<Key> with_joined = sorted_keys(search_once(c, self_settings(0.0), p0, p1, near_lists, joined_lists));
  EXPECT_EQ(with_near, brute_force(c, p0, p1, kThickness, near_at_rest));
  EXPECT_EQ(with_joined, brute_force(c, p0, p1, kThickness, near_at_rest, joined));
  // The lists change the result: across the sheets the near pairs (boxes grown by the near
  // separation) are fewer than the plain ones, and the joined patch has none.
  auto count = [](const std::vector<Key>& ks, bool near) {
    return std::count_if(ks.begin(), ks.end(), [&](const Key& k) { return std::get<3>(k) == near; });
  };
  std::printf("plain %zu, with near at rest %zu (near %ld), with joined %zu\n", plain.size(), with_near.size(),
              static_cast<long>(count(with_near, true)), with_joined.size());
  EXPECT_LT(with_near.size(), plain.size());
  EXPECT_GT(count(with_near, true), count(plain, true));
  EXPECT_LT(with_joined.size(), with_near.size());
}

TEST(CandidateSearch, FlatSheetMakesNoSelfPairsButAFoldKeepsItsPairsAcrossTheCrease) {
  // A 4 cm square of 4 × 4 cells refined once, moving 0.5 mm down over the step.
  const Cloth flat(make_grid(0.04, 0.04, 4, 4), 1);
  Eigen::MatrixX3d p1 = flat.rest;
  p1.col(2).array() -= 0.5e-3;
  const std::vector<Candidate> culled = search_once(flat, self_settings(kPi / 3), flat.rest, p1);
  const std::vector<Candidate> all = search_once(flat, self_settings(0.0), flat.rest, p1);
  EXPECT_TRUE(culled.empty()) << culled.size() << " pairs inside a flat region";
  EXPECT_GT(all.size(), 0u) << "without the cull the neighbour patches make near pairs";

  // The same square folded along x = 0 to 15° between its halves (normals 165° apart): the
  // patches on either side of the crease are not in one flat region.
  TriMesh folded_mesh = make_grid(0.04, 0.04, 4, 4);
  const double half = 0.5 * (kPi - 15.0 * kPi / 180.0);  // each half's turn from the plane
  for (Eigen::Index v = 0; v < folded_mesh.vertices.rows(); ++v) {
    const double x = folded_mesh.vertices(v, 0);
    folded_mesh.vertices(v, 0) = std::abs(x) * std::cos(half) * (x < 0 ? -1.0 : 1.0);
    folded_mesh.vertices(v, 2) = std::abs(x) * std::sin(half);
  }
  const Cloth folded(folded_mesh, 1);
  Eigen::MatrixX3d q1 = folded.rest;
  q1.col(2).array() -= 0.5e-3;
  const std::vector<Candidate> kept = search_once(folded, self_settings(kPi / 3), folded.rest, q1);
  const std::vector<Candidate> every = search_once(folded, self_settings(0.0), folded.rest, q1);
  // The patch's side of the crease: the sign of its centroid's x.
  auto side = [&](int fine) {
    const Triangle& t = folded.mesh.triangles[static_cast<size_t>(folded.patch(fine))];
    return folded.mesh.vertices(t[0], 0) + folded.mesh.vertices(t[1], 0) + folded.mesh.vertices(t[2], 0) > 0;
  };
  auto triangles_of = [&](const Candidate& k) -> std::pair<int, int> {
    if (k.kind == Kind::cloth_point_cloth_triangle) return {folded.point_owner[static_cast<size_t>(k.a)], k.b};
    return {folded.edge_owner[static_cast<size_t>(k.a)], folded.edge_owner[static_cast<size_t>(k.b)]};
  };
  std::set<Key> have;
  for (const Candidate& k : kept) have.insert(key(k));
  int across = 0;
  for (const Candidate& k : every) {
    const auto [i, j] = triangles_of(k);
    if (side(i) == side(j)) continue;
    ++across;
    EXPECT_TRUE(have.count(key(k))) << "a pair across the crease was culled";
  }
  std::printf("flat: %zu pairs without the cull; folded: %d pairs across the crease, %zu of %zu kept\n", all.size(), across,
              kept.size(), every.size());
  EXPECT_GT(across, 0);
  EXPECT_LT(kept.size(), every.size());  // the flat halves are still culled
}

Obstacle box_obstacle() {
  Obstacle o;
  o.name = "box";
  o.shape = Obstacle::Shape::box;
  o.center = Eigen::Vector3d(0, 0, 0);
  o.size = Eigen::Vector3d(0.02, 0.02, 0.02);  // top face at z = 0.01
  return o;
}

TEST(CandidateSearch, PointMovingIntoAnObstacleTriangleIsFound) {
  std::vector<Obstacle> obstacles = {box_obstacle()};
  const ObstacleSet obs(obstacles);
  const Eigen::MatrixX3d o = obstacles[0].mesh.vertices;  // static: o0 = o1
  // A 1 cm square 5 mm above the box's top face; its middle point goes 2 mm into the box.
  TriMesh sheet = make_grid(0.01, 0.01, 2, 2);
  sheet.vertices.col(2).array() += 0.015;
  const Cloth c(sheet, 1);
  int middle = 0;
  for (Eigen::Index i = 0; i < c.rest.rows(); ++i)
    if (c.rest.row(i).head<2>().norm() < c.rest.row(middle).head<2>().norm()) middle = static_cast<int>(i);
  ASSERT_LT(c.rest.row(middle).head<2>().norm(), 1e-12);
  Eigen::MatrixX3d p1 = c.rest;
  p1(middle, 2) = 0.008;
  CandidateSettings s;
  s.thickness = kThickness;
  CandidateSearch search(c.surface(), {}, {}, obs, s);
  ContactCounters report;
  const std::vector<Candidate> still = search.find(c.rest, c.rest, o, o, false, kThickness, report);
  EXPECT_TRUE(still.empty()) << still.size() << " pairs 5 mm away";
  const std::vector<Candidate> moving = search.find(c.rest, p1, o, o, true, kThickness, report);
  // The top face's triangles under the point's path (z = 0.01, over x = y = 0) each make a pair
  // with it.
  int under = 0;
  for (size_t j = 0; j < obs.triangles.size(); ++j) {
    const Triangle& t = obs.triangles[j];
    bool top = true;
    Eigen::Vector2d lo(1, 1), hi(-1, -1);
    for (int v : t) {
      top = top && std::abs(o(v, 2) - 0.01) < 1e-12;
      lo = lo.cwiseMin(o.row(v).head<2>().transpose());
      hi = hi.cwiseMax(o.row(v).head<2>().transpose());
    }
    if (!top || (lo.array() > 0).any() || (hi.array() < 0).any()) continue;
    ++under;
    const bool found = std::any_of(moving.begin(), moving.end(), [&](const Candidate& k) {
      return k.kind == Kind::cloth_point_obstacle_triangle && k.a == middle && k.b == static_cast<int>(j);
    });
    EXPECT_TRUE(found) << "obstacle triangle " << j;
  }
  EXPECT_GT(under, 0);
  // Only what the moving point reaches: pairs of the middle point, or of cloth edges or
  // triangles at it.
  for (const Candidate& k : moving) {
    EXPECT_NE(k.kind, Kind::cloth_point_cloth_triangle);
    if (k.kind == Kind::cloth_point_obstacle_triangle) {
      EXPECT_EQ(k.a, middle);
    }
    if (k.kind == Kind::cloth_edge_obstacle_edge) {
      EXPECT_TRUE(c.edges[static_cast<size_t>(k.a)][0] == middle || c.edges[static_cast<size_t>(k.a)][1] == middle);
    }
    if (k.kind == Kind::obstacle_point_cloth_triangle) {
      const Triangle& t = c.op.triangles[static_cast<size_t>(k.b)];
      EXPECT_TRUE(t[0] == middle || t[1] == middle || t[2] == middle);
    }
  }
  std::printf("%zu pairs, %d top-face triangles under the point\n", moving.size(), under);
}

TEST(CandidateSearch, ObstaclesAreReachedByTheWholeGrowth) {
  // A sheet resting still over the box's top face at 0.9 × the growth (static obstacle): every
  // point is within the growth of the face below it, so each makes a pair with a top-face
  // triangle; at 1.1 × the growth there is none. (Before the fix the patches reached the
  // obstacles by half the growth: 0 pairs from 0.55 thicknesses on.)
  std::vector<Obstacle> obstacles = {box_obstacle()};
  const ObstacleSet obs(obstacles);
  const Eigen::MatrixX3d o = obstacles[0].mesh.vertices;
  CandidateSettings s;
  s.thickness = kThickness;
  for (const double grow : {kThickness, 2.0 * kThickness}) {
    for (const double factor : {0.9, 1.1}) {
      TriMesh sheet = make_grid(0.01, 0.01, 2, 2);
      sheet.vertices.col(2).array() += 0.01 + factor * grow;
      const Cloth c(sheet, 1);
      CandidateSearch search(c.surface(), {}, {}, obs, s);
      ContactCounters report;
      const std::vector<Candidate> found = search.find(c.rest, c.rest, o, o, false, grow, report);
      std::set<int> points;
      for (const Candidate& k : found)
        if (k.kind == Kind::cloth_point_obstacle_triangle) points.insert(k.a);
      std::printf("sheet %.1f x growth %.1e m above the face: %zu pairs, %zu of %td points paired\n", factor, grow, found.size(),
                  points.size(), c.rest.rows());
      if (factor < 1.0) {
        EXPECT_EQ(static_cast<Eigen::Index>(points.size()), c.rest.rows()) << "growth " << grow;
      } else {
        EXPECT_TRUE(found.empty()) << "growth " << grow;
      }
    }
  }
}

TEST(CandidateSearch, SameListInTheSameOrderEveryTime) {
  std::vector<Obstacle> obstacles = {box_obstacle()};
  const ObstacleSet obs(obstacles);
  Eigen::MatrixX3d o0 = obstacles[0].mesh.vertices, o1 = o0;
  o1.col(2).array() += 1e-3;  // the box rises 1 mm over the step
  // The two sheets just over the box's top face, crumpled, with self-collision and flat regions.
  TriMesh sheets = two_sheets();
  sheets.vertices.col(2).array() += 0.0105;
  const Cloth c(sheets, 2);
  const Eigen::MatrixX3d p0 = jittered(c.rest, 0.3e-3, 7), p1 = jittered(c.rest, 0.3e-3, 8);
  ContactCounters report;
  CandidateSearch a(c.surface(), {}, {}, obs, self_settings(kPi / 3));
  const std::vector<Key> first = keys(a.find(p0, p1, o0, o1, false, kThickness, report));
  const std::vector<Key> kept_boxes = keys(a.find(p0, p1, o0, o1, true, kThickness, report));
  const std::vector<Key> new_boxes = keys(a.find(p0, p1, o0, o1, false, kThickness, report));
  CandidateSearch b(c.surface(), {}, {}, obs, self_settings(kPi / 3));
  const std::vector<Key> fresh = keys(b.find(p0, p1, o0, o1, false, kThickness, report));
  EXPECT_EQ(kept_boxes, first);
  EXPECT_EQ(new_boxes, first);
  EXPECT_EQ(fresh, first);
  // Self pairs first, then the obstacles'; both present.
  const auto obstacle_begin = std::find_if(first.begin(), first.end(), [](const Key& k) {
    return std::get<0>(k) >= static_cast<int>(Kind::cloth_point_obstacle_triangle);
  });
  EXPECT_NE(obstacle_begin, first.begin());
  EXPECT_NE(obstacle_begin, first.end());
  EXPECT_TRUE(std::all_of(obstacle_begin, first.end(), [](const Key& k) {
    return std::get<0>(k) >= static_cast<int>(Kind::cloth_point_obstacle_triangle);
  }));
  // Boxes kept from a call with other obstacle positions are that call's: told they are valid,
  // the search does not see the box move.
  const std::vector<Key> stale = keys(a.find(p0, p1, o0, o0, true, kThickness, report));
  const std::vector<Key> moved = keys(a.find(p0, p1, o0, o0, false, kThickness, report));
  EXPECT_EQ(stale, first);
  EXPECT_NE(moved, first);
  std::printf("%zu candidates, %td of them with the obstacle; %zu with the box standing still\n", first.size(),
              first.end() - obstacle_begin, moved.size());
}

TEST(CandidateSearch, RejectsAMismatchedSurface) {
  const Cloth c(make_grid(0.01, 0.01, 2, 2), 1);
  const ObstacleSet none;
  SearchSurface s = c.surface();
  s.levels = 3;  // 32 fine triangles are not a whole number of patches of 4^3
  EXPECT_THROW(CandidateSearch(s, {}, {}, none, self_settings(0.0)), std::invalid_argument);
  CandidateSearch search(c.surface(), {}, {}, none, self_settings(0.0));
  ContactCounters report;
  const Eigen::MatrixX3d none_rows(0, 3);
  EXPECT_THROW(search.find(c.rest, c.rest, none_rows, none_rows, false, 0.0, report), std::invalid_argument);
  EXPECT_THROW(search.find(c.rest, c.rest.topRows(3), none_rows, none_rows, false, kThickness, report), std::invalid_argument);
}

}  // namespace
}  // namespace clothsim::contact

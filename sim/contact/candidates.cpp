#include "sim/contact/candidates.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <tuple>

namespace clothsim::contact {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

bool overlap(const Box& a, const Box& b) {
  return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

Box grown(Box b, double g) {
  b.lo.array() -= g;
  b.hi.array() += g;
  return b;
}

}  // namespace

Box swept_box(const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b, const std::array<int, 3>& t, double grow) {
  Box box{Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()),
          Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity())};
  for (int v : t) {
    box.lo = box.lo.cwiseMin(a.row(v).transpose()).cwiseMin(b.row(v).transpose());
    box.hi = box.hi.cwiseMax(a.row(v).transpose()).cwiseMax(b.row(v).transpose());
  }
  box.lo.array() -= grow;
  box.hi.array() += grow;
  return box;
}

bool shares_vertex(const std::array<int, 3>& a, const std::array<int, 3>& b) {
  for (int x : a)
    for (int y : b)
      if (x == y) return true;
  return false;
}

CandidateSearch::CandidateSearch(const SearchSurface& surface, std::vector<std::vector<int>> near_at_rest,
                                 std::vector<std::vector<int>> joined_at_rest, const ObstacleSet& obstacles,
                                 const CandidateSettings& settings)
    : surface_(surface),
      obs_(obstacles),
      settings_(settings),
      near_at_rest_(std::move(near_at_rest)),
      joined_at_rest_(std::move(joined_at_rest)) {
  if (surface_.levels < 0) throw std::invalid_argument("CandidateSearch: the levels must be >= 0");
  fine_per_patch_ = 1 << (2 * surface_.levels);
  if (surface_.triangles.size() % static_cast<size_t>(fine_per_patch_) != 0)
    throw std::invalid_argument("CandidateSearch: the fine triangles must be 4^levels per patch");
  num_patches_ = static_cast<int>(surface_.triangles.size()) / fine_per_patch_;
  if (surface_.patch_corners.size() < static_cast<size_t>(num_patches_))
    throw std::invalid_argument("CandidateSearch: every patch needs its corners");
  const size_t n = surface_.triangles.size();
  if (surface_.triangle_edges.size() != n || surface_.owned_points.size() != n || surface_.owned_edges.size() != n)
    throw std::invalid_argument("CandidateSearch: the triangles' edges and ownership must cover every fine triangle");
  if (settings_.self) {  // (lists per fine triangle; empty ones when none were given)
    if (near_at_rest_.empty()) near_at_rest_.resize(n);
    if (joined_at_rest_.empty()) joined_at_rest_.resize(n);
    if (near_at_rest_.size() != n || joined_at_rest_.size() != n)
      throw std::invalid_argument("CandidateSearch: the near and joined pairs at rest must have one list per fine triangle");
  }
  for (int t = 0; t < num_patches_; ++t) patch_corners_.push_back(surface_.patch_corners[static_cast<size_t>(t)]);
  vertex_patches_.assign(static_cast<size_t>(surface_.num_nodes), {});
  for (int t = 0; t < num_patches_; ++t)
    for (int v : patch_corners_[static_cast<size_t>(t)]) {
      if (v < 0 || v >= surface_.num_nodes) throw std::invalid_argument("CandidateSearch: a patch corner is not a control node");
      vertex_patches_[static_cast<size_t>(v)].push_back(t);
    }
  control_edges_.assign(static_cast<size_t>(surface_.num_nodes), {});
  for (const auto& corners : patch_corners_)
    for (int k = 0; k < 3; ++k) {
      const int u = corners[static_cast<size_t>(k)], w = corners[static_cast<size_t>((k + 1) % 3)];
      if (control_edge(u, w) >= 0) continue;
      control_edges_[static_cast<size_t>(u)].emplace_back(w, static_cast<int>(num_control_edges_));
      control_edges_[static_cast<size_t>(w)].emplace_back(u, static_cast<int>(num_control_edges_));
      ++num_control_edges_;
    }
}

void CandidateSearch::measure_smooth_tangents(const Eigen::MatrixX3d& p0, const Eigen::MatrixX3d& p1) {
  const double eta = settings_.min_separation_ratio * settings_.thickness;
  smooth_tangent_triangle_.resize(surface_.triangles.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, surface_.triangles.size(), 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      double longest = 0.0;
      const auto& t = surface_.triangles[i];
      for (int k = 0; k < 3; ++k) {
        const int a = t[static_cast<size_t>(k)], b = t[static_cast<size_t>((k + 1) % 3)];
        longest = std::max({longest, (p0.row(a) - p0.row(b)).squaredNorm(), (p1.row(a) - p1.row(b)).squaredNorm()});
      }
      smooth_tangent_triangle_[i] = longest > 0 ? eta / std::sqrt(longest) : std::numeric_limits<double>::infinity();
    }
  });
  smooth_tangent_edge_.assign(surface_.edges.size(), std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < surface_.triangles.size(); ++i)
    for (int e : surface_.triangle_edges[i])
      smooth_tangent_edge_[static_cast<size_t>(e)] = std::min(smooth_tangent_edge_[static_cast<size_t>(e)], smooth_tangent_triangle_[i]);
}

// Flat regions. Over the step a fine triangle's (unnormalised) normal is the quadratic
// n(τ) = (1−τ)² n₀ + 2τ(1−τ) n½ + τ² n₁ in the corners' linear motion, a positive combination of
// n₀, n½ and n₁; so if all three lie in a cone (axis a, half-angle θ < π/2), so does n(τ) for
// the whole step, and n(τ)·a > 0 when n₀, n₁ ≠ 0. Per patch: a cone around the sum of its
// triangles' n₀ + n₁ holding every such vector (half-angle π when a triangle is degenerate at
// either end); per control vertex: a cone holding the cones of the patches of its star; per
// control edge: the smallest cone holding its two end points' cones. A star, or the union of
// the two stars of an edge, is flat when that cone's half-angle is below
// settings.flat_region_angle.
struct CandidateSearch::FlatRegions {
  std::vector<char> star;  // per control vertex
  std::vector<char> edge;  // per control edge (numbered as control_edge() finds them)
};

CandidateSearch::FlatRegions CandidateSearch::flat_regions(const std::vector<Eigen::Vector3d>& axis,
                                                           const std::vector<double>& angle) const {
  FlatRegions flat;
  flat.star.assign(vertex_patches_.size(), 0);
  flat.edge.assign(num_control_edges_, 0);
  if (!(settings_.flat_region_angle > 0)) return flat;
  std::vector<Eigen::Vector3d> star_axis(vertex_patches_.size(), Eigen::Vector3d::Zero());
  std::vector<double> star_angle(vertex_patches_.size(), M_PI);
  for (size_t v = 0; v < vertex_patches_.size(); ++v) {
    const std::vector<int>& star = vertex_patches_[v];
    Eigen::Vector3d a = Eigen::Vector3d::Zero();
    bool open = star.empty();
    for (int q : star) {
      open = open || angle[static_cast<size_t>(q)] >= settings_.flat_region_angle;
      a += axis[static_cast<size_t>(q)];
    }
    const double length = a.norm();
    if (open || !(length > 0)) continue;
    a /= length;
    double theta = 0.0;
    for (int q : star)
      theta = std::max(theta, std::acos(std::clamp(a.dot(axis[static_cast<size_t>(q)]), -1.0, 1.0)) + angle[static_cast<size_t>(q)]);
    star_axis[v] = a;
    star_angle[v] = theta;
    flat.star[v] = theta < settings_.flat_region_angle;
  }
  for (size_t u = 0; u < control_edges_.size(); ++u)
    for (const auto& [w, e] : control_edges_[u]) {
      if (w < static_cast<int>(u) || !flat.star[u] || !flat.star[static_cast<size_t>(w)]) continue;
      // The smallest cone holding cones (a, α) and (b, β) at an angle φ: the larger one when it
      // holds the other, else half-angle (φ + α + β) / 2.
      const double alpha = star_angle[u], beta = star_angle[static_cast<size_t>(w)];
      const double phi = std::acos(std::clamp(star_axis[u].dot(star_axis[static_cast<size_t>(w)]), -1.0, 1.0));
      const double theta = phi + std::min(alpha, beta) <= std::max(alpha, beta) ? std::max(alpha, beta) : 0.5 * (phi + alpha + beta);
      flat.edge[static_cast<size_t>(e)] = theta < settings_.flat_region_angle;
    }
  return flat;
}

// The cone of patch q's normals over the step (see flat regions): unit axis and half-angle
// [rad], π when a triangle is degenerate at either end or a normal is at a right angle or more
// to the axis. r0 and r1: the surface points at the start and end of the step (row-major copies).
std::pair<Eigen::Vector3d, double> CandidateSearch::patch_cone(int q, const RowPoints& r0, const RowPoints& r1,
                                                               std::vector<Eigen::Vector3d>& normals) const {
  normals.resize(static_cast<size_t>(3 * fine_per_patch_));
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  bool degenerate = false;
  for (int k = 0; k < fine_per_patch_; ++k) {
    const auto& tri = surface_.triangles[static_cast<size_t>(q * fine_per_patch_ + k)];
    const Eigen::Vector3d a0 = r0.row(tri[0]), a1 = r1.row(tri[0]);
    const Eigen::Vector3d e0 = r0.row(tri[1]).transpose() - a0, e1 = r1.row(tri[1]).transpose() - a1;
    const Eigen::Vector3d f0 = r0.row(tri[2]).transpose() - a0, f1 = r1.row(tri[2]).transpose() - a1;
    Eigen::Vector3d* n = &normals[static_cast<size_t>(3 * k)];
    n[0] = e0.cross(f0);
    n[1] = 0.5 * (e0.cross(f1) + e1.cross(f0));
    n[2] = e1.cross(f1);
    if (!(n[0].squaredNorm() > 0) || !(n[2].squaredNorm() > 0)) degenerate = true;
    sum += n[0] + n[2];
  }
  const double length = sum.norm();
  if (degenerate || !(length > 0)) return {Eigen::Vector3d::Zero(), M_PI};
  sum /= length;
  // The smallest cos² over the vectors (no square roots); a vector at or beyond a right angle
  // to the axis opens the cone to π.
  double min_cos2 = 1.0;
  for (const Eigen::Vector3d& n : normals) {
    const double dot = n.dot(sum), norm2 = n.squaredNorm();
    if (!(norm2 > 0)) continue;
    if (!(dot > 0)) return {sum, M_PI};
    min_cos2 = std::min(min_cos2, dot * dot / norm2);
  }
  return {sum, std::acos(std::sqrt(std::min(min_cos2, 1.0)))};
}

// The control edge between nodes u and w, or −1.
int CandidateSearch::control_edge(int u, int w) const {
  for (const auto& [x, e] : control_edges_[static_cast<size_t>(u)])
    if (x == w) return e;
  return -1;
}

std::vector<Candidate> CandidateSearch::find(const Eigen::MatrixX3d& p0, const Eigen::MatrixX3d& p1, const Eigen::MatrixX3d& o0,
                                             const Eigen::MatrixX3d& o1, bool obstacle_boxes_valid, double grow,
                                             ContactCounters& report) {
  const auto t0 = Clock::now();
  if (!(grow > 0)) throw std::invalid_argument("CandidateSearch: the growth must be > 0 [m]");
  const Eigen::Index np = p0.rows();
  if (p1.rows() != np) throw std::invalid_argument("CandidateSearch: the start and end points must have as many rows");
  std::vector<Candidate> out;
  // Swept boxes: triangles grown by the thickness (for the broad phase), and exact ones of the
  // triangles, points (grown by the thickness) and edges (grown by half of it) to cull the
  // pairs a triangle pair stands for.
  // Swept boxes of the points first (p0 and p1 per point), then of triangles and edges as unions.
  rows0_ = p0;  // row-major copies: the per-patch pass reads whole points
  rows1_ = p1;
  const RowPoints& rows0 = rows0_;
  const RowPoints& rows1 = rows1_;
  std::vector<Box>& point_box = scratch_point_box_;
  point_box.resize(static_cast<size_t>(np));
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, np, 4096), [&](const tbb::blocked_range<Eigen::Index>& range) {
    for (Eigen::Index p = range.begin(); p != range.end(); ++p) {
      Box& b = point_box[static_cast<size_t>(p)];
      b.lo = rows0.row(p).cwiseMin(rows1.row(p)).transpose();
      b.hi = rows0.row(p).cwiseMax(rows1.row(p)).transpose();
    }
  });
  auto unite = [](Box a, const Box& b) {
    a.lo = a.lo.cwiseMin(b.lo);
    a.hi = a.hi.cwiseMax(b.hi);
    return a;
  };
  // A box hierarchy over the refinement: level `levels` holds the fine triangles' swept boxes,
  // level l − 1 the unions of each four children (triangle t of level l − 1 has children
  // 4t … 4t + 3), level 0 the patches. A patch's subtree is contiguous on every level, so one
  // pass over the patches builds it, together with the patches' normal cones (self-collision).
  const int levels = surface_.levels;
  const int fine_per_patch = fine_per_patch_, num_patches = num_patches_;
  std::vector<std::vector<Box>>& hierarchy = scratch_hierarchy_;
  hierarchy.resize(static_cast<size_t>(levels + 1));
  for (int l = 0; l <= levels; ++l) hierarchy[static_cast<size_t>(l)].resize(static_cast<size_t>(num_patches) << (2 * l));
  cone_axis_.resize(static_cast<size_t>(num_patches));
  cone_angle_.resize(static_cast<size_t>(num_patches));
  tbb::parallel_for(tbb::blocked_range<int>(0, num_patches, 256), [&](const tbb::blocked_range<int>& range) {
    std::vector<Eigen::Vector3d> normals;
    for (int q = range.begin(); q != range.end(); ++q) {
      std::vector<Box>& fine = hierarchy[static_cast<size_t>(levels)];
      for (int t = q * fine_per_patch; t < (q + 1) * fine_per_patch; ++t) {
        const auto& tri = surface_.triangles[static_cast<size_t>(t)];
        fine[static_cast<size_t>(t)] = unite(unite(point_box[static_cast<size_t>(tri[0])], point_box[static_cast<size_t>(tri[1])]),
                                             point_box[static_cast<size_t>(tri[2])]);
      }
      for (int l = levels; l > 0; --l) {
        const std::vector<Box>& child = hierarchy[static_cast<size_t>(l)];
        std::vector<Box>& parent = hierarchy[static_cast<size_t>(l - 1)];
        const size_t per = size_t{1} << (2 * (l - 1));
        for (size_t t = static_cast<size_t>(q) * per; t < static_cast<size_t>(q + 1) * per; ++t)
          parent[t] = unite(unite(child[4 * t], child[4 * t + 1]), unite(child[4 * t + 2], child[4 * t + 3]));
      }
      if (settings_.self && settings_.flat_region_angle > 0)
        std::tie(cone_axis_[static_cast<size_t>(q)], cone_angle_[static_cast<size_t>(q)]) = patch_cone(q, rows0, rows1, normals);
    }
  });
  const std::vector<Box>& tight = hierarchy[static_cast<size_t>(levels)];
  std::vector<Box> patch_box(static_cast<size_t>(num_patches));
  for (int q = 0; q < num_patches; ++q) patch_box[static_cast<size_t>(q)] = grown(hierarchy[0][static_cast<size_t>(q)], 0.5 * grow);
  auto triangle_box = [&](int t) -> const Box& { return tight[static_cast<size_t>(t)]; };
  const std::vector<std::array<int, 2>>& edges = surface_.edges;
  auto edge_swept = [&](int e) {  // (computed where needed; read-only, so safe in parallel)
    const auto& ed = edges[static_cast<size_t>(e)];
    return grown(unite(point_box[static_cast<size_t>(ed[0])], point_box[static_cast<size_t>(ed[1])]), 0.5 * grow);
  };
  std::vector<Box> point_grown(point_box.size());
  for (size_t p = 0; p < point_box.size(); ++p) point_grown[p] = grown(point_box[p], grow);
  // Two fine triangles of the cloth from patches that share no vertex: their owned points
  // against the other triangle, and their owned edges against each other.
  const double near_growth = settings_.near_separation_ratio * settings_.thickness;
  const std::vector<std::vector<int>>& owned_points = surface_.owned_points;
  const std::vector<std::vector<int>>& owned_edges = surface_.owned_edges;
  auto add_triangle_pair = [&](int i, int j, bool neighbours, std::vector<Candidate>& into) {  // i < j
    const std::vector<int>& near_i = near_at_rest_[static_cast<size_t>(i)];
    const bool near = neighbours || std::binary_search(near_i.begin(), near_i.end(), j);
    const std::vector<int>& joined_i = joined_at_rest_[static_cast<size_t>(i)];
    if (near && std::binary_search(joined_i.begin(), joined_i.end(), j)) return;
    const auto& ti = surface_.triangles[static_cast<size_t>(i)];
    const auto& tj = surface_.triangles[static_cast<size_t>(j)];
    // (Triangles sharing a vertex still make pairs of their other points and edges: a point is
    // tested through the triangle that owns it, which may be another neighbour.)
    auto not_in = [](int v, const std::array<int, 3>& t) { return v != t[0] && v != t[1] && v != t[2]; };
    // Near pairs are only kept from crossing (CCD down to near_separation), so their boxes are
    // grown by that separation, not by the thickness.
    const double g_point = near ? near_growth : grow, g_edge = 0.5 * g_point;
    auto point_reach = [&](int v) { return near ? grown(point_box[static_cast<size_t>(v)], g_point) : point_grown[static_cast<size_t>(v)]; };
    auto edge_reach = [&](int e) {
      if (!near) return edge_swept(e);
      const auto& ed = edges[static_cast<size_t>(e)];
      return grown(unite(point_box[static_cast<size_t>(ed[0])], point_box[static_cast<size_t>(ed[1])]), g_edge);
    };
    if (near && !overlap(grown(triangle_box(i), g_point), triangle_box(j))) return;
    for (int v : owned_points[static_cast<size_t>(i)])
      if (not_in(v, tj) && overlap(point_reach(v), triangle_box(j)))
        into.push_back({Kind::cloth_point_cloth_triangle, v, j, near});
    for (int v : owned_points[static_cast<size_t>(j)])
      if (not_in(v, ti) && overlap(point_reach(v), triangle_box(i)))
        into.push_back({Kind::cloth_point_cloth_triangle, v, i, near});
    for (int ea : owned_edges[static_cast<size_t>(i)])
      for (int eb : owned_edges[static_cast<size_t>(j)]) {
        const auto& e = edges[static_cast<size_t>(ea)];
        const auto& f = edges[static_cast<size_t>(eb)];
        if (e[0] == f[0] || e[0] == f[1] || e[1] == f[0] || e[1] == f[1]) continue;
        if (overlap(edge_reach(ea), edge_reach(eb)))
          into.push_back({Kind::cloth_edge_cloth_edge, std::min(ea, eb), std::max(ea, eb), near});
      }
  };
  const FlatRegions flat = settings_.self ? flat_regions(cone_axis_, cone_angle_) : FlatRegions{};
  // Whether patches qa and qb lie in one flat region (the star of a shared vertex, or the two
  // stars of an edge between them) whose normals stay in a cone narrower than a right angle all
  // step: then no two points of theirs can meet (docs/contact.md, "Flat regions").
  auto in_flat_region = [&](int qa, int qb) {
    const auto& ca = patch_corners_[static_cast<size_t>(qa)];
    const auto& cb = patch_corners_[static_cast<size_t>(qb)];
    for (int x : ca)
      for (int y : cb) {
        if (x == y) {
          if (flat.star[static_cast<size_t>(x)]) return true;
          continue;
        }
        const int e = control_edge(x, y);
        if (e >= 0 && flat.edge[static_cast<size_t>(e)]) return true;
      }
    return false;
  };
  // Down the hierarchy from a pair of boxes at level l whose (grown) boxes overlap.
  struct Node {
    int level, a, b;
  };
  // Patches over surface triangles that share a vertex are neighbours: all their fine pairs are
  // near pairs (kept from crossing only), and their boxes grow by the near separation.
  auto descend = [&](int qa, int qb, std::vector<Node>& stack, std::vector<Candidate>& into) {  // depth first, fixed order
    const bool neighbours = shares_vertex(patch_corners_[static_cast<size_t>(qa)], patch_corners_[static_cast<size_t>(qb)]);
    const double g = neighbours ? near_growth : grow;
    stack.clear();
    stack.push_back({0, qa, qb});
    while (!stack.empty()) {
      const Node n = stack.back();
      stack.pop_back();
      const Box& ba = hierarchy[static_cast<size_t>(n.level)][static_cast<size_t>(n.a)];
      const Box& bb = hierarchy[static_cast<size_t>(n.level)][static_cast<size_t>(n.b)];
      if (!((ba.lo.array() - g <= bb.hi.array()).all() && (bb.lo.array() <= ba.hi.array() + g).all())) continue;
      if (n.level == levels) {
        add_triangle_pair(n.a, n.b, neighbours, into);
        continue;
      }
      for (int i = 4 * n.a + 3; i >= 4 * n.a; --i)
        for (int j = 4 * n.b + 3; j >= 4 * n.b; --j) stack.push_back({n.level + 1, i, j});
    }
  };
  if (settings_.self) {
    // Patch pairs in fixed chunks on both cores; the chunks' pairs are joined in order, so the
    // list does not depend on the threads.
    const std::vector<std::pair<int, int>> pairs =
        self_broad_.self_pairs(patch_box, [&](int qa, int qb) { return !in_flat_region(qa, qb); });
    constexpr size_t kChunk = 128;
    std::vector<std::vector<Candidate>> chunks((pairs.size() + kChunk - 1) / kChunk);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks.size(), 1), [&](const tbb::blocked_range<size_t>& range) {
      std::vector<Node> stack;
      for (size_t c = range.begin(); c != range.end(); ++c)
        for (size_t k = c * kChunk; k < std::min(pairs.size(), (c + 1) * kChunk); ++k)
          descend(pairs[k].first, pairs[k].second, stack, chunks[c]);
    });
    for (const std::vector<Candidate>& chunk : chunks) out.insert(out.end(), chunk.begin(), chunk.end());
  }
  if (!obs_.triangles.empty()) {
    if (!obstacle_boxes_valid || obstacle_boxes_.size() != obs_.triangles.size()) {  // once per step (once per run for static obstacles)
      const auto nv = static_cast<Eigen::Index>(obs_.obstacle_of_vertex.size());
      if (o0.rows() != nv || o1.rows() != nv)
        throw std::invalid_argument("CandidateSearch: the obstacle vertices must have one row per vertex of the obstacle set");
      obstacle_boxes_.resize(obs_.triangles.size());
      for (size_t t = 0; t < obs_.triangles.size(); ++t) obstacle_boxes_[t] = swept_box(o0, o1, obs_.triangles[t], 0.0);
      obstacle_point_box_.resize(obs_.obstacle_of_vertex.size());
      for (size_t v = 0; v < obstacle_point_box_.size(); ++v) {
        const int i = static_cast<int>(v);
        obstacle_point_box_[v] = swept_box(o0, o1, {i, i, i}, 0.0);
      }
      obstacle_edge_box_.resize(obs_.edges.size());
      for (size_t e = 0; e < obs_.edges.size(); ++e) {
        const Box& a = obstacle_point_box_[static_cast<size_t>(obs_.edges[e][0])];
        const Box& b = obstacle_point_box_[static_cast<size_t>(obs_.edges[e][1])];
        obstacle_edge_box_[e] = Box{a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi)};  // (grown where used)
      }
    }
    measure_smooth_tangents(p0, p1);
    // (The patches reach the obstacles, whose boxes are not grown, by all of `grow`, as the fine
    // triangles do below. Before 2026-11-28 they reached half as far: the barrier's candidates,
    // made to serve moves of half the thickness, then reached obstacles only one thickness away.)
    std::vector<Box> patch_reach(patch_box.size());
    for (int q = 0; q < num_patches; ++q) patch_reach[static_cast<size_t>(q)] = grown(hierarchy[0][static_cast<size_t>(q)], grow);
    const std::vector<std::pair<int, int>> obroad = obstacle_broad_.pairs(patch_reach, obstacle_boxes_);
    auto descend_obstacle = [&](int q, int j, std::vector<Candidate>& into) {
      for (int i = q * fine_per_patch; i < (q + 1) * fine_per_patch; ++i) {
        if (!overlap(grown(triangle_box(i), grow), obstacle_boxes_[static_cast<size_t>(j)])) continue;
        for (int v : owned_points[static_cast<size_t>(i)])
          if (overlap(point_grown[static_cast<size_t>(v)], obstacle_boxes_[static_cast<size_t>(j)]))
            into.push_back({Kind::cloth_point_obstacle_triangle, v, j});
        for (int v : obs_.owned_points[static_cast<size_t>(j)])
          if (obs_.vertex_tangent[static_cast<size_t>(v)] > smooth_tangent_triangle_[static_cast<size_t>(i)] &&
              overlap(grown(obstacle_point_box_[static_cast<size_t>(v)], grow), triangle_box(i)))
            into.push_back({Kind::obstacle_point_cloth_triangle, v, i});
        for (int ea : owned_edges[static_cast<size_t>(i)])
          for (int eb : obs_.owned_edges[static_cast<size_t>(j)])
            if (obs_.edge_tangent[static_cast<size_t>(eb)] > smooth_tangent_edge_[static_cast<size_t>(ea)] &&
                overlap(edge_swept(ea), grown(obstacle_edge_box_[static_cast<size_t>(eb)], 0.5 * grow)))
              into.push_back({Kind::cloth_edge_obstacle_edge, ea, eb});
      }
    };
    // (In fixed chunks on both cores, joined in order, as the self pairs.)
    constexpr size_t kChunk = 256;
    std::vector<std::vector<Candidate>> chunks((obroad.size() + kChunk - 1) / kChunk);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks.size(), 1), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t c = range.begin(); c != range.end(); ++c)
        for (size_t k = c * kChunk; k < std::min(obroad.size(), (c + 1) * kChunk); ++k)
          descend_obstacle(obroad[k].first, obroad[k].second, chunks[c]);
    });
    for (const std::vector<Candidate>& chunk : chunks) out.insert(out.end(), chunk.begin(), chunk.end());
  }
  // Every pair is made once (ownership) in an order fixed by the sorted broad-phase pairs, so
  // the list is deterministic without sorting.
  report.broad_ms += ms_since(t0);
  return out;
}

}  // namespace clothsim::contact

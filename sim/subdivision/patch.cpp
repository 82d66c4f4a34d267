#include "sim/subdivision/patch.hpp"

#include "sim/subdivision/loop.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>

namespace clothsim {

bool is_regular(const Topology& top, const Triangle& tri) {
  for (int v : tri)
    if (top.is_boundary(v) || top.valence(v) != 6) return false;
  return true;
}

std::array<int, 12> regular_patch(const Topology& top, const Triangle& tri) {
  const int a = tri[0], b = tri[1], c = tri[2];
  const std::vector<int> ra = top.ring_from(a, b);  // [b, c, 5, 2, 1, 3]
  const std::vector<int> rb = top.ring_from(b, c);  // [c, a, 3, 6, 10, 11]
  const std::vector<int> rc = top.ring_from(c, a);  // [a, b, 11, 12, 9, 5]
  if (ra[1] != c || rb[1] != a || rc[1] != b || rb[2] != ra[5] || rc[5] != ra[2] || rc[2] != rb[5])
    throw std::logic_error("regular_patch: inconsistent one-rings around triangle (" + std::to_string(a) + ", " +
                           std::to_string(b) + ", " + std::to_string(c) + ")");
  return {ra[4], ra[3], ra[5], a, ra[2], rb[3], b, c, rc[4], rb[4], rb[5], rc[3]};
}

namespace {

constexpr int kMaxDepth = 64;

PatchEvaluation evaluate_recursive(const Topology& top, const Triangle& tri, double v, double w, int depth,
                                   int min_levels) {
  PatchEvaluation out;
  if (depth >= min_levels && is_regular(top, tri)) {
    const std::array<int, 12> ids = regular_patch(top, tri);
    out.vertices.assign(ids.begin(), ids.end());
    out.basis = box_spline_basis(v, w);
    return out;
  }
  if (depth >= kMaxDepth)
    throw std::invalid_argument("evaluate_patch: the point lies at an irregular vertex; use the limit masks there");
  for (int x : tri)
    if (top.is_boundary(x))
      throw std::invalid_argument("evaluate_patch: element vertex " + std::to_string(x) + " has an open one-ring");

  // The patch: the three vertices and their one-rings (N + 6 vertices).
  std::vector<int>& patch = out.vertices;
  for (int x : tri) {
    patch.push_back(x);
    for (int r : top.ring(x)) patch.push_back(r);
  }
  std::sort(patch.begin(), patch.end());
  patch.erase(std::unique(patch.begin(), patch.end()), patch.end());
  std::map<int, int> local;  // mesh id -> column in `patch`
  for (int i = 0; i < static_cast<int>(patch.size()); ++i) local[patch[i]] = i;

  // One local Loop step: vertex points of a, b, c and edge points of every edge at a, b or c.
  // Rows of `weights` are the new vertices as combinations of the patch's vertices.
  std::vector<Eigen::RowVectorXd> rows;
  std::map<int, int> vertex_point;                  // mesh id -> new id
  std::map<std::pair<int, int>, int> edge_point;    // sorted mesh edge -> new id
  const Eigen::Index np = static_cast<Eigen::Index>(patch.size());
  for (int x : tri) {
    const int n = top.valence(x);
    const double beta = loop_beta(n);
    Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(np);
    row(local.at(x)) = 1.0 - n * beta;
    for (int r : top.ring(x)) row(local.at(r)) += beta;
    vertex_point[x] = static_cast<int>(rows.size());
    rows.push_back(row);
  }
  for (int x : tri)
    for (int y : top.ring(x)) {
      const auto key = std::make_pair(std::min(x, y), std::max(x, y));
      if (edge_point.count(key)) continue;
      Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(np);
      row(local.at(x)) += 0.375;
      row(local.at(y)) += 0.375;
      row(local.at(top.opposite(x, y))) += 0.125;
      row(local.at(top.opposite(y, x))) += 0.125;
      edge_point[key] = static_cast<int>(rows.size());
      rows.push_back(row);
    }
  auto ep = [&](int x, int y) -> int {
    auto it = edge_point.find({std::min(x, y), std::max(x, y)});
    return it == edge_point.end() ? -1 : it->second;
  };
  auto vp = [&](int x) -> int {
    auto it = vertex_point.find(x);
    return it == vertex_point.end() ? -1 : it->second;
  };

  // Sub-triangles of the triangles around a, b, c whose corners are all known.
  std::vector<Triangle> fine;
  std::vector<Triangle> coarse;
  for (int x : tri) {
    const std::vector<int>& ring = top.ring(x);
    for (size_t i = 0; i < ring.size(); ++i) {
      Triangle t{x, ring[i], ring[(i + 1) % ring.size()]};
      std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
      if (std::find(coarse.begin(), coarse.end(), t) == coarse.end()) coarse.push_back(t);
    }
  }
  for (const Triangle& t : coarse) {
    const int p = t[0], q = t[1], r = t[2];
    const std::array<Triangle, 4> subs = {{{vp(p), ep(p, q), ep(r, p)},
                                           {vp(q), ep(q, r), ep(p, q)},
                                           {vp(r), ep(r, p), ep(q, r)},
                                           {ep(p, q), ep(q, r), ep(r, p)}}};
    for (const Triangle& s : subs)
      if (s[0] >= 0 && s[1] >= 0 && s[2] >= 0) fine.push_back(s);
  }
  const Topology fine_top(static_cast<int>(rows.size()), fine);

  // The sub-triangle that holds (v, w), and the affine map to its parameters:
  // (v', w') = J (v, w) + offset.
  const int a = tri[0], b = tri[1], c = tri[2];
  const double u = 1.0 - v - w;
  Triangle sub;
  Eigen::Matrix2d jac;
  double vs, ws;
  if (u >= 0.5) {
    sub = {vp(a), ep(a, b), ep(c, a)};
    jac << 2, 0, 0, 2;
    vs = 2 * v, ws = 2 * w;
  } else if (v >= 0.5) {
    sub = {vp(b), ep(b, c), ep(a, b)};
    jac << 0, 2, -2, -2;
    vs = 2 * w, ws = 2 * u;
  } else if (w >= 0.5) {
    sub = {vp(c), ep(c, a), ep(b, c)};
    jac << -2, -2, 2, 0;
    vs = 2 * u, ws = 2 * v;
  } else {
    sub = {ep(b, c), ep(c, a), ep(a, b)};
    jac << -2, 0, 0, -2;
    vs = 1 - 2 * v, ws = 1 - 2 * w;
  }
  const PatchEvaluation inner = evaluate_recursive(fine_top, sub, vs, ws, depth + 1, min_levels);

  // Chain rule: gradient Jᵀ g, Hessian Jᵀ H J (the map is affine).
  const Eigen::Index m = static_cast<Eigen::Index>(inner.vertices.size());
  Eigen::Matrix<double, 6, Eigen::Dynamic> mapped(6, m);
  for (Eigen::Index k = 0; k < m; ++k) {
    const Eigen::Vector2d g(inner.basis(kDv, k), inner.basis(kDw, k));
    Eigen::Matrix2d h;
    h << inner.basis(kDvv, k), inner.basis(kDvw, k), inner.basis(kDvw, k), inner.basis(kDww, k);
    const Eigen::Vector2d gp = jac.transpose() * g;
    const Eigen::Matrix2d hp = jac.transpose() * h * jac;
    mapped.col(k) << inner.basis(kValue, k), gp(0), gp(1), hp(0, 0), hp(0, 1), hp(1, 1);
  }
  out.basis = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, np);
  for (Eigen::Index k = 0; k < m; ++k) out.basis += mapped.col(k) * rows[inner.vertices[k]];
  return out;
}

}  // namespace

PatchEvaluation evaluate_patch(const Topology& top, const Triangle& tri, double v, double w, int min_levels) {
  return evaluate_recursive(top, tri, v, w, 0, min_levels);
}

}  // namespace clothsim

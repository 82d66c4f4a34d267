// The planar geometry of one pattern piece (piece_mesh.hpp): outline check, interior lattice and
// constrained Delaunay triangulation. The only file of sim/pattern that includes CGAL.
#include "sim/pattern/piece_mesh.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_data_structure_2.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <deque>
#include <exception>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>

namespace clothsim::pattern_detail {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_2;
using Segment = K::Segment_2;

using Vb = CGAL::Triangulation_vertex_base_with_info_2<int, K>;
using Fb = CGAL::Triangulation_face_base_with_info_2<int, K, CGAL::Constrained_triangulation_face_base_2<K>>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
// No_constraint_intersection_tag: the boundary is a simple polygon, so constraints never cross;
// CGAL throws instead of inserting an intersection point if they did.
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::No_constraint_intersection_tag>;

Point to_point(const Eigen::Vector2d& p) { return Point(p.x(), p.y()); }

std::size_t at(int i) { return static_cast<std::size_t>(i); }

// Whether edges i < j (of an n-gon) share a point: neighbours along the polygon.
bool adjacent(int i, int j, int n) { return j == i + 1 || (i == 0 && j == n - 1); }

// Squared distance from p to the segment ab.
double squared_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  double t = len2 > 0.0 ? (p - a).dot(ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return (a + t * ab - p).squaredNorm();
}

// A uniform grid over the polygon's bounding box (grown by `clearance`): per cell, the edges
// within `clearance` of it (for the distance test), and per row of cells, the edges whose y-range
// meets the row (for the crossing-number inside test).
class EdgeGrid {
 public:
  EdgeGrid(const std::vector<Eigen::Vector2d>& loop, double clearance) : loop_(loop) {
    Eigen::Vector2d lo = loop.front(), hi = loop.front();
    for (const Eigen::Vector2d& p : loop) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    lo -= Eigen::Vector2d::Constant(clearance);
    hi += Eigen::Vector2d::Constant(clearance);
    origin_ = lo;
    const Eigen::Vector2d extent = hi - lo;
    // Cells about the clearance in size, at most ~4 million of them.
    cell_ = std::max({clearance, extent.x() / 2048.0, extent.y() / 2048.0, 1e-300});
    nx_ = static_cast<int>(std::floor(extent.x() / cell_)) + 1;
    ny_ = static_cast<int>(std::floor(extent.y() / cell_)) + 1;
    cells_.resize(at(nx_) * at(ny_));
    rows_.resize(at(ny_));
    const int n = static_cast<int>(loop.size());
    for (int e = 0; e < n; ++e) {
      const Eigen::Vector2d& a = loop[at(e)];
      const Eigen::Vector2d& b = loop[at((e + 1) % n)];
      const Eigen::Vector2d elo = a.cwiseMin(b), ehi = a.cwiseMax(b);
      const int x0 = cx(elo.x() - clearance), x1 = cx(ehi.x() + clearance);
      const int y0 = cy(elo.y() - clearance), y1 = cy(ehi.y() + clearance);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) cells_[at(y) * at(nx_) + at(x)].push_back(e);
      for (int y = cy(elo.y()); y <= cy(ehi.y()); ++y) rows_[at(y)].push_back(e);
    }
  }

  // Whether some edge is within `clearance` of p (p inside the grown bounding box).
  bool near_edge(const Eigen::Vector2d& p, double clearance) const {
    const int n = static_cast<int>(loop_.size());
    for (int e : cells_[at(cy(p.y())) * at(nx_) + at(cx(p.x()))])
      if (squared_distance(p, loop_[at(e)], loop_[at((e + 1) % n)]) <= clearance * clearance) return true;
    return false;
  }

  // Crossing number of the ray from p towards +x (half-open rule at vertices); reliable here
  // because p is farther than the clearance from every edge.
  bool inside(const Eigen::Vector2d& p) const {
    const int n = static_cast<int>(loop_.size());
    bool in = false;
    for (int e : rows_[at(cy(p.y()))]) {
      const Eigen::Vector2d& a = loop_[at(e)];
      const Eigen::Vector2d& b = loop_[at((e + 1) % n)];
      if ((a.y() > p.y()) == (b.y() > p.y())) continue;
      const double x = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (x > p.x()) in = !in;
    }
    return in;
  }

  Eigen::Vector2d box_min() const { return origin_; }
  Eigen::Vector2d box_max() const { return origin_ + cell_ * Eigen::Vector2d(static_cast<double>(nx_), static_cast<double>(ny_)); }

  bool in_box(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = p - origin_;
    return d.x() >= 0.0 && d.y() >= 0.0 && d.x() < static_cast<double>(nx_) * cell_ &&
           d.y() < static_cast<double>(ny_) * cell_;
  }

 private:
  int cx(double x) const { return std::clamp(static_cast<int>(std::floor((x - origin_.x()) / cell_)), 0, nx_ - 1); }
  int cy(double y) const { return std::clamp(static_cast<int>(std::floor((y - origin_.y()) / cell_)), 0, ny_ - 1); }

  const std::vector<Eigen::Vector2d>& loop_;
  Eigen::Vector2d origin_;
  double cell_ = 1.0;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> cells_;
  std::vector<std::vector<int>> rows_;
};

}  // namespace

double signed_area(const std::vector<Eigen::Vector2d>& points) {
  const std::size_t n = points.size();
  double twice = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector2d& a = points[k];
    const Eigen::Vector2d& b = points[(k + 1) % n];
    twice += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * twice;
}

PolygonDefect find_polygon_defect(const std::vector<Eigen::Vector2d>& points) {
  using Kind = PolygonDefect::Kind;
  const int n = static_cast<int>(points.size());
  if (n < 3) return {Kind::too_few_points, -1, -1, 0.0};
  for (int k = 0; k < n; ++k)
    if (!points[at(k)].allFinite()) return {Kind::not_finite, k, -1, 0.0};
  for (int k = 0; k < n; ++k)
    if (points[at(k)] == points[at((k + 1) % n)]) return {Kind::zero_edge, k, -1, 0.0};

  // Repeated points: equal neighbours after a sort by (x, y, index).
  std::vector<int> order(at(n));
  for (int k = 0; k < n; ++k) order[at(k)] = k;
  std::sort(order.begin(), order.end(), [&points](int a, int b) {
    const Eigen::Vector2d& p = points[at(a)];
    const Eigen::Vector2d& q = points[at(b)];
    return std::tie(p.x(), p.y(), a) < std::tie(q.x(), q.y(), b);
  });
  std::pair<int, int> best{n, n};
  for (int k = 0; k + 1 < n; ++k) {
    const int a = order[at(k)], b = order[at(k + 1)];
    if (points[at(a)] == points[at(b)]) best = std::min(best, std::make_pair(std::min(a, b), std::max(a, b)));
  }
  if (best.first < n) return {Kind::repeated_point, best.first, best.second, 0.0};

  // Edge pairs: a sweep over the edges sorted by their smallest x; exact predicates.
  struct Box {
    double xmin, xmax, ymin, ymax;
    int edge;
  };
  std::vector<Box> boxes;
  boxes.reserve(at(n));
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d& a = points[at(k)];
    const Eigen::Vector2d& b = points[at((k + 1) % n)];
    boxes.push_back({std::min(a.x(), b.x()), std::max(a.x(), b.x()), std::min(a.y(), b.y()), std::max(a.y(), b.y()), k});
  }
  std::sort(boxes.begin(), boxes.end(),
            [](const Box& a, const Box& b) { return std::tie(a.xmin, a.edge) < std::tie(b.xmin, b.edge); });
  Kind best_kind = Kind::none;
  for (std::size_t s = 0; s < boxes.size(); ++s)
    for (std::size_t t = s + 1; t < boxes.size() && boxes[t].xmin <= boxes[s].xmax; ++t) {
      if (boxes[t].ymin > boxes[s].ymax || boxes[s].ymin > boxes[t].ymax) continue;
      const int i = std::min(boxes[s].edge, boxes[t].edge), j = std::max(boxes[s].edge, boxes[t].edge);
      if (std::make_pair(i, j) >= best) continue;
      const Point pi = to_point(points[at(i)]), qi = to_point(points[at((i + 1) % n)]);
      const Point pj = to_point(points[at(j)]), qj = to_point(points[at((j + 1) % n)]);
      if (adjacent(i, j, n)) {
        // Neighbours share one point; they overlap when the other two ends lie on the same ray
        // from it (the outline folds back).
        const bool forward = j == i + 1;  // edge i ends where edge j starts
        const Point shared = forward ? qi : pi;
        const Point u = forward ? pi : qi, w = forward ? qj : pj;
        if (CGAL::orientation(u, shared, w) == CGAL::COLLINEAR &&
            (u.x() - shared.x()) * (w.x() - shared.x()) + (u.y() - shared.y()) * (w.y() - shared.y()) > 0.0) {
          best = {i, j};
          best_kind = Kind::overlap;
        }
      } else if (CGAL::do_intersect(Segment(pi, qi), Segment(pj, qj))) {
        best = {i, j};
        best_kind = Kind::crossing;
      }
    }
  if (best_kind != Kind::none) return {best_kind, best.first, best.second, 0.0};

  const double area = signed_area(points);
  if (!(area > 0.0)) return {Kind::clockwise, -1, -1, area};
  return {Kind::none, -1, -1, area};
}

std::vector<Eigen::Vector2d> interior_lattice(const std::vector<Eigen::Vector2d>& loop, double spacing,
                                              double angle_deg, const Eigen::Vector2d& origin, double clearance) {
  const double a = angle_deg * std::numbers::pi / 180.0;
  const double b = a + std::numbers::pi / 3.0;
  const Eigen::Vector2d u(std::cos(a), std::sin(a)), v(std::cos(b), std::sin(b));
  Eigen::Matrix2d basis;
  basis.col(0) = spacing * u;
  basis.col(1) = spacing * v;
  const Eigen::Matrix2d to_lattice = basis.inverse();
  // The lattice-coordinate range covering the polygon.
  Eigen::Vector2d lo = to_lattice * (loop.front() - origin), hi = lo;
  for (const Eigen::Vector2d& p : loop) {
    const Eigen::Vector2d c = to_lattice * (p - origin);
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const EdgeGrid grid(loop, clearance);
  std::vector<Eigen::Vector2d> out;
  const long i0 = static_cast<long>(std::floor(lo.x())), i1 = static_cast<long>(std::ceil(hi.x()));
  const long j0 = static_cast<long>(std::floor(lo.y())), j1 = static_cast<long>(std::ceil(hi.y()));
  for (long j = j0; j <= j1; ++j) {
    // The part of row j inside the box (grown by one lattice step; in_box has the last word).
    const Eigen::Vector2d row = origin + basis.col(1) * static_cast<double>(j);
    double ilo = static_cast<double>(i0), ihi = static_cast<double>(i1);
    for (int d = 0; d < 2; ++d) {
      const double step = basis(d, 0);
      if (std::abs(step) < 1e-12 * spacing) continue;
      const double t0 = (grid.box_min()(d) - row(d)) / step, t1 = (grid.box_max()(d) - row(d)) / step;
      ilo = std::max(ilo, std::min(t0, t1) - 1.0);
      ihi = std::min(ihi, std::max(t0, t1) + 1.0);
    }
    if (!(ilo <= ihi)) continue;
    for (long i = static_cast<long>(std::floor(ilo)); i <= static_cast<long>(std::ceil(ihi)); ++i) {
      const Eigen::Vector2d p = origin + basis * Eigen::Vector2d(static_cast<double>(i), static_cast<double>(j));
      if (!grid.in_box(p) || grid.near_edge(p, clearance) || !grid.inside(p)) continue;
      out.push_back(p);
    }
  }
  return out;
}

std::vector<Triangle> triangulate_polygon(const std::vector<Eigen::Vector2d>& points, int num_boundary) {
  const int n = static_cast<int>(points.size());
  Cdt cdt;
  std::vector<Cdt::Vertex_handle> handle(at(n));
  try {
    // One point at a time, in the given order, each located from the previous one: CGAL's
    // incremental insertion is deterministic for a fixed order.
    Cdt::Face_handle hint;
    for (int k = 0; k < n; ++k) {
      const Cdt::Vertex_handle vh = cdt.insert(to_point(points[at(k)]), hint);
      vh->info() = k;
      handle[at(k)] = vh;
      hint = vh->face();
    }
    if (static_cast<int>(cdt.number_of_vertices()) != n)
      throw MeshError("two of its mesh points coincide (" + std::to_string(n - static_cast<int>(cdt.number_of_vertices())) +
                      " duplicate(s))");
    for (int k = 0; k < num_boundary; ++k) cdt.insert_constraint(handle[at(k)], handle[at((k + 1) % num_boundary)]);
  } catch (const Cdt::Intersection_of_constraints_exception&) {
    throw MeshError("its resampled outline intersects itself (constrained triangulation)");
  } catch (const MeshError&) {
    throw;
  } catch (const std::exception& e) {
    throw MeshError(std::string("the constrained triangulation failed: ") + e.what());
  }
  if (static_cast<int>(cdt.number_of_vertices()) != n)
    throw MeshError("the constrained triangulation added points on the outline");

  // Nesting level of every face: 0 outside, 1 inside; a flood fill from the infinite face that
  // crosses a constrained edge to go one level deeper.
  for (Cdt::All_faces_iterator f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info() = -1;
  std::deque<Cdt::Face_handle> border{cdt.infinite_face()};
  cdt.infinite_face()->info() = 0;
  while (!border.empty()) {
    // Fill the component at the current level, queueing the faces across constraints.
    std::deque<Cdt::Face_handle> queue{border.front()};
    border.pop_front();
    const int level = queue.front()->info();
    while (!queue.empty()) {
      const Cdt::Face_handle f = queue.front();
      queue.pop_front();
      for (int k = 0; k < 3; ++k) {
        const Cdt::Face_handle g = f->neighbor(k);
        if (g->info() != -1) continue;
        if (cdt.is_constrained(Cdt::Edge(f, k))) {
          g->info() = level + 1;
          border.push_back(g);
        } else {
          g->info() = level;
          queue.push_back(g);
        }
      }
    }
  }

  std::vector<Triangle> out;
  for (Cdt::Finite_faces_iterator f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (f->info() % 2 != 1) continue;
    Triangle t{f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    out.push_back(t);
  }
  std::sort(out.begin(), out.end());
  const int expected = num_boundary + 2 * (n - num_boundary) - 2;
  if (static_cast<int>(out.size()) != expected)
    throw MeshError("the constrained triangulation gave " + std::to_string(out.size()) + " triangles inside the outline, not " +
                    std::to_string(expected));
  return out;
}

}  // namespace clothsim::pattern_detail

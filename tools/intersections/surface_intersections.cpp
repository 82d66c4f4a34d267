// Exact triangle-surface intersection check on CGAL (see the header for what it decides).
//
// Broad phase: one closed axis-aligned box per triangle, from the exact min/max of its corners,
// fed to CGAL::box_self_intersection_d / CGAL::box_intersection_d. Narrow phase: CGAL::do_intersect
// with the Epick kernel, whose predicates are exact (filtered, with exact fallback) on double
// input. All CGAL code stays in this file; the header is plain C++.
#include "tools/intersections/surface_intersections.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Intersections_3/Point_3_Point_3.h>
#include <CGAL/Intersections_3/Point_3_Segment_3.h>
#include <CGAL/Intersections_3/Point_3_Triangle_3.h>
#include <CGAL/Intersections_3/Segment_3_Segment_3.h>
#include <CGAL/Intersections_3/Segment_3_Triangle_3.h>
#include <CGAL/Intersections_3/Triangle_3_Triangle_3.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace clothsim::check {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Segment = Kernel::Segment_3;
using Triangle = Kernel::Triangle_3;

// A mesh triangle as the point set it really is: a proper triangle, or, when its corners are
// collinear, the segment between its extreme corners, or a single point when all coincide.
// CGAL's do_intersect requires non-degenerate triangles and segments, so each kind is tested
// with the matching overload.
struct Element {
  enum class Kind : unsigned char { triangle = 0, segment = 1, point = 2 };
  Kind kind = Kind::point;
  std::array<Point, 3> p;  // triangle: p[0..2]; segment: p[0], p[1]; point: p[0]
};

Element make_element(const Point& a, const Point& b, const Point& c) {
  Element e;
  if (!CGAL::collinear(a, b, c)) {
    e.kind = Element::Kind::triangle;
    e.p = {a, b, c};
    return e;
  }
  // On a line, lexicographic xyz order is the order along the line (or its reverse), so the
  // lexicographic extremes are the segment's endpoints. Exact comparisons only.
  const Point* lo = &a;
  const Point* hi = &a;
  for (const Point* q : {&b, &c}) {
    if (CGAL::compare_xyz(*q, *lo) == CGAL::SMALLER) lo = q;
    if (CGAL::compare_xyz(*q, *hi) == CGAL::LARGER) hi = q;
  }
  if (*lo == *hi) {
    e.kind = Element::Kind::point;
    e.p = {*lo, *lo, *lo};
  } else {
    e.kind = Element::Kind::segment;
    e.p = {*lo, *hi, *hi};
  }
  return e;
}

Triangle as_triangle(const Element& e) { return Triangle(e.p[0], e.p[1], e.p[2]); }
Segment as_segment(const Element& e) { return Segment(e.p[0], e.p[1]); }

// Exact: do the two closed point sets share at least one point?
bool elements_meet(const Element& first, const Element& second) {
  using Kind = Element::Kind;
  // Order the pair so that e is the "larger" kind (triangle < segment < point).
  const bool swap = first.kind > second.kind;
  const Element& e = swap ? second : first;
  const Element& f = swap ? first : second;
  switch (e.kind) {
    case Kind::triangle:
      switch (f.kind) {
        case Kind::triangle: return CGAL::do_intersect(as_triangle(e), as_triangle(f));
        case Kind::segment: return CGAL::do_intersect(as_triangle(e), as_segment(f));
        case Kind::point: return CGAL::do_intersect(as_triangle(e), f.p[0]);
      }
      break;
    case Kind::segment:
      if (f.kind == Kind::segment) return CGAL::do_intersect(as_segment(e), as_segment(f));
      return CGAL::do_intersect(as_segment(e), f.p[0]);
    case Kind::point:
      return e.p[0] == f.p[0];
  }
  return false;  // not reached
}

// One box per triangle. The id must be unique over both ranges given to box_intersection_d
// (CGAL skips pairs of equal ids, which is how it avoids reporting a box against itself), so it
// is set explicitly: the triangle index, offset by the first surface's size for the second.
using BoxBase = CGAL::Box_intersection_d::Box_d<double, 3, CGAL::Box_intersection_d::ID_NONE>;
class TriangleBox : public BoxBase {
 public:
  TriangleBox(const CGAL::Bbox_3& box, std::size_t id, int triangle)
      : BoxBase(box), id_(id), triangle_(triangle) {}
  std::size_t id() const { return id_; }
  int triangle() const { return triangle_; }

 private:
  std::size_t id_;
  int triangle_;
};

struct Prepared {
  std::vector<Element> elements;
  std::vector<TriangleBox> boxes;
};

Prepared prepare(const Surface& s, const char* name, std::size_t id_offset) {
  const std::size_t nv = s.vertices.size();
  std::vector<char> checked(nv, 0);
  Prepared out;
  out.elements.reserve(s.triangles.size());
  out.boxes.reserve(s.triangles.size());
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    std::array<Point, 3> corner;
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      const int v = s.triangles[t][static_cast<std::size_t>(k)];
      if (v < 0 || static_cast<std::size_t>(v) >= nv)
        throw std::invalid_argument(std::string(name) + ": triangle " + std::to_string(t) + " has vertex index " +
                                    std::to_string(v) + " outside [0, " + std::to_string(nv) + ")");
      const auto& x = s.vertices[static_cast<std::size_t>(v)];
      if (!checked[static_cast<std::size_t>(v)]) {
        if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
          throw std::invalid_argument(std::string(name) + ": vertex " + std::to_string(v) +
                                      " has a non-finite coordinate");
        checked[static_cast<std::size_t>(v)] = 1;
      }
      corner[static_cast<std::size_t>(k)] = Point(x[0], x[1], x[2]);
      for (int d = 0; d < 3; ++d) {
        const double c = x[static_cast<std::size_t>(d)];
        lo[d] = k == 0 ? c : std::min(lo[d], c);
        hi[d] = k == 0 ? c : std::max(hi[d], c);
      }
    }
    out.elements.push_back(make_element(corner[0], corner[1], corner[2]));
    out.boxes.emplace_back(CGAL::Bbox_3(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]), id_offset + t,
                           static_cast<int>(t));
  }
  return out;
}

bool share_vertex(const std::array<int, 3>& a, const std::array<int, 3>& b) {
  for (int u : a)
    for (int v : b)
      if (u == v) return true;
  return false;
}

// Counts and the smallest intersecting pairs, independent of the order pairs are reported in.
class Collector {
 public:
  explicit Collector(std::size_t first_triangles) : involved_(first_triangles, 0) {}

  void tested() { ++report_.pairs_tested; }

  // (i, j): an intersecting pair, i of the first surface; first_j: whether j is of it too.
  void found(int i, int j, bool first_j) {
    ++report_.intersecting_pairs;
    involved_[static_cast<std::size_t>(i)] = 1;
    if (first_j) involved_[static_cast<std::size_t>(j)] = 1;
    candidates_.emplace_back(i, j);
    if (candidates_.size() >= trim_at) trim();
  }

  IntersectionReport finish() {
    trim();
    report_.examples = candidates_;
    report_.triangles_involved = static_cast<int>(std::count(involved_.begin(), involved_.end(), 1));
    return report_;
  }

 private:
  static constexpr std::size_t trim_at = 4096;
  void trim() {
    std::sort(candidates_.begin(), candidates_.end());
    candidates_.erase(std::unique(candidates_.begin(), candidates_.end()), candidates_.end());
    if (candidates_.size() > max_examples) candidates_.resize(max_examples);
  }

  IntersectionReport report_;
  std::vector<char> involved_;
  std::vector<std::pair<int, int>> candidates_;
};

}  // namespace

IntersectionReport self_intersections(const Surface& s) {
  Prepared p = prepare(s, "surface", 0);
  Collector collector(s.triangles.size());
  if (p.boxes.size() < 2) return collector.finish();
  auto callback = [&](const TriangleBox& x, const TriangleBox& y) {
    const int i = std::min(x.triangle(), y.triangle());
    const int j = std::max(x.triangle(), y.triangle());
    if (share_vertex(s.triangles[static_cast<std::size_t>(i)], s.triangles[static_cast<std::size_t>(j)])) return;
    collector.tested();
    if (elements_meet(p.elements[static_cast<std::size_t>(i)], p.elements[static_cast<std::size_t>(j)]))
      collector.found(i, j, true);
  };
  // Closed boxes (the default topology), so boxes that only touch are still tested exactly.
  CGAL::box_self_intersection_d(p.boxes.begin(), p.boxes.end(), callback);
  return collector.finish();
}

IntersectionReport intersections(const Surface& a, const Surface& b) {
  Prepared pa = prepare(a, "first surface", 0);
  Prepared pb = prepare(b, "second surface", a.triangles.size());
  Collector collector(a.triangles.size());
  if (pa.boxes.empty() || pb.boxes.empty()) return collector.finish();
  const std::size_t na = a.triangles.size();
  auto callback = [&](const TriangleBox& x, const TriangleBox& y) {
    // CGAL passes (box of the first range, box of the second); the id check keeps this exact
    // whatever the order.
    const bool x_in_a = x.id() < na;
    const int i = x_in_a ? x.triangle() : y.triangle();
    const int j = x_in_a ? y.triangle() : x.triangle();
    collector.tested();
    if (elements_meet(pa.elements[static_cast<std::size_t>(i)], pb.elements[static_cast<std::size_t>(j)]))
      collector.found(i, j, false);
  };
  CGAL::box_intersection_d(pa.boxes.begin(), pa.boxes.end(), pb.boxes.begin(), pb.boxes.end(), callback);
  return collector.finish();
}

double closest_vertex_distance(const Surface& a, const Surface& b) {
  prepare(a, "first surface", 0);  // the same input checks as the intersection tests
  prepare(b, "second surface", a.triangles.size());
  std::vector<Triangle> faces;
  faces.reserve(b.triangles.size());
  const auto point = [](const std::array<double, 3>& v) { return Point(v[0], v[1], v[2]); };
  for (const auto& t : b.triangles) {
    const Triangle f(point(b.vertices[static_cast<std::size_t>(t[0])]), point(b.vertices[static_cast<std::size_t>(t[1])]),
                     point(b.vertices[static_cast<std::size_t>(t[2])]));
    if (!f.is_degenerate()) faces.push_back(f);
  }
  if (faces.empty()) return std::numeric_limits<double>::infinity();
  using Primitive = CGAL::AABB_triangle_primitive<Kernel, std::vector<Triangle>::const_iterator>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;
  Tree tree(faces.cbegin(), faces.cend());
  tree.accelerate_distance_queries();
  std::vector<char> used(a.vertices.size(), 0);
  for (const auto& t : a.triangles)
    for (const int v : t) used[static_cast<std::size_t>(v)] = 1;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t v = 0; v < a.vertices.size(); ++v)
    if (used[v]) best = std::min(best, std::sqrt(CGAL::to_double(tree.squared_distance(point(a.vertices[v])))));
  return best;
}

}  // namespace clothsim::check

// Sewing patterns → one control mesh (pattern.hpp; docs/pattern.md): validation, boundary
// resampling, per-piece triangulation (piece_mesh.cpp), seam merging, the 1 → 4 split, placement.
#include "sim/pattern/pattern.hpp"

#include "sim/mesh/topology.hpp"
#include "sim/pattern/piece_mesh.hpp"
#include "sim/shell/ghost_layer.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <map>
#include <numbers>
#include <numeric>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace clothsim {

namespace {

using pattern_detail::PolygonDefect;

std::size_t at(int i) { return static_cast<std::size_t>(i); }
int count_of(std::size_t n) { return static_cast<int>(n); }

[[noreturn]] void fail(const std::string& what) { throw MeshError("pattern: " + what); }

std::string printf_text(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

// A length [m] with three decimals, or three significant digits below a centimetre.
std::string metres(double value) {
  return printf_text(value != 0.0 && std::abs(value) < 0.01 ? "%.3g" : "%.3f", value) + " m";
}

std::string num(double value) { return printf_text("%.6g", value); }

std::uint64_t edge_key(int a, int b) {
  const auto lo = static_cast<std::uint64_t>(static_cast<std::uint32_t>(std::min(a, b)));
  const auto hi = static_cast<std::uint64_t>(static_cast<std::uint32_t>(std::max(a, b)));
  return (lo << 32) | hi;
}

// "front edge 1" or "front edges 1–3".
std::string side_text(const SeamSide& side) {
  if (side.first_edge == side.last_edge) return side.piece + " edge " + std::to_string(side.first_edge);
  return side.piece + " edges " + std::to_string(side.first_edge) + "\u2013" + std::to_string(side.last_edge);
}

// "seam 2 (front edge 1 – back edge 3)".
std::string seam_text(const std::vector<Seam>& seams, int s) {
  const Seam& seam = seams[at(s)];
  return "seam " + std::to_string(s) + " (" + side_text(seam.a) + " \u2013 " + side_text(seam.b) + ")";
}

// "seam 0 (...)" or "seams 0 (...) and 2 (...)"; "the seams" when the list is empty.
std::string seams_text(const std::vector<Seam>& seams, const std::vector<int>& list) {
  if (list.empty()) return "the seams";
  std::string out = list.size() == 1 ? "seam " : "seams ";
  for (std::size_t k = 0; k < list.size(); ++k) {
    if (k > 0) out += k + 1 == list.size() ? " and " : ", ";
    const std::string full = seam_text(seams, list[k]);
    out += full.substr(5);  // without "seam "
  }
  return out;
}

std::string point_text(const Eigen::Vector2d& p) { return "(" + num(p.x()) + ", " + num(p.y()) + ")"; }

// A seam side, resolved.
struct Side {
  int piece = -1;
  int first = 0;      // first edge
  int count = 0;      // edges on the path
  double length = 0;  // along the outline [m]
  int segments = 0;   // coarse segments (the same on both sides of a seam)
  int start = 0;      // index of its first point in the piece's coarse boundary loop
};

struct SewnBy {
  int seam = -1;
  int side = -1;  // 0: a, 1: b
};

// One piece while it is meshed.
struct Piece {
  std::vector<Eigen::Vector2d> loop;       // coarse boundary points, counter-clockwise
  std::vector<int> loop_edge;              // per loop segment: the outline edge its start lies on
  std::vector<int> corner_fine;            // per outline point: its index in the fine boundary loop
  std::vector<Eigen::Vector2d> points;     // coarse vertices: the loop, then the lattice
  std::vector<Triangle> triangles;         // coarse, local vertex ids, sorted
  int first_vertex = 0;                    // global id of its coarse vertex 0 among all pieces
  std::vector<int> fine_loop;              // piece-vertex ids along the fine boundary
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
};

// A vertex of one piece after the split: its pattern coordinates and the merged vertex it is.
struct PieceVertex {
  int piece;
  Eigen::Vector2d uv;
  int merged;
};

double edge_len(const PatternPiece& piece, int e) {
  const int n = count_of(piece.points.size());
  return (piece.points[at((e + 1) % n)] - piece.points[at(e)]).norm();
}

double radians(double deg) { return deg * std::numbers::pi / 180.0; }

Eigen::Vector3d place(const PatternPlacement& placement, const Eigen::Matrix3d& rotation, const Eigen::Vector2d& q) {
  Eigen::Vector3d p(q.x(), q.y(), 0.0);
  if (placement.wrap_radius) {
    const double r = *placement.wrap_radius;
    p = Eigen::Vector3d(r * std::sin(q.x() / r), q.y(), r * std::cos(q.x() / r));
  }
  return rotation * p + placement.translate;
}

// ---- 1. Validation -------------------------------------------------------------------------

void validate_piece(const PatternPiece& piece, int index) {
  if (piece.name.empty()) fail("piece " + std::to_string(index) + " has an empty name");
  const std::string who = "piece " + piece.name;
  const int n = count_of(piece.points.size());
  if (!std::isfinite(piece.grain_deg)) fail(who + ": grain_deg is not finite");
  const PatternPlacement& pl = piece.placement;
  if (pl.wrap_radius && !(std::isfinite(*pl.wrap_radius) && *pl.wrap_radius > 0.0))
    fail(who + ": wrap radius must be positive and finite (got " + num(*pl.wrap_radius) + " m)");
  if (!pl.rotate_deg.allFinite()) fail(who + ": rotate_deg is not finite");
  if (!pl.translate.allFinite()) fail(who + ": translate is not finite");

  using Kind = PolygonDefect::Kind;
  const PolygonDefect d = pattern_detail::find_polygon_defect(piece.points);
  const auto edge = [n](int e) {
    return "edge " + std::to_string(e) + " (point " + std::to_string(e) + " to point " + std::to_string((e + 1) % n) + ")";
  };
  switch (d.kind) {
    case Kind::none:
      return;
    case Kind::too_few_points:
      fail(who + ": the outline has " + std::to_string(n) + " point(s); a piece needs at least 3");
    case Kind::not_finite:
      fail(who + ": point " + std::to_string(d.i) + " is not finite");
    case Kind::zero_edge:
      fail(who + ": " + edge(d.i) + " has zero length (its two points coincide)");
    case Kind::repeated_point:
      fail(who + ": points " + std::to_string(d.i) + " and " + std::to_string(d.j) + " coincide at " +
           point_text(piece.points[at(d.i)]) + " (the outline must be a simple polygon)");
    case Kind::crossing:
      fail(who + ": " + edge(d.i) + " and " + edge(d.j) +
           " intersect (the outline must be a simple polygon, without self-intersection)");
    case Kind::overlap:
      fail(who + ": " + edge(d.i) + " and " + edge(d.j) + " overlap (the outline folds back on itself)");
    case Kind::clockwise:
      fail(who + ": the outline is clockwise or degenerate (signed area " + num(d.signed_area) +
           " m\u00b2); list its points counter-clockwise");
  }
}

// Resolves every seam side, checks ranges, double sewing and lengths; fills sewn[piece][edge].
std::vector<std::array<Side, 2>> resolve_seams(const PatternSpec& spec, const std::map<std::string, int>& index,
                                               std::vector<std::vector<SewnBy>>& sewn) {
  std::vector<std::array<Side, 2>> sides;
  for (int s = 0; s < count_of(spec.seams.size()); ++s) {
    const Seam& seam = spec.seams[at(s)];
    std::array<Side, 2> resolved;
    for (int k = 0; k < 2; ++k) {
      const SeamSide& raw = k == 0 ? seam.a : seam.b;
      const std::string which = "seam " + std::to_string(s) + " side " + (k == 0 ? "a" : "b");
      const auto it = index.find(raw.piece);
      if (it == index.end()) fail(which + ": unknown piece '" + raw.piece + "'");
      const PatternPiece& piece = spec.pieces[at(it->second)];
      const int n = count_of(piece.points.size());
      for (int e : {raw.first_edge, raw.last_edge})
        if (e < 0 || e >= n)
          fail(which + " (" + side_text(raw) + "): edge " + std::to_string(e) + " is out of range (piece " + raw.piece +
               " has " + std::to_string(n) + " edges, 0\u2013" + std::to_string(n - 1) + ")");
      Side& side = resolved[at(k)];
      side.piece = it->second;
      side.first = raw.first_edge;
      side.count = (raw.last_edge - raw.first_edge + n) % n + 1;
      for (int j = 0; j < side.count; ++j) {
        const int e = (side.first + j) % n;
        SewnBy& by = sewn[at(side.piece)][at(e)];
        if (by.seam >= 0)
          fail("piece " + raw.piece + " edge " + std::to_string(e) + " is sewn twice: by " + seam_text(spec.seams, by.seam) +
               " side " + (by.side == 0 ? "a" : "b") + " and by " + seam_text(spec.seams, s) + " side " + (k == 0 ? "a" : "b"));
        by = {s, k};
        side.length += edge_len(piece, e);
      }
    }
    const double la = resolved[0].length, lb = resolved[1].length;
    const double mean = 0.5 * (la + lb);
    const double rel = std::abs(la - lb) / mean;
    if (rel > 0.01)
      fail(seam_text(spec.seams, s) + ": lengths " + metres(la) + " and " + metres(lb) + " differ by " +
           printf_text("%.1f", 100.0 * rel) + " % (more than 1 %)");
    sides.push_back(resolved);
  }
  return sides;
}

// ---- 2. Boundary points --------------------------------------------------------------------

int segment_count(double length, double spacing) {
  return std::max(1, static_cast<int>(std::lround(length / spacing)));
}

// The coarse boundary loop of piece p: unsewn edges split evenly (corners kept), seam paths
// resampled at equal arc length with the seam's segment count. Sets each side's start.
void build_loop(const PatternPiece& piece, const std::vector<SewnBy>& sewn, std::vector<std::array<Side, 2>>& sides,
                double spacing, Piece& out) {
  const int n = count_of(piece.points.size());
  const auto run_start = [&](int e) {
    const SewnBy& by = sewn[at(e)];
    return by.seam < 0 || sides[at(by.seam)][at(by.side)].first == e;
  };
  int e0 = 0;
  while (!run_start(e0)) ++e0;  // every path has a first edge, so this stops
  std::vector<int> corner_raw(at(n), -1);
  int e = e0;
  do {
    const SewnBy& by = sewn[at(e)];
    const int start = count_of(out.loop.size());
    if (by.seam < 0) {
      const Eigen::Vector2d& p = piece.points[at(e)];
      const Eigen::Vector2d& q = piece.points[at((e + 1) % n)];
      const int m = segment_count((q - p).norm(), spacing);
      corner_raw[at(e)] = 2 * start;
      for (int k = 0; k < m; ++k) {
        out.loop.push_back(k == 0 ? p : Eigen::Vector2d(p + (static_cast<double>(k) / m) * (q - p)));
        out.loop_edge.push_back(e);
      }
      e = (e + 1) % n;
    } else {
      Side& side = sides[at(by.seam)][at(by.side)];
      side.start = start;
      const int m = side.segments;
      std::vector<double> cum(at(side.count) + 1, 0.0);
      for (int j = 0; j < side.count; ++j) cum[at(j) + 1] = cum[at(j)] + edge_len(piece, (side.first + j) % n);
      const double total = cum.back();
      int j = 0;
      for (int k = 0; k < m; ++k) {
        const double s = total * static_cast<double>(k) / m;
        while (j + 1 < side.count && cum[at(j) + 1] <= s) ++j;
        const int edge = (side.first + j) % n;
        const Eigen::Vector2d& p = piece.points[at(edge)];
        const Eigen::Vector2d& q = piece.points[at((edge + 1) % n)];
        const double t = (s - cum[at(j)]) / (cum[at(j) + 1] - cum[at(j)]);
        out.loop.push_back(t == 0.0 ? p : Eigen::Vector2d(p + t * (q - p)));
        out.loop_edge.push_back(edge);
      }
      corner_raw[at(side.first)] = 2 * start;
      // Inner corners of the path: the fine boundary point nearest by arc length.
      for (int c = 1; c < side.count; ++c)
        corner_raw[at((side.first + c) % n)] = 2 * start + static_cast<int>(std::lround(2.0 * m * cum[at(c)] / total));
      e = (side.first + side.count) % n;
    }
  } while (e != e0);
  const int fine = 2 * count_of(out.loop.size());
  out.corner_fine.resize(at(n));
  for (int c = 0; c < n; ++c) out.corner_fine[at(c)] = corner_raw[at(c)] % fine;
}

void check_loop(const PatternPiece& piece, const Piece& mesh, double edge_length) {
  using Kind = PolygonDefect::Kind;
  const PolygonDefect d = pattern_detail::find_polygon_defect(mesh.loop);
  if (d.kind == Kind::none) return;
  std::string what;
  const auto on = [&mesh](int k) { return std::to_string(mesh.loop_edge[at(k)]); };
  switch (d.kind) {
    case Kind::too_few_points:
      what = "has only " + std::to_string(mesh.loop.size()) + " point(s)";
      break;
    case Kind::crossing:
    case Kind::overlap:
      what = "intersects itself (its segments on edges " + on(d.i) + " and " + on(d.j) + ")";
      break;
    case Kind::zero_edge:
    case Kind::repeated_point:
      what = "has repeated points (on edge " + on(d.i) + ")";
      break;
    default:
      what = "is degenerate (signed area " + num(d.signed_area) + " m\u00b2)";
      break;
  }
  fail("piece " + piece.name + ": its outline resampled at about 2\u00b7edge_length (edge_length " + metres(edge_length) +
       ", seam paths cut across their inner corners) " + what + "; use a smaller edge_length or sew shorter paths");
}

// ---- 4. Merge --------------------------------------------------------------------------------

int find_root(std::vector<int>& parent, int v) {
  while (parent[at(v)] != v) {
    parent[at(v)] = parent[at(parent[at(v)])];
    v = parent[at(v)];
  }
  return v;
}

void unite(std::vector<int>& parent, int a, int b) {
  a = find_root(parent, a);
  b = find_root(parent, b);
  if (a == b) return;
  if (a < b) parent[at(b)] = a;
  else parent[at(a)] = b;
}

// The seams touching both u and v (by their merged seam lists), or either when none touches both.
std::vector<int> seams_near(const std::vector<std::vector<int>>& seams_of, int u, int v) {
  std::vector<int> both;
  const std::vector<int>& a = seams_of[at(u)];
  const std::vector<int>& b = seams_of[at(v)];
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
  if (!both.empty()) return both;
  std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
  return both;
}

// Checks the merged coarse mesh and names the seams behind any defect, then runs Topology.
void check_merged(const PatternSpec& spec, const std::vector<Piece>& pieces, const std::vector<Triangle>& tris,
                  const std::vector<int>& tri_piece, const std::vector<int>& tri_local, int num_merged,
                  const std::vector<std::vector<int>>& seams_of, const std::vector<int>& sources) {
  const auto where = [&](int t) {
    const Piece& piece = pieces[at(tri_piece[at(t)])];
    const Triangle& local = piece.triangles[at(tri_local[at(t)])];
    const Eigen::Vector2d c =
        (piece.points[at(local[0])] + piece.points[at(local[1])] + piece.points[at(local[2])]) / 3.0;
    return "piece " + spec.pieces[at(tri_piece[at(t)])].name + " near " + point_text(c);
  };
  for (int t = 0; t < count_of(tris.size()); ++t) {
    const Triangle& tri = tris[at(t)];
    for (int k = 0; k < 3; ++k) {
      const int u = tri[at(k)], v = tri[at((k + 1) % 3)];
      if (u == v)
        fail(seams_text(spec.seams, seams_of[at(u)]) + ": joins two corners of one triangle (" + where(t) +
             "): the sewn paths are too few segments long at edge_length " + metres(spec.edge_length) +
             "; use a smaller edge_length");
    }
  }
  std::vector<std::pair<std::uint64_t, int>> uses;  // key, 2·triangle + (a > b)
  uses.reserve(3 * tris.size());
  for (int t = 0; t < count_of(tris.size()); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = tris[at(t)][at(k)], b = tris[at(t)][at((k + 1) % 3)];
      uses.emplace_back(edge_key(a, b), 2 * t + (a > b ? 1 : 0));
    }
  std::sort(uses.begin(), uses.end());
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].first == uses[i].first) ++j;
    const int lo = static_cast<int>(uses[i].first >> 32), hi = static_cast<int>(uses[i].first & 0xffffffffu);
    const std::vector<int> near = seams_near(seams_of, lo, hi);
    const int t0 = uses[i].second / 2;
    if (j - i > 2)
      fail(seams_text(spec.seams, near) + ": an edge (" + where(t0) + ") is shared by " + std::to_string(j - i) +
           " triangles; a seam joins exactly two sides, so check which edges these seams name");
    if (j - i == 2 && uses[i].second % 2 == uses[i + 1].second % 2) {
      bool any_reversed = false;
      for (int s : near) any_reversed = any_reversed || spec.seams[at(s)].reversed;
      fail(seams_text(spec.seams, near) + ": joins its pieces with opposite orientations (" + where(t0) +
           ": both sides run the same way along the seam); " +
           (any_reversed ? std::string("check that every piece is listed counter-clockwise seen from the same side and "
                                       "that the seams name the intended edges")
                         : std::string("set reversed = true for this seam (two pieces seen from the same side run "
                                       "along a shared seam in opposite directions)")));
    }
    i = j;
  }
  // Fans around the merged vertices (the pieces themselves are disks).
  std::vector<std::vector<std::pair<int, int>>> fan(at(num_merged));
  for (const Triangle& tri : tris)
    for (int k = 0; k < 3; ++k)
      if (sources[at(tri[at(k)])] > 1) fan[at(tri[at(k)])].emplace_back(tri[at((k + 1) % 3)], tri[at((k + 2) % 3)]);
  for (int v = 0; v < num_merged; ++v) {
    std::vector<std::pair<int, int>>& pairs = fan[at(v)];
    if (pairs.empty()) continue;
    std::sort(pairs.begin(), pairs.end());
    std::vector<int> values;
    for (const auto& pair : pairs) values.push_back(pair.second);
    std::sort(values.begin(), values.end());
    int start = pairs.front().first, starts = 0;
    for (const auto& pair : pairs)
      if (!std::binary_search(values.begin(), values.end(), pair.first)) {
        if (starts == 0) start = pair.first;
        ++starts;
      }
    int visited = 0, cur = start;
    while (visited <= count_of(pairs.size())) {
      const auto it = std::lower_bound(pairs.begin(), pairs.end(), std::make_pair(cur, -1));
      if (it == pairs.end() || it->first != cur) break;
      ++visited;
      cur = it->second;
      if (cur == start) break;
    }
    if (starts > 1 || visited != count_of(pairs.size()))
      fail(seams_text(spec.seams, seams_of[at(v)]) +
           ": the pieces meet at a point without sharing the edges around it (the surface would touch itself there); "
           "check which edges these seams name");
  }
  try {
    const Topology topology(num_merged, tris);
  } catch (const MeshError& error) {
    fail(std::string("the sewn mesh is not a manifold surface: ") + error.what() + "; check the seams");
  }
}

}  // namespace

PatternMesh build_pattern(const PatternSpec& spec) {
  // ---- 1. Validation.
  const double h = spec.edge_length;
  if (!(std::isfinite(h) && h > 0.0)) fail("edge_length must be positive and finite (got " + num(h) + " m)");
  if (spec.pieces.empty()) fail("the pattern has no pieces");
  std::map<std::string, int> index;
  for (int p = 0; p < count_of(spec.pieces.size()); ++p) {
    const PatternPiece& piece = spec.pieces[at(p)];
    validate_piece(piece, p);
    if (const auto [it, added] = index.emplace(piece.name, p); !added)
      fail("pieces " + std::to_string(it->second) + " and " + std::to_string(p) + " are both named " + piece.name +
           " (names must be unique)");
  }
  std::vector<std::vector<SewnBy>> sewn;
  for (const PatternPiece& piece : spec.pieces) sewn.emplace_back(piece.points.size());
  std::vector<std::array<Side, 2>> sides = resolve_seams(spec, index, sewn);

  const double spacing = 2.0 * h;
  // Size estimate before anything is allocated: the split mesh has about 4× the coarse vertices.
  {
    double estimate = 0.0;
    for (const PatternPiece& piece : spec.pieces) {
      double perimeter = 0.0;
      for (int e = 0; e < count_of(piece.points.size()); ++e) perimeter += edge_len(piece, e);
      const double area = pattern_detail::signed_area(piece.points);
      estimate += 4.0 * (area / (0.5 * std::sqrt(3.0) * spacing * spacing) + perimeter / spacing + 3.0);
    }
    if (estimate > static_cast<double>(kDefaultMaxVertices))
      throw MeshLimitError("pattern: edge_length " + metres(h) + " would give about " + printf_text("%.3g", estimate) +
                           " vertices, more than the limit of " + std::to_string(kDefaultMaxVertices));
  }
  for (std::array<Side, 2>& pair : sides) {
    const int m = segment_count(0.5 * (pair[0].length + pair[1].length), spacing);
    pair[0].segments = pair[1].segments = m;
  }

  // ---- 2, 3. Per piece: boundary loop, lattice, constrained Delaunay triangulation.
  const int num_pieces = count_of(spec.pieces.size());
  std::vector<Piece> pieces(at(num_pieces));
  int total = 0;
  for (int p = 0; p < num_pieces; ++p) {
    const PatternPiece& src = spec.pieces[at(p)];
    Piece& piece = pieces[at(p)];
    build_loop(src, sewn[at(p)], sides, spacing, piece);
    check_loop(src, piece, h);
    piece.points = piece.loop;
    const std::vector<Eigen::Vector2d> lattice =
        pattern_detail::interior_lattice(piece.loop, spacing, src.grain_deg, src.points.front(), 0.6 * spacing);
    piece.points.insert(piece.points.end(), lattice.begin(), lattice.end());
    try {
      piece.triangles = pattern_detail::triangulate_polygon(piece.points, count_of(piece.loop.size()));
    } catch (const MeshError& error) {
      fail("piece " + src.name + ": " + error.what());
    }
    piece.first_vertex = total;
    total += count_of(piece.points.size());
    const Eigen::Vector3d r = src.placement.rotate_deg;
    piece.rotation = (Eigen::AngleAxisd(radians(r.z()), Eigen::Vector3d::UnitZ()) *
                      Eigen::AngleAxisd(radians(r.y()), Eigen::Vector3d::UnitY()) *
                      Eigen::AngleAxisd(radians(r.x()), Eigen::Vector3d::UnitX()))
                         .toRotationMatrix();
  }

  // ---- 4. Merge the coarse piece vertices tied by seams.
  const int num_seams = count_of(spec.seams.size());
  std::vector<int> parent(at(total));
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::vector<int>> seams_of_global(at(total));
  const auto loop_vertex = [&pieces](const Side& side, int k) {
    const Piece& piece = pieces[at(side.piece)];
    return piece.first_vertex + (side.start + k) % count_of(piece.loop.size());
  };
  for (int s = 0; s < num_seams; ++s) {
    const Side& a = sides[at(s)][0];
    const Side& b = sides[at(s)][1];
    const int m = a.segments;
    for (int k = 0; k <= m; ++k) {
      const int ga = loop_vertex(a, k), gb = loop_vertex(b, spec.seams[at(s)].reversed ? m - k : k);
      unite(parent, ga, gb);
      seams_of_global[at(ga)].push_back(s);
      seams_of_global[at(gb)].push_back(s);
    }
  }
  std::vector<int> merged_of(at(total), -1), id_of_root(at(total), -1);
  int num_coarse = 0;
  for (int g = 0; g < total; ++g) {
    const int r = find_root(parent, g);
    if (id_of_root[at(r)] < 0) id_of_root[at(r)] = num_coarse++;
    merged_of[at(g)] = id_of_root[at(r)];
  }
  std::vector<std::vector<int>> seams_of(at(num_coarse));
  std::vector<int> sources(at(num_coarse), 0);
  for (int g = 0; g < total; ++g) {
    std::vector<int>& list = seams_of[at(merged_of[at(g)])];
    list.insert(list.end(), seams_of_global[at(g)].begin(), seams_of_global[at(g)].end());
    ++sources[at(merged_of[at(g)])];
  }
  for (std::vector<int>& list : seams_of) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  {
    std::vector<Triangle> coarse;
    std::vector<int> tri_piece, tri_local;
    for (int p = 0; p < num_pieces; ++p) {
      const Piece& piece = pieces[at(p)];
      for (int t = 0; t < count_of(piece.triangles.size()); ++t) {
        Triangle tri;
        for (int k = 0; k < 3; ++k) tri[at(k)] = merged_of[at(piece.first_vertex + piece.triangles[at(t)][at(k)])];
        coarse.push_back(tri);
        tri_piece.push_back(p);
        tri_local.push_back(t);
      }
    }
    check_merged(spec, pieces, coarse, tri_piece, tri_local, num_coarse, seams_of, sources);
  }

  // ---- 5. Split every triangle 1 → 4 at its edge midpoints (pattern coordinates).
  std::vector<PieceVertex> pv;
  pv.reserve(at(total) * 4);
  for (int p = 0; p < num_pieces; ++p)
    for (int k = 0; k < count_of(pieces[at(p)].points.size()); ++k)
      pv.push_back({p, pieces[at(p)].points[at(k)], merged_of[at(pieces[at(p)].first_vertex + k)]});
  int num_merged = num_coarse;
  std::unordered_map<std::uint64_t, int> merged_mid;  // merged coarse edge → merged midpoint
  std::vector<Triangle> fine;                         // piece-vertex ids
  std::vector<int> fine_piece;
  for (int p = 0; p < num_pieces; ++p) {
    Piece& piece = pieces[at(p)];
    std::unordered_map<std::uint64_t, int> local_mid;  // local coarse edge → piece vertex
    const auto mid = [&](int a, int b) {
      const auto [it, added] = local_mid.emplace(edge_key(a, b), count_of(pv.size()));
      if (added) {
        const int ma = merged_of[at(piece.first_vertex + a)], mb = merged_of[at(piece.first_vertex + b)];
        const auto found = merged_mid.emplace(edge_key(ma, mb), num_merged);
        if (found.second) ++num_merged;
        pv.push_back({p, 0.5 * (piece.points[at(a)] + piece.points[at(b)]), found.first->second});
      }
      return it->second;
    };
    for (const Triangle& t : piece.triangles) {
      const int a = piece.first_vertex + t[0], b = piece.first_vertex + t[1], c = piece.first_vertex + t[2];
      const int ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      fine.push_back({a, ab, ca});
      fine.push_back({ab, b, bc});
      fine.push_back({ca, bc, c});
      fine.push_back({ab, bc, ca});
      for (int k = 0; k < 4; ++k) fine_piece.push_back(p);
    }
    const int nb = count_of(piece.loop.size());
    for (int k = 0; k < nb; ++k) {
      piece.fine_loop.push_back(piece.first_vertex + k);
      piece.fine_loop.push_back(local_mid.at(edge_key(k, (k + 1) % nb)));
    }
  }

  // ---- 6. Start positions.
  PatternMesh out;
  std::vector<Eigen::Vector3d> pv_placed;
  pv_placed.reserve(pv.size());
  out.placed.resize(at(num_merged));
  for (const PieceVertex& v : pv) {
    const PatternPlacement& placement = spec.pieces[at(v.piece)].placement;
    pv_placed.push_back(place(placement, pieces[at(v.piece)].rotation, v.uv));
    out.placed[at(v.merged)].push_back(pv_placed.back());
  }
  out.mesh.vertices.resize(num_merged, 3);
  for (int v = 0; v < num_merged; ++v) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& x : out.placed[at(v)]) sum += x;
    out.mesh.vertices.row(v) = (sum / static_cast<double>(out.placed[at(v)].size())).transpose();
  }
  out.mesh.triangles.reserve(fine.size());
  out.mesh.uv.reserve(fine.size());
  out.mesh.warp.reserve(fine.size());
  for (std::size_t t = 0; t < fine.size(); ++t) {
    const Triangle& f = fine[t];
    const Triangle tri{pv[at(f[0])].merged, pv[at(f[1])].merged, pv[at(f[2])].merged};
    const std::array<Eigen::Vector2d, 3> uv{pv[at(f[0])].uv, pv[at(f[1])].uv, pv[at(f[2])].uv};
    const int p = fine_piece[t];
    Eigen::Matrix2d duv;
    duv << uv[1] - uv[0], uv[2] - uv[0];
    Eigen::Matrix<double, 3, 2> dx;
    dx << (out.mesh.vertices.row(tri[1]) - out.mesh.vertices.row(tri[0])).transpose(),
        (out.mesh.vertices.row(tri[2]) - out.mesh.vertices.row(tri[0])).transpose();
    const double g = radians(spec.pieces[at(p)].grain_deg);
    const Eigen::Vector3d w = dx * (duv.inverse() * Eigen::Vector2d(std::cos(g), std::sin(g)));
    if (!(w.norm() > 0.0) || !w.allFinite())
      fail("piece " + spec.pieces[at(p)].name + ": the start triangle near " + point_text((uv[0] + uv[1] + uv[2]) / 3.0) +
           " is degenerate (its sewn corners were pulled together); place the pieces closer to their seams");
    out.mesh.triangles.push_back(tri);
    out.mesh.uv.push_back(uv);
    out.mesh.warp.push_back(w.normalized());
  }
  out.triangle_piece = std::move(fine_piece);

  // Edge vertices and seam gaps along the fine boundary loops.
  out.edge_vertices.resize(at(num_pieces));
  for (int p = 0; p < num_pieces; ++p) {
    const Piece& piece = pieces[at(p)];
    const int n = count_of(spec.pieces[at(p)].points.size());
    const int nf = count_of(piece.fine_loop.size());
    for (int e = 0; e < n; ++e) {
      const int from = piece.corner_fine[at(e)], to = piece.corner_fine[at((e + 1) % n)];
      std::vector<int> run;
      for (int k = 0, len = (to - from + nf) % nf; k <= len; ++k) run.push_back(pv[at(piece.fine_loop[at((from + k) % nf)])].merged);
      out.edge_vertices[at(p)].push_back(std::move(run));
    }
  }
  for (int s = 0; s < num_seams; ++s) {
    const Side& a = sides[at(s)][0];
    const Side& b = sides[at(s)][1];
    const Piece& pa = pieces[at(a.piece)];
    const Piece& pb = pieces[at(b.piece)];
    const int fa = count_of(pa.fine_loop.size()), fb = count_of(pb.fine_loop.size());
    const int m = 2 * a.segments;
    double gap = 0.0;
    for (int k = 0; k <= m; ++k) {
      const int va = pa.fine_loop[at((2 * a.start + k) % fa)];
      const int vb = pb.fine_loop[at((2 * b.start + (spec.seams[at(s)].reversed ? m - k : k)) % fb)];
      gap = std::max(gap, (pv_placed[at(va)] - pv_placed[at(vb)]).norm());
    }
    out.seam_gap.push_back(gap);
  }

  // ---- 5 (check). At most one irregular vertex per triangle; valence within the ghost layer's.
  {
    const Topology topology(num_merged, out.mesh.triangles);
    const auto vertex_text = [&](int v) {
      std::string text = "vertex " + std::to_string(v) + " (";
      bool first = true;
      for (const PieceVertex& x : pv)
        if (x.merged == v) {
          text += std::string(first ? "" : ", ") + "piece " + spec.pieces[at(x.piece)].name + " at " + point_text(x.uv);
          first = false;
        }
      return text + ")";
    };
    for (int v = 0; v < num_merged; ++v) {
      const int valence = topology.is_boundary(v) ? topology.num_incident_triangles(v) + 3 : topology.valence(v);
      if (valence > 12)
        fail(vertex_text(v) + " has valence " + std::to_string(valence) +
             " (with the ghost layer at borders); at most 12 are supported: too many triangles meet there");
    }
    const ExtendedMesh ext = build_ghost_layer(out.mesh);
    for (int t = 0; t < out.mesh.num_triangles(); ++t)
      if (irregular_vertex_count(ext, out.mesh.triangles[at(t)]) > 1)
        fail("piece " + spec.pieces[at(out.triangle_piece[at(t)])].name + ": triangle " + std::to_string(t) +
             " has more than one irregular vertex after the split (internal error)");
  }
  return out;
}

}  // namespace clothsim

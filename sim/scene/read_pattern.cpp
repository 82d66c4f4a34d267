// The scene's pattern garments: see read_pattern.hpp.
#include "sim/scene/read_pattern.hpp"

#include <algorithm>

namespace clothsim::scene_io {

namespace {

Eigen::Vector2d point2(const Reader& r, const Json& j, const std::string& path) {
  if (!j.is_array() || j.size() != 2) r.fail(path, "expected a point [x, y] in metres (got " + describe(j) + ")");
  return {r.number(j[0], join_index(path, 0)), r.number(j[1], join_index(path, 1))};
}

int edge_index(const Reader& r, const Json& j, const std::string& path, const PatternPiece& piece) {
  const int n = static_cast<int>(piece.points.size());
  const int e = r.integer(j, path);
  if (e < 0 || e >= n)
    r.fail(path, "piece " + quote(piece.name) + " has edges 0 to " + std::to_string(n - 1) + " (one per point; got " +
                     std::to_string(e) + ")");
  return e;
}

PatternPlacement read_placement(const Reader& r, const Json& j, const std::string& path) {
  PatternPlacement p;
  r.check_object(j, path, {"wrap", "rotate_deg", "translate"});
  if (const Json* w = r.find(j, "wrap")) {
    const std::string wp = join_key(path, "wrap");
    r.check_object(*w, wp, {"radius"});
    p.wrap_radius = r.positive(r.require(*w, wp, "radius"), join_key(wp, "radius"), "[m]");
  }
  if (const Json* v = r.find(j, "rotate_deg")) p.rotate_deg = r.vec3(*v, join_key(path, "rotate_deg"));
  if (const Json* v = r.find(j, "translate")) p.translate = r.vec3(*v, join_key(path, "translate"));
  return p;
}

}  // namespace

std::size_t read_piece_name(const Reader& r, const Json& j, const std::string& path, const PatternSpec& spec) {
  const std::string name = r.string(j, path);
  std::vector<std::string> names;
  for (const PatternPiece& p : spec.pieces) names.push_back(p.name);
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end())
    r.fail(path, "no piece " + quote(name) + " (pieces: " + format_list(names, true) + ")" + did_you_mean(name, names));
  return static_cast<std::size_t>(it - names.begin());
}

SeamSide read_piece_edge(const Reader& r, const Json& j, const std::string& path, const PatternSpec& spec) {
  r.check_object(j, path, {"piece", "edge"});
  SeamSide side;
  const std::size_t index = read_piece_name(r, r.require(j, path, "piece"), join_key(path, "piece"), spec);
  side.piece = spec.pieces[index].name;
  const PatternPiece& piece = spec.pieces[index];
  const std::string ep = join_key(path, "edge");
  const Json& edge = r.require(j, path, "edge");
  if (edge.is_array()) {
    if (edge.size() != 2) r.fail(ep, "expected an edge number or [first, last] (got " + describe(edge) + ")");
    side.first_edge = edge_index(r, edge[0], join_index(ep, 0), piece);
    side.last_edge = edge_index(r, edge[1], join_index(ep, 1), piece);
  } else {
    side.first_edge = side.last_edge = edge_index(r, edge, ep, piece);
  }
  return side;
}

PatternSpec read_pattern(const Reader& r, const Json& j, const std::string& path) {
  r.check_object(j, path, {"edge_length", "pieces", "seams"});
  PatternSpec spec;
  spec.edge_length = r.positive(r.require(j, path, "edge_length"), join_key(path, "edge_length"), "[m]");
  const std::string pieces_path = join_key(path, "pieces");
  const Json& pieces = r.array(r.require(j, path, "pieces"), pieces_path);
  if (pieces.empty()) r.fail(pieces_path, "needs at least one piece");
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const std::string pp = join_index(pieces_path, i);
    const Json& item = pieces[i];
    r.check_object(item, pp, {"name", "points", "grain_deg", "placement"});
    PatternPiece piece;
    piece.name = r.string(r.require(item, pp, "name"), join_key(pp, "name"));
    if (piece.name.empty()) r.fail(join_key(pp, "name"), "must not be empty");
    for (const PatternPiece& other : spec.pieces)
      if (other.name == piece.name) r.fail(join_key(pp, "name"), "a second piece called " + quote(piece.name));
    const std::string points_path = join_key(pp, "points");
    const Json& points = r.array(r.require(item, pp, "points"), points_path);
    if (points.size() < 3) r.fail(points_path, "a piece needs at least 3 points (got " + std::to_string(points.size()) + ")");
    for (std::size_t k = 0; k < points.size(); ++k) piece.points.push_back(point2(r, points[k], join_index(points_path, k)));
    if (const Json* g = r.find(item, "grain_deg")) piece.grain_deg = r.number(*g, join_key(pp, "grain_deg"));
    if (const Json* p = r.find(item, "placement")) piece.placement = read_placement(r, *p, join_key(pp, "placement"));
    spec.pieces.push_back(std::move(piece));
  }
  if (const Json* seams = r.find(j, "seams")) {
    const std::string sp = join_key(path, "seams");
    r.array(*seams, sp);
    for (std::size_t i = 0; i < seams->size(); ++i) {
      const std::string p = join_index(sp, i);
      const Json& item = (*seams)[i];
      r.check_object(item, p, {"a", "b", "reversed"});
      Seam seam;
      seam.a = read_piece_edge(r, r.require(item, p, "a"), join_key(p, "a"), spec);
      seam.b = read_piece_edge(r, r.require(item, p, "b"), join_key(p, "b"), spec);
      seam.reversed = r.boolean(r.require(item, p, "reversed"), join_key(p, "reversed"));
      spec.seams.push_back(seam);
    }
  }
  return spec;
}

}  // namespace clothsim::scene_io

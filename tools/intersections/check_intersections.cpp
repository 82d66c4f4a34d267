// check_intersections SURFACE.obj [OBSTACLE.obj ...]
//
// Exact check of a triangle surface for self-intersections and for intersections with each
// obstacle (see surface_intersections.hpp for what counts and the limitations). Prints one line
// per check:
//   self: N intersecting pairs (M tested)
//   obstacle PATH: N intersecting pairs (M tested); closest vertex D m
// (D: the smallest distance from a vertex of SURFACE to a triangle of the obstacle, a
// floating-point measurement, closest_vertex_distance), followed, on the same line when N > 0, by
//   ; K surface triangles involved; first pairs: i-j i-j ...
// (up to 20 pairs, 0-based triangle indices in file order after fan triangulation; for an
// obstacle line, i is the surface's triangle and j the obstacle's).
// Exit code: 0 no intersections, 1 some, 2 bad input (message on stderr naming file and line).
//
// Reads Wavefront OBJ: `v x y z [w]` and `f` lines with entries `a`, `a/b`, `a/b/c` or `a//c`
// (1-based, or negative = relative to the vertices read so far; only the vertex index a is read,
// b and c are ignored); polygons are fan-triangulated.
// Every other statement (vn, vt, o, g, s, usemtl, mtllib, l, p, ...) and `#` comments are
// ignored. A file without any face is bad input.
#include "tools/intersections/surface_intersections.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <exception>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace {

using clothsim::check::IntersectionReport;
using clothsim::check::Surface;

// Bad input: the message already names the file (and line, where there is one).
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::vector<std::string_view> split_whitespace(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r' || line[i] == '\f' ||
                               line[i] == '\v'))
      ++i;
    const std::size_t start = i;
    while (i < line.size() && !(line[i] == ' ' || line[i] == '\t' || line[i] == '\r' || line[i] == '\f' ||
                                line[i] == '\v'))
      ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  return result.ec == std::errc() && result.ptr == end && std::isfinite(value);
}

bool parse_int(std::string_view token, long long& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  return result.ec == std::errc() && result.ptr == end;
}

Surface read_obj(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open file");
  Surface surface;
  std::vector<long long> triangle_line;  // OBJ line of each triangle, for index errors
  std::string line;
  long long line_number = 0;
  auto fail = [&](const std::string& what) -> InputError {
    return InputError(path + ":" + std::to_string(line_number) + ": " + what);
  };
  while (std::getline(in, line)) {
    ++line_number;
    std::string_view text(line);
    if (const std::size_t hash = text.find('#'); hash != std::string_view::npos) text = text.substr(0, hash);
    const std::vector<std::string_view> tokens = split_whitespace(text);
    if (tokens.empty()) continue;
    if (tokens[0] == "v") {
      if (tokens.size() != 4 && tokens.size() != 5)
        throw fail("a vertex needs 3 coordinates (optionally a weight), got " + std::to_string(tokens.size() - 1));
      std::array<double, 3> x{};
      for (std::size_t d = 0; d < 3; ++d)
        if (!parse_double(tokens[d + 1], x[d]))
          throw fail("bad vertex coordinate '" + std::string(tokens[d + 1]) + "'");
      double w = 1.0;
      if (tokens.size() == 5 && !parse_double(tokens[4], w))
        throw fail("bad vertex weight '" + std::string(tokens[4]) + "'");
      surface.vertices.push_back(x);
    } else if (tokens[0] == "f") {
      if (tokens.size() < 4) throw fail("a face needs at least 3 vertices, got " + std::to_string(tokens.size() - 1));
      std::vector<int> polygon;
      for (std::size_t k = 1; k < tokens.size(); ++k) {
        const std::string_view entry = tokens[k];
        const std::string_view index_text = entry.substr(0, entry.find('/'));
        long long index = 0;
        if (!parse_int(index_text, index) || index == 0)
          throw fail("bad face entry '" + std::string(entry) + "' (expected a, a/b, a/b/c or a//c, a != 0)");
        // Negative: relative to the vertices read so far (-1 is the last one).
        const long long zero_based =
            index > 0 ? index - 1 : static_cast<long long>(surface.vertices.size()) + index;
        if (zero_based < 0 || zero_based > 2147483647LL)
          throw fail("face entry '" + std::string(entry) + "' refers to no vertex");
        polygon.push_back(static_cast<int>(zero_based));
      }
      for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
        surface.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
        triangle_line.push_back(line_number);
      }
    }
  }
  if (in.bad()) throw InputError(path + ": read error");
  if (surface.triangles.empty()) throw InputError(path + ": no faces");
  for (std::size_t t = 0; t < surface.triangles.size(); ++t)
    for (int v : surface.triangles[t])
      if (static_cast<std::size_t>(v) >= surface.vertices.size())
        throw InputError(path + ":" + std::to_string(triangle_line[t]) + ": face refers to vertex " +
                         std::to_string(v + 1) + " but the file has " + std::to_string(surface.vertices.size()) +
                         " vertices");
  return surface;
}

std::string describe(const IntersectionReport& r) {
  std::ostringstream out;
  out << r.intersecting_pairs << " intersecting pairs (" << r.pairs_tested << " tested)";
  if (r.intersecting_pairs > 0) {
    out << "; " << r.triangles_involved << " surface triangles involved; first pairs:";
    for (const auto& [i, j] : r.examples) out << ' ' << i << '-' << j;
  }
  return out.str();
}

void usage(std::ostream& out) {
  out << "usage: check_intersections SURFACE.obj [OBSTACLE.obj ...]\n"
         "Exact check: SURFACE against itself (triangles sharing a vertex are not tested) and\n"
         "against each OBSTACLE. Touching counts as intersecting. Triangle indices printed are\n"
         "0-based, in file order after fan triangulation.\n"
         "Exit code: 0 no intersections, 1 intersections found, 2 bad input.\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> paths(argv + 1, argv + argc);
  if (paths.size() == 1 && (paths[0] == "-h" || paths[0] == "--help")) {
    usage(std::cout);
    return 0;
  }
  if (paths.empty()) {
    usage(std::cerr);
    return 2;
  }
  try {
    // Read everything first, so that bad input is reported before any result.
    std::vector<Surface> surfaces;
    for (const std::string& path : paths) surfaces.push_back(read_obj(path));
    bool any = false;
    const IntersectionReport self = clothsim::check::self_intersections(surfaces[0]);
    any = any || self.intersecting_pairs > 0;
    std::cout << "self: " << describe(self) << '\n';
    for (std::size_t k = 1; k < surfaces.size(); ++k) {
      const IntersectionReport r = clothsim::check::intersections(surfaces[0], surfaces[k]);
      any = any || r.intersecting_pairs > 0;
      std::ostringstream closest;
      closest << std::setprecision(4) << clothsim::check::closest_vertex_distance(surfaces[0], surfaces[k]);
      std::string line = describe(r);
      const std::size_t cut = line.find(')') + 1;  // after "(M tested)"
      line.insert(cut, "; closest vertex " + closest.str() + " m");
      std::cout << "obstacle " << paths[k] << ": " << line << '\n';
    }
    std::cout.flush();
    return any ? 1 : 0;
  } catch (const std::exception& e) {  // InputError, or invalid data found by the check itself
    std::cerr << "check_intersections: " << e.what() << '\n';
    return 2;
  }
}

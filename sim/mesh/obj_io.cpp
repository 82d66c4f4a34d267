// Wavefront OBJ reading (with line-numbered errors and mesh validation) and exact-precision
// writing.
#include "sim/mesh/obj_io.hpp"

#include "sim/mesh/topology.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>

namespace clothsim {

namespace {

// Splits a line into whitespace-separated tokens.
std::vector<std::string_view> tokenize(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && (line[pos] == ' ' || line[pos] == '\t' || line[pos] == '\v' || line[pos] == '\f'))
      ++pos;
    if (pos >= line.size()) break;
    const std::size_t start = pos;
    while (pos < line.size() && line[pos] != ' ' && line[pos] != '\t' && line[pos] != '\v' && line[pos] != '\f')
      ++pos;
    tokens.push_back(line.substr(start, pos - start));
  }
  return tokens;
}

// Parses the whole token as a double (an optional leading '+' is accepted).
bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') {
    token.remove_prefix(1);
    if (!token.empty() && token.front() == '-') return false;
  }
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return !token.empty() && ec == std::errc() && ptr == end;
}

// Parses the whole token as an integer.
bool parse_integer(std::string_view token, long long& value) {
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end;
}

struct FaceCorner {
  long long index;    // 0-based; a positive file index is range-checked once all vertices are read
  long long written;  // the index as written in the file, for error messages
  long long texture = -1;  // 0-based texture-coordinate index (`i/t`, `i/t/n`), or -1 (none / out of range)
};

struct PendingTriangle {
  std::array<FaceCorner, 3> corners;
  long long line;
};

[[noreturn]] void fail(const std::string& path, long long line, const std::string& message) {
  throw MeshError(path + ":" + std::to_string(line) + ": " + message);
}

// Reads the next line (without its '\n') into `line`; false at the end of the input. Sets
// `too_long` and stops reading once the line has more than `max_length` characters, so that a
// file without line breaks is not read into memory whole.
bool next_line(std::streambuf& buffer, std::string& line, std::size_t max_length, bool& too_long) {
  using Traits = std::char_traits<char>;
  line.clear();
  too_long = false;
  Traits::int_type c = buffer.sbumpc();
  if (Traits::eq_int_type(c, Traits::eof())) return false;
  while (!Traits::eq_int_type(c, Traits::eof()) && c != '\n') {
    if (line.size() >= max_length) {
      too_long = true;
      return true;
    }
    line.push_back(Traits::to_char_type(c));
    c = buffer.sbumpc();
  }
  return true;
}

}  // namespace

TriMesh read_obj(const std::string& path, long long max_vertices) {
  // Only a regular file (or a link to one): a device such as /dev/zero or a pipe has no end.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw MeshError(path + ": not a regular file (" +
                    std::string(std::filesystem::is_directory(status) ? "a directory" : "a device, pipe or socket") +
                    "); a mesh must be an OBJ file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MeshError(path + ": cannot open file");
  return read_obj(in, path, max_vertices);
}

TriMesh read_obj_text(std::string_view text, const std::string& name, long long max_vertices) {
  std::istringstream in{std::string(text)};
  return read_obj(in, name, max_vertices);
}

TriMesh read_obj(std::istream& in, const std::string& path, long long max_vertices) {
  if (in.rdbuf() == nullptr || !in) throw MeshError(path + ": cannot read");
  // A manifold triangle mesh has about twice as many triangles as vertices (a closed surface of
  // genus g: 2V + 4g - 4); four times is room for any practical mesh.
  const long long max_triangles = 4 * max_vertices;
  std::vector<std::array<double, 3>> positions;
  std::vector<std::array<double, 2>> texcoords;  // `vt u v`
  std::vector<PendingTriangle> pending;
  std::string text;
  long long line_number = 0;
  bool too_long = false;
  while (next_line(*in.rdbuf(), text, kMaxObjLineLength, too_long)) {
    ++line_number;
    if (too_long)
      fail(path, line_number, "line longer than " + std::to_string(kMaxObjLineLength) + " characters (not an OBJ file?)");
    std::string_view line(text);
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::vector<std::string_view> tokens = tokenize(line);
    if (tokens.empty()) continue;

    if (tokens[0] == "v") {
      // x y z, optionally followed by w or by an r g b colour; only x y z are used.
      const std::size_t count = tokens.size() - 1;
      if (count != 3 && count != 4 && count != 6 && count != 7) fail(path, line_number, "malformed vertex line");
      std::array<double, 3> p{};
      for (std::size_t k = 1; k < tokens.size(); ++k) {
        double value = 0.0;
        if (!parse_double(tokens[k], value)) fail(path, line_number, "malformed vertex line");
        if (k <= 3) {
          if (!std::isfinite(value))
            fail(path, line_number, "non-finite vertex coordinate '" + std::string(tokens[k]) + "'");
          p[k - 1] = value;
        }
      }
      if (static_cast<long long>(positions.size()) >= max_vertices)
        throw MeshLimitError(path + ":" + std::to_string(line_number) + ": more than " + std::to_string(max_vertices) +
                             " vertices");
      positions.push_back(p);
    } else if (tokens[0] == "vt") {
      // u [v [w]]; a malformed or non-finite one is kept as unusable (NaN), as vt was ignored before.
      std::array<double, 2> t{std::nan(""), std::nan("")};
      if (tokens.size() >= 3 && parse_double(tokens[1], t[0]) && parse_double(tokens[2], t[1]) && std::isfinite(t[0]) &&
          std::isfinite(t[1])) {
      } else {
        t = {std::nan(""), std::nan("")};
      }
      if (static_cast<long long>(texcoords.size()) >= max_triangles)
        throw MeshLimitError(path + ":" + std::to_string(line_number) + ": more than " + std::to_string(max_triangles) +
                             " texture coordinates (4 x the limit of " + std::to_string(max_vertices) + " vertices)");
      texcoords.push_back(t);
    } else if (tokens[0] == "f") {
      if (tokens.size() < 4)
        fail(path, line_number, "malformed face line: a face needs at least 3 vertices, found " +
                              std::to_string(tokens.size() - 1));
      std::vector<FaceCorner> corners;
      corners.reserve(tokens.size() - 1);
      for (std::size_t k = 1; k < tokens.size(); ++k) {
        const std::string_view entry = tokens[k];
        // Forms: i, i/t, i//n, i/t/n. Only i is used, but t and n must be integers if present.
        long long index = 0;
        long long ignored = 0;
        long long texture = 0;  // as written; 0: none
        const std::size_t slash = entry.find('/');
        bool well_formed = parse_integer(entry.substr(0, slash), index);
        if (well_formed && slash != std::string_view::npos) {
          const std::string_view rest = entry.substr(slash + 1);
          const std::size_t second = rest.find('/');
          if (second == std::string_view::npos) {
            well_formed = parse_integer(rest, texture);  // i/t
          } else {
            const std::string_view tex = rest.substr(0, second);  // empty in i//n
            well_formed = (tex.empty() || parse_integer(tex, texture)) && parse_integer(rest.substr(second + 1), ignored);
          }
        }
        // The texture index resolved like the vertex index; unusable ones give -1 (no uv).
        long long texture_index = -1;
        if (texture > 0 && texture <= static_cast<long long>(texcoords.size()))
          texture_index = texture - 1;
        else if (texture < 0 && static_cast<long long>(texcoords.size()) + texture >= 0)
          texture_index = static_cast<long long>(texcoords.size()) + texture;
        if (!well_formed) fail(path, line_number, "malformed face entry '" + std::string(entry) + "'");
        if (index == 0) fail(path, line_number, "face index 0 is invalid (OBJ indices start at 1)");
        if (index < 0) {
          // Relative to the vertices defined so far: -1 is the most recent one.
          const long long resolved = static_cast<long long>(positions.size()) + index;
          if (resolved < 0)
            fail(path, line_number, "face index " + std::to_string(index) + " out of range (only " +
                                  std::to_string(positions.size()) + " vertices defined before this line)");
          corners.push_back({resolved, index, texture_index});
        } else {
          corners.push_back({index - 1, index, texture_index});
        }
      }
      // Fan triangulation around the first corner.
      if (static_cast<long long>(pending.size() + corners.size() - 2) > max_triangles)
        throw MeshLimitError(path + ":" + std::to_string(line_number) + ": more than " + std::to_string(max_triangles) +
                             " triangles (4 x the limit of " + std::to_string(max_vertices) + " vertices)");
      for (std::size_t k = 1; k + 1 < corners.size(); ++k)
        pending.push_back({{corners[0], corners[k], corners[k + 1]}, line_number});
    }
    // Everything else (vn, vp, o, g, s, l, usemtl, mtllib, ...) is ignored.
  }
  if (in.bad()) throw MeshError(path + ": read error");

  const long long num_vertices = static_cast<long long>(positions.size());
  if (pending.empty()) throw MeshError(path + ": file has no faces");
  for (const PendingTriangle& tri : pending)
    for (const FaceCorner& corner : tri.corners)
      if (corner.index >= num_vertices)
        fail(path, tri.line, "face index " + std::to_string(corner.written) + " out of range (file has " +
                                 std::to_string(num_vertices) + " vertices)");
  if (num_vertices > std::numeric_limits<int>::max()) throw MeshError(path + ": too many vertices");

  TriMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(positions.size()), 3);
  for (std::size_t v = 0; v < positions.size(); ++v)
    for (int k = 0; k < 3; ++k) mesh.vertices(static_cast<Eigen::Index>(v), k) = positions[v][static_cast<std::size_t>(k)];
  mesh.triangles.reserve(pending.size());
  for (const PendingTriangle& tri : pending)
    mesh.triangles.push_back({static_cast<int>(tri.corners[0].index), static_cast<int>(tri.corners[1].index),
                              static_cast<int>(tri.corners[2].index)});
  // Texture coordinates, when every corner of every face names a usable one.
  bool textured = !texcoords.empty();
  for (const PendingTriangle& tri : pending)
    for (const FaceCorner& corner : tri.corners)
      if (corner.texture < 0 || !std::isfinite(texcoords[static_cast<std::size_t>(corner.texture)][0])) textured = false;
  if (textured) {
    mesh.uv.reserve(pending.size());
    for (const PendingTriangle& tri : pending) {
      std::array<Eigen::Vector2d, 3> uv;
      for (int k = 0; k < 3; ++k) {
        const auto& t = texcoords[static_cast<std::size_t>(tri.corners[static_cast<std::size_t>(k)].texture)];
        uv[static_cast<std::size_t>(k)] = Eigen::Vector2d(t[0], t[1]);
      }
      mesh.uv.push_back(uv);
    }
  }

  try {
    check_triangles(mesh);
    const Topology topology(mesh.num_vertices(), mesh.triangles);
    (void)topology;
  } catch (const MeshError& e) {
    throw MeshError(path + ": " + e.what());
  }
  return mesh;
}

void write_obj(const std::string& path, const Eigen::MatrixX3d& vertices, const std::vector<Triangle>& triangles,
               const std::string& comment, const Eigen::MatrixX3d* normals,
               const std::vector<std::array<Eigen::Vector2d, 3>>* uv) {
  const Eigen::Index n = vertices.rows();
  if (normals != nullptr && normals->rows() != n)
    throw MeshError("cannot write '" + path + "': " + std::to_string(normals->rows()) + " normals for " +
                    std::to_string(n) + " vertices");
  if (uv != nullptr && uv->size() != triangles.size())
    throw MeshError("cannot write '" + path + "': texture coordinates for " + std::to_string(uv->size()) +
                    " triangles, the mesh has " + std::to_string(triangles.size()));
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (const int v : triangles[t])
      if (v < 0 || v >= n)
        throw MeshError("cannot write '" + path + "': triangle " + std::to_string(t) + " has vertex index " +
                        std::to_string(v) + " out of range (mesh has " + std::to_string(n) + " vertices)");

  const std::filesystem::path final_path(path);
  std::string tmp_name = ".";
  tmp_name += final_path.filename().string();
  tmp_name += ".tmp";
  const std::filesystem::path tmp = final_path.parent_path() / tmp_name;
  std::ofstream out(tmp, std::ios::out | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot open '" + path + "' for writing");

  if (!comment.empty()) {
    std::size_t start = 0;
    while (start <= comment.size()) {
      std::size_t end = comment.find('\n', start);
      if (end == std::string::npos) end = comment.size();
      std::string_view line(comment.data() + start, end - start);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      out << "# " << line << '\n';
      if (end == comment.size()) break;
      start = end + 1;
    }
  }

  // Shortest representation that parses back to the same double (round-trip exact).
  std::array<char, 64> buffer{};
  auto put = [&out, &buffer](double value) {
    const auto [ptr, ec] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
    (void)ec;  // cannot fail: 64 characters hold any double
    out.write(buffer.data(), ptr - buffer.data());
  };
  for (Eigen::Index v = 0; v < n; ++v) {
    out << "v ";
    put(vertices(v, 0));
    out << ' ';
    put(vertices(v, 1));
    out << ' ';
    put(vertices(v, 2));
    out << '\n';
  }
  if (normals != nullptr)
    for (Eigen::Index v = 0; v < n; ++v) {
      out << "vn ";
      put((*normals)(v, 0));
      out << ' ';
      put((*normals)(v, 1));
      out << ' ';
      put((*normals)(v, 2));
      out << '\n';
    }
  // Texture coordinates: one `vt` per distinct (vertex, u, v), so a vertex on a seam has one per
  // piece and the others one.
  std::vector<std::array<int, 3>> corner_vt;
  if (uv != nullptr) {
    std::map<std::tuple<int, double, double>, int> index;
    corner_vt.resize(triangles.size());
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (std::size_t k = 0; k < 3; ++k) {
        const Eigen::Vector2d& c = (*uv)[t][k];
        const auto [it, added] = index.emplace(std::make_tuple(triangles[t][k], c.x(), c.y()), static_cast<int>(index.size()));
        if (added) {
          out << "vt ";
          put(c.x());
          out << ' ';
          put(c.y());
          out << '\n';
        }
        corner_vt[t][k] = it->second;
      }
  }
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Triangle& tri = triangles[t];
    out << 'f';
    for (std::size_t k = 0; k < 3; ++k) {
      out << ' ' << tri[k] + 1;
      if (uv != nullptr) out << '/' << corner_vt[t][k] + 1;
      if (normals != nullptr) out << (uv != nullptr ? "/" : "//") << tri[k] + 1;
    }
    out << '\n';
  }

  out.close();
  std::error_code ec;
  if (!out) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("error while writing '" + path + "'");
  }
  std::filesystem::rename(tmp, final_path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("cannot write '" + path + "': " + ec.message());
  }
}

}  // namespace clothsim

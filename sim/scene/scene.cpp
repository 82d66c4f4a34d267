// Scene loader: reads a scene file (json_reader.hpp: parsing, --set overrides, checked access;
// read_settings.hpp: the sections that are plain settings) and builds from it the mesh
// (build_mesh.hpp), the boundary selections, loads, obstacles and probes, and the Problem.
#include "sim/scene/scene.hpp"

#include "sim/scene/build_mesh.hpp"
#include "sim/scene/json_reader.hpp"
#include "sim/scene/read_pattern.hpp"
#include "sim/scene/read_settings.hpp"

#include "sim/mesh/imperfection.hpp"
#include "sim/mesh/mesh_part.hpp"
#include "sim/mesh/obj_io.hpp"
#include "sim/problem/validate.hpp"
#include "sim/setup/setup.hpp"
#include "sim/shell/fit_limit.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <set>
#include <utility>

namespace clothsim {

using namespace scene_io;  // this file's own reader (json_reader.hpp, read_settings.hpp, build_mesh.hpp)

namespace {

const char* const kAxes[3] = {"x", "y", "z"};

// Top-level keys that only a dynamic scene may have.
const char* const kDynamicOnlyKeys[] = {"time", "damping", "solver", "corotational", "initial", "output", "collision",
                                        "obstacles", "settle"};

const char* const kNeedsDynamic = "needs \"analysis\": \"dynamic\" (this scene is static)";

std::string bounding_box(const Eigen::MatrixX3d& v) {
  if (v.rows() == 0) return "empty";
  const Eigen::Vector3d lo = v.colwise().minCoeff().transpose();
  const Eigen::Vector3d hi = v.colwise().maxCoeff().transpose();
  return "[" + format_point(lo) + ", " + format_point(hi) + "]";
}

// A boundary translated by more than this many times the mesh's size (its bounding-box diagonal)
// is refused: no cloth scene moves a boundary that far, and such a motion (a slip in an exponent:
// -1e9 m) stretched the cloth past anything the contact and the solver can follow, growing to
// gigabytes before it failed with a message that named no key.
constexpr double kMaxTravel = 1000.0;

void check_travel(const Reader& r, const Motion& m, const std::string& path, const TriMesh& mesh,
                  const char* what = "the boundary") {
  if (m.type != Motion::Type::translate || mesh.vertices.rows() == 0) return;
  const double size = (mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff()).norm();
  const double travel = m.displacement.stableNorm();  // (finite for components near the largest double)
  if (travel <= kMaxTravel * size) return;
  r.fail(join_key(path, "displacement"), std::string("moves ") + what + " by " + format_number(travel) + " m, more than " +
                                             format_number(kMaxTravel) + " times the mesh's size (" + format_number(size) +
                                             " m, its bounding-box diagonal); is the unit metres?");
}

// `v` sorted, each vertex once.
std::vector<int> sorted_unique(std::vector<int> v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

// {"piece_edge": {"piece": name, "edge": i or [first, last]}} at `path`: the vertices along the
// piece's edge or path of edges.
std::vector<int> select_piece_edge(const Reader& r, const Json& j, const std::string& path, const SewnPattern& pattern) {
  const SeamSide side = read_piece_edge(r, j, path, pattern.spec);
  std::size_t piece = 0;
  while (pattern.spec.pieces[piece].name != side.piece) ++piece;
  const auto& edges = pattern.built.edge_vertices[piece];
  const int n = static_cast<int>(edges.size());
  std::vector<int> vertices;
  for (int e = side.first_edge;; e = (e + 1) % n) {
    vertices.insert(vertices.end(), edges[static_cast<std::size_t>(e)].begin(), edges[static_cast<std::size_t>(e)].end());
    if (e == side.last_edge) break;
  }
  return sorted_unique(std::move(vertices));
}

// {"piece": {"name": name, "box": [[umin, vmin], [umax, vmax]]}} at `path`: the piece's vertices,
// those whose pattern coordinates lie in the closed box if one is given (a vertex group drawn on
// the pattern); at least one.
std::vector<int> select_piece_region(const Reader& r, const Json& j, const std::string& path, const SewnPattern& pattern) {
  r.check_object(j, path, {"name", "box"});
  const std::size_t piece = read_piece_name(r, r.require(j, path, "name"), join_key(path, "name"), pattern.spec);
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(-std::numeric_limits<double>::infinity()), hi = -lo;
  const std::string box_path = join_key(path, "box");
  if (const Json* box = r.find(j, "box")) {
    if (!box->is_array() || box->size() != 2)
      r.fail(box_path, "expected an array of 2 points [[umin, vmin], [umax, vmax]] in the piece's pattern coordinates [m] "
                       "(got " + describe(*box) + ")");
    for (int c = 0; c < 2; ++c) {
      const std::string corner = join_index(box_path, c);
      const Json& p = (*box)[static_cast<std::size_t>(c)];
      if (!p.is_array() || p.size() != 2) r.fail(corner, "expected [u, v] [m] (got " + describe(p) + ")");
      (c == 0 ? lo : hi) = Eigen::Vector2d(r.number(p[0], join_index(corner, 0)), r.number(p[1], join_index(corner, 1)));
    }
    for (int k = 0; k < 2; ++k)
      if (lo[k] > hi[k])
        r.fail(box_path, "min must be <= max in u and v (got " + format_number(lo[k]) + " > " + format_number(hi[k]) + ")");
  }
  const PatternMesh& built = pattern.built;
  std::vector<int> vertices;
  for (std::size_t t = 0; t < built.triangle_piece.size(); ++t) {
    if (built.triangle_piece[t] != static_cast<int>(piece)) continue;
    for (std::size_t c = 0; c < 3; ++c) {
      const Eigen::Vector2d& uv = built.mesh.uv[t][c];
      if ((uv.array() >= lo.array()).all() && (uv.array() <= hi.array()).all()) vertices.push_back(built.mesh.triangles[t][c]);
    }
  }
  if (vertices.empty()) r.fail(box_path, "selects no vertex of piece " + quote(pattern.spec.pieces[piece].name));
  return sorted_unique(std::move(vertices));
}

// {"box": [[xmin, ymin, zmin], [xmax, ymax, zmax]]} at `path`: the control vertices in the closed
// box (at least one).
std::vector<int> select_in_box(const Reader& r, const Json& box, const std::string& path, const TriMesh& mesh) {
  if (!box.is_array() || box.size() != 2)
    r.fail(path, "expected an array of 2 points [[xmin, ymin, zmin], [xmax, ymax, zmax]] (got " + describe(box) + ")");
  const Eigen::Vector3d lo = r.vec3(box[0], join_index(path, 0));
  const Eigen::Vector3d hi = r.vec3(box[1], join_index(path, 1));
  for (int k = 0; k < 3; ++k)
    if (lo[k] > hi[k])
      r.fail(path, std::string("min must be <= max in every component (got ") + kAxes[k] + "min = " +
                       format_number(lo[k]) + " > " + kAxes[k] + "max = " + format_number(hi[k]) + ")");
  std::vector<int> vertices = select_box(mesh.vertices, lo, hi);
  if (vertices.empty())
    r.fail(path, "selects no vertex of the mesh (mesh bounding box: " + bounding_box(mesh.vertices) + ")");
  return vertices;
}

// {"ball": {"center": [x, y, z], "radius": r}} at `path`: the control vertices in the closed ball
// (at least one).
std::vector<int> select_in_ball(const Reader& r, const Json& ball, const std::string& path, const TriMesh& mesh) {
  r.check_object(ball, path, {"center", "radius"});
  const Eigen::Vector3d center = r.vec3(r.require(ball, path, "center"), join_key(path, "center"));
  const double radius = r.positive(r.require(ball, path, "radius"), join_key(path, "radius"), "[m]");
  std::vector<int> vertices = select_ball(mesh.vertices, center, radius);
  if (vertices.empty())
    r.fail(path, "selects no vertex of the mesh (mesh bounding box: " + bounding_box(mesh.vertices) + ")");
  return vertices;
}

// A boundary's or a load's "select": one of "box" (select_in_box), "ball" (select_in_ball) or, on
// a pattern garment, "piece_edge" (select_piece_edge) and "piece" (select_piece_region).
std::vector<int> read_selection(const Reader& r, const Json& item, const std::string& path, const TriMesh& mesh,
                                const SewnPattern* pattern) {
  const std::string select_path = join_key(path, "select");
  const Json& select = r.require(item, path, "select");
  r.check_object(select, select_path, {"box", "ball", "piece_edge", "piece"});
  if (select.contains("box") + select.contains("ball") + select.contains("piece_edge") + select.contains("piece") != 1)
    r.fail(select_path, "give one of \"box\", \"ball\", \"piece_edge\" and \"piece\"");
  for (const char* key : {"piece_edge", "piece"})
    if (const Json* j = r.find(select, key)) {
      const std::string key_path = join_key(select_path, key);
      if (pattern == nullptr) r.fail(key_path, "needs a pattern mesh (\"mesh\": {\"pattern\": ...})");
      return std::string(key) == "piece" ? select_piece_region(r, *j, key_path, *pattern)
                                         : select_piece_edge(r, *j, key_path, *pattern);
    }
  if (const Json* ball = r.find(select, "ball")) return select_in_ball(r, *ball, join_key(select_path, "ball"), mesh);
  return select_in_box(r, select["box"], join_key(select_path, "box"), mesh);
}

std::vector<BoundaryCondition> read_boundary(const Reader& r, const Json* j, const TriMesh& mesh,
                                             const SewnPattern* pattern, bool dynamic,
                                             const LogFn& log) {
  std::vector<BoundaryCondition> out;
  if (j == nullptr) return out;
  r.array(*j, "boundary");
  for (std::size_t i = 0; i < j->size(); ++i) {
    const std::string path = join_index("boundary", i);
    const Json& item = (*j)[i];
    r.check_object(item, path, {"select", "fix", "rotation", "motion"});
    BoundaryCondition bc;
    bc.vertices = read_selection(r, item, path, mesh, pattern);

    if (const Json* fix = r.find(item, "fix")) {
      const std::string fix_path = join_key(path, "fix");
      r.array(*fix, fix_path);
      bc.fix = {false, false, false};
      for (std::size_t c = 0; c < fix->size(); ++c) {
        const std::string component = r.choice((*fix)[c], join_index(fix_path, c), {"x", "y", "z"}, "component");
        const auto axis = static_cast<std::size_t>(component[0] - 'x');
        if (bc.fix[axis]) r.fail(join_index(fix_path, c), "duplicate component " + quote(component));
        bc.fix[axis] = true;
      }
    }
    if (const Json* rotation = r.find(item, "rotation")) {
      const std::string kind = r.choice(*rotation, join_key(path, "rotation"), {"free", "clamped", "symmetry"});
      bc.clamped = kind == "clamped";
      bc.symmetric = kind == "symmetry";
    }
    if (const Json* motion = r.find(item, "motion")) {
      const std::string motion_path = join_key(path, "motion");
      if (!dynamic) r.fail(motion_path, kNeedsDynamic);
      r.array(*motion, motion_path);
      for (std::size_t m = 0; m < motion->size(); ++m) {
        bc.motion.push_back(read_motion(r, (*motion)[m], join_index(motion_path, m)));
        check_travel(r, bc.motion.back(), join_index(motion_path, m), mesh);
      }
      if (!bc.motion.empty() && !bc.fix[0] && !bc.fix[1] && !bc.fix[2])
        r.fail(motion_path, "has no effect: the motion drives the fixed components and \"fix\" is empty");
    }

    log(path + ": " + std::to_string(bc.vertices.size()) + " vertices");
    out.push_back(std::move(bc));
  }
  return out;
}

// "vertex 12 at [x, y, z] (0.01 m from the requested point)" for snapped points.
std::string describe_snap(const Eigen::MatrixX3d& vertices, int v, const Eigen::Vector3d& at) {
  const Eigen::Vector3d p = vertices.row(v).transpose();
  return "vertex " + std::to_string(v) + " at " + format_point(p) + " (" + format_number((p - at).norm()) +
         " m from the requested point)";
}

// A probe or point load must lie on or near the mesh: fails naming `path` if `point` is further
// from its nearest vertex than the diagonal of the mesh's bounding box.
void check_near_mesh(const Reader& r, const Eigen::MatrixX3d& vertices, int vertex, const Eigen::Vector3d& point,
                     const std::string& path) {
  if (vertex < 0) r.fail(path, "the mesh has no vertices");
  const double diagonal = (vertices.colwise().maxCoeff() - vertices.colwise().minCoeff()).norm();
  const double distance = (vertices.row(vertex).transpose() - point).stableNorm();
  if (!(distance <= diagonal))
    r.fail(path, "[" + format_number(point.x()) + ", " + format_number(point.y()) + ", " + format_number(point.z()) +
                     "] is " + format_number(distance) + " m from the nearest vertex, further than the mesh's size (" +
                     format_number(diagonal) + " m, its bounding box's diagonal); give a point on or near the mesh");
}

void read_loads(const Reader& r, const Json* j, Problem& problem, const SewnPattern* pattern, double* ramp_time,
                const LogFn& log) {
  if (j == nullptr) return;
  r.check_object(*j, "loads", {"gravity", "surface_load", "pressure", "point_loads", "moments", "ramp_time"});
  if (const Json* ramp = r.find(*j, "ramp_time")) {
    if (ramp_time == nullptr) r.fail("loads.ramp_time", "needs \"analysis\": \"dynamic\" (this scene is static)");
    *ramp_time = r.non_negative(*ramp, "loads.ramp_time", "[s]");
  }
  if (const Json* moments = r.find(*j, "moments")) {
    r.array(*moments, "loads.moments");
    for (std::size_t i = 0; i < moments->size(); ++i) {
      const std::string path = join_index("loads.moments", i);
      const Json& item = (*moments)[i];
      r.check_object(item, path, {"select", "moment"});
      MomentLoad load;
      load.vertices = read_selection(r, item, path, problem.mesh, pattern);
      load.moment = r.vec3(r.require(item, path, "moment"), join_key(path, "moment"));
      log(path + ": " + std::to_string(load.vertices.size()) + " vertices");
      problem.moments.push_back(std::move(load));
    }
  }
  if (const Json* g = r.find(*j, "gravity")) problem.gravity = r.vec3(*g, "loads.gravity");
  if (const Json* s = r.find(*j, "surface_load")) problem.surface_load = r.vec3(*s, "loads.surface_load");
  if (const Json* s = r.find(*j, "pressure")) problem.pressure = r.number(*s, "loads.pressure");
  if (const Json* p = r.find(*j, "point_loads")) {
    r.array(*p, "loads.point_loads");
    for (std::size_t i = 0; i < p->size(); ++i) {
      const std::string path = join_index("loads.point_loads", i);
      const Json& item = (*p)[i];
      r.check_object(item, path, {"at", "force"});
      const Eigen::Vector3d at = r.vec3(r.require(item, path, "at"), join_key(path, "at"));
      PointLoad load;
      load.force = r.vec3(r.require(item, path, "force"), join_key(path, "force"));
      load.vertex = nearest_vertex(problem.mesh.vertices, at);
      check_near_mesh(r, problem.mesh.vertices, load.vertex, at, join_key(path, "at"));
      log(path + ": " + describe_snap(problem.mesh.vertices, load.vertex, at));
      problem.point_loads.push_back(load);
    }
  }
}

// "obstacles": [{"name", "primitive" | "obj", shape parameters, "friction", "motion"}].
std::vector<Obstacle> read_obstacles(const Reader& r, const Json* j, double default_friction,
                                     const std::filesystem::path& folder, const LogFn& log, long long max_vertices) {
  std::vector<Obstacle> out;
  if (j == nullptr) return out;
  r.array(*j, "obstacles");
  std::set<std::string> names;
  for (std::size_t i = 0; i < j->size(); ++i) {
    const std::string path = join_index("obstacles", i);
    const Json& item = (*j)[i];
    if (!item.is_object()) r.fail(path, "expected an object (got " + describe(item) + ")");
    const bool has_obj = item.contains("obj"), has_primitive = item.contains("primitive");
    if (has_obj && has_primitive) r.fail(path, "give either \"obj\" or \"primitive\", not both");
    if (!has_obj && !has_primitive)
      r.fail(path, "needs \"primitive\" (allowed: \"plane\", \"sphere\", \"capsule\", \"box\", \"cylinder\") or \"obj\" (a file)");
    Obstacle o;
    o.name = "obstacle" + std::to_string(i);
    o.friction = default_friction;
    auto key = [&](const char* k) { return join_key(path, k); };
    std::vector<std::string> allowed = {"name", "friction", "motion"};
    if (has_obj) {
      o.shape = Obstacle::Shape::mesh;
      allowed.insert(allowed.end(), {"obj", "keep", "cut"});
    } else {
      const std::string shape =
          r.choice(item["primitive"], key("primitive"), {"plane", "sphere", "capsule", "box", "cylinder"}, "primitive");
      allowed.push_back("primitive");
      if (shape == "plane") {
        o.shape = Obstacle::Shape::plane;
        allowed.insert(allowed.end(), {"point", "normal"});
      } else if (shape == "sphere") {
        o.shape = Obstacle::Shape::sphere;
        allowed.insert(allowed.end(), {"center", "radius"});
      } else if (shape == "box") {
        o.shape = Obstacle::Shape::box;
        allowed.insert(allowed.end(), {"center", "size"});
      } else {
        o.shape = shape == "capsule" ? Obstacle::Shape::capsule : Obstacle::Shape::cylinder;
        allowed.insert(allowed.end(), {"from", "to", "radius"});
      }
    }
    r.check_object(item, path, allowed);
    if (const Json* v = r.find(item, "name")) {
      o.name = r.string(*v, key("name"));
      if (o.name.empty()) r.fail(key("name"), "must not be empty");
    }
    if (!names.insert(o.name).second)
      r.fail(item.contains("name") ? key("name") : path, "duplicate obstacle name " + quote(o.name) +
                                                              (item.contains("name") ? "" : " (the default name of this unnamed obstacle)"));
    if (const Json* v = r.find(item, "friction")) o.friction = r.non_negative(*v, key("friction"), "[-]");
    if (const Json* motion = r.find(item, "motion")) {
      r.array(*motion, key("motion"));
      for (std::size_t m = 0; m < motion->size(); ++m)
        o.motion.push_back(read_motion(r, (*motion)[m], join_index(key("motion"), m)));
    }
    switch (o.shape) {
      case Obstacle::Shape::plane:
        o.point = r.vec3(r.require(item, path, "point"), key("point"));
        o.normal = r.vec3(r.require(item, path, "normal"), key("normal"));
        if (!(o.normal.norm() > 0)) r.fail(key("normal"), "must be a non-zero vector");
        o.normal.normalize();
        break;
      case Obstacle::Shape::sphere:
        o.center = r.vec3(r.require(item, path, "center"), key("center"));
        o.radius = r.positive(r.require(item, path, "radius"), key("radius"), "[m]");
        break;
      case Obstacle::Shape::box:
        o.center = r.vec3(r.require(item, path, "center"), key("center"));
        o.size = r.vec3(r.require(item, path, "size"), key("size"));
        if (!(o.size.minCoeff() > 0)) r.fail(key("size"), "every edge length must be > 0 [m] (got " + item["size"].dump() + ")");
        break;
      case Obstacle::Shape::capsule:
      case Obstacle::Shape::cylinder:
        o.from = r.vec3(r.require(item, path, "from"), key("from"));
        o.to = r.vec3(r.require(item, path, "to"), key("to"));
        o.radius = r.positive(r.require(item, path, "radius"), key("radius"), "[m]");
        if (!((o.to - o.from).norm() > 0)) r.fail(key("to"), "must differ from \"from\"");
        break;
      case Obstacle::Shape::mesh: {
        const std::string name = r.string(item["obj"], key("obj"));
        if (name.empty()) r.fail(key("obj"), "expected a non-empty file path");
        o.file = name;
        const std::filesystem::path obj = folder / name;
        try {
          o.mesh = read_obj(obj.string(), max_vertices);
          check_triangles(o.mesh);
        } catch (const MeshLimitError& e) {
          r.fail(key("obj"), std::string(e.what()) + " (mesh.max_vertices = " + std::to_string(max_vertices) +
                                 ", which limits obstacle meshes too; raise it to read larger ones)");
        } catch (const std::exception& e) {
          r.fail(key("obj"), e.what());
        }
        if (o.mesh.num_triangles() == 0) r.fail(key("obj"), obj.string() + ": no triangles");
        if (item.contains("keep") || item.contains("cut")) {
          // A part of the mesh, cut out by planes (sim/mesh/mesh_part.hpp).
          const auto half_spaces = [&](const Json& list, const std::string& at) {
            r.array(list, at);
            std::vector<HalfSpace> out_list;
            for (std::size_t h = 0; h < list.size(); ++h) {
              const std::string hp = join_index(at, h);
              r.check_object(list[h], hp, {"point", "normal"});
              HalfSpace half;
              half.point = r.vec3(r.require(list[h], hp, "point"), join_key(hp, "point"));
              half.normal = r.vec3(r.require(list[h], hp, "normal"), join_key(hp, "normal"));
              if (!(half.normal.norm() > 0)) r.fail(join_key(hp, "normal"), "must be a non-zero vector");
              out_list.push_back(half);
            }
            return out_list;
          };
          std::vector<HalfSpace> keep;
          std::vector<std::vector<HalfSpace>> cut;
          if (const Json* k = r.find(item, "keep")) keep = half_spaces(*k, key("keep"));
          if (const Json* c = r.find(item, "cut")) {
            r.array(*c, key("cut"));
            for (std::size_t g = 0; g < c->size(); ++g) cut.push_back(half_spaces((*c)[g], join_index(key("cut"), g)));
          }
          o.mesh = mesh_part(o.mesh, keep, cut);
          if (o.mesh.num_triangles() == 0)
            r.fail(item.contains("keep") ? key("keep") : key("cut"), "leaves no triangle of " + obj.string());
        }
        break;
      }
    }
    if (o.shape != Obstacle::Shape::plane && o.shape != Obstacle::Shape::mesh) o.mesh = tessellate(o);
    log("obstacle " + o.name + ": " + to_string(o.shape) +
        (o.shape == Obstacle::Shape::plane ? std::string()
                                           : ", " + std::to_string(o.mesh.num_triangles()) + " triangles") +
        (o.motion.empty() ? "" : ", moving"));
    out.push_back(std::move(o));
  }
  return out;
}

std::vector<Probe> read_probes(const Reader& r, const Json* j, const TriMesh& mesh, const LogFn& log) {
  std::vector<Probe> out;
  if (j == nullptr) return out;
  r.array(*j, "probes");
  std::set<std::string> names;
  for (std::size_t i = 0; i < j->size(); ++i) {
    const std::string path = join_index("probes", i);
    const Json& item = (*j)[i];
    r.check_object(item, path, {"name", "at"});
    Probe probe;
    probe.name = r.string(r.require(item, path, "name"), join_key(path, "name"));
    if (probe.name.empty()) r.fail(join_key(path, "name"), "must not be empty");
    if (!names.insert(probe.name).second)
      r.fail(join_key(path, "name"), "duplicate probe name " + quote(probe.name));
    probe.at = r.vec3(r.require(item, path, "at"), join_key(path, "at"));
    probe.vertex = nearest_vertex(mesh.vertices, probe.at);
    check_near_mesh(r, mesh.vertices, probe.vertex, probe.at, join_key(path, "at"));
    log("probe " + probe.name + ": " + describe_snap(mesh.vertices, probe.vertex, probe.at));
    out.push_back(std::move(probe));
  }
  return out;
}

}  // namespace

int nearest_vertex(const Eigen::MatrixX3d& vertices, const Eigen::Vector3d& point) {
  int best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    // The (overflow-safe) norm, not its square: a point 1e200 m away must not overflow to infinity.
    const double d2 = (vertices.row(v).transpose() - point).stableNorm();
    if (best < 0 || d2 < best_d2) {
      best_d2 = d2;
      best = static_cast<int>(v);
    }
  }
  return best;
}

std::vector<int> select_box(const Eigen::MatrixX3d& vertices, const Eigen::Vector3d& lo,
                            const Eigen::Vector3d& hi) {
  std::vector<int> out;
  for (Eigen::Index v = 0; v < vertices.rows(); ++v) {
    bool inside = true;
    for (Eigen::Index k = 0; k < 3; ++k) inside = inside && vertices(v, k) >= lo[k] && vertices(v, k) <= hi[k];
    if (inside) out.push_back(static_cast<int>(v));
  }
  return out;
}

std::vector<int> select_ball(const Eigen::MatrixX3d& vertices, const Eigen::Vector3d& center, double radius) {
  std::vector<int> out;
  for (Eigen::Index v = 0; v < vertices.rows(); ++v)
    if ((vertices.row(v).transpose() - center).squaredNorm() <= radius * radius) out.push_back(static_cast<int>(v));
  return out;
}

namespace {
Scene load_scene_json(const Json& root, const Reader& r, const std::filesystem::path& file, const LogFn& log);

// Applies the --set overrides to the parsed scene in order, then reads it; errors at or around an
// overridden key name the override.
Scene load_overridden(Json root, Reader& r, const std::filesystem::path& file, const LogFn& log,
                      const std::vector<std::string>& overrides) {
  std::vector<std::pair<std::string, std::string>> written;
  for (const std::string& argument : overrides)
    written.emplace_back(apply_override(root, argument, log), shortened(argument));
  r.set_overrides(std::move(written));
  Scene scene = load_scene_json(root, r, file, log);
  scene.overrides = overrides;
  return scene;
}
}  // namespace

Scene load_scene(const std::filesystem::path& file, const LogFn& log, const std::vector<std::string>& overrides) {
  Reader r(file.string());
  return load_overridden(parse_file(r, file), r, file, log, overrides);
}

Scene load_scene_text(const std::string& text, const std::filesystem::path& file, const LogFn& log,
                      const std::vector<std::string>& overrides) {
  Reader r(file.string());
  return load_overridden(parse_text(r, text), r, file, log, overrides);
}

namespace {
// A number for a message, to 3 significant digits ("1.41e+304", "0.25"); "inf" past the doubles.
std::string approx(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", v);
  return buffer;
}

// Loads so large that no shell could carry them are errors naming the key. The estimate is the
// membrane strain they would cause if carried by stretching alone, the stiffest way a shell can
// carry a load: force per unit width over the stretch modulus E·t, with L the mesh's
// bounding-box diagonal — (|pressure|, |surface_load| or areal density·|gravity|)·L, |F|/L for a
// point load, |M|/L² for a couple, summed. Above kMaxLoadStrain it is an error, above 1 (100 %)
// a warning (far beyond the linear-elastic model). Gravity above 1e4 g is an error in any case.
constexpr double kMaxLoadStrain = 100.0;
constexpr double kMaxGravity = 1e4 * 9.80665;  // [m/s²]

void check_load_magnitudes(const Reader& r, const Problem& p, const LogFn& log) {
  if (const double g = p.gravity.stableNorm(); g > kMaxGravity)
    r.fail("loads.gravity", "|g| = " + approx(g) + " m/s² is more than 1e4 g (" + approx(kMaxGravity) +
                                " m/s²); check the value and its unit [m/s²]");
  const Eigen::MatrixX3d& v = p.mesh.vertices;
  if (v.rows() == 0) return;
  const Eigen::Vector3d half = (v.colwise().maxCoeff() / 2 - v.colwise().minCoeff() / 2).transpose();
  const double size = 2 * half.stableNorm();          // L [m]
  const double stretch = p.material.stretch_modulus;  // E·t [N/m]
  struct Term {
    std::string key, value, formula;  // "loads.pressure", "1e+308 N/m²", "|p|·L"
    double strain;
  };
  std::vector<Term> terms;
  auto add = [&](std::string key, std::string value, std::string formula, double strain) {
    terms.push_back({std::move(key), std::move(value), std::move(formula), std::isnan(strain) ? HUGE_VAL : strain});
  };
  if (const double w = p.material.areal_density * p.gravity.stableNorm(); w > 0)
    add("loads.gravity", approx(p.gravity.stableNorm()) + " m/s²", "areal density·|g|·L", w / stretch * size);
  if (const double s = p.surface_load.stableNorm(); s > 0)
    add("loads.surface_load", approx(s) + " N/m²", "|surface_load|·L", s / stretch * size);
  if (const double s = std::abs(p.pressure); s > 0)
    add("loads.pressure", approx(p.pressure) + " N/m²", "|p|·L", s / stretch * size);
  for (std::size_t i = 0; i < p.point_loads.size(); ++i)
    if (const double f = p.point_loads[i].force.stableNorm(); f > 0)
      add(join_key(join_index("loads.point_loads", i), "force"), "|F| = " + approx(f) + " N", "|F|/L",
          f / size / stretch);
  for (std::size_t i = 0; i < p.moments.size(); ++i)
    if (const double m = p.moments[i].moment.stableNorm(); m > 0)
      add(join_key(join_index("loads.moments", i), "moment"), "|M| = " + approx(m) + " N·m", "|M|/L²",
          m / size / size / stretch);
  if (terms.empty()) return;
  double total = 0;
  const Term* largest = &terms.front();
  for (const Term& t : terms) {
    total += t.strain;
    if (t.strain > largest->strain) largest = &t;
  }
  const std::string estimate =
      largest->value + ": even carried by stretching alone (the stiffest way a shell carries a load) the scene's "
      "loads would strain the sheet by about " + approx(total) + " (force per unit width, here " + largest->formula +
      ", over the stretch modulus E·t = " + approx(stretch) + " N/m; L = " + approx(size) +
      " m, the mesh's bounding-box diagonal)";
  if (!(total <= kMaxLoadStrain))
    r.fail(largest->key, estimate + ", more than " + approx(kMaxLoadStrain) +
                             " (10000 %): refused; check the value and its unit");
  if (total > 1)
    log("warning: " + largest->key + ": " + estimate +
        ", more than 1 (100 %): far beyond the range of the linear-elastic model");
}

Scene load_scene_json(const Json& root, const Reader& r, const std::filesystem::path& file, const LogFn& log) {
  const LogFn say = log ? log : LogFn([](const std::string&) {});
  r.check_object(root, "",
                 {"name", "description", "analysis", "method", "mesh", "material", "boundary", "loads", "probes",
                  "numerics", "time", "damping", "solver", "corotational", "initial", "output", "render",
                  "collision", "obstacles", "imperfection", "rest", "settle", "$schema"});
  // "$schema": the JSON Schema the file follows (scenes/scene.schema.json), for editors; ignored.
  if (const Json* schema = r.find(root, "$schema")) r.string(*schema, "$schema");

  Scene scene;
  scene.file = file;
  if (const Json* name = r.find(root, "name")) {
    scene.name = r.string(*name, "name");
    if (!is_safe_name(scene.name))
      r.fail("name", "must be a safe folder name: at most " + std::to_string(kMaxNameLength) +
                         " letters, digits, '_', '-', '.', not starting with '.' (got " +
                         (scene.name.size() > 60 ? quote(scene.name.substr(0, 40)) + "... (" +
                                                       std::to_string(scene.name.size()) + " characters)"
                                                 : quote(scene.name)) +
                         ")");
  } else {
    scene.name = file.stem().string();
    if (!is_safe_name(scene.name))
      r.fail("name", "not given, and the file name " + quote(scene.name) +
                         " is not a safe folder name; set \"name\" (letters, digits, '_', '-', '.', not "
                         "starting with '.')");
  }
  if (const Json* d = r.find(root, "description")) scene.description = r.string(*d, "description");
  scene.analysis = "static";
  if (const Json* a = r.find(root, "analysis")) scene.analysis = r.choice(*a, "analysis", {"static", "dynamic"});
  const bool dynamic = scene.analysis == "dynamic";
  if (!dynamic)
    for (const char* key : kDynamicOnlyKeys)
      if (r.find(root, key) != nullptr) r.fail(key, kNeedsDynamic);

  // The discretisation: it decides how the mesh is prepared, so it is read before the mesh.
  if (const Json* m = r.find(root, "method")) scene.problem.method = r.choice(*m, "method", discretization_methods(), "method");

  // Cheap checks first, the mesh (possibly large) after; nothing larger than this is read or made.
  const long long max_vertices = read_max_vertices(r, root);
  GrainSpec grain;
  scene.problem.material = read_material(r, r.find(root, "material"), grain);
  scene.problem.quadrature = read_numerics(r, r.find(root, "numerics"));
  Problem& dyn = scene.problem;
  if (dynamic) {
    if (const auto issue = find_issue(scene.problem, Analysis::dynamics); issue && issue->key == "material")
      r.fail(issue->key, issue->message);  // before the (possibly large) mesh is built
    dyn.time = read_time(r, r.find(root, "time"));
    dyn.damping = read_damping(r, r.find(root, "damping"));
    dyn.solver = read_solver(r, r.find(root, "solver"));
    if (const Json* c = r.find(root, "corotational")) dyn.corotational = r.boolean(*c, "corotational");
    dyn.initial = read_initial(r, r.find(root, "initial"));
    read_output(r, r.find(root, "output"), scene);
  }

  scene.render = read_render(r, r.find(root, "render"));
  const Imperfection imperfection = read_imperfection(r, r.find(root, "imperfection"));
  if (dynamic) {
    bool level_given = false;
    read_collision(r, r.find(root, "collision"), scene.problem, level_given);
    // Contact acts on the surface that is drawn, unless the scene says otherwise.
    if (!level_given) scene.problem.collision_level = scene.render.refine;
    scene.problem.obstacles =
        read_obstacles(r, r.find(root, "obstacles"), scene.problem.collision.friction, file.parent_path(), say,
                       max_vertices);
  }
  const Json& mesh_json = r.require(root, "", "mesh");
  const bool draw_grain = scene.render.texture == "grain";
  grain.needed_by = scene.problem.material.orthotropic() ? "material" : "render.texture";
  std::optional<SewnPattern> pattern;
  TriMesh mesh = build_mesh(r, mesh_json, file.parent_path(), say, max_vertices, grain,
                            grain.given || scene.problem.material.orthotropic() || draw_grain, pattern);
  // The default texture: the checker where the mesh has texture coordinates to lay it on.
  if (!scene.render.texture_given && mesh.uv.size() == mesh.triangles.size() && !mesh.triangles.empty())
    scene.render.texture = "checker";
  if (scene.render.texture == "checker" && mesh.uv.size() != mesh.triangles.size())
    r.fail("render.texture", "\"checker\" needs texture coordinates on the mesh (a pattern garment, or an OBJ with vt "
                             "on every face)");
  // "rest": the elements' rest state (sim/shell/flat_rest.hpp); a pattern garment rests flat.
  scene.problem.rest = pattern ? RestShape::pattern : RestShape::initial;
  if (const Json* rest = r.find(root, "rest"))
    scene.problem.rest = r.choice(*rest, "rest", {"pattern", "initial"}) == "pattern" ? RestShape::pattern : RestShape::initial;
  if (dynamic) scene.problem.settle = read_settle(r, r.find(root, "settle"));
  warn_about_cracks(mesh, mesh_json.contains("obj"), say);
  // "mesh.fit_limit": control vertices whose limit points are the mesh's vertices (the paper's
  // §7 limitation lifted; sim/shell/fit_limit.hpp).
  if (const Json* fit = r.find(mesh_json, "fit_limit"); fit != nullptr && r.boolean(*fit, "mesh.fit_limit")) {
    if (scene.problem.method != "loop_kl")
      r.fail("mesh.fit_limit", "needs \"method\": \"loop_kl\" (the other methods draw the mesh itself)");
    try {
      const LimitFit fitted = fit_limit(mesh);
      mesh = fitted.control;
      say("mesh: fitted to its limit surface (the limit points are the mesh's vertices to " +
          format_number(fitted.residual) + " of its size)");
    } catch (const std::exception& e) {
      r.fail("mesh.fit_limit", e.what());
    }
  }
  // An obstacle's translations too are measured against the cloth (the scene's scale).
  for (std::size_t i = 0; i < scene.problem.obstacles.size(); ++i)
    for (std::size_t m = 0; m < scene.problem.obstacles[i].motion.size(); ++m)
      check_travel(r, scene.problem.obstacles[i].motion[m], join_index(join_key(join_index("obstacles", i), "motion"), m), mesh,
                   "the obstacle");
  try {
    scene.problem.mesh = prepare_mesh(scene.problem.method, mesh, say);
  } catch (const std::exception& e) {
    r.fail("mesh", e.what());
  }
  if (pattern && scene.problem.mesh.num_vertices() != mesh.num_vertices())
    r.fail("mesh.pattern", "the pattern mesh was refined for the method, so its piece edges no longer name its "
                           "vertices (report this: the pattern builder isolates irregular vertices itself)");
  if (scene.problem.mesh.num_vertices() > max_vertices)
    r.fail("mesh", "prepared for the method (refined once by Loop subdivision) it has " +
                       std::to_string(scene.problem.mesh.num_vertices()) + " vertices, more than mesh.max_vertices = " +
                       std::to_string(max_vertices) + " (raise mesh.max_vertices to allow it)");

  scene.problem.boundary =
      read_boundary(r, r.find(root, "boundary"), scene.problem.mesh, pattern ? &*pattern : nullptr, dynamic, say);
  read_loads(r, r.find(root, "loads"), scene.problem, pattern ? &*pattern : nullptr, dynamic ? &dyn.ramp_time : nullptr, say);
  check_load_magnitudes(r, scene.problem, say);
  // The pictures' up: opposite to gravity unless the scene says (render.up); the ground, by
  // default there when gravity is, lies normal to it.
  if (!scene.render.up_given && scene.problem.gravity.norm() > 0)
    scene.render.world_up = -scene.problem.gravity.normalized();
  if (!scene.render.ground_given) scene.render.ground = scene.problem.gravity.norm() > 0;
  scene.probes = read_probes(r, r.find(root, "probes"), scene.problem.mesh, say);
  // The boundary and probes were selected on the mesh as placed; the imperfection then changes
  // its rest shape by at most the amplitude.
  if (imperfection.amplitude > 0) {
    try {
      apply_imperfection(scene.problem.mesh, imperfection);
    } catch (const std::exception& e) {
      r.fail("imperfection", e.what());
    }
    say("imperfection: amplitude " + format_number(imperfection.amplitude) + " m, seed " + std::to_string(imperfection.seed));
  }

  if (const auto issue = find_issue(scene.problem, dynamic ? Analysis::dynamics : Analysis::statics))
    r.fail(issue->key, issue->message);
  return scene;
}
}  // namespace

}  // namespace clothsim

// The cloth's mesh from the scene's "mesh" object: see build_mesh.hpp.
#include "sim/scene/build_mesh.hpp"

#include "sim/mesh/cracks.hpp"
#include "sim/mesh/generators.hpp"
#include "sim/mesh/grain.hpp"
#include "sim/mesh/obj_io.hpp"
#include "sim/scene/read_pattern.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

namespace clothsim {
namespace scene_io {
namespace {

// The grain of an OBJ mesh: from its texture coordinates, or an error naming what is missing
// when the scene needs one (`need`: an orthotropic material or a "grain" key).
void obj_grain(const Reader& r, TriMesh& mesh, const GrainSpec& grain, bool need, const std::string& file) {
  if (!need) return;
  if (mesh.uv.empty()) {
    if (grain.given)
      r.fail("material.grain", "the mesh " + quote(file) +
                                   " has no texture coordinates (vt on every face) to measure the grain from");
    r.fail(grain.needed_by, std::string(grain.needed_by == "material" ? "an orthotropic material" : "\"grain\"") +
                                " needs the grain direction, and the mesh " + quote(file) +
                                " has no texture coordinates (vt on every face) to measure it from");
  }
  try {
    mesh.warp = uv_warp(mesh, grain.warp_deg);
  } catch (const std::exception& e) {
    r.fail(grain.given ? "material.grain" : grain.needed_by, quote(file) + ": " + e.what());
  }
}

// A pattern garment: the pieces sewn into one mesh (sim/pattern/pattern.hpp), each piece with its
// own grain.
TriMesh build_pattern_mesh(const Reader& r, const Json& j, const LogFn& log, long long max_vertices,
                           const GrainSpec& grain, std::optional<SewnPattern>& pattern) {
  r.check_object(j, "mesh", {"pattern", "rotate", "translate", "max_vertices", "fit_limit"});
  if (grain.given)
    r.fail("material.grain", "a pattern mesh takes its grain from its pieces (mesh.pattern.pieces[i].grain_deg, "
                             "degrees from the piece's +x axis); remove material.grain");
  const PatternSpec spec = read_pattern(r, j["pattern"], "mesh.pattern");
  try {
    pattern = SewnPattern{spec, build_pattern(spec)};
  } catch (const MeshLimitError& e) {
    r.fail("mesh.pattern.edge_length", std::string(e.what()) + " (use a larger edge length)");
  } catch (const std::exception& e) {
    r.fail("mesh.pattern", e.what());
  }
  check_vertex_count(r, "mesh.pattern.edge_length", "the pattern", pattern->built.mesh.num_vertices(), max_vertices);
  double gap = 0;
  for (const double g : pattern->built.seam_gap) gap = std::max(gap, g);
  log("mesh: pattern of " + std::to_string(spec.pieces.size()) + " piece(s) and " + std::to_string(spec.seams.size()) +
      " seam(s), edge length " + format_number(spec.edge_length) + " m: " + std::to_string(pattern->built.mesh.num_vertices()) +
      " vertices, " + std::to_string(pattern->built.mesh.num_triangles()) + " triangles; largest seam gap as placed " +
      format_number(gap) + " m");
  if (!pattern->built.seam_gap.empty()) {
    std::string gaps;
    char buffer[48];
    for (std::size_t i = 0; i < pattern->built.seam_gap.size(); ++i) {
      std::snprintf(buffer, sizeof buffer, "%s%zu: %.3g", i > 0 ? ", " : "", i, pattern->built.seam_gap[i]);
      gaps += buffer;
    }
    log("mesh: seam gaps as placed [m] (seam: gap): " + gaps);
  }
  return pattern->built.mesh;
}

TriMesh build_mesh_shape(const Reader& r, const Json& j, const std::filesystem::path& folder, const LogFn& log,
                         long long max_vertices, const GrainSpec& grain, bool need_grain,
                         std::optional<SewnPattern>& pattern) {
  const std::string path = "mesh";
  if (!j.is_object()) r.fail(path, "expected an object (got " + describe(j) + ")");
  const bool has_obj = j.contains("obj");
  const bool has_primitive = j.contains("primitive");
  const bool has_pattern = j.contains("pattern");
  if (static_cast<int>(has_obj) + static_cast<int>(has_primitive) + static_cast<int>(has_pattern) > 1)
    r.fail(path, "give one of \"obj\", \"primitive\" and \"pattern\"");
  if (!has_obj && !has_primitive && !has_pattern)
    r.fail(path, "needs \"obj\" (a file), \"primitive\" (allowed: \"grid\", \"cylinder\") or \"pattern\" (sewn pieces)");
  if (has_pattern) return build_pattern_mesh(r, j, log, max_vertices, grain, pattern);

  if (has_obj) {
    r.check_object(j, path, {"obj", "rotate", "translate", "max_vertices", "fit_limit"});  // (the others: build_mesh)
    const std::string key = "mesh.obj";
    const std::string name = r.string(j["obj"], key);
    if (name.empty()) r.fail(key, "expected a non-empty file path");
    const std::filesystem::path obj = folder / name;
    try {
      TriMesh mesh = read_obj(obj.string(), max_vertices);
      log("mesh: " + obj.string() + ": " + std::to_string(mesh.num_vertices()) + " vertices, " +
          std::to_string(mesh.num_triangles()) + " triangles");
      obj_grain(r, mesh, grain, need_grain, name);
      return mesh;
    } catch (const SceneError&) {
      throw;
    } catch (const MeshLimitError& e) {
      r.fail(key, std::string(e.what()) + " (mesh.max_vertices = " + std::to_string(max_vertices) +
                      "; raise it to read larger meshes)");
    } catch (const std::exception& e) {
      r.fail(key, e.what());
    }
  }

  const std::string primitive = r.choice(j["primitive"], "mesh.primitive", {"grid", "cylinder"}, "primitive");
  TriMesh mesh;
  try {
    if (primitive == "grid") {
      r.check_object(j, path, {"primitive", "size", "divisions", "rotate", "translate", "max_vertices", "fit_limit"});
      const Json& size = r.sized_array(r.require(j, path, "size"), "mesh.size", 2, "numbers");
      const Json& div = r.sized_array(r.require(j, path, "divisions"), "mesh.divisions", 2, "integers");
      const double sx = r.positive(size[0], "mesh.size[0]", "[m]");
      const double sy = r.positive(size[1], "mesh.size[1]", "[m]");
      const int dx = r.integer_at_least(div[0], "mesh.divisions[0]", 1);
      const int dy = r.integer_at_least(div[1], "mesh.divisions[1]", 1);
      check_vertex_count(r, "mesh.divisions", "a " + std::to_string(dx) + " x " + std::to_string(dy) + " grid",
                         (static_cast<long long>(dx) + 1) * (static_cast<long long>(dy) + 1), max_vertices);
      mesh = make_grid(sx, sy, dx, dy);
      if (need_grain) mesh.warp = grid_warp(mesh, grain.warp_deg);
      log("mesh: grid " + format_number(sx) + " m x " + format_number(sy) + " m, " + std::to_string(dx) +
          " x " + std::to_string(dy) + " divisions");
    } else {
      r.check_object(j, path,
                     {"primitive", "radius", "length", "segments", "rings", "angle_deg", "rotate", "translate",
                      "max_vertices", "fit_limit"});
      const double radius = r.positive(r.require(j, path, "radius"), "mesh.radius", "[m]");
      const double length = r.positive(r.require(j, path, "length"), "mesh.length", "[m]");
      double angle = 360.0;
      if (const Json* a = r.find(j, "angle_deg")) {
        angle = r.positive(*a, "mesh.angle_deg", "[deg]");
        if (angle > 360.0) r.fail("mesh.angle_deg", "must be <= 360 [deg] (got " + a->dump() + ")");
      }
      const int segments = r.integer_at_least(r.require(j, path, "segments"), "mesh.segments", angle < 360.0 ? 1 : 3);
      const int rings = r.integer_at_least(r.require(j, path, "rings"), "mesh.rings", 2);
      check_vertex_count(r, "mesh", "a cylinder" + std::string(angle < 360.0 ? " panel" : "") + " of " +
                                        std::to_string(segments) + " segments x " + std::to_string(rings) + " rings",
                         (static_cast<long long>(segments) + (angle < 360.0 ? 1 : 0)) * static_cast<long long>(rings),
                         max_vertices);
      mesh = angle < 360.0 ? make_cylinder_panel(radius, length, angle, segments, rings)
                           : make_cylinder(radius, length, segments, rings);
      if (need_grain) mesh.warp = cylinder_warp(mesh, grain.warp_deg);
      log("mesh: cylinder r = " + format_number(radius) + " m, L = " + format_number(length) + " m, " +
          (angle < 360.0 ? "open panel of " + format_number(angle) + " deg, " : std::string()) +
          std::to_string(segments) + " segments, " + std::to_string(rings) + " rings");
    }
  } catch (const SceneError&) {
    throw;
  } catch (const std::exception& e) {
    r.fail(path, e.what());
  }
  return mesh;
}

}  // namespace

void check_vertex_count(const Reader& r, const std::string& path, const std::string& what, long long count,
                        long long max_vertices) {
  if (count > max_vertices)
    r.fail(path, what + " has " + std::to_string(count) + " vertices, more than mesh.max_vertices = " +
                     std::to_string(max_vertices) + " (raise mesh.max_vertices to allow it)");
}

TriMesh build_mesh(const Reader& r, const Json& j, const std::filesystem::path& folder, const LogFn& log,
                   long long max_vertices, const GrainSpec& grain, bool need_grain, std::optional<SewnPattern>& pattern) {
  if (!j.is_object()) r.fail("mesh", "expected an object (got " + describe(j) + ")");
  Json shape = j;
  shape.erase("max_vertices");  // (read by read_max_vertices)
  shape.erase("fit_limit");     // (applied by the scene loader, which knows the method)
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  if (const Json* rot = r.find(j, "rotate")) {
    r.check_object(*rot, "mesh.rotate", {"axis", "angle_deg"});
    const Eigen::Vector3d axis = r.vec3(r.require(*rot, "mesh.rotate", "axis"), "mesh.rotate.axis");
    if (!(axis.norm() > 0)) r.fail("mesh.rotate.axis", "must be a non-zero vector");
    const double angle = r.number(r.require(*rot, "mesh.rotate", "angle_deg"), "mesh.rotate.angle_deg");
    rotation = Eigen::AngleAxisd(angle * M_PI / 180.0, axis.normalized()).toRotationMatrix();
    shape.erase("rotate");
  }
  if (const Json* tr = r.find(j, "translate")) {
    translation = r.vec3(*tr, "mesh.translate");
    shape.erase("translate");
  }
  TriMesh mesh = build_mesh_shape(r, shape, folder, log, max_vertices, grain, need_grain, pattern);
  if (j.contains("rotate") || j.contains("translate")) {
    for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
      mesh.vertices.row(v) = (rotation * mesh.vertices.row(v).transpose() + translation).transpose();
    for (Eigen::Vector3d& w : mesh.warp) w = rotation * w;  // the grain turns with the mesh
    if (!mesh.vertices.allFinite())
      r.fail(j.contains("translate") ? "mesh.translate" : "mesh.rotate",
             "the placed mesh has a coordinate beyond the range of a double (overflow)");
    log("mesh: placed (rotated, then translated)");
  }
  return mesh;
}

void warn_about_cracks(const TriMesh& mesh, bool from_obj, const LogFn& log) {
  const std::vector<std::pair<int, int>> cracks = find_cracks(mesh);
  if (cracks.empty()) return;
  std::string examples;
  const std::size_t shown = std::min<std::size_t>(cracks.size(), 3);
  for (std::size_t i = 0; i < shown; ++i) {
    const auto [a, b] = cracks[i];
    examples += (i > 0 ? "; " : "") + std::string("vertices ") + std::to_string(a) + " and " + std::to_string(b) +
                (from_obj ? " (OBJ indices " + std::to_string(a + 1) + " and " + std::to_string(b + 1) + ")" : "") +
                " at " + format_point(mesh.vertices.row(a).transpose());
  }
  log("warning: mesh: " + std::to_string(cracks.size()) +
      (cracks.size() == 1 ? " pair" : " pairs") + " of distinct border vertices at the same position (within " +
      format_number(kCrackTolerance) + " of the mesh's size): " + examples +
      (cracks.size() > shown ? "; ..." : "") +
      ". The surface is split there (a crack of border edges) and the cloth will come apart along it; "
      "merge the vertices in the mesh file if it should be connected (a cut made on purpose is fine)");
}

}  // namespace scene_io
}  // namespace clothsim

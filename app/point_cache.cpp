#include "app/point_cache.hpp"

#include "app/output_folders.hpp"
#include "sim/mesh/obj_io.hpp"

#include <Eigen/Geometry>

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {

namespace {

namespace fs = std::filesystem;

// Little-endian bytes of a 32-bit value (the PC2 layout, whatever the host's order).
void put32(std::string& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out += static_cast<char>((v >> (8 * k)) & 0xffu);
}
void put_int(std::string& out, std::int32_t v) { put32(out, static_cast<std::uint32_t>(v)); }
void put_float(std::string& out, float f) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  put32(out, bits);
}

// Area-weighted unit vertex normals of a triangle mesh (a vertex of zero area gets +z).
Eigen::MatrixX3d vertex_normals(const TriMesh& mesh) {
  Eigen::MatrixX3d n = Eigen::MatrixX3d::Zero(mesh.num_vertices(), 3);
  for (const Triangle& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices.row(t[0]), b = mesh.vertices.row(t[1]), c = mesh.vertices.row(t[2]);
    const Eigen::RowVector3d area_normal = (b - a).cross(c - a).transpose();  // twice the area
    for (const int v : t) n.row(v) += area_normal;
  }
  for (Eigen::Index v = 0; v < n.rows(); ++v) {
    const double len = n.row(v).norm();
    n.row(v) = len > 0 ? Eigen::RowVector3d(n.row(v) / len) : Eigen::RowVector3d(0, 0, 1);
  }
  return n;
}

}  // namespace

PointCacheReport write_point_cache(const fs::path& run_dir) {
  const std::vector<fs::path> frames = files_like(run_dir / "frames", "mesh_", ".obj");
  if (frames.empty())
    throw std::runtime_error((run_dir / "frames").string() +
                             ": no OBJ frames (mesh_NNNN.obj) to build a point cache from; run the scene with "
                             "\"output\": {\"obj\": true}");
  const TriMesh first = read_obj(frames.front().string());
  PointCacheReport report;
  report.points = first.num_vertices();
  report.frames = static_cast<int>(frames.size());
  std::string bytes("POINTCACHE2", 11);
  bytes += '\0';
  put_int(bytes, 1);
  put_int(bytes, report.points);
  put_float(bytes, 0.0f);  // start frame
  put_float(bytes, 1.0f);  // sample rate: one sample per frame
  put_int(bytes, report.frames);
  bytes.reserve(bytes.size() + static_cast<std::size_t>(report.frames) * static_cast<std::size_t>(report.points) * 12);
  for (const fs::path& f : frames) {
    const TriMesh mesh = f == frames.front() ? first : read_obj(f.string());
    if (mesh.num_vertices() != report.points || mesh.triangles != first.triangles)
      throw std::runtime_error(f.string() + ": not the mesh of " + frames.front().filename().string() + " (" +
                               std::to_string(mesh.num_vertices()) + " vertices, " +
                               std::to_string(mesh.num_triangles()) + " triangles against " +
                               std::to_string(report.points) + ", " + std::to_string(first.num_triangles()) +
                               "): a point cache needs one mesh for every frame");
    for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
      for (int k = 0; k < 3; ++k) put_float(bytes, static_cast<float>(mesh.vertices(v, k)));
  }
  const Eigen::MatrixX3d normals = vertex_normals(first);
  write_obj((run_dir / "cache_rest.obj").string(), first.vertices, first.triangles,
            "clothsim point cache rest mesh: the first frame of " + run_dir.filename().string() +
                " (apply cache.pc2 to it; docs/animation_tools.md)",
            &normals, first.uv.empty() ? nullptr : &first.uv);
  write_atomically(run_dir / "cache.pc2", bytes);
  return report;
}

}  // namespace clothsim

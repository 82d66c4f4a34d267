#include "sim/mesh/mesh_part.hpp"

#include <stdexcept>

namespace clothsim {

TriMesh mesh_part(const TriMesh& mesh, const std::vector<HalfSpace>& keep,
                  const std::vector<std::vector<HalfSpace>>& cut) {
  const auto check = [](const HalfSpace& h) {
    if (!(h.normal.norm() > 0) || !h.normal.allFinite() || !h.point.allFinite())
      throw std::invalid_argument("mesh_part: a half-space needs a finite point and a non-zero normal");
  };
  for (const HalfSpace& h : keep) check(h);
  for (const auto& region : cut)
    for (const HalfSpace& h : region) check(h);
  const auto inside = [](const std::vector<HalfSpace>& all, const Eigen::Vector3d& x) {
    for (const HalfSpace& h : all)
      if ((x - h.point).dot(h.normal) < 0) return false;
    return true;
  };
  TriMesh out;
  std::vector<size_t> kept_triangles;
  std::vector<int> index(static_cast<size_t>(mesh.num_vertices()), -1);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    const Eigen::Vector3d c =
        (mesh.vertices.row(tri[0]) + mesh.vertices.row(tri[1]) + mesh.vertices.row(tri[2])).transpose() / 3.0;
    if (!inside(keep, c)) continue;
    bool removed = false;
    for (const auto& region : cut) removed = removed || (!region.empty() && inside(region, c));
    if (removed) continue;
    kept_triangles.push_back(t);
    for (const int v : tri) index[static_cast<size_t>(v)] = 0;
  }
  int count = 0;
  for (int& id : index)
    if (id == 0) id = count++;
  out.vertices.resize(count, 3);
  for (int v = 0; v < mesh.num_vertices(); ++v)
    if (index[static_cast<size_t>(v)] >= 0) out.vertices.row(index[static_cast<size_t>(v)]) = mesh.vertices.row(v);
  for (const size_t t : kept_triangles) {
    const Triangle& tri = mesh.triangles[t];
    out.triangles.push_back({index[static_cast<size_t>(tri[0])], index[static_cast<size_t>(tri[1])], index[static_cast<size_t>(tri[2])]});
    if (!mesh.warp.empty()) out.warp.push_back(mesh.warp[t]);
    if (!mesh.uv.empty()) out.uv.push_back(mesh.uv[t]);
  }
  return out;
}

}  // namespace clothsim

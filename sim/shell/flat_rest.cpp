#include "sim/shell/flat_rest.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

namespace clothsim {

namespace {

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

}  // namespace

FlatRestLayout::FlatRestLayout(const TriMesh& mesh, const ExtendedMesh& ext) : mesh_(mesh), ext_(ext) {
  if (mesh.uv.size() != mesh.triangles.size())
    throw MeshError("a flat rest state from the pattern needs texture coordinates (pattern coordinates in metres) on "
                    "every triangle; the mesh has them on " + std::to_string(mesh.uv.size()) + " of " +
                    std::to_string(mesh.triangles.size()));
  vertex_triangles_.resize(static_cast<size_t>(mesh.num_vertices()));
  mirrored_.resize(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& u = mesh.uv[t];
    const double twice_area = cross2(u[1] - u[0], u[2] - u[0]);
    const double scale = std::max({(u[1] - u[0]).squaredNorm(), (u[2] - u[0]).squaredNorm(), (u[2] - u[1]).squaredNorm()});
    if (!std::isfinite(twice_area) || !(std::abs(twice_area) > 1e-12 * scale))
      throw MeshError("triangle " + std::to_string(t) + ": its texture coordinates (the rest layout) are degenerate "
                      "(zero area)");
    mirrored_[t] = twice_area < 0;
    for (const int v : mesh.triangles[t]) vertex_triangles_[static_cast<size_t>(v)].push_back(static_cast<int>(t));
  }
}

Eigen::MatrixX3d FlatRestLayout::patch(int triangle, const std::vector<int>& patch) const {
  const int nr = ext_.num_real;
  std::vector<int> need;
  for (const int p : patch) {
    if (p < nr) {
      need.push_back(p);
    } else {
      const GhostVertex& g = ext_.ghosts[static_cast<size_t>(p - nr)];
      need.insert(need.end(), {g.a, g.b, g.c});
    }
  }
  std::sort(need.begin(), need.end());
  need.erase(std::unique(need.begin(), need.end()), need.end());
  std::vector<int> region;
  for (const int v : need) region.insert(region.end(), vertex_triangles_[static_cast<size_t>(v)].begin(),
                                         vertex_triangles_[static_cast<size_t>(v)].end());
  std::sort(region.begin(), region.end());
  region.erase(std::unique(region.begin(), region.end()), region.end());

  // A triangle's texture coordinates, mirrored (u → −u) where they run clockwise.
  const auto uv = [&](int t, int k) {
    Eigen::Vector2d u = mesh_.uv[static_cast<size_t>(t)][static_cast<size_t>(k)];
    if (mirrored_[static_cast<size_t>(t)]) u.x() = -u.x();
    return u;
  };
  struct Placement {
    Eigen::Vector2d first, sum;
    int count = 0;
  };
  std::map<int, Placement> placed;
  const auto place = [&](int v, const Eigen::Vector2d& at) {
    Placement& p = placed[v];
    if (p.count == 0) p.first = p.sum = at;
    else p.sum += at;
    ++p.count;
  };
  const Triangle& seed = mesh_.triangles[static_cast<size_t>(triangle)];
  for (int k = 0; k < 3; ++k) place(seed[static_cast<size_t>(k)], uv(triangle, k));
  std::vector<int> queue = {triangle};
  std::vector<int> visited = {triangle};
  for (size_t head = 0; head < queue.size(); ++head) {
    const int t = queue[head];
    const Triangle& tri = mesh_.triangles[static_cast<size_t>(t)];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[static_cast<size_t>(k)], b = tri[static_cast<size_t>((k + 1) % 3)];
      // The triangle across the edge a–b (it holds b → a), if it is in the region and new.
      int n = -1;
      for (const int c : vertex_triangles_[static_cast<size_t>(a)]) {
        if (c == t) continue;
        const Triangle& ct = mesh_.triangles[static_cast<size_t>(c)];
        if (std::find(ct.begin(), ct.end(), b) != ct.end()) {
          n = c;
          break;
        }
      }
      if (n < 0 || std::find(visited.begin(), visited.end(), n) != visited.end() ||
          !std::binary_search(region.begin(), region.end(), n))
        continue;
      visited.push_back(n);
      queue.push_back(n);
      const Triangle& nt = mesh_.triangles[static_cast<size_t>(n)];
      int ka = 0, kb = 0, kr = 0;
      for (int j = 0; j < 3; ++j) {
        if (nt[static_cast<size_t>(j)] == a) ka = j;
        else if (nt[static_cast<size_t>(j)] == b) kb = j;
        else kr = j;
      }
      // Turn and shift n's layout so that its edge a–b lies on the one already placed.
      const Eigen::Vector2d pa = placed[a].first, pb = placed[b].first;
      const Eigen::Vector2d ua = uv(n, ka), ub = uv(n, kb), ur = uv(n, kr);
      const Eigen::Vector2d du = ub - ua, dp = pb - pa;
      const double angle = std::atan2(cross2(du, dp), du.dot(dp));
      const Eigen::Matrix2d turn = (Eigen::Matrix2d() << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle)).finished();
      place(nt[static_cast<size_t>(kr)], 0.5 * (pa + pb) + turn * (ur - 0.5 * (ua + ub)));
    }
  }
  const auto at = [&](int v) -> Eigen::Vector2d {
    const auto it = placed.find(v);
    if (it == placed.end())
      throw MeshError("triangle " + std::to_string(triangle) + ": vertex " + std::to_string(v) +
                      " of its patch cannot be reached across edges to lay the patch out flat");
    return it->second.sum / it->second.count;
  };
  Eigen::MatrixX3d out(static_cast<Eigen::Index>(patch.size()), 3);
  for (size_t i = 0; i < patch.size(); ++i) {
    const int p = patch[i];
    Eigen::Vector2d x;
    if (p < nr) {
      x = at(p);
    } else {
      const GhostVertex& g = ext_.ghosts[static_cast<size_t>(p - nr)];
      x = at(g.a) + at(g.b) - at(g.c);
    }
    out.row(static_cast<Eigen::Index>(i)) << x.x(), x.y(), 0.0;
  }
  return out;
}

Eigen::Vector3d FlatRestLayout::to_layout(int triangle, const Eigen::Vector3d& d) const {
  const Triangle& tri = mesh_.triangles[static_cast<size_t>(triangle)];
  const auto& u = mesh_.uv[static_cast<size_t>(triangle)];
  Eigen::Matrix<double, 3, 2> j;
  j.col(0) = mesh_.vertices.row(tri[1]) - mesh_.vertices.row(tri[0]);
  j.col(1) = mesh_.vertices.row(tri[2]) - mesh_.vertices.row(tri[0]);
  Eigen::Matrix2d du;
  du.col(0) = u[1] - u[0];
  du.col(1) = u[2] - u[0];
  if (mirrored_[static_cast<size_t>(triangle)]) du.row(0) *= -1.0;
  // x − x₀ = J du⁻¹ (u − u₀): a direction d goes back to du (JᵀJ)⁻¹ Jᵀ d.
  const Eigen::Vector2d w = du * (j.transpose() * j).ldlt().solve(j.transpose() * d);
  const double n = w.norm();
  if (!(n > 0) || !std::isfinite(n))
    throw MeshError("triangle " + std::to_string(triangle) + ": its direction cannot be carried into the rest layout");
  return Eigen::Vector3d(w.x() / n, w.y() / n, 0.0);
}

double FlatRestLayout::area(int triangle) const {
  const auto& u = mesh_.uv[static_cast<size_t>(triangle)];
  return 0.5 * std::abs(cross2(u[1] - u[0], u[2] - u[0]));
}

Eigen::VectorXd lumped_vertex_mass_uv(const TriMesh& mesh, double areal_density) {
  if (mesh.uv.size() != mesh.triangles.size())
    throw MeshError("lumped_vertex_mass_uv: the mesh has no texture coordinates on every triangle");
  Eigen::VectorXd m = Eigen::VectorXd::Zero(mesh.num_vertices());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& u = mesh.uv[t];
    const double a = 0.5 * std::abs(cross2(u[1] - u[0], u[2] - u[0]));
    for (const int v : mesh.triangles[t]) m(v) += areal_density * a / 3.0;
  }
  return m;
}

}  // namespace clothsim

// Coincident border vertices by a spatial hash (sorted cells, 27-cell neighbourhood).
#include "sim/mesh/cracks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace clothsim {

std::vector<std::pair<int, int>> find_cracks(const TriMesh& mesh, double relative_tolerance) {
  std::vector<std::pair<int, int>> out;
  const int n = mesh.num_vertices();
  if (n == 0 || mesh.triangles.empty() || !(relative_tolerance > 0)) return out;

  // Border edges: an undirected edge used by one triangle only (one sort of all edges).
  std::vector<std::uint64_t> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::uint64_t>(std::min(t[k], t[(k + 1) % 3]));
      const auto b = static_cast<std::uint64_t>(std::max(t[k], t[(k + 1) % 3]));
      edges.push_back((a << 32) | b);
    }
  std::sort(edges.begin(), edges.end());
  std::vector<char> on_border(static_cast<std::size_t>(n), 0);
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) {
      on_border[edges[i] >> 32] = 1;
      on_border[edges[i] & 0xffffffffu] = 1;
    }
    i = j;
  }

  // Unit coordinates (centred, largest half-extent 1; divided before subtracting so nothing
  // overflows), so that the tolerance is relative and the cells' integer keys stay small.
  const Eigen::RowVector3d lo = mesh.vertices.colwise().minCoeff(), hi = mesh.vertices.colwise().maxCoeff();
  double scale = (0.5 * hi - 0.5 * lo).cwiseAbs().maxCoeff();
  if (!(scale > 0) || !std::isfinite(scale)) scale = 1.0;
  const Eigen::RowVector3d center = 0.5 * lo + 0.5 * hi;
  const double diagonal = (hi / scale - lo / scale).norm();
  const double tol = relative_tolerance * (diagonal > 0 ? diagonal : 1.0);
  auto unit = [&](int v) -> Eigen::Vector3d { return (mesh.vertices.row(v) / scale - center / scale).transpose(); };

  // Cells of side tol: coincident vertices lie in the same or in neighbouring cells.
  using Key = std::array<std::int64_t, 3>;
  auto key_of = [&](const Eigen::Vector3d& p) {
    Key k{};
    for (int c = 0; c < 3; ++c) k[static_cast<std::size_t>(c)] = static_cast<std::int64_t>(std::floor(p[c] / tol));
    return k;
  };
  std::vector<std::pair<Key, int>> cells;
  for (int v = 0; v < n; ++v)
    if (on_border[static_cast<std::size_t>(v)]) cells.emplace_back(key_of(unit(v)), v);
  std::sort(cells.begin(), cells.end());

  // Vertex pairs that share a triangle (joined by an edge) are not a crack.
  auto share_edge = [&](int a, int b) {
    const auto key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint64_t>(std::max(a, b));
    return std::binary_search(edges.begin(), edges.end(), key);
  };
  for (const auto& [key, a] : cells) {
    const Eigen::Vector3d pa = unit(a);
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const Key neighbour{key[0] + dx, key[1] + dy, key[2] + dz};
          auto it = std::lower_bound(cells.begin(), cells.end(), std::make_pair(neighbour, -1));
          for (; it != cells.end() && it->first == neighbour; ++it) {
            const int b = it->second;
            if (b <= a) continue;  // each pair once, from its lower index
            if ((unit(b) - pa).norm() <= tol && !share_edge(a, b)) out.emplace_back(a, b);
          }
        }
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace clothsim

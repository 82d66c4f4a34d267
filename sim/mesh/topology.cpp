#include "sim/mesh/topology.hpp"

#include <algorithm>
#include <cstdint>
#include <tuple>
#include <string>

namespace clothsim {

namespace {
std::string tri_name(int t, const Triangle& tri) {
  return "triangle " + std::to_string(t) + " (" + std::to_string(tri[0]) + ", " +
         std::to_string(tri[1]) + ", " + std::to_string(tri[2]) + ")";
}
}  // namespace

Topology::Topology(int num_vertices, const std::vector<Triangle>& triangles)
    : rings_(num_vertices), boundary_(num_vertices, false), next_(num_vertices) {
  // Every triangle edge under the key (min, max), with its triangle and direction; one sort
  // groups the uses of each undirected edge: more than two is non-manifold, two in the same
  // direction is an inconsistent orientation.
  std::vector<std::pair<std::uint64_t, std::int64_t>> uses;  // key, 2·triangle + (a > b)
  uses.reserve(3 * triangles.size());
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    const Triangle& tri = triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3], c = tri[(k + 2) % 3];
      if (a < 0 || a >= num_vertices)
        throw MeshError(tri_name(t, tri) + ": vertex index out of range (mesh has " +
                        std::to_string(num_vertices) + " vertices)");
      if (a == b || b == c || a == c) throw MeshError(tri_name(t, tri) + " is degenerate: repeated vertex");
      const auto lo = static_cast<std::uint64_t>(std::min(a, b)), hi = static_cast<std::uint64_t>(std::max(a, b));
      uses.emplace_back((lo << 32) | hi, 2 * static_cast<std::int64_t>(t) + (a > b ? 1 : 0));
      next_[a].emplace_back(b, c);
    }
  }
  std::sort(uses.begin(), uses.end());
  for (size_t i = 0; i < uses.size();) {
    size_t j = i + 1;
    while (j < uses.size() && uses[j].first == uses[i].first) ++j;
    const int lo = static_cast<int>(uses[i].first >> 32), hi = static_cast<int>(uses[i].first & 0xffffffffu);
    if (j - i > 2) {
      const int t = static_cast<int>(uses[i + 2].second / 2);
      throw MeshError("non-manifold edge (" + std::to_string(lo) + ", " + std::to_string(hi) +
                      "): shared by more than two triangles, e.g. " + tri_name(t, triangles[t]));
    }
    if (j - i == 2 && uses[i].second % 2 == uses[i + 1].second % 2) {
      const int t0 = static_cast<int>(uses[i].second / 2), t1 = static_cast<int>(uses[i + 1].second / 2);
      const bool reversed = uses[i].second % 2 == 1;
      throw MeshError("inconsistent orientation at edge (" + std::to_string(reversed ? hi : lo) + ", " +
                      std::to_string(reversed ? lo : hi) + "): " + tri_name(t0, triangles[t0]) + " and " +
                      tri_name(t1, triangles[t1]) + " traverse it in the same direction");
    }
    i = j;
  }
  for (int v = 0; v < num_vertices; ++v) {
    auto& pairs = next_[v];
    if (pairs.empty()) throw MeshError("isolated vertex " + std::to_string(v) + ": it belongs to no triangle");
    std::sort(pairs.begin(), pairs.end());
    // A fan start is a key b that is never a value c.
    std::vector<int> starts;
    for (const auto& [b, c] : pairs) {
      (void)c;
      const bool is_value = std::any_of(pairs.begin(), pairs.end(), [b = b](const auto& p) { return p.second == b; });
      if (!is_value) starts.push_back(b);
    }
    if (starts.size() > 1)
      throw MeshError("non-manifold vertex " + std::to_string(v) +
                      ": its triangles form more than one fan (the surface touches itself there)");
    boundary_[v] = !starts.empty();
    int cur = boundary_[v] ? starts.front() : pairs.front().first;
    const int first = cur;
    std::vector<int>& ring = rings_[v];
    ring.push_back(cur);
    int visited = 0;
    while (true) {
      auto it = std::lower_bound(pairs.begin(), pairs.end(), std::make_pair(cur, -1));
      if (it == pairs.end() || it->first != cur) break;  // reached the end of a boundary fan
      ++visited;
      cur = it->second;
      if (cur == first) break;  // closed fan
      ring.push_back(cur);
      if (visited > static_cast<int>(pairs.size())) break;
    }
    if (visited != static_cast<int>(pairs.size()))
      throw MeshError("non-manifold vertex " + std::to_string(v) +
                      ": its triangles form more than one fan (the surface touches itself there)");
  }
  // Boundary loops: from a boundary vertex, the boundary edge leaving it goes to ring.front().
  std::vector<bool> seen(num_vertices, false);
  for (int v = 0; v < num_vertices; ++v) {
    if (!boundary_[v] || seen[v]) continue;
    std::vector<int> loop;
    int cur = v;
    while (!seen[cur]) {
      seen[cur] = true;
      loop.push_back(cur);
      cur = rings_[cur].front();
    }
    loops_.push_back(std::move(loop));
  }
}

int Topology::opposite(int a, int b) const {
  const auto& pairs = next_[a];
  auto it = std::lower_bound(pairs.begin(), pairs.end(), std::make_pair(b, -1));
  if (it == pairs.end() || it->first != b) return -1;
  return it->second;
}

std::vector<int> Topology::ring_from(int v, int first) const {
  const auto& ring = rings_[v];
  auto it = std::find(ring.begin(), ring.end(), first);
  if (it == ring.end())
    throw MeshError("vertex " + std::to_string(first) + " is not a neighbour of vertex " + std::to_string(v));
  std::vector<int> out(it, ring.end());
  out.insert(out.end(), ring.begin(), it);
  return out;
}

}  // namespace clothsim

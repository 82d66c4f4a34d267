// Small meshes built for tests: a regular triangular lattice, a "fan disc" whose centre has any
// valence, with every other interior vertex regular, and a grid with jittered interior vertices;
// the area of a mesh; and two meshes as one.
#pragma once

#include "sim/mesh/generators.hpp"
#include "sim/mesh/mesh.hpp"

#include <cmath>
#include <map>
#include <numbers>
#include <random>

namespace clothsim::testing {

// n × n lattice points i·(1, 0) + j·(½, √3/2) (equilateral triangles), counter-clockwise.
inline TriMesh make_lattice(int n) {
  TriMesh m;
  m.vertices.resize(n * n, 3);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) m.vertices.row(j * n + i) << i + 0.5 * j, std::sqrt(3.0) / 2 * j, 0.0;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int p = j * n + i;
      m.triangles.push_back({p, p + 1, p + n});
      m.triangles.push_back({p + 1, p + n + 1, p + n});
    }
  return m;
}

// The same lattice of n × n points scaled to `side` [m] in total along x.
inline TriMesh make_lattice(int n, double side) {
  TriMesh m = make_lattice(n);
  m.vertices *= side / (n - 1);
  return m;
}

// A disc of `sectors` triangles around a centre vertex of valence `sectors`, each sector split
// regularly into k² triangles; all other interior vertices have valence 6. Radius 1, z = 0.
inline TriMesh make_fan_disc(int sectors, int k) {
  std::map<std::array<int, 3>, int> ids;  // (sector, i, j) with spoke points shared
  TriMesh m;
  std::vector<Eigen::RowVector3d> pts;
  auto spoke = [&](int s) {
    const double t = 2.0 * std::numbers::pi * s / sectors;
    return Eigen::RowVector3d(std::cos(t), std::sin(t), 0.0);
  };
  auto id = [&](int s, int i, int j) {
    // Point i/k along spoke s plus j/k along spoke s + 1; canonical keys for shared points.
    std::array<int, 3> key{s, i, j};
    if (i == 0 && j == 0) key = {0, 0, 0};
    else if (i == 0) key = {(s + 1) % sectors, j, 0};
    auto [it, inserted] = ids.emplace(key, static_cast<int>(pts.size()));
    if (inserted) pts.push_back((key[1] * spoke(key[0]) + key[2] * spoke(key[0] + 1)) / k);
    return it->second;
  };
  for (int s = 0; s < sectors; ++s)
    for (int i = 0; i < k; ++i)
      for (int j = 0; i + j < k; ++j) {
        m.triangles.push_back({id(s, i, j), id(s, i + 1, j), id(s, i, j + 1)});
        if (i + j + 2 <= k) m.triangles.push_back({id(s, i + 1, j), id(s, i + 1, j + 1), id(s, i, j + 1)});
      }
  m.vertices.resize(static_cast<Eigen::Index>(pts.size()), 3);
  for (size_t i = 0; i < pts.size(); ++i) m.vertices.row(static_cast<Eigen::Index>(i)) = pts[i];
  return m;
}

// A 0.1 m × 0.08 m grid (5 × 4 cells) whose interior vertices are moved in the plane by up to 15 %
// of a cell (seeded): triangles of many shapes, still a valid mesh.
inline TriMesh jittered_grid() {
  TriMesh m = make_grid(0.1, 0.08, 5, 4);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.003, 0.003);
  for (int v = 0; v < m.num_vertices(); ++v) {
    const double x = m.vertices(v, 0), y = m.vertices(v, 1);
    if (std::abs(std::abs(x) - 0.05) < 1e-9 || std::abs(std::abs(y) - 0.04) < 1e-9) continue;
    m.vertices(v, 0) += u(rng);
    m.vertices(v, 1) += u(rng);
  }
  return m;
}

// The sum of the triangles' areas [m²].
inline double mesh_area(const TriMesh& m) {
  double area = 0.0;
  for (const Triangle& t : m.triangles)
    area += 0.5 * (m.vertices.row(t[1]) - m.vertices.row(t[0])).cross(m.vertices.row(t[2]) - m.vertices.row(t[0])).norm();
  return area;
}

// `a` and `b` as one mesh of two parts: b's vertices follow a's, its triangles renumbered.
inline TriMesh concatenated(const TriMesh& a, const TriMesh& b) {
  TriMesh m;
  m.vertices.resize(a.vertices.rows() + b.vertices.rows(), 3);
  m.vertices << a.vertices, b.vertices;
  m.triangles = a.triangles;
  for (const Triangle& t : b.triangles) m.triangles.push_back({t[0] + a.num_vertices(), t[1] + a.num_vertices(), t[2] + a.num_vertices()});
  return m;
}

}  // namespace clothsim::testing

// Regular grid and cylinder control meshes.
#include "sim/mesh/generators.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {

void require_positive(double value, const char* name, const char* function) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw std::invalid_argument(std::string(function) + ": " + name + " must be positive and finite, got " +
                                std::to_string(value));
}

// Rejects meshes whose vertex or triangle count would not fit in an int.
void require_fits(std::int64_t num_vertices, std::int64_t num_triangles, const char* function) {
  constexpr std::int64_t limit = std::numeric_limits<int>::max();
  if (num_vertices > limit || num_triangles > limit)
    throw std::invalid_argument(std::string(function) + ": too many vertices or triangles");
}

}  // namespace

TriMesh make_grid(double size_x, double size_y, int divisions_x, int divisions_y) {
  require_positive(size_x, "size_x", "make_grid");
  require_positive(size_y, "size_y", "make_grid");
  if (divisions_x < 1 || divisions_y < 1)
    throw std::invalid_argument("make_grid: divisions must be at least 1, got " + std::to_string(divisions_x) +
                                " x " + std::to_string(divisions_y));
  const int nx = divisions_x + 1;  // vertices per row
  require_fits(std::int64_t{nx} * (std::int64_t{divisions_y} + 1),
               2 * std::int64_t{divisions_x} * std::int64_t{divisions_y}, "make_grid");

  TriMesh mesh;
  mesh.vertices.resize(nx * (divisions_y + 1), 3);
  for (int j = 0; j <= divisions_y; ++j)
    for (int i = 0; i <= divisions_x; ++i) {
      const int v = j * nx + i;
      mesh.vertices(v, 0) = size_x * (static_cast<double>(i) / divisions_x - 0.5);
      mesh.vertices(v, 1) = size_y * (static_cast<double>(j) / divisions_y - 0.5);
      mesh.vertices(v, 2) = 0.0;
    }
  mesh.triangles.reserve(static_cast<std::size_t>(2 * divisions_x * divisions_y));
  for (int j = 0; j < divisions_y; ++j)
    for (int i = 0; i < divisions_x; ++i) {
      const int a = j * nx + i;  // (i, j)
      const int b = a + 1;       // (i+1, j)
      const int c = b + nx;      // (i+1, j+1)
      const int d = a + nx;      // (i, j+1)
      mesh.triangles.push_back({a, b, c});
      mesh.triangles.push_back({a, c, d});
    }
  return mesh;
}

TriMesh make_cylinder(double radius, double length, int segments, int rings) {
  require_positive(radius, "radius", "make_cylinder");
  require_positive(length, "length", "make_cylinder");
  if (segments < 3)
    throw std::invalid_argument("make_cylinder: segments must be at least 3, got " + std::to_string(segments));
  if (rings < 2) throw std::invalid_argument("make_cylinder: rings must be at least 2, got " + std::to_string(rings));
  require_fits(std::int64_t{segments} * rings, 2 * std::int64_t{segments} * (std::int64_t{rings} - 1),
               "make_cylinder");

  TriMesh mesh;
  mesh.vertices.resize(segments * rings, 3);
  for (int r = 0; r < rings; ++r) {
    const double y = length * static_cast<double>(r) / (rings - 1);
    for (int k = 0; k < segments; ++k) {
      const double theta = 2.0 * std::numbers::pi * static_cast<double>(k) / segments;
      const int v = r * segments + k;
      mesh.vertices(v, 0) = radius * std::cos(theta);
      mesh.vertices(v, 1) = y;
      mesh.vertices(v, 2) = -radius * std::sin(theta);
    }
  }
  // Going from k to k+1 turns by +θ about +y (x → −z); that tangent × (+y) is the outward radial
  // direction, so (k, r) → (k+1, r) → (k+1, r+1) is counter-clockwise seen from outside.
  mesh.triangles.reserve(static_cast<std::size_t>(2 * segments * (rings - 1)));
  for (int r = 0; r + 1 < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const int k1 = (k + 1) % segments;
      const int a = r * segments + k;
      const int b = r * segments + k1;
      const int c = (r + 1) * segments + k1;
      const int d = (r + 1) * segments + k;
      mesh.triangles.push_back({a, b, c});
      mesh.triangles.push_back({a, c, d});
    }
  return mesh;
}

TriMesh make_cylinder_panel(double radius, double length, double angle_deg, int segments, int rings) {
  require_positive(radius, "radius", "make_cylinder_panel");
  require_positive(length, "length", "make_cylinder_panel");
  if (!(angle_deg > 0.0 && angle_deg < 360.0))
    throw std::invalid_argument("make_cylinder_panel: angle_deg must lie in (0, 360), got " + std::to_string(angle_deg));
  if (segments < 1)
    throw std::invalid_argument("make_cylinder_panel: segments must be at least 1, got " + std::to_string(segments));
  if (rings < 2) throw std::invalid_argument("make_cylinder_panel: rings must be at least 2, got " + std::to_string(rings));
  require_fits(std::int64_t{segments + 1} * rings, 2 * std::int64_t{segments} * (std::int64_t{rings} - 1),
               "make_cylinder_panel");
  const int per_ring = segments + 1;
  const double angle = angle_deg * std::numbers::pi / 180.0;
  TriMesh mesh;
  mesh.vertices.resize(per_ring * rings, 3);
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < per_ring; ++k) {
      const double phi = angle * (static_cast<double>(k) / segments - 0.5);
      mesh.vertices.row(r * per_ring + k) << radius * std::sin(phi), length * static_cast<double>(r) / (rings - 1),
          radius * std::cos(phi);
    }
  // k → k+1 moves towards +x at the crown; (k, r) → (k+1, r) → (k+1, r+1) then faces outwards.
  for (int r = 0; r + 1 < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const int a = r * per_ring + k, b = a + 1, c = b + per_ring, d = a + per_ring;
      mesh.triangles.push_back({a, b, c});
      mesh.triangles.push_back({a, c, d});
    }
  return mesh;
}

}  // namespace clothsim

// Double-precision 3-vectors for the renderer's own geometry (camera framing, the ground, the
// shadow's light): plain arithmetic, no Eigen (render/ stays independent of sim/). Internal to
// render/.
#pragma once

#include <cmath>

#include "render/frame.hpp"

namespace clothsim::render::detail {

struct Vec3d {
  double x = 0, y = 0, z = 0;
};

inline Vec3d to_d(const Vec3f& v) { return {v[0], v[1], v[2]}; }
inline Vec3f to_f(const Vec3d& v) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}
inline Vec3d operator-(const Vec3d& a, const Vec3d& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3d operator+(const Vec3d& a, const Vec3d& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3d operator*(double s, const Vec3d& a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(const Vec3d& a, const Vec3d& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(const Vec3d& a) { return std::sqrt(dot(a, a)); }
inline Vec3d unit(const Vec3d& a) { return (1.0 / norm(a)) * a; }
inline bool finite(const Vec3d& a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

}  // namespace clothsim::render::detail

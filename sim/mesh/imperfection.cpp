#include "sim/mesh/imperfection.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Uniform in [0, 1) from the top 53 bits of one draw.
double unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

struct Wave {
  Eigen::Vector3d k;
  double phase;
};

void resolve(const Imperfection& in, double diagonal, double& lo, double& hi) {
  const bool given = in.wavelength_min > 0 || in.wavelength_max > 0;
  lo = given ? in.wavelength_min : diagonal / 16.0;
  hi = given ? in.wavelength_max : diagonal / 2.0;
}

std::vector<Wave> waves(const Imperfection& in, double lo, double hi) {
  std::mt19937_64 rng(in.seed);
  std::vector<Wave> w(kImperfectionWaves);
  for (Wave& wave : w) {
    const double z = 2.0 * unit(rng) - 1.0, angle = 2.0 * kPi * unit(rng);
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d direction(s * std::cos(angle), s * std::sin(angle), z);
    const double wavelength = lo * std::pow(hi / lo, unit(rng));
    wave.k = (2.0 * kPi / wavelength) * direction;
    wave.phase = 2.0 * kPi * unit(rng);
  }
  return w;
}

void check(const Imperfection& in) {
  if (!std::isfinite(in.amplitude) || in.amplitude < 0)
    throw std::invalid_argument("imperfection: the amplitude must be a finite number >= 0 [m]");
  const bool none = in.wavelength_min == 0 && in.wavelength_max == 0;
  if (!none && !(std::isfinite(in.wavelength_min) && std::isfinite(in.wavelength_max) && in.wavelength_min > 0 &&
                 in.wavelength_min <= in.wavelength_max))
    throw std::invalid_argument("imperfection: the wavelengths must be finite, > 0 and the shortest first [m]");
}

}  // namespace

Eigen::VectorXd imperfection_field(const Eigen::MatrixX3d& points, const Imperfection& imperfection, double diagonal) {
  check(imperfection);
  double lo = 0, hi = 0;
  resolve(imperfection, diagonal, lo, hi);
  if (!(lo > 0) || !(hi > 0)) throw std::invalid_argument("imperfection: the mesh has no extent to set the wavelengths from");
  const std::vector<Wave> w = waves(imperfection, lo, hi);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d x = points.row(i).transpose();
    double sum = 0.0;
    for (const Wave& wave : w) sum += std::cos(wave.k.dot(x) + wave.phase);
    f(i) = sum;
  }
  return f;
}

void apply_imperfection(TriMesh& mesh, const Imperfection& imperfection) {
  check(imperfection);
  if (imperfection.amplitude == 0.0 || mesh.num_vertices() == 0) return;
  const Eigen::Vector3d lo = mesh.vertices.colwise().minCoeff(), hi = mesh.vertices.colwise().maxCoeff();
  const Eigen::VectorXd f = imperfection_field(mesh.vertices, imperfection, (hi - lo).norm());
  Eigen::MatrixX3d normal = Eigen::MatrixX3d::Zero(mesh.num_vertices(), 3);
  for (const Triangle& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices.row(t[0]), b = mesh.vertices.row(t[1]), c = mesh.vertices.row(t[2]);
    const Eigen::RowVector3d n = (b - a).cross(c - a).transpose();  // twice the area times the unit normal
    for (int v : t) normal.row(v) += n;
  }
  const double largest = f.cwiseAbs().maxCoeff();
  if (!(largest > 0)) return;  // (all 32 waves cancel at every vertex: not met in practice)
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const double length = normal.row(v).norm();
    if (!(length > 0))
      throw std::invalid_argument("imperfection: vertex " + std::to_string(v) + " has no normal (no triangle, or its triangles' normals cancel)");
    mesh.vertices.row(v) += (imperfection.amplitude * f(v) / largest / length) * normal.row(v);
  }
}

}  // namespace clothsim

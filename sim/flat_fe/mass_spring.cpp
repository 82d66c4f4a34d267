#include "sim/flat_fe/mass_spring.hpp"

#include "sim/flat_fe/mass_spring_term.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace clothsim {

namespace {

constexpr double kStandardGravity = 9.80665;  // [m/s²]

// The bending springs' calibration constant: k_b = kBendingCalibration · B Ā_e / (κ_ref² L₀⁶).
// From ½ k_b (κ² L₀³/24)² ⟨cos⁸ψ⟩ = B κ² (Ā_e/3) / 2 with ⟨cos⁸ψ⟩ = 35/128 over the bending
// directions: k_b = 2 · 576 · 128 / (3 · 35) · B Ā_e / (κ² L₀⁶) = 24576/35 · … (docs/mass_spring.md).
constexpr double kBendingCalibration = 24576.0 / 35.0;

}  // namespace

double MassSpringDiscretization::bending_length_curvature(const ShellMaterial& material) {
  if (!(material.areal_density > 0) || !(material.bending_rigidity > 0)) return std::numeric_limits<double>::quiet_NaN();
  return std::cbrt(material.areal_density * kStandardGravity / material.bending_rigidity);
}

MassSpringDiscretization::MassSpringDiscretization(const TriMesh& mesh, const std::vector<BoundaryCondition>& boundary,
                                                   const ShellMaterial& material, double reference_curvature)
    : FlatDiscretization("mass_spring", mesh, boundary, material),
      reference_curvature_(reference_curvature != 0.0 ? reference_curvature : bending_length_curvature(material)) {
  if (!(std::isfinite(reference_curvature_) && reference_curvature_ > 0)) {
    std::ostringstream s;
    s << "mass_spring: the bending springs' reference curvature must be a positive number [1/m] (got "
      << reference_curvature_ << "; by default it is the inverse bending length (rho_A g / B)^(1/3), which needs a "
      << "positive areal density and bending rigidity)";
    throw std::runtime_error(s.str());
  }
  if (material.orthotropic())
    throw std::runtime_error("mass_spring: an orthotropic material cannot be represented by a spring network (its shear "
                             "modulus and Poisson ratio follow from the lattice); use loop_kl or linear_fe");
  const TriMesh& m = this->mesh();
  const double stretch_modulus = material.stretch_modulus;
  std::vector<double> area(m.triangles.size());
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const Triangle& tri = m.triangles[t];
    const Eigen::Vector3d x0 = m.vertices.row(tri[0]), x1 = m.vertices.row(tri[1]), x2 = m.vertices.row(tri[2]);
    area[t] = 0.5 * (x1 - x0).cross(x2 - x0).norm();
  }
  auto check_length = [](const Spring& s, const char* kind) {
    if (!(s.rest_length > 0))
      throw std::runtime_error("mass_spring: the nodes " + std::to_string(s.i) + " and " + std::to_string(s.j) + " of a " +
                               kind + " spring coincide at rest");
  };

  // Stretch springs: k_e = E·t Σ A_T / |e|², summed over the triangles that have the edge.
  std::map<std::pair<int, int>, size_t> edge_index;  // (smaller node, larger node) → spring
  std::vector<double> edge_area;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    const Triangle& tri = m.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int i = tri[static_cast<size_t>(k)], j = tri[static_cast<size_t>((k + 1) % 3)];
      const auto [it, inserted] = edge_index.emplace(std::make_pair(std::min(i, j), std::max(i, j)), stretch_.size());
      if (inserted) {
        Spring s;
        s.i = i;
        s.j = j;
        s.group = static_cast<int>(t);
        s.a = k;
        s.b = (k + 1) % 3;
        s.rest_length = (m.vertices.row(i) - m.vertices.row(j)).norm();
        check_length(s, "stretch");
        stretch_.push_back(s);
        edge_area.push_back(0.0);
      }
      edge_area[it->second] += area[t];
    }
  }
  for (size_t e = 0; e < stretch_.size(); ++e)
    stretch_[e].stiffness = stretch_modulus * edge_area[e] / (stretch_[e].rest_length * stretch_[e].rest_length);

  // Bending springs across every hinge, between its apexes x2 and x3.
  const double kappa2 = reference_curvature_ * reference_curvature_;
  const int nt = m.num_triangles();
  for (size_t h = 0; h < hinges().size(); ++h) {
    const Hinge& hinge = hinges()[h];
    Spring s;
    s.i = hinge.nodes[2];
    s.j = hinge.nodes[3];
    s.group = nt + static_cast<int>(h);
    s.a = 2;
    s.b = 3;
    s.rest_length = (m.vertices.row(s.i) - m.vertices.row(s.j)).norm();
    check_length(s, "bending");
    const double areas = area[static_cast<size_t>(hinge.triangle_a)] + area[static_cast<size_t>(hinge.triangle_b)];
    s.stiffness = kBendingCalibration * material.bending_rigidity * areas / (kappa2 * std::pow(s.rest_length, 6));
    bending_.push_back(s);
  }
}

std::unique_ptr<ForceTerm> MassSpringDiscretization::elastic_term(bool /*corotational*/, bool tension_stiffening) const {
  return std::make_unique<MassSpringElastic>(*this, tension_stiffening);
}

}  // namespace clothsim

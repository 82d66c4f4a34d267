// A seeded geometric imperfection of a rest shape, as post-buckling analyses use: every vertex
// moves along the mesh's vertex normal by a smooth random field w(x) scaled so that the largest
// displacement is exactly the amplitude. The mesh's rest shape changes (the perturbed shape is
// stress-free); nothing else does.
//
// The field is a sum of `kWaves` plane waves in space, w(x) = Σₖ cos(kₖ · x + φₖ), with directions
// uniform on the sphere, phases uniform in [0, 2π) and wavelengths 2π/|kₖ| log-uniform between
// `wavelength_min` and `wavelength_max` [m]. It is a function of position, not of the mesh: two
// meshes of one surface get the same field (up to the normalisation by the largest value on
// their vertices). The random numbers come from std::mt19937_64 seeded with `seed` and are turned
// into doubles by the generator's bits alone (no standard distribution, whose output differs
// between library implementations), so a seed gives the same shape on every platform.
#pragma once

#include "sim/mesh/mesh.hpp"

#include <cstdint>

namespace clothsim {

struct Imperfection {
  double amplitude = 0.0;       // [m] largest normal displacement; 0: none
  std::uint64_t seed = 1;
  // [m] shortest and longest wavelength, both > 0 and min <= max; both 0 (default): the mesh's
  // bounding-box diagonal / 16 and / 2.
  double wavelength_min = 0.0;
  double wavelength_max = 0.0;
};

constexpr int kImperfectionWaves = 32;

// The field's value at every vertex before scaling (for tests), with the wavelengths resolved
// as in apply_imperfection.
Eigen::VectorXd imperfection_field(const Eigen::MatrixX3d& points, const Imperfection& imperfection, double diagonal);

// Moves the mesh's vertices along their area-weighted vertex normals by the scaled field.
// Throws std::invalid_argument for a negative or non-finite amplitude, bad wavelengths
// (not both 0, and not finite with 0 < min <= max), or a vertex without a normal (isolated, or its triangles'
// normals cancel) while the amplitude is not 0. Does nothing for amplitude 0.
void apply_imperfection(TriMesh& mesh, const Imperfection& imperfection);

}  // namespace clothsim

// The corotational stiffness gather's block sums (sim/corotation/assembly_kernels.hpp): the AVX2
// kernel and the portable one against a plain Eigen reference, Σ R K Rᵀ (+ the tension term on
// the diagonal), on random rotations, blocks and tensions.
#include "sim/corotation/assembly_kernels.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace clothsim {
namespace {

using assembly_avx2::kLanes;

struct Layout {
  int groups = 0, points = 0;
  std::vector<int> element, point_offset;
  std::vector<double> rotations, stiffness, rows, tension;
};

// `contributions` element blocks (padded to whole groups with zero blocks of element 0) of
// `elements` elements with `points` quadrature points each.
Layout random_layout(int contributions, int elements, int points, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Layout l;
  l.points = points;
  l.groups = (contributions + kLanes - 1) / kLanes;
  for (int e = 0; e < elements; ++e) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(3.0 * uniform(generator), Eigen::Vector3d(uniform(generator), uniform(generator), 1.0).normalized())
            .toRotationMatrix();
    l.rotations.insert(l.rotations.end(), r.data(), r.data() + 9);
    l.point_offset.push_back(e * points);
    for (int q = 0; q < 3 * points; ++q) l.tension.push_back(500.0 * uniform(generator));
  }
  l.element.assign(static_cast<size_t>(kLanes * l.groups), 0);
  l.stiffness.assign(static_cast<size_t>(9 * kLanes * l.groups), 0.0);
  l.rows.assign(static_cast<size_t>(3 * kLanes * points * l.groups), 0.0);
  std::uniform_int_distribution<int> pick(0, elements - 1);
  for (int k = 0; k < contributions; ++k) {
    const int g = k / kLanes, lane = k % kLanes;
    l.element[static_cast<size_t>(kLanes * g + lane)] = pick(generator);
    for (int c = 0; c < 9; ++c) l.stiffness[static_cast<size_t>(kLanes * (9 * g + c) + lane)] = 1e3 * uniform(generator);
    for (int q = 0; q < points; ++q)
      for (int c = 0; c < 3; ++c) l.rows[static_cast<size_t>(kLanes * (3 * (points * g + q) + c) + lane)] = uniform(generator);
  }
  return l;
}

Eigen::Matrix3d reference(const Layout& l, bool tension) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (int g = 0; g < l.groups; ++g)
    for (int lane = 0; lane < kLanes; ++lane) {
      const int e = l.element[static_cast<size_t>(kLanes * g + lane)];
      const Eigen::Map<const Eigen::Matrix3d> r(l.rotations.data() + 9 * e);
      Eigen::Matrix3d k;
      for (int c = 0; c < 9; ++c) k(c % 3, c / 3) = l.stiffness[static_cast<size_t>(kLanes * (9 * g + c) + lane)];
      sum += r * k * r.transpose();
      if (!tension) continue;
      for (int q = 0; q < l.points; ++q) {
        double geometric = 0.0;
        for (int c = 0; c < 3; ++c)
          geometric += l.rows[static_cast<size_t>(kLanes * (3 * (l.points * g + q) + c) + lane)] *
                       l.tension[static_cast<size_t>(3 * (l.point_offset[static_cast<size_t>(e)] + q) + c)];
        sum.diagonal().array() += geometric;
      }
    }
  return sum;
}

TEST(AssemblyKernels, BlockSumsMatchAPlainReference) {
  for (const bool tension : {false, true})
    for (const int contributions : {1, 3, 4, 7, 13}) {
      const Layout l = random_layout(contributions, 9, 3, 17u + static_cast<unsigned>(contributions));
      const Eigen::Matrix3d expected = reference(l, tension);
      Eigen::Matrix3d portable, vector;
      const double* t = tension ? l.tension.data() : nullptr;
      assembly_avx2::sum_block_portable(l.groups, l.element.data(), l.rotations.data(), l.stiffness.data(), l.rows.data(), t,
                                        l.point_offset.data(), l.points, portable.data());
      EXPECT_LT((portable - expected).norm(), 1e-12 * expected.norm()) << contributions << " contributions, tension " << tension;
      if (!assembly_avx2::supported()) continue;  // the portable kernel is the one in use
      assembly_avx2::sum_block(l.groups, l.element.data(), l.rotations.data(), l.stiffness.data(), l.rows.data(), t,
                               l.point_offset.data(), l.points, vector.data());
      EXPECT_LT((vector - expected).norm(), 1e-12 * expected.norm()) << contributions << " contributions, tension " << tension;
    }
}

}  // namespace
}  // namespace clothsim

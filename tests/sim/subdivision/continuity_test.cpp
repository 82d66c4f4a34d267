// C¹ continuity of the limit surface across element edges near a valence-3..12 vertex, rotation invariance, and the limit masks.
#include "sim/mesh/topology.hpp"
#include "sim/subdivision/loop.hpp"
#include "sim/subdivision/patch.hpp"
#include "tests/support/test_meshes.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace clothsim {
namespace {

// make_fan_disc(valence, 4) lifted to z = 0.3 sin(2x) cos(3y) + 0.2 x y, then every coordinate of
// every vertex perturbed by a seeded uniform ±0.02, so the normals vary from element to element.
TriMesh curved_fan_disc(int valence) {
  TriMesh m = testing::make_fan_disc(valence, 4);
  std::mt19937 rng(1234u + static_cast<unsigned>(valence));
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  for (Eigen::Index i = 0; i < m.vertices.rows(); ++i) {
    const double x = m.vertices(i, 0), y = m.vertices(i, 1);
    m.vertices(i, 2) = 0.3 * std::sin(2 * x) * std::cos(3 * y) + 0.2 * x * y;
    for (int c = 0; c < 3; ++c) m.vertices(i, c) += jitter(rng);
  }
  return m;
}

struct Sample {
  Eigen::Vector3d position, normal;
};

// Limit position Σ N_i X_i and unit normal a1 × a2 / |a1 × a2| of element `tri` at (v, w).
Sample sample(const Topology& top, const Eigen::MatrixX3d& x, const Triangle& tri, double v, double w) {
  const PatchEvaluation e = evaluate_patch(top, tri, v, w);
  Eigen::Vector3d p = Eigen::Vector3d::Zero(), a1 = Eigen::Vector3d::Zero(), a2 = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < e.vertices.size(); ++k) {
    const Eigen::Index col = static_cast<Eigen::Index>(k);
    const Eigen::Vector3d xk = x.row(e.vertices[k]).transpose();
    p += e.basis(kValue, col) * xk;
    a1 += e.basis(kDv, col) * xk;
    a2 += e.basis(kDw, col) * xk;
  }
  return {p, a1.cross(a2).normalized()};
}

bool all_interior(const Topology& top, const Triangle& t) {
  return !top.is_boundary(t[0]) && !top.is_boundary(t[1]) && !top.is_boundary(t[2]);
}

std::string name(const Triangle& t) {
  std::string out = "(";
  for (int k = 0; k < 3; ++k) {
    out += std::to_string(t[k]);
    out += k < 2 ? ", " : ")";
  }
  return out;
}

class LimitSurfaceContinuity : public ::testing::TestWithParam<int> {};

TEST_P(LimitSurfaceContinuity, PositionAndNormalAgreeAcrossEveryInteriorEdge) {
  const int valence = GetParam();
  const TriMesh disc = curved_fan_disc(valence);
  const Topology top(disc.num_vertices(), disc.triangles);
  ASSERT_EQ(top.valence(0), valence);
  ASSERT_FALSE(top.is_boundary(0));

  int edges = 0, edges_at_centre = 0;
  double normal_spread = 0;  // the normals do vary: largest distance from the first one sampled
  Eigen::Vector3d first_normal = Eigen::Vector3d::Zero();
  for (const Triangle& t : disc.triangles)
    for (int k = 0; k < 3; ++k) {
      const int x = t[k], y = t[(k + 1) % 3], p = t[(k + 2) % 3];
      if (x > y) continue;  // each undirected edge once (its twin has x > y)
      const int q = top.opposite(y, x);
      if (q < 0) continue;
      const Triangle first{x, y, p}, second{y, x, q};
      if (!all_interior(top, first) || !all_interior(top, second)) continue;
      ++edges;
      if (x == 0 || y == 0) ++edges_at_centre;
      for (double s : {0.1, 0.3, 0.5, 0.7, 0.9}) {
        // The point (1 − s) x + s y from both sides of the edge.
        const Sample a = sample(top, disc.vertices, first, s, 0.0);
        const Sample b = sample(top, disc.vertices, second, 1.0 - s, 0.0);
        if (edges == 1 && s == 0.1) first_normal = a.normal;
        normal_spread = std::max(normal_spread, (a.normal - first_normal).norm());
        EXPECT_LT((a.position - b.position).norm(), 1e-10) << name(first) << " | " << name(second) << " at " << s;
        EXPECT_LT((a.normal - b.normal).norm(), 1e-8) << name(first) << " | " << name(second) << " at " << s;
        // The same point with the vertices of each triangle rotated: (y, p, x) at (0, 1 − s),
        // (p, x, y) at (1 − s, s); (x, q, y) at (0, s), (q, y, x) at (s, 1 − s).
        const Sample rotated[4] = {sample(top, disc.vertices, {y, p, x}, 0.0, 1.0 - s),
                                   sample(top, disc.vertices, {p, x, y}, 1.0 - s, s),
                                   sample(top, disc.vertices, {x, q, y}, 0.0, s),
                                   sample(top, disc.vertices, {q, y, x}, s, 1.0 - s)};
        for (int r = 0; r < 4; ++r) {
          EXPECT_LT((a.position - rotated[r].position).norm(), 1e-10) << name(first) << " rotation " << r << " at " << s;
          EXPECT_LT((a.normal - rotated[r].normal).norm(), 1e-8) << name(first) << " rotation " << r << " at " << s;
        }
      }
    }
  // Every spoke edge at the centre is tested, and the interior of the disc has many more edges.
  EXPECT_EQ(edges_at_centre, valence);
  EXPECT_GT(edges, 3 * valence);
  EXPECT_GT(normal_spread, 0.3);  // observed 0.75 .. 1.07
}

TEST_P(LimitSurfaceContinuity, EvaluationNearAVertexApproachesTheLimitPositionMask) {
  const int valence = GetParam();
  const TriMesh disc = curved_fan_disc(valence);
  const Topology top(disc.num_vertices(), disc.triangles);
  auto limit_point = [&](int a) {
    const int n = top.valence(a);
    const double omega = limit_neighbour_weight(n);
    Eigen::Vector3d p = (1.0 - n * omega) * disc.vertices.row(a).transpose();
    for (int r : top.ring(a)) p += omega * disc.vertices.row(r).transpose();
    return p;
  };
  int checked = 0;
  for (const Triangle& t : disc.triangles) {
    if (!all_interior(top, t)) continue;
    for (int k = 0; k < 3; ++k) {
      const Triangle rotated{t[k], t[(k + 1) % 3], t[(k + 2) % 3]};
      const int a = rotated[0];
      const Eigen::Vector3d expect = limit_point(a);
      if (top.valence(a) == 6) {
        // A regular corner: the evaluation at the vertex itself is allowed and exact, and
        // (1e-9, 1e-9) is within |a1 + a2|·1e-9 of it.
        EXPECT_LT((sample(top, disc.vertices, rotated, 0.0, 0.0).position - expect).norm(), 1e-12) << name(rotated);
        EXPECT_LT((sample(top, disc.vertices, rotated, 1e-9, 1e-9).position - expect).norm(), 1e-8) << name(rotated);
      } else {
        // The irregular vertex itself cannot be evaluated; near it the surface converges like
        // λ^k, λ = 3/8 + cos(2π/N)/4 the subdominant eigenvalue, with 2^-k ≈ 1e-9.
        // Observed: up to 7e-8 (N = 12).
        EXPECT_LT((sample(top, disc.vertices, rotated, 1e-9, 1e-9).position - expect).norm(), 1e-6) << name(rotated);
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 3 * valence);
}

TEST_P(LimitSurfaceContinuity, TangentMasksGiveTheLimitNormalAtTheIrregularVertex) {
  const int valence = GetParam();
  const TriMesh disc = curved_fan_disc(valence);
  const Topology top(disc.num_vertices(), disc.triangles);
  const std::vector<int>& ring = top.ring(0);
  const std::vector<double> m1 = limit_tangent_mask(valence, 0), m2 = limit_tangent_mask(valence, 1);
  Eigen::Vector3d t1 = Eigen::Vector3d::Zero(), t2 = Eigen::Vector3d::Zero();
  for (int i = 0; i < valence; ++i) {
    t1 += m1[i] * disc.vertices.row(ring[i]).transpose();
    t2 += m2[i] * disc.vertices.row(ring[i]).transpose();
  }
  const Eigen::Vector3d limit_normal = t1.cross(t2).normalized();
  // Every element at the centre, approached along its bisector (v = w = d). The normal converges
  // geometrically, by λ₂/λ₁ per halving of d (λ_j = 3/8 + cos(2πj/N)/4; 0.845 for N = 12), while
  // roundoff in the 2^k-scaled derivatives grows like eps/λ₁^k (λ₁ = 1/4 for N = 3, where the
  // tangents vanish like d). So the best of a few distances is compared. Observed best errors:
  // ≲ 1e-8 for N ≤ 7, ~1e-6 for N = 9, ~1e-5 for N = 11, 12; at the worst distance up to 0.4.
  for (int i = 0; i < valence; ++i) {
    const Triangle tri{0, ring[i], ring[(i + 1) % valence]};
    double best = std::numeric_limits<double>::infinity();
    for (double d : {1e-5, 1e-7, 1e-9, 1e-11, 1e-13})
      best = std::min(best, (sample(top, disc.vertices, tri, d, d).normal - limit_normal).norm());
    EXPECT_LT(best, 1e-4) << "element " << name(tri);
  }
  // The limit normal is not trivially close to the element normals away from the centre.
  EXPECT_GT((sample(top, disc.vertices, {0, ring[0], ring[1]}, 0.5, 0.5).normal - limit_normal).norm(), 1e-3);
}

INSTANTIATE_TEST_SUITE_P(Valences, LimitSurfaceContinuity, ::testing::Values(3, 4, 5, 6, 7, 8, 9, 10, 11, 12));

}  // namespace
}  // namespace clothsim

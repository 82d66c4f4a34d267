// The refinement operator (k Loop steps + limit masks, composed into sparse matrices) against
// direct evaluation of the element basis (patch.hpp) and the limit masks, on a curved mesh with
// an irregular vertex and borders (ghost layer).
#include "sim/shell/ghost_layer.hpp"
#include "sim/subdivision/limit_refinement.hpp"
#include "sim/subdivision/loop.hpp"
#include "sim/subdivision/patch.hpp"
#include "tests/support/test_meshes.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <utility>

namespace clothsim {
namespace {

ExtendedMesh curved_disc(int valence) {
  TriMesh disc = testing::make_fan_disc(valence, 4);
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> noise(-0.02, 0.02);
  for (int v = 0; v < disc.num_vertices(); ++v) {
    const double x = disc.vertices(v, 0), y = disc.vertices(v, 1);
    disc.vertices(v, 2) = 0.3 * std::sin(2 * x) * std::cos(3 * y) + 0.2 * x * y + noise(rng);
  }
  return build_ghost_layer(disc);
}

// Position and unit normal of element `tri` at (v, w) by direct evaluation.
void direct(const ExtendedMesh& ext, const Triangle& tri, double v, double w, Eigen::Vector3d& p, Eigen::Vector3d& n) {
  const PatchEvaluation e = evaluate_patch(ext.topology, tri, v, w);
  p.setZero();
  Eigen::Vector3d a1 = Eigen::Vector3d::Zero(), a2 = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < e.vertices.size(); ++k) {
    const Eigen::Vector3d x = ext.rest.row(e.vertices[k]);
    p += e.basis(kValue, static_cast<Eigen::Index>(k)) * x;
    a1 += e.basis(kDv, static_cast<Eigen::Index>(k)) * x;
    a2 += e.basis(kDw, static_cast<Eigen::Index>(k)) * x;
  }
  n = a1.cross(a2).normalized();
}

class LimitRefinementTest : public ::testing::TestWithParam<int> {};

TEST_P(LimitRefinementTest, MatchesDirectEvaluationInsideEveryElement) {
  const ExtendedMesh ext = curved_disc(GetParam());
  for (int levels : {1, 2, 3}) {
    const LimitRefinement r = build_limit_refinement(ext.rest, ext.triangles, ext.num_real_triangles, levels);
    ASSERT_EQ(r.triangles.size(), static_cast<size_t>(ext.num_real_triangles) << (2 * levels));
    Eigen::MatrixX3d p, n;
    evaluate_limit(r, ext.rest, p, n);
    // The middle of the middle sub-triangle: fine triangle index t·4^k + (4^k − 1) has its
    // vertices at known parameters for k = 1 and 2.
    const std::size_t per = std::size_t{1} << (2 * levels);
    double worst_p = 0, worst_n = 0;
    for (int t = 0; t < ext.num_real_triangles; ++t) {
      const Triangle& fine = r.triangles[t * per + per - 1];
      const std::array<std::array<double, 2>, 3> params =
          levels == 1 ? std::array<std::array<double, 2>, 3>{{{0.5, 0.0}, {0.5, 0.5}, {0.0, 0.5}}}
          : levels == 2 ? std::array<std::array<double, 2>, 3>{{{0.5, 0.25}, {0.25, 0.5}, {0.25, 0.25}}}
                        : std::array<std::array<double, 2>, 3>{{{0.375, 0.375}, {0.25, 0.375}, {0.375, 0.25}}};
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d dp, dn;
        direct(ext, ext.triangles[t], params[k][0], params[k][1], dp, dn);
        worst_p = std::max(worst_p, (p.row(fine[k]).transpose() - dp).norm());
        worst_n = std::max(worst_n, (n.row(fine[k]).transpose() - dn).norm());
      }
    }
    EXPECT_LT(worst_p, 1e-12) << "levels " << levels;
    EXPECT_LT(worst_n, 1e-10) << "levels " << levels;
  }
}

TEST_P(LimitRefinementTest, ControlVerticesGoToTheirLimitPoints) {
  const ExtendedMesh ext = curved_disc(GetParam());
  for (int levels : {0, 2}) {
    const LimitRefinement r = build_limit_refinement(ext.rest, ext.triangles, ext.num_real_triangles, levels);
    Eigen::MatrixX3d p, n;
    evaluate_limit(r, ext.rest, p, n);
    // Fine triangle t·4^k (the corner child chain) starts at the control vertex tri[0].
    const std::size_t per = std::size_t{1} << (2 * levels);
    for (int t = 0; t < ext.num_real_triangles; ++t) {
      const int v = ext.triangles[t][0];
      const std::vector<int>& ring = ext.topology.ring(v);
      const int valence = static_cast<int>(ring.size());
      const double w = limit_neighbour_weight(valence);
      Eigen::RowVector3d expect = (1 - valence * w) * ext.rest.row(v);
      for (int q : ring) expect += w * ext.rest.row(q);
      EXPECT_LT((p.row(r.triangles[t * per][0]) - expect).norm(), 1e-12) << "triangle " << t << " levels " << levels;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Valences, LimitRefinementTest, ::testing::Values(3, 5, 6, 8, 12));

}  // namespace
}  // namespace clothsim

namespace clothsim {
namespace {

// refine_corner_uv (sim/subdivision/loop.hpp): the texture coordinates of the refined surface's
// triangles, as the OBJ frames write them.
TEST(RefineCornerUv, SplitsLikeTheSubdivisionAndKeepsAreaAndSharedPoints) {
  const std::vector<std::array<Eigen::Vector2d, 3>> uv = {
      {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.3, 0), Eigen::Vector2d(0, 0.2)},
      {Eigen::Vector2d(0.3, 0), Eigen::Vector2d(0.3, 0.2), Eigen::Vector2d(0, 0.2)}};
  const auto area = [](const std::array<Eigen::Vector2d, 3>& t) {
    const Eigen::Vector2d e1 = t[1] - t[0], e2 = t[2] - t[0];
    return 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
  };
  for (int levels = 0; levels <= 3; ++levels) {
    const auto fine = refine_corner_uv(uv, levels);
    ASSERT_EQ(fine.size(), uv.size() << (2 * levels));
    double total = 0;
    for (const auto& t : fine) {
      EXPECT_GT(area(t), 0.0);  // orientation kept
      total += area(t);
    }
    EXPECT_NEAR(total, 0.06, 1e-15);
  }
  // One split: corner a, corner b, corner c, middle, as loop_subdivision_step orders them.
  const auto one = refine_corner_uv(uv, 1);
  EXPECT_EQ(one[0][0], uv[0][0]);
  EXPECT_EQ(one[1][0], uv[0][1]);
  EXPECT_EQ(one[2][0], uv[0][2]);
  EXPECT_EQ(one[3][0], Eigen::Vector2d(0.15, 0));
  // The two triangles share the edge (0.3, 0)–(0, 0.2): its midpoint is the same double in both.
  const auto two = refine_corner_uv(uv, 2);
  std::set<std::pair<double, double>> first, second;
  for (std::size_t i = 0; i < 16; ++i)
    for (const auto& p : two[i]) first.insert({p.x(), p.y()});
  for (std::size_t i = 16; i < 32; ++i)
    for (const auto& p : two[i]) second.insert({p.x(), p.y()});
  int shared = 0;
  for (const auto& p : first) shared += static_cast<int>(second.count(p));
  EXPECT_EQ(shared, 5);  // the 5 points of a twice-split edge
}

}  // namespace
}  // namespace clothsim

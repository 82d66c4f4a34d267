// The impact zones' parts, built directly: the union–find that merges nodes into zones and the
// rigid fit each zone moves with.
#include "sim/contact/impact_zones.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <vector>

namespace clothsim::contact {
namespace {

TEST(ImpactZones, UnionFindMergesChainsIntoTheirSmallestNode) {
  Zones z(6);
  z.unite(4, 2);
  z.unite(2, 5);
  z.unite(0, 1);
  EXPECT_EQ(z.find(5), 2);
  EXPECT_EQ(z.find(4), 2);
  EXPECT_EQ(z.find(1), 0);
  EXPECT_EQ(z.find(3), 3);  // alone
  z.unite(5, 1);            // joins the two zones
  for (int i : {0, 1, 2, 4, 5}) EXPECT_EQ(z.find(i), 0) << i;
  EXPECT_EQ(z.find(3), 3);
}

std::vector<Eigen::Vector3d> cloud() {
  return {{0.1, 0.0, 0.0}, {0.0, 0.2, 0.0}, {0.0, 0.0, 0.3}, {0.2, -0.1, 0.05}, {-0.1, 0.1, 0.1}};
}

TEST(ImpactZones, RigidFitRecoversARotationAndTranslation) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d c(0.5, -0.25, 2.0);
  const std::vector<Eigen::Vector3d> from = cloud();
  std::vector<Eigen::Vector3d> to;
  for (const Eigen::Vector3d& p : from) to.push_back(r * p + c);
  const RigidMap m = fit_rigid(from, to);
  EXPECT_LT((m.r - r).norm(), 1e-12);
  EXPECT_LT((m.c - c).norm(), 1e-12);
  for (size_t i = 0; i < from.size(); ++i) EXPECT_LT((m(from[i]) - to[i]).norm(), 1e-12);
}

TEST(ImpactZones, RigidFitOfAMirrorImageIsStillARotation) {
  // A reflection cannot be followed by a rigid motion: the fit stays proper (det R = +1).
  const std::vector<Eigen::Vector3d> from = cloud();
  std::vector<Eigen::Vector3d> to;
  for (const Eigen::Vector3d& p : from) to.emplace_back(-p.x(), p.y(), p.z());
  const RigidMap m = fit_rigid(from, to);
  EXPECT_NEAR(m.r.determinant(), 1.0, 1e-12);
  EXPECT_LT((m.r * m.r.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(ImpactZones, RigidFitOfFewerThanThreePointsIsTheMeanTranslation) {
  const std::vector<Eigen::Vector3d> from = {{0, 0, 0}, {1, 0, 0}};
  const std::vector<Eigen::Vector3d> to = {{0, 1, 0}, {1, 3, 0}};
  const RigidMap m = fit_rigid(from, to);
  EXPECT_EQ(m.r, Eigen::Matrix3d::Identity());
  EXPECT_LT((m.c - Eigen::Vector3d(0, 2, 0)).norm(), 1e-15);
  EXPECT_EQ(fit_rigid({}, {}).c, Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace clothsim::contact

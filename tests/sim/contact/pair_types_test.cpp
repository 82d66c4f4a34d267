// Distance bounds over a list of candidate pairs (sim/contact/pair_types.hpp), built directly.
#include "sim/contact/pair_types.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace clothsim::contact {
namespace {

TEST(DistanceBounds, CloseListHoldsTheBoundsBelowTheReachInOrder) {
  Bounds b;
  b.lower = {0.5, 3.0, 0.0, 1.2, 2.0};
  b.make_close(1.25);
  EXPECT_EQ(b.close, (std::vector<size_t>{0, 2, 3}));
  EXPECT_EQ(b.reach, 1.25);
  b.make_close(0.0);  // nothing is below zero
  EXPECT_TRUE(b.close.empty());
}

TEST(DistanceBounds, MotionLowersEveryBoundButNotBelowZero) {
  Bounds b;
  b.lower = {0.5, 3.0, 0.0};
  EXPECT_EQ(b.less(1.0), (std::vector<double>{0.0, 2.0, 0.0}));
  EXPECT_EQ(b.less(0.0), b.lower);
}

}  // namespace
}  // namespace clothsim::contact

// Distance bounds over a list of candidate pairs (sim/contact/pair_types.hpp), built directly.
#include "sim/contact/pair_types.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace clothsim::contact {
namespace {

TEST(DistanceBounds, CloseListsHoldTheBoundsBelowTheirReachesInOrder) {
  Bounds b;
  b.lower = {0.5, 3.0, 0.0, 1.2, 2.0};
  b.make_close({1.25, 0.1, 2.5});
  ASSERT_EQ(b.lists.size(), 3u);
  EXPECT_EQ(b.lists[0].reach, 0.1);  // (by increasing reach)
  EXPECT_EQ(b.lists[0].index, (std::vector<size_t>{2}));
  EXPECT_EQ(b.lists[1].index, (std::vector<size_t>{0, 2, 3}));
  EXPECT_EQ(b.lists[2].index, (std::vector<size_t>{0, 2, 3, 4}));
  b.make_close({0.0});  // nothing is below zero
  EXPECT_TRUE(b.lists[0].index.empty());
}

TEST(DistanceBounds, WithinPicksTheShortestListThatHoldsEveryPairThatCanComeBelowTheThreshold) {
  Bounds b;
  b.lower = {0.5, 3.0, 0.0, 1.2, 2.0};
  b.make_close({0.15, 1.05, 1.25});
  // Pairs below 0.1 after moves of 0.01: bounds below 0.11, so the 0.15 list.
  ASSERT_NE(b.within(0.1, 0.01), nullptr);
  EXPECT_EQ(*b.within(0.1, 0.01), (std::vector<size_t>{2}));
  // Below 1.0 after moves of 0.1: bounds below 1.1, so the 1.25 list (1.05 − 0.1 < 1.0).
  EXPECT_EQ(*b.within(1.0, 0.1), (std::vector<size_t>{0, 2, 3}));
  EXPECT_EQ(b.within(1.0, 0.1), &b.lists[2].index);
  // Moves larger than every list allows: all candidates.
  EXPECT_EQ(b.within(1.0, 0.5), nullptr);
  // Every candidate that a list leaves out stays above the threshold.
  for (double threshold : {0.05, 0.1, 0.9, 1.0}) {
    for (double motion : {0.0, 0.01, 0.04, 0.2}) {
      const std::vector<size_t>* list = b.within(threshold, motion);
      if (list == nullptr) continue;
      for (size_t i = 0; i < b.lower.size(); ++i) {
        if (std::find(list->begin(), list->end(), i) == list->end()) {
          EXPECT_GE(b.lower[i] - motion, threshold);
        }
      }
    }
  }
}

TEST(DistanceBounds, MotionLowersEveryBoundButNotBelowZero) {
  Bounds b;
  b.lower = {0.5, 3.0, 0.0};
  EXPECT_EQ(b.less(1.0), (std::vector<double>{0.0, 2.0, 0.0}));
  EXPECT_EQ(b.less(0.0), b.lower);
}

}  // namespace
}  // namespace clothsim::contact

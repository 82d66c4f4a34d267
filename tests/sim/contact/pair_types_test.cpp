// Distance bounds over a list of candidate pairs (sim/contact/pair_types.hpp), built directly.
#include "sim/contact/pair_types.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace clothsim::contact {
namespace {

// The candidates of a list, sorted (a list's order is by level).
std::vector<size_t> sorted(const Bounds::List& list) {
  std::vector<size_t> out(list.index, list.index + list.size);
  std::sort(out.begin(), out.end());
  return out;
}

TEST(DistanceBounds, CloseListsHoldTheBoundsBelowTheirReaches) {
  Bounds b;
  b.lower = {0.5, 3.0, 0.0, 1.2, 2.0};
  b.make_close({1.25, 0.1, 2.5});
  ASSERT_EQ(b.reaches, (std::vector<double>{0.1, 1.25, 2.5}));  // (by increasing reach)
  ASSERT_EQ(b.ends, (std::vector<size_t>{1, 3, 4}));
  EXPECT_EQ(sorted(b.within(0.1, 0.0)), (std::vector<size_t>{2}));
  EXPECT_EQ(sorted(b.within(1.25, 0.0)), (std::vector<size_t>{0, 2, 3}));
  EXPECT_EQ(sorted(b.within(2.5, 0.0)), (std::vector<size_t>{0, 2, 3, 4}));
  // Each level in increasing order: below 0.1, then [0.1, 1.25), then [1.25, 2.5).
  EXPECT_EQ(b.close, (std::vector<size_t>{2, 0, 3, 4}));
  b.make_close({0.0});  // nothing is below zero: an empty list, not all
  EXPECT_EQ(b.within(0.0, 0.0).size, 0u);
  EXPECT_FALSE(b.within(0.0, 0.0).all);
  Bounds none;  // no candidates at all
  none.make_close({1.0});
  EXPECT_FALSE(none.within(0.5, 0.0).all);
  EXPECT_EQ(none.within(0.5, 0.0).size, 0u);
}

TEST(DistanceBounds, WithinPicksTheShortestListThatHoldsEveryPairThatCanComeBelowTheThreshold) {
  Bounds b;
  b.lower = {0.5, 3.0, 0.0, 1.2, 2.0};
  b.make_close({0.15, 1.05, 1.25});
  // Pairs below 0.1 after moves of 0.01: bounds below 0.11, so the 0.15 list.
  EXPECT_EQ(b.within(0.1, 0.01).size, 1u);
  // Below 1.0 after moves of 0.1: bounds below 1.1, so the 1.25 list (1.05 − 0.1 < 1.0).
  EXPECT_EQ(b.within(1.0, 0.1).size, 3u);
  EXPECT_EQ(sorted(b.within(1.0, 0.1)), (std::vector<size_t>{0, 2, 3}));
  // Moves larger than every list allows: all candidates.
  EXPECT_TRUE(b.within(1.0, 0.5).all);
  // Every candidate that a list leaves out stays above the threshold.
  for (double threshold : {0.05, 0.1, 0.9, 1.0}) {
    for (double motion : {0.0, 0.01, 0.04, 0.2}) {
      const std::vector<size_t> list = sorted(b.within(threshold, motion));
      if (b.within(threshold, motion).all) continue;
      for (size_t i = 0; i < b.lower.size(); ++i) {
        if (!std::binary_search(list.begin(), list.end(), i)) {
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

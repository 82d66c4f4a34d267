// BroadPhase: exact agreement with brute-force double-precision overlap tests on random and
// hand-made boxes (touching faces, sub-float gaps near 1e3, degenerate, far away, infinite),
// the refit path, determinism, and a 20k-box set checked against sweep and prune.
#include "sim/contact/broad_phase.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

namespace clothsim {
namespace {

using contact::Box;
using contact::BroadPhase;
using Pairs = std::vector<std::pair<int, int>>;

constexpr double kInf = std::numeric_limits<double>::infinity();

Box make_box(double x0, double y0, double z0, double x1, double y1, double z1) {
  return Box{Eigen::Vector3d(x0, y0, z0), Eigen::Vector3d(x1, y1, z1)};
}

// Closed boxes; written independently of the implementation.
bool boxes_overlap(const Box& a, const Box& b) {
  for (int k = 0; k < 3; ++k)
    if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
  return true;
}

Pairs brute_self(const std::vector<Box>& boxes) {
  Pairs out;
  for (int i = 0; i < static_cast<int>(boxes.size()); ++i)
    for (int j = i + 1; j < static_cast<int>(boxes.size()); ++j)
      if (boxes_overlap(boxes[i], boxes[j])) out.emplace_back(i, j);
  return out;  // already sorted
}

Pairs brute_pairs(const std::vector<Box>& a, const std::vector<Box>& b) {
  Pairs out;
  for (int i = 0; i < static_cast<int>(a.size()); ++i)
    for (int j = 0; j < static_cast<int>(b.size()); ++j)
      if (boxes_overlap(a[i], b[j])) out.emplace_back(i, j);
  return out;
}

// Sweep and prune on x, for sets too large for O(n²).
Pairs sweep_self(const std::vector<Box>& boxes) {
  std::vector<int> order(boxes.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int p, int q) { return boxes[p].lo.x() < boxes[q].lo.x(); });
  Pairs out;
  for (std::size_t s = 0; s < order.size(); ++s) {
    const Box& a = boxes[order[s]];
    for (std::size_t t = s + 1; t < order.size() && boxes[order[t]].lo.x() <= a.hi.x(); ++t) {
      if (boxes_overlap(a, boxes[order[t]]))
        out.emplace_back(std::min(order[s], order[t]), std::max(order[s], order[t]));
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

Pairs sorted(Pairs p) {
  std::sort(p.begin(), p.end());
  return p;
}

double uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

double log_uniform(std::mt19937& rng, double lo, double hi) {
  return std::exp(uniform(rng, std::log(lo), std::log(hi)));
}

// A box placed in one of several clusters: near the origin, around 1e3 (where float spacing is
// 6e-5 and sub-float gaps matter), around 1e7 (float spacing 1, larger than many boxes) and
// around -3e12. Sizes are log-uniform relative to the cluster.
Box cluster_box(std::mt19937& rng) {
  struct Cluster {
    double origin, side;
  };
  static const Cluster clusters[] = {{0.0, 2.0}, {1e3, 10.0}, {1e3, 10.0}, {1e7, 20.0}, {-3e12, 1e6}};
  const Cluster& c = clusters[std::uniform_int_distribution<int>(0, 4)(rng)];
  Box b;
  for (int k = 0; k < 3; ++k) {
    const double ext = c.side * log_uniform(rng, 0.003, 0.1);
    b.lo[k] = c.origin + uniform(rng, 0.0, c.side);
    b.hi[k] = b.lo[k] + ext;
  }
  return b;
}

// Mixed random boxes: clustered boxes, degenerate ones, ones that touch a previous box exactly,
// miss it by one double ulp or overlap it by one double ulp (on one to three axes), and a few
// beyond Embree's float range or with infinite coordinates.
std::vector<Box> mixed_boxes(unsigned seed, int n) {
  std::mt19937 rng(seed);
  std::vector<Box> boxes;
  boxes.reserve(n);
  for (int i = 0; i < n; ++i) {
    const int category = std::uniform_int_distribution<int>(0, 99)(rng);
    Box b = cluster_box(rng);
    if (category < 15) {  // degenerate: zero extent on one to three axes
      bool any = false;
      for (int k = 0; k < 3; ++k) {
        if (rng() % 2 == 0 || (k == 2 && !any)) {
          b.hi[k] = b.lo[k];
          any = true;
        }
      }
    } else if (category < 45 && i > 0) {  // derived from a previous box
      const Box& p = boxes[std::uniform_int_distribution<int>(0, i - 1)(rng)];
      b = p;
      bool any = false;
      for (int k = 0; k < 3; ++k) {
        if (rng() % 2 != 0 && !(k == 2 && !any)) continue;
        any = true;
        const double ext = (rng() % 4 == 0) ? 0.0 : (p.hi[k] - p.lo[k]) * uniform(rng, 0.1, 2.0);
        const int mode = static_cast<int>(rng() % 3);  // 0: touch, 1: one ulp apart, 2: one ulp in
        if (rng() % 2 == 0) {                          // beyond p.hi
          double lo = p.hi[k];
          if (mode == 1) lo = std::nextafter(lo, kInf);
          if (mode == 2) lo = std::nextafter(lo, -kInf);
          b.lo[k] = lo;
          b.hi[k] = std::max(lo, lo + ext);
        } else {  // below p.lo
          double hi = p.lo[k];
          if (mode == 1) hi = std::nextafter(hi, -kInf);
          if (mode == 2) hi = std::nextafter(hi, kInf);
          b.hi[k] = hi;
          b.lo[k] = std::min(hi, hi - ext);
        }
      }
    } else if (category == 98) {  // beyond Embree's float range (|x| > 1.8e18)
      const double o = (rng() % 2 == 0 ? 1.0 : -1.0) * log_uniform(rng, 1e19, 1e30);
      for (int k = 0; k < 3; ++k) {
        b.lo[k] = o + uniform(rng, 0.0, 1e-3 * std::abs(o));
        b.hi[k] = b.lo[k] + uniform(rng, 0.0, 1e-3 * std::abs(o));
      }
    } else if (category == 99) {  // an infinite coordinate
      const int k = static_cast<int>(rng() % 3);
      if (rng() % 2 == 0)
        b.lo[k] = -kInf;
      else
        b.hi[k] = kInf;
    }
    boxes.push_back(b);
  }
  return boxes;
}

// Small boxes in the unit cube (like the triangles of a fine cloth).
std::vector<Box> small_boxes(unsigned seed, int n, double min_size, double max_size) {
  std::mt19937 rng(seed);
  std::vector<Box> boxes(n);
  for (Box& b : boxes) {
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = uniform(rng, 0.0, 1.0);
      b.hi[k] = b.lo[k] + uniform(rng, min_size, max_size);
    }
  }
  return boxes;
}

TEST(BroadPhase, SelfPairsMatchBruteForceOnMixedBoxes) {
  BroadPhase bp;
  for (int n : {0, 1, 2, 50, 2000}) {
    const unsigned num_seeds = n <= 50 ? 20u : 3u;  // small sets: many draws, some overlapping
    for (unsigned seed = 1; seed <= num_seeds; ++seed) {
      const std::vector<Box> boxes = mixed_boxes(seed * 7919u + static_cast<unsigned>(n), n);
      const Pairs expected = brute_self(boxes);
      EXPECT_EQ(sorted(bp.self_pairs(boxes)), expected) << "n = " << n << ", seed = " << seed;
      if (n == 2000) {
        EXPECT_GT(expected.size(), 200u);  // the sets are not trivially sparse
      }
    }
  }
}

TEST(BroadPhase, OutputIsSortedUniqueAndOrdered) {
  BroadPhase bp;
  const std::vector<Box> boxes = mixed_boxes(11, 2000);
  const Pairs got = bp.self_pairs(boxes);
  EXPECT_TRUE(std::is_sorted(got.begin(), got.end()));
  EXPECT_TRUE(std::adjacent_find(got.begin(), got.end()) == got.end());
  for (const auto& [i, j] : got) EXPECT_LT(i, j);
}

TEST(BroadPhase, SubFloatGapsNearOneThousand) {
  // Boxes that touch at x = 1000, or miss / overlap by one double ulp there; float cannot
  // resolve these (its spacing near 1e3 is 6e-5).
  const double x = 1000.0;
  const double up = std::nextafter(x, 2000.0);
  const double down = std::nextafter(x, 0.0);
  BroadPhase bp;
  const Box a = make_box(999.0, 0.0, 0.0, x, 1.0, 1.0);
  EXPECT_TRUE(bp.self_pairs({a, make_box(up, 0.0, 0.0, 1001.0, 1.0, 1.0)}).empty());
  EXPECT_EQ(bp.self_pairs({a, make_box(x, 0.0, 0.0, 1001.0, 1.0, 1.0)}), (Pairs{{0, 1}}));
  EXPECT_EQ(bp.self_pairs({a, make_box(down, 0.0, 0.0, 1001.0, 1.0, 1.0)}), (Pairs{{0, 1}}));
  // A coordinate that is not a float: 1000.00001 lies between two floats.
  const double y = 1000.00001;
  const Box c = make_box(999.0, 0.0, 0.0, y, 1.0, 1.0);
  EXPECT_TRUE(bp.self_pairs({c, make_box(std::nextafter(y, 2000.0), 0, 0, 1001, 1, 1)}).empty());
  EXPECT_EQ(bp.self_pairs({c, make_box(y, 0.0, 0.0, 1001.0, 1.0, 1.0)}), (Pairs{{0, 1}}));
  // The same through pairs(a, b), with the touching box on either side of a.
  const std::vector<Box> left = {a, c};
  const std::vector<Box> right = {make_box(up, 0, 0, 1001, 1, 1), make_box(x, 0, 0, 1001, 1, 1),
                                  make_box(y, 0, 0, 1001, 1, 1),
                                  make_box(std::nextafter(y, 2000.0), 0, 0, 1001, 1, 1)};
  // c (hi.x = y) reaches right[0] (lo.x = 1000 + 1 ulp) but not right[3].
  EXPECT_EQ(bp.pairs(left, right), (Pairs{{0, 1}, {1, 0}, {1, 1}, {1, 2}}));
  EXPECT_EQ(bp.pairs(left, right), brute_pairs(left, right));
  // The gap on the lower side of the box.
  const Box d = make_box(x, 0.0, 0.0, 1001.0, 1.0, 1.0);
  EXPECT_TRUE(bp.self_pairs({d, make_box(999.0, 0.0, 0.0, down, 1.0, 1.0)}).empty());
}

TEST(BroadPhase, TouchingFacesEdgesCornersAndPoints) {
  BroadPhase bp;
  const std::vector<Box> boxes = {
      make_box(0, 0, 0, 1, 1, 1),          // 0
      make_box(1, 0, 0, 2, 1, 1),          // 1: shares the face x = 1 with 0
      make_box(1, 1, 0, 2, 2, 1),          // 2: shares an edge with 0, a face with 1
      make_box(1, 1, 1, 2, 2, 2),          // 3: shares a corner with 0, an edge with 1
      make_box(0.5, 0.5, 0.5, 0.5, 0.5, 0.5),  // 4: a point inside 0
      make_box(0.5, 0.5, 0.5, 0.5, 0.5, 0.5),  // 5: the same point
      make_box(3, 3, 3, 3, 3, 3),          // 6: an isolated point
      make_box(2, 2, 2, 2, 2, 2),          // 7: a point on the corner of 3
  };
  const Pairs expected = {{0, 1}, {0, 2}, {0, 3}, {0, 4}, {0, 5}, {1, 2}, {1, 3},
                          {2, 3}, {3, 7}, {4, 5}};
  EXPECT_EQ(brute_self(boxes), expected);
  EXPECT_EQ(bp.self_pairs(boxes), expected);
}

TEST(BroadPhase, FarAwayHugeAndInfiniteBoxes) {
  BroadPhase bp;
  const std::vector<Box> boxes = {
      make_box(1e19, 1e19, 1e19, 2e19, 2e19, 2e19),  // 0: beyond Embree's float range
      make_box(1.5e19, 1.5e19, 1.5e19, 3e19, 3e19, 3e19),  // 1: overlaps 0
      make_box(2.5e19, 2.5e19, 2.5e19, 2.5e19, 2.5e19, 2.5e19),  // 2: point in 1 only
      make_box(-kInf, 0, 0, -1e25, 1, 1),              // 3: infinite towards -x
      make_box(-1e30, 0.5, 0.5, -1e30, 0.5, 0.5),      // 4: point in 3
      make_box(-kInf, -kInf, -kInf, kInf, kInf, kInf),  // 5: everything
      make_box(1e12, 1e12, 1e12, 1e12 + 1e-3, 1e12, 1e12),  // 6: tiny, far away
      make_box(1e12 + 2e-3, 1e12, 1e12, 1e12 + 3e-3, 1e12, 1e12),  // 7: misses 6 by 1e-3
  };
  const Pairs expected = {{0, 1}, {0, 5}, {1, 2}, {1, 5}, {2, 5}, {3, 4},
                          {3, 5}, {4, 5}, {5, 6}, {5, 7}};
  EXPECT_EQ(brute_self(boxes), expected);
  EXPECT_EQ(bp.self_pairs(boxes), expected);
}

TEST(BroadPhase, ManyIdenticalBoxes) {
  BroadPhase bp;
  const std::vector<Box> boxes(300, make_box(0.25, 0.25, 0.25, 0.75, 0.75, 0.75));
  const Pairs got = bp.self_pairs(boxes);
  ASSERT_EQ(got.size(), 300u * 299u / 2u);
  EXPECT_EQ(got, brute_self(boxes));
}

TEST(BroadPhase, PairsMatchBruteForce) {
  BroadPhase bp;
  const std::vector<std::pair<int, int>> sizes = {{0, 0},   {0, 10},   {10, 0},  {1, 1},
                                                  {1, 700}, {700, 1},  {37, 500}, {900, 1300}};
  unsigned seed = 100;
  for (const auto& [na, nb] : sizes) {
    const std::vector<Box> a = mixed_boxes(seed++, na);
    const std::vector<Box> b = mixed_boxes(seed++, nb);
    EXPECT_EQ(sorted(bp.pairs(a, b)), brute_pairs(a, b)) << na << " x " << nb;
  }
  // A set against itself: includes (i, i) and both orders.
  const std::vector<Box> s = mixed_boxes(999, 400);
  const Pairs both = bp.pairs(s, s);
  EXPECT_EQ(both, brute_pairs(s, s));
  EXPECT_EQ(std::count_if(both.begin(), both.end(), [](auto p) { return p.first == p.second; }),
            400);
}

// Moves every box by up to `step` (and changes its size), so the overlapping pairs change.
void jitter(std::vector<Box>& boxes, std::mt19937& rng, double step) {
  for (Box& b : boxes) {
    for (int k = 0; k < 3; ++k) {
      const double d = uniform(rng, -step, step);
      const double ext = (b.hi[k] - b.lo[k]) * uniform(rng, 0.5, 1.5);
      b.lo[k] += d;
      b.hi[k] = b.lo[k] + ext;
    }
  }
}

TEST(BroadPhase, RepeatedQueriesRefitAndRebuild) {
  BroadPhase bp;
  std::mt19937 rng(42);
  std::vector<Box> boxes = small_boxes(5, 1500, 0.01, 0.08);
  std::vector<Box> other = small_boxes(6, 800, 0.01, 0.08);
  Pairs previous;
  for (int step = 0; step < 6; ++step) {
    const Pairs expected = brute_self(boxes);
    ASSERT_EQ(bp.self_pairs(boxes), expected) << "step " << step;
    EXPECT_NE(expected, previous);  // the moves do change the answer
    previous = expected;
    // Interleaved two-set queries use their own scenes and refit as well.
    ASSERT_EQ(bp.pairs(boxes, other), brute_pairs(boxes, other)) << "step " << step;
    jitter(boxes, rng, 0.2);
    if (step % 2 == 0) jitter(other, rng, 0.2);
  }
  // A different count: rebuild; then the refit path again from that count.
  boxes.resize(1100);
  EXPECT_EQ(bp.self_pairs(boxes), brute_self(boxes));
  jitter(boxes, rng, 0.2);
  EXPECT_EQ(bp.self_pairs(boxes), brute_self(boxes));
  boxes.push_back(make_box(0, 0, 0, 1, 1, 1));
  EXPECT_EQ(bp.self_pairs(boxes), brute_self(boxes));
  other.resize(3);
  EXPECT_EQ(bp.pairs(boxes, other), brute_pairs(boxes, other));
  EXPECT_EQ(bp.pairs(other, boxes), brute_pairs(other, boxes));
  // Small sets (a handful of primitives take a different path inside Embree) and back.
  for (int n : {2, 3, 4, 5, 4, 4}) {
    std::vector<Box> few(boxes.begin(), boxes.begin() + n);
    jitter(few, rng, 0.5);
    few[0] = make_box(-1, -1, -1, 2, 2, 2);
    EXPECT_EQ(bp.self_pairs(few), brute_self(few)) << n;
  }
  EXPECT_TRUE(bp.self_pairs({}).empty());
  EXPECT_EQ(bp.self_pairs(boxes), brute_self(boxes));
}

TEST(BroadPhase, Deterministic) {
  const std::vector<Box> boxes = mixed_boxes(77, 2000);
  BroadPhase bp;
  const Pairs first = bp.self_pairs(boxes);
  const Pairs second = bp.self_pairs(boxes);  // refit path
  EXPECT_EQ(first, second);
  BroadPhase fresh;
  EXPECT_EQ(fresh.self_pairs(boxes), first);
  const std::vector<Box> other = mixed_boxes(78, 1500);
  EXPECT_EQ(bp.pairs(boxes, other), bp.pairs(boxes, other));
}

TEST(BroadPhase, TwentyThousandSmallBoxesMatchSweepAndPrune) {
  const std::vector<Box> boxes = small_boxes(2024, 20000, 0.002, 0.02);
  const Pairs expected = sweep_self(boxes);
  EXPECT_GT(expected.size(), 1000u);
  BroadPhase bp;
  EXPECT_EQ(bp.self_pairs(boxes), expected);
  // Split into two sets: pairs(a, b) against the cross pairs of the sweep.
  const std::vector<Box> a(boxes.begin(), boxes.begin() + 12000);
  const std::vector<Box> b(boxes.begin() + 12000, boxes.end());
  Pairs cross;
  for (const auto& [i, j] : expected)
    if (i < 12000 && j >= 12000) cross.emplace_back(i, j - 12000);
  EXPECT_EQ(bp.pairs(a, b), cross);
}

TEST(BroadPhase, MovedObjectsStayUsable) {
  const std::vector<Box> boxes = mixed_boxes(5, 300);
  const Pairs expected = brute_self(boxes);
  BroadPhase a;
  EXPECT_EQ(a.self_pairs(boxes), expected);
  BroadPhase b(std::move(a));
  EXPECT_EQ(b.self_pairs(boxes), expected);
  EXPECT_EQ(a.self_pairs(boxes), expected);  // NOLINT(bugprone-use-after-move): documented
  BroadPhase c;
  c = std::move(b);
  EXPECT_EQ(c.self_pairs(boxes), expected);
}

TEST(BroadPhase, RejectsInvalidBoxes) {
  BroadPhase bp;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Box good = make_box(0, 0, 0, 1, 1, 1);
  EXPECT_THROW(bp.self_pairs({good, make_box(0, 0, 0, 1, nan, 1)}), std::invalid_argument);
  EXPECT_THROW(bp.self_pairs({good, make_box(0, 2, 0, 1, 1, 1)}), std::invalid_argument);
  EXPECT_THROW(bp.self_pairs({make_box(nan, 0, 0, 1, 1, 1)}), std::invalid_argument);
  EXPECT_THROW(bp.pairs({good}, {make_box(0, 0, 1, 1, 1, 0)}), std::invalid_argument);
  EXPECT_THROW(bp.pairs({}, {make_box(0, 0, 1, 1, 1, 0)}), std::invalid_argument);
  // Still usable afterwards.
  EXPECT_EQ(bp.self_pairs({good, good}), (Pairs{{0, 1}}));
}

}  // namespace
}  // namespace clothsim

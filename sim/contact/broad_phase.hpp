// Broad phase for contact: all pairs of overlapping axis-aligned boxes, found with Embree 3's
// BVH-versus-BVH traversal (rtcCollide) over user geometry, then filtered exactly in double.
//
// Units: box coordinates are positions in metres (any consistent unit works; nothing is scaled).
//
// Exactness: the result is exactly the set of pairs whose closed double-precision boxes overlap
// (a.lo <= b.hi and b.lo <= a.hi on every axis; touching counts). Embree works in single
// precision, so each double box is converted to float bounds rounded OUTWARD (lo to the largest
// float <= lo, hi to the smallest float >= hi); the float box therefore contains the double box
// and no true overlap is lost. Coordinates are also clamped to [-1e18, 1e18] before the
// conversion, because Embree silently drops primitives whose bounds reach beyond about
// ±1.8e18; clamping is monotone, so it too keeps every true overlap. Every candidate pair Embree
// reports is then tested exactly in double, which removes all false positives.
//
// Determinism: the pairs are returned sorted lexicographically without duplicates, so the
// output depends only on the input boxes (not on thread scheduling or on the BVH), and is
// identical from run to run.
//
// Cost: a BroadPhase owns one Embree device and keeps one scene for self_pairs and one scene per
// side for pairs (so alternating self_pairs(x) and pairs(x, y) refits all three). Each call
// converts and checks the boxes (O(n)), then per scene:
//   - if its box count equals the one of the previous call on that scene, Embree refits the
//     existing BVH to the new bounds: O(n), about 1 ms for 80k boxes (2 cores);
//   - otherwise (first call, or a different count) the scene is released and a new BVH is
//     built with a SAH builder: O(n log n), about 15-30 ms for 80k boxes.
// Then the BVH-versus-BVH traversal and the exact filter run on TBB threads, and the pairs are
// sorted (O(k log k) for k pairs). Sets of fewer than two boxes (self_pairs) or an empty side
// (pairs) return at once without touching Embree.
// Refitting keeps the tree topology of the last build. It stays efficient while boxes that
// were close at that build stay close, as the triangles of a cloth do: for 20k triangle boxes
// of a sheet built flat and refit to a folded, rolled or crumpled sheet, the refit query was
// still faster than a fresh build. Boxes that jump around (in the extreme, permuted among the
// indices) make every leaf overlap every other and a query O(n^2). The result stays exact
// either way; to force a new build, query a fresh BroadPhase (construction: well under 1 ms).
//
// Preconditions: every coordinate is a number (not NaN) and lo <= hi componentwise; otherwise
// std::invalid_argument is thrown. At most INT_MAX boxes per set. Infinite coordinates are
// allowed. Embree errors are reported as std::runtime_error.
//
// Thread safety: one BroadPhase must not be used from several threads at once; separate
// BroadPhase objects are independent.
#pragma once

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <utility>
#include <vector>

namespace clothsim::contact {

struct Box {
  Eigen::Vector3d lo, hi;  // axis-aligned box [m], lo <= hi componentwise
};

class BroadPhase {
 public:
  // Creates the Embree device; throws std::runtime_error if Embree cannot create it.
  BroadPhase();
  ~BroadPhase();
  BroadPhase(const BroadPhase&) = delete;
  BroadPhase& operator=(const BroadPhase&) = delete;
  // A moved-from BroadPhase stays usable: it creates a new device on its next query.
  BroadPhase(BroadPhase&&) noexcept;
  BroadPhase& operator=(BroadPhase&&) noexcept;

  // All pairs (i, j), i < j, of boxes of one set that overlap (closed boxes: touching counts),
  // sorted lexicographically, without duplicates.
  // `keep`, if given, is asked (from several threads at once, so it must only read) about each
  // overlapping pair (i < j) and drops the pair when it returns false, before the pairs are
  // gathered and sorted.
  std::vector<std::pair<int, int>> self_pairs(const std::vector<Box>& boxes,
                                              const std::function<bool(int, int)>& keep = {});
  // All pairs (i, j), i indexing a and j indexing b, whose boxes overlap, sorted
  // lexicographically. Empty if either set is empty.
  std::vector<std::pair<int, int>> pairs(const std::vector<Box>& a, const std::vector<Box>& b);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothsim::contact

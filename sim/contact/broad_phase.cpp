// Broad phase on Embree 3: user geometry of float boxes rounded outward, rtcCollide, exact
// double-precision filter, sorted unique output.
//
// Embree facts this file relies on (Embree 3.13):
//   - rtcCollide only supports scenes made entirely of RTC_GEOMETRY_TYPE_USER geometry.
//   - It reports every pair of primitives in two leaves whose node bounds overlap, without
//     testing the primitives' own bounds, so the exact filter below is what makes the result
//     exact (not just conservative).
//   - Refitting needs three settings together: the geometry's build quality
//     RTC_BUILD_QUALITY_REFIT, which is only honoured when the scene's build quality is
//     RTC_BUILD_QUALITY_LOW (two-level BVH; rtcSetSceneBuildQuality itself rejects REFIT), and
//     the scene flag RTC_SCENE_FLAG_DYNAMIC: a commit of a non-dynamic scene throws the
//     acceleration structure away and builds a new one. Missing any of them still gives correct
//     results, just a full SAH build on every commit (about 30x slower than a refit at 80k).
//   - rtcCommitScene does nothing unless a geometry's modification counter changed, so after new
//     bounds rtcCommitGeometry must be called before rtcCommitScene (otherwise the old bounds
//     stay in the BVH); the refit then calls the bounds function again for every primitive.
//     rtcUpdateGeometryBuffer is not needed (user geometry has no buffers). A change of the
//     primitive count makes the refit builder build a new tree (we release the scene instead).
//   - The per-geometry SAH builder used under the two-level BVH makes leaves of up to 7
//     primitives (the static scene builder: 1), and rtcCollide reports every primitive pair of
//     two overlapping leaves: for small random boxes about 12x more candidates than a static
//     scene, all removed by the exact filter (still cheaper than rebuilding every query).
//   - Primitives whose float bounds are not inside (-1.844e18, 1.844e18) are silently dropped,
//     hence the clamping to ±1e18.
#include "sim/contact/broad_phase.hpp"

#include <embree3/rtcore.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <functional>
#include <atomic>
#include <climits>
#include <cmath>
#include <cstddef>
#include <limits>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>

namespace clothsim::contact {
namespace {

using Pair = std::pair<int, int>;
using PairBuffers = tbb::enumerable_thread_specific<std::vector<Pair>>;

// Coordinates are clamped to this before conversion; Embree drops bounds beyond ~1.844e18.
constexpr double kClamp = 1e18;

// Largest float <= x (x clamped to [-kClamp, kClamp] first; x is not NaN).
float round_down(double x) {
  x = std::clamp(x, -kClamp, kClamp);
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

// Smallest float >= x (x clamped to [-kClamp, kClamp] first; x is not NaN).
float round_up(double x) {
  x = std::clamp(x, -kClamp, kClamp);
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// Closed boxes: touching counts as overlap.
bool overlap(const Box& a, const Box& b) {
  return a.lo.x() <= b.hi.x() && b.lo.x() <= a.hi.x() && a.lo.y() <= b.hi.y() &&
         b.lo.y() <= a.hi.y() && a.lo.z() <= b.hi.z() && b.lo.z() <= a.hi.z();
}

// Throws std::invalid_argument for a NaN coordinate or lo > hi, std::length_error for more
// boxes than an int can index.
void validate(const std::vector<Box>& boxes, const char* what) {
  if (boxes.size() > static_cast<std::size_t>(INT_MAX))
    throw std::length_error(std::string("BroadPhase: too many boxes in ") + what);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      // Also false when either coordinate is NaN.
      if (!(boxes[i].lo[k] <= boxes[i].hi[k])) {
        throw std::invalid_argument(std::string("BroadPhase: box ") + std::to_string(i) + " of " +
                                    what + " has lo > hi or a NaN coordinate on axis " +
                                    std::to_string(k));
      }
    }
  }
}

const char* error_name(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE: return "RTC_ERROR_NONE";
    case RTC_ERROR_UNKNOWN: return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT: return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION: return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY: return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU: return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED: return "RTC_ERROR_CANCELLED";
  }
  return "unknown Embree error code";
}

// Collects the messages the device's error callback receives. The callback must not throw
// (it is called from inside Embree's C API), so errors are stored here and turned into
// exceptions by BroadPhase::Impl::check after the Embree calls.
struct ErrorSink {
  std::mutex mutex;
  std::string message;  // first error since the last check; empty if none
};

void on_embree_error(void* user, RTCError code, const char* str) {
  auto* sink = static_cast<ErrorSink*>(user);
  try {
    std::lock_guard<std::mutex> lock(sink->mutex);
    if (sink->message.empty())
      sink->message = std::string(error_name(code)) + ": " + (str != nullptr ? str : "");
  } catch (...) {
    // Out of memory while recording: rtcGetDeviceError still reports the code.
  }
}

// One Embree scene holding one user geometry with one primitive per box.
struct BoxScene {
  RTCScene scene = nullptr;
  RTCGeometry geometry = nullptr;
  unsigned count = 0;                // number of primitives the scene was built with
  std::vector<RTCBounds> bounds;     // float bounds of the current boxes, rounded outward

  void release() noexcept {
    if (geometry != nullptr) rtcReleaseGeometry(geometry);
    if (scene != nullptr) rtcReleaseScene(scene);
    geometry = nullptr;
    scene = nullptr;
    count = 0;
  }
};

// Bounds callback of the user geometry: reads the precomputed float bounds.
void box_bounds(const RTCBoundsFunctionArguments* args) {
  const auto* s = static_cast<const BoxScene*>(args->geometryUserPtr);
  *args->bounds_o = s->bounds[args->primID];
}

// State shared by the collide callbacks of one rtcCollide call.
struct CollideContext {
  const Box* boxes0;
  const Box* boxes1;
  unsigned n0, n1;
  bool self;
  const std::function<bool(int, int)>* keep;  // optional filter (self pairs, i < j)
  PairBuffers* buffers;
  std::atomic<bool> bad_index{false};
  std::atomic<bool> out_of_memory{false};
};

// Called by Embree on several TBB threads at once with batches of candidate pairs.
void on_collide(void* user, RTCCollision* collisions, unsigned num_collisions) {
  auto* ctx = static_cast<CollideContext*>(user);
  try {
    std::vector<Pair>& out = ctx->buffers->local();
    for (unsigned k = 0; k < num_collisions; ++k) {
      unsigned i = collisions[k].primID0;
      unsigned j = collisions[k].primID1;
      if (i >= ctx->n0 || j >= ctx->n1) {
        ctx->bad_index.store(true, std::memory_order_relaxed);
        continue;
      }
      if (ctx->self) {
        if (i == j) continue;
        if (i > j) std::swap(i, j);
      }
      if (overlap(ctx->boxes0[i], ctx->boxes1[j]) && (ctx->keep == nullptr || (*ctx->keep)(static_cast<int>(i), static_cast<int>(j))))
        out.emplace_back(static_cast<int>(i), static_cast<int>(j));
    }
  } catch (...) {  // std::bad_alloc from a buffer; must not escape into Embree
    ctx->out_of_memory.store(true, std::memory_order_relaxed);
  }
}

}  // namespace

struct BroadPhase::Impl {
  ErrorSink errors;
  RTCDevice device = nullptr;
  BoxScene self_scene;  // for self_pairs
  BoxScene scene_a;     // first set of pairs
  BoxScene scene_b;     // second set of pairs
  PairBuffers buffers;  // per-thread candidate buffers, kept for their capacity

  Impl() {
    device = rtcNewDevice(nullptr);
    if (device == nullptr) {
      const RTCError code = rtcGetDeviceError(nullptr);
      throw std::runtime_error(std::string("BroadPhase: rtcNewDevice failed: ") +
                               error_name(code));
    }
    rtcSetDeviceErrorFunction(device, on_embree_error, &errors);
  }

  ~Impl() {
    self_scene.release();
    scene_a.release();
    scene_b.release();
    rtcReleaseDevice(device);
  }

  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  // Throws std::runtime_error if Embree reported an error since the last check.
  void check(const char* what) {
    const RTCError code = rtcGetDeviceError(device);
    std::string message;
    {
      std::lock_guard<std::mutex> lock(errors.mutex);
      message.swap(errors.message);
    }
    if (message.empty() && code == RTC_ERROR_NONE) return;
    if (message.empty()) message = error_name(code);
    throw std::runtime_error(std::string("BroadPhase: Embree error in ") + what + ": " + message);
  }

  // For a creation call that returned null: throws Embree's error, or a generic one.
  [[noreturn]] void fail(const char* what) {
    check(what);
    throw std::runtime_error(std::string("BroadPhase: ") + what + " failed");
  }

  // Makes s hold the (validated) boxes: refit if the count is unchanged, else a new scene.
  void update(BoxScene& s, const std::vector<Box>& boxes) {
    const auto n = static_cast<unsigned>(boxes.size());
    s.bounds.resize(n);
    for (unsigned i = 0; i < n; ++i) {
      const Box& b = boxes[i];
      RTCBounds& f = s.bounds[i];
      f.lower_x = round_down(b.lo.x());
      f.lower_y = round_down(b.lo.y());
      f.lower_z = round_down(b.lo.z());
      f.align0 = 0.0f;
      f.upper_x = round_up(b.hi.x());
      f.upper_y = round_up(b.hi.y());
      f.upper_z = round_up(b.hi.z());
      f.align1 = 0.0f;
    }
    try {
      if (s.scene == nullptr || s.count != n) {
        s.release();
        s.scene = rtcNewScene(device);
        if (s.scene == nullptr) fail("rtcNewScene");
        // LOW selects the two-level builder, the only one that honours the per-geometry
        // quality REFIT set below (the scene quality itself cannot be REFIT). DYNAMIC keeps the
        // acceleration structure between commits; without it every commit of a static scene
        // re-creates it and builds from scratch, whatever the geometry's quality.
        rtcSetSceneBuildQuality(s.scene, RTC_BUILD_QUALITY_LOW);
        rtcSetSceneFlags(s.scene, RTC_SCENE_FLAG_DYNAMIC);
        s.geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
        if (s.geometry == nullptr) fail("rtcNewGeometry");
        rtcSetGeometryUserPrimitiveCount(s.geometry, n);
        rtcSetGeometryUserData(s.geometry, &s);
        // Embree 3 passes the geometry's user data (above) to the bounds function and ignores
        // this pointer; it is given anyway.
        rtcSetGeometryBoundsFunction(s.geometry, box_bounds, &s);
        rtcSetGeometryBuildQuality(s.geometry, RTC_BUILD_QUALITY_REFIT);
        rtcCommitGeometry(s.geometry);
        rtcAttachGeometry(s.scene, s.geometry);
        check("scene setup");
        s.count = n;
      } else {
        // Bumps the geometry's modification counter; without it rtcCommitScene would consider
        // the scene unchanged and keep the old bounds.
        rtcCommitGeometry(s.geometry);
      }
      rtcCommitScene(s.scene);
      check("rtcCommitScene");
    } catch (...) {
      s.release();  // the next call starts from a fresh scene
      throw;
    }
  }

  std::vector<Pair> collide(const BoxScene& s0, const BoxScene& s1, const std::vector<Box>& b0,
                            const std::vector<Box>& b1, bool self, const std::function<bool(int, int)>* keep = nullptr) {
    for (std::vector<Pair>& buffer : buffers) buffer.clear();
    CollideContext ctx;
    ctx.boxes0 = b0.data();
    ctx.boxes1 = b1.data();
    ctx.n0 = static_cast<unsigned>(b0.size());
    ctx.n1 = static_cast<unsigned>(b1.size());
    ctx.self = self;
    ctx.keep = keep;
    ctx.buffers = &buffers;
    rtcCollide(s0.scene, s1.scene, on_collide, &ctx);
    check("rtcCollide");
    if (ctx.out_of_memory.load()) throw std::bad_alloc();
    if (ctx.bad_index.load())
      throw std::runtime_error("BroadPhase: rtcCollide reported a primitive index out of range");

    // Counting sort by the first index (O(n + k)), then each bucket by the second: the result
    // depends only on the set of pairs, not on the buffers' order.
    std::vector<std::size_t> start(static_cast<std::size_t>(ctx.n0) + 1, 0);
    for (const std::vector<Pair>& buffer : buffers)
      for (const Pair& p : buffer) ++start[static_cast<std::size_t>(p.first) + 1];
    for (std::size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    std::vector<Pair> result(start.back());
    std::vector<std::size_t> next(start.begin(), start.end() - 1);
    for (const std::vector<Pair>& buffer : buffers)
      for (const Pair& p : buffer) result[next[static_cast<std::size_t>(p.first)]++] = p;
    for (std::size_t i = 0; i + 1 < start.size(); ++i)
      if (start[i + 1] - start[i] > 1)
        std::sort(result.begin() + static_cast<std::ptrdiff_t>(start[i]), result.begin() + static_cast<std::ptrdiff_t>(start[i + 1]));
    result.erase(std::unique(result.begin(), result.end()), result.end());
    return result;
  }
};

BroadPhase::BroadPhase() : impl_(std::make_unique<Impl>()) {}
BroadPhase::~BroadPhase() = default;
BroadPhase::BroadPhase(BroadPhase&&) noexcept = default;
BroadPhase& BroadPhase::operator=(BroadPhase&&) noexcept = default;

std::vector<std::pair<int, int>> BroadPhase::self_pairs(const std::vector<Box>& boxes,
                                                        const std::function<bool(int, int)>& keep) {
  validate(boxes, "the set");
  if (boxes.size() < 2) return {};
  if (!impl_) impl_ = std::make_unique<Impl>();
  impl_->update(impl_->self_scene, boxes);
  return impl_->collide(impl_->self_scene, impl_->self_scene, boxes, boxes, true, keep ? &keep : nullptr);
}

std::vector<std::pair<int, int>> BroadPhase::pairs(const std::vector<Box>& a,
                                                   const std::vector<Box>& b) {
  validate(a, "set a");
  validate(b, "set b");
  if (a.empty() || b.empty()) return {};
  if (!impl_) impl_ = std::make_unique<Impl>();
  impl_->update(impl_->scene_a, a);
  impl_->update(impl_->scene_b, b);
  return impl_->collide(impl_->scene_a, impl_->scene_b, a, b, false);
}

}  // namespace clothsim::contact

// The pictures of a dynamic run, DIR/frame_NNNN.png, with one camera for the whole run. Framing
// "motion" fixes the camera before the run (the scene's camera, or one framing the rest shape and
// the scripted boundary motions, see motion_framing_bounds) and draws each picture while the
// simulation goes on: add() takes a copy of the frame's drawn surface (the refined positions and
// normals, computed on the caller's thread) and a drawing thread renders it, encodes the PNG and
// writes it (a temporary file renamed into place), at most kMaxPendingPictures frames behind; the
// caller waits only when that many are pending. The bytes are those of drawing on the caller's
// thread (`asynchronous` false, or CLOTHSIM_RENDER_THREAD=0 for a run, see dynamic_run.cpp).
// Framing "sequence" frames the bounds of the whole simulated sequence, so it appends each
// frame's control-net positions to the spool file DIR/.frames.bin during the run and draws every
// picture afterwards (it cannot start before the last frame is known), then deletes the spool.
#pragma once

#include "app/limit_surface_drawer.hpp"
#include "render/image.hpp"
#include "render/renderer.hpp"
#include "sim/problem/problem.hpp"
#include "sim/scene/scene.hpp"

#include <Eigen/Core>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

namespace clothsim {

// An axis-aligned box [lo, hi] [m]; empty (lo > hi) until something is added.
struct Bounds {
  render::Vec3f lo{1e30f, 1e30f, 1e30f};
  render::Vec3f hi{-1e30f, -1e30f, -1e30f};
};

// Motion framing grows its box on every side by this fraction of the box's diagonal, so that a
// cloth sagging, bulging or swinging somewhat beyond its rest shape and its moved rims stays in
// the picture.
inline constexpr float kMotionFramingMargin = 0.1f;

// Number of equally spaced times over [0, time.end] at which motion framing samples each boundary
// motion (the end time and every motion's start and end time are sampled as well).
inline constexpr int kMotionFramingSamples = 64;

// The box framed by motion framing: the refined surface of the rest shape (`rest`, node positions,
// 3·#nodes [m]) together with the positions that the
// vertices of every boundary condition of `problem` with a motion chain pass through over
// [0, time.end], and the obstacles' meshes (not planes) over the same times, grown by
// kMotionFramingMargin.
Bounds motion_framing_bounds(const LimitSurfaceDrawer& drawer, const Eigen::VectorXd& rest, const Problem& problem);

// The spool file of sequence framing in the output folder `dir`: per frame, its time and the node
// positions (1 + 3·#nodes doubles in native byte order: t, then x, y, z of node 0, node 1, ...),
// no header. Deleted once the pictures are drawn; left behind only by a run that
// was killed.
std::filesystem::path frame_spool_path(const std::filesystem::path& dir);

// Where a resumed run's pictures continue (from its checkpoint): frames handed in and pictures
// written so far, and for sequence framing the bounds of the spooled frames and the spool's length.
struct FrameResume {
  int frames = 0;
  int written = 0;
  Bounds bounds;
  std::uintmax_t spool_bytes = 0;
  Eigen::Index state_size = 0;  // 3·#nodes, the length of a spooled frame's positions
};

// A frame's picture that could not be drawn or written: the error (naming the file or the
// renderer's failure) and the simulation step whose state the frame shows.
class FramePictureError : public std::runtime_error {
 public:
  FramePictureError(const std::string& what, int step) : std::runtime_error(what), step_(step) {}
  int step() const { return step_; }

 private:
  int step_;
};

// Motion framing with a drawing thread: pictures handed in but not yet on disk (queued or being
// drawn) before add() waits.
inline constexpr int kMaxPendingPictures = 2;

class FrameImages {
 public:
  // Pictures of frames drawn by `drawer` and `renderer` into `dir`. With Framing::motion,
  // `motion_bounds` (motion_framing_bounds) sets the camera, unless the scene has one, and the
  // ground height; it is ignored with Framing::sequence. With `resume`, continues a run: the
  // spool is cut to resume->spool_bytes and appended to. With `asynchronous` and motion framing
  // the pictures are drawn on a thread of this object's (which then uses `renderer`: the caller's
  // thread must not, until finish() or destruction).
  FrameImages(const LimitSurfaceDrawer& drawer, render::Renderer& renderer, Framing framing,
              const Bounds& motion_bounds, std::filesystem::path dir, const FrameResume* resume = nullptr,
              bool asynchronous = false);
  // Draws the pictures still pending (their errors are dropped: call finish() to see them),
  // removes the spool file if it is still there (unless finish(true)).
  ~FrameImages();
  FrameImages(const FrameImages&) = delete;
  FrameImages& operator=(const FrameImages&) = delete;

  // The next frame shows the state with node positions `x` (3·#nodes [m]) at time `t` [s],
  // reached by simulation step `step`. Motion framing: writes its picture now, or hands it to the
  // drawing thread. Throws FramePictureError naming the file if this picture, or (asynchronous)
  // an earlier one, could not be drawn or written.
  void add(const Eigen::VectorXd& x, double t, int step);
  // The next frame shows the same state as the previous one (a step longer than a frame period).
  void repeat(int step);
  // Frames handed in so far.
  int frames() const { return frames_; }
  // Waits until every picture handed in is on disk (asynchronous motion framing; otherwise they
  // are already). Throws FramePictureError for the first one that failed (once; the pictures
  // after it are not drawn).
  void drain();
  // What a checkpoint records to continue from here: the pictures handed in are on disk first
  // (drain()), the spool is flushed.
  FrameResume resume_point();
  // Motion framing: drain(). Sequence framing: draws every spooled frame with one camera framing
  // their bounds and deletes the spool file, or keeps it with `keep_spool` (an interrupted run
  // that may be resumed). Returns the number of pictures written by this object in all.
  int finish(bool keep_spool = false);

 private:
  // A picture for the drawing thread: a new frame's surface, or the previous picture again.
  struct Job {
    int frame = 0;
    int step = 0;
    bool repeat = false;
    SurfaceSnapshot surface;
  };
  void write_picture(const render::Image& image, int frame) const;
  void spool(const Eigen::VectorXd& x, double t);
  void hand_over(Job job);
  void draw_pictures();  // the drawing thread
  void stop_drawing() noexcept;

  const LimitSurfaceDrawer& drawer_;
  render::Renderer& renderer_;
  Framing framing_;
  std::filesystem::path dir_;
  Bounds bounds_;  // motion: the framing box; sequence: the bounds of the frames so far
  render::Camera camera_;  // motion framing
  std::optional<render::Image> last_image_;  // motion framing: for a repeated frame
  Eigen::VectorXd last_positions_;           // sequence framing: for a repeated frame
  double last_time_ = 0.0;
  std::ofstream spool_;                      // sequence framing
  int frames_ = 0;
  int written_ = 0;  // asynchronous: guarded by mutex_
  bool keep_spool_ = false;

  // The drawing thread (asynchronous motion framing) and what it shares with the caller's.
  bool asynchronous_ = false;
  std::thread drawing_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> queue_;                   // waiting to be drawn
  int pending_ = 0;                         // queued or being drawn
  bool stopping_ = false;                   // no more jobs will come: finish the queue and end
  std::optional<FramePictureError> error_;  // the first failure; nothing is drawn after it
  bool error_reported_ = false;             // drain() has thrown error_
  render::Image drawn_last_;                // the drawing thread's last picture, for a repeat
};

}  // namespace clothsim

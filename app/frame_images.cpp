// The pictures of a dynamic run: drawn one frame at a time as the frames come (motion framing,
// on a drawing thread while the simulation goes on, or on the caller's) or after the run from a
// spool file of control-net positions (sequence framing).
#include "app/frame_images.hpp"

#include "render/png_io.hpp"
#include "sim/boundary/motion.hpp"

#include <signal.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

void extend(Bounds& b, const Eigen::Vector3d& p) {
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<std::size_t>(k);
    b.lo[i] = std::min(b.lo[i], static_cast<float>(p(k)));
    b.hi[i] = std::max(b.hi[i], static_cast<float>(p(k)));
  }
}

std::string frame_file(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%04d.png", frame);
  return name;
}

}  // namespace

Bounds motion_framing_bounds(const LimitSurfaceDrawer& drawer, const Eigen::VectorXd& rest, const Problem& problem) {
  Bounds b;
  LimitSurfaceDrawer::extend_bounds(drawer.snapshot(rest), b.lo, b.hi);
  const double end = problem.time.end;
  for (const BoundaryCondition& bc : problem.boundary) {
    if (bc.motion.empty()) continue;
    std::vector<double> times;
    for (int s = 0; s <= kMotionFramingSamples; ++s) times.push_back(end * s / kMotionFramingSamples);
    for (const Motion& m : bc.motion)
      for (double t : {m.start, m.end})
        if (t > 0 && t < end) times.push_back(t);
    for (int v : bc.vertices) {
      const Eigen::Vector3d rest_vertex = problem.mesh.vertices.row(v).transpose();
      for (double t : times) extend(b, apply_motions(bc.motion, rest_vertex, t));
    }
  }
  for (const Obstacle& o : problem.obstacles) {
    if (o.shape == Obstacle::Shape::plane) continue;
    std::vector<double> times = {0.0};
    if (!o.motion.empty())
      for (int s = 1; s <= kMotionFramingSamples; ++s) times.push_back(end * s / kMotionFramingSamples);
    for (double t : times) {
      const Eigen::MatrixX3d v = mesh_at(o, t);
      for (Eigen::Index i = 0; i < v.rows(); ++i) extend(b, v.row(i).transpose());
    }
  }
  float diagonal = 0.0f;
  for (std::size_t k = 0; k < 3; ++k) diagonal += (b.hi[k] - b.lo[k]) * (b.hi[k] - b.lo[k]);
  const float margin = kMotionFramingMargin * std::sqrt(diagonal);
  for (std::size_t k = 0; k < 3; ++k) {
    b.lo[k] -= margin;
    b.hi[k] += margin;
  }
  return b;
}

fs::path frame_spool_path(const fs::path& dir) { return dir / ".frames.bin"; }

FrameImages::FrameImages(const LimitSurfaceDrawer& drawer, render::Renderer& renderer, Framing framing,
                         const Bounds& motion_bounds, fs::path dir, const FrameResume* resume, bool asynchronous)
    : drawer_(drawer), renderer_(renderer), framing_(framing), dir_(std::move(dir)) {
  if (resume) {
    frames_ = resume->frames;
    written_ = resume->written;
  }
  if (framing_ == Framing::motion) {
    bounds_ = motion_bounds;
    camera_ = drawer_.camera(bounds_.lo, bounds_.hi);
    if (asynchronous) {
      renderer_.release_context();  // the drawing thread makes it current on itself
      asynchronous_ = true;
      drawing_ = std::thread(&FrameImages::draw_pictures, this);
    }
  } else {
    const fs::path path = frame_spool_path(dir_);
    if (resume) {
      bounds_ = resume->bounds;
      std::error_code ec;
      if (fs::file_size(path, ec) < resume->spool_bytes || ec)
        throw std::runtime_error(path.string() + ": the frame spool is shorter than the checkpoint says (" +
                                 std::to_string(resume->spool_bytes) + " bytes)");
      fs::resize_file(path, resume->spool_bytes);
      spool_.open(path, std::ios::binary | std::ios::app);
      // The last spooled frame, for a repeat in the first step after resuming.
      const std::uintmax_t frame_bytes = sizeof(double) * (1 + static_cast<std::uintmax_t>(resume->state_size));
      if (resume->spool_bytes >= frame_bytes) {
        std::ifstream in(path, std::ios::binary);
        in.seekg(static_cast<std::streamoff>(resume->spool_bytes - frame_bytes));
        last_positions_.resize(resume->state_size);
        in.read(reinterpret_cast<char*>(&last_time_), sizeof(double));
        in.read(reinterpret_cast<char*>(last_positions_.data()),
                static_cast<std::streamsize>(last_positions_.size() * sizeof(double)));
        if (!in) throw std::runtime_error(path.string() + ": cannot read the last spooled frame");
      }
    } else {
      spool_.open(path, std::ios::binary | std::ios::trunc);
    }
    if (!spool_) throw std::runtime_error(path.string() + ": cannot open the file for writing");
  }
}

FrameResume FrameImages::resume_point() {
  drain();  // a checkpoint counts only pictures that are on disk
  FrameResume r;
  r.frames = frames_;
  {
    std::lock_guard lock(mutex_);
    r.written = written_;
  }
  r.bounds = bounds_;
  if (framing_ == Framing::sequence && spool_.is_open()) {
    spool_.flush();
    if (!spool_) throw std::runtime_error(frame_spool_path(dir_).string() + ": cannot write the file");
    r.spool_bytes = static_cast<std::uintmax_t>(spool_.tellp());
  }
  return r;
}

FrameImages::~FrameImages() {
  stop_drawing();
  if (framing_ != Framing::sequence || keep_spool_) return;
  spool_.close();
  std::error_code ec;
  fs::remove(frame_spool_path(dir_), ec);
}

void FrameImages::write_picture(const render::Image& image, int frame) const {
  render::write_png((dir_ / frame_file(frame)).string(), image);  // a temporary file renamed into place
}

void FrameImages::spool(const Eigen::VectorXd& x, double t) {
  spool_.write(reinterpret_cast<const char*>(&t), sizeof(double));
  spool_.write(reinterpret_cast<const char*>(x.data()), static_cast<std::streamsize>(x.size() * sizeof(double)));
  if (!spool_) throw std::runtime_error(frame_spool_path(dir_).string() + ": cannot write the file");
}

void FrameImages::add(const Eigen::VectorXd& x, double t, int step) {
  if (framing_ == Framing::motion && asynchronous_) {
    hand_over(Job{frames_, step, false, drawer_.snapshot(x, t)});
  } else if (framing_ == Framing::motion) {
    try {
      last_image_ = renderer_.render(drawer_.frame(drawer_.snapshot(x, t), camera_, bounds_.lo, bounds_.hi));
      write_picture(*last_image_, frames_);
    } catch (const std::exception& e) {
      throw FramePictureError(e.what(), step);
    }
    ++written_;
  } else {
    LimitSurfaceDrawer::extend_bounds(drawer_.snapshot(x, t), bounds_.lo, bounds_.hi);
    spool(x, t);
    last_positions_ = x;
    last_time_ = t;
  }
  ++frames_;
}

void FrameImages::repeat(int step) {
  if (frames_ == 0) throw std::logic_error("FrameImages::repeat: no frame to repeat");
  if (framing_ == Framing::motion && asynchronous_) {
    hand_over(Job{frames_, step, true, {}});
  } else if (framing_ == Framing::motion) {
    try {
      write_picture(*last_image_, frames_);
    } catch (const std::exception& e) {
      throw FramePictureError(e.what(), step);
    }
    ++written_;
  } else {
    spool(last_positions_, last_time_);
  }
  ++frames_;
}

void FrameImages::hand_over(Job job) {
  {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return pending_ < kMaxPendingPictures || error_.has_value(); });
    if (error_) {
      error_reported_ = true;
      throw *error_;
    }
    queue_.push_back(std::move(job));
    ++pending_;
  }
  changed_.notify_all();
}

void FrameImages::drain() {
  if (!asynchronous_) return;
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return pending_ == 0 || error_.has_value(); });
  // Reported once, like a failure on the simulating thread (finish() after it returns).
  if (error_ && !error_reported_) {
    error_reported_ = true;
    throw *error_;
  }
}

void FrameImages::draw_pictures() {
  // Interrupts are the simulating thread's business (it stops after the current step).
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return !queue_.empty() || stopping_; });
      if (queue_.empty()) break;
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    try {
      if (!job.repeat) drawn_last_ = renderer_.render(drawer_.frame(job.surface, camera_, bounds_.lo, bounds_.hi));
      job.surface = SurfaceSnapshot{};
      write_picture(drawn_last_, job.frame);
      std::lock_guard lock(mutex_);
      ++written_;
      --pending_;
    } catch (const std::exception& e) {
      // As on the simulating thread: the run stops at this picture; the later ones are dropped.
      std::lock_guard lock(mutex_);
      error_.emplace(e.what(), job.step);
      queue_.clear();
      pending_ = 0;
    } catch (...) {
      std::lock_guard lock(mutex_);
      error_.emplace("drawing frame " + std::to_string(job.frame) + " failed", job.step);
      queue_.clear();
      pending_ = 0;
    }
    changed_.notify_all();
  }
  renderer_.release_context();
}

void FrameImages::stop_drawing() noexcept {
  if (!drawing_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  drawing_.join();
}

int FrameImages::finish(bool keep_spool) {
  if (framing_ == Framing::motion) {
    drain();
    std::lock_guard lock(mutex_);
    return written_;
  }
  if (!spool_.is_open()) return written_;
  keep_spool_ = keep_spool;
  const fs::path path = frame_spool_path(dir_);
  spool_.close();
  if (!spool_) throw std::runtime_error(path.string() + ": cannot write the file");
  if (frames_ > 0) {
    const render::Camera camera = drawer_.camera(bounds_.lo, bounds_.hi);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path.string() + ": cannot open the file for reading");
    Eigen::VectorXd positions(last_positions_.size());
    for (int frame = 0; frame < frames_; ++frame) {
      double t = 0.0;
      in.read(reinterpret_cast<char*>(&t), sizeof(double));
      in.read(reinterpret_cast<char*>(positions.data()), static_cast<std::streamsize>(positions.size() * sizeof(double)));
      if (!in) throw std::runtime_error(path.string() + ": cannot read frame " + std::to_string(frame));
      write_picture(renderer_.render(drawer_.frame(drawer_.snapshot(positions, t), camera, bounds_.lo, bounds_.hi)), frame);
      ++written_;
    }
  }
  if (keep_spool_) return written_;
  std::error_code ec;
  fs::remove(path, ec);
  if (ec) throw std::runtime_error(path.string() + ": cannot delete the file: " + ec.message());
  return written_;
}

}  // namespace clothsim

// Off-screen renderer: draws a Frame into an RGB image with Mesa's OSMesa (software GL, GL 3.3+
// core-profile shaders, multisampled anti-aliasing, Blinn-Phong two-sided lighting). The output
// is deterministic: the same Frame gives byte-identical images on every run. frame_bounds()
// (declared in camera_math.hpp, included here) fixes one camera for a whole animation.
#pragma once

#include <memory>

#include "render/camera_math.hpp"
#include "render/frame.hpp"
#include "render/image.hpp"

namespace clothsim::render {

struct RendererInfo {
  bool core_profile = false;  // false: fell back to a compatibility-profile context
  int gl_major = 0;
  int gl_minor = 0;
  int samples = 0;  // MSAA samples per pixel actually used (1: no multisampling)
};

// Wall-clock time [ms] of the phases of one render(), filled only while phase timing is on
// (Renderer::set_phase_timing). Timing inserts glFinish after the drawing and after the resolve,
// so that llvmpipe's deferred rasterisation is charged to the phase that queued it; the image is
// the same with and without timing.
struct RenderPhases {
  double prepare = 0;   // validation, near/far planes, vertex data (normals when missing), buffers
  double shadow = 0;    // the shadow map: the meshes' coverage seen from the light, blurred, uploaded
  double backdrop = 0;  // drawing and resolving the backdrop (once per camera, see Renderer)
  double restore = 0;   // the backdrop copied over what the previous frame drew (glFinish)
  double upload = 0;    // glBufferData of vertices and indices
  double draw = 0;      // draw calls: vertex shading, clipping and binning (calling thread)
  double raster = 0;    // glFinish after the draw calls: rasterisation and fragment shading
  double resolve = 0;   // MSAA resolve (glBlitFramebuffer into the single-sample buffer, glFinish)
  double read = 0;      // glReadPixels of the resolved pixels
  double convert = 0;   // rows flipped to top first, RGBA to RGB
  double total() const {
    return prepare + shadow + backdrop + restore + upload + draw + raster + resolve + read + convert;
  }
};

// Owns one OSMesa context (created in the constructor, destroyed in the destructor). The
// context is made current on the calling thread by the constructor and by every render(); a
// Renderer must be used from one thread at a time, and a thread that is done with it before
// another takes over calls release_context(). Framebuffers are allocated on the first
// render() and reallocated when the frame size changes. Not copyable; movable (a moved-from
// Renderer may only be destroyed or assigned to).
//
// Frames in a row with the same size and background, and the same camera and ground if they
// show the ground (an animation), are drawn over a kept backdrop: from the second such frame on, the background and ground are drawn
// once, multisampled and resolved (an extra multisampled colour and depth buffer), and each
// frame draws only its meshes and lines over them, and resolves and reads back only the
// rectangle those can touch. The pixels are those of drawing the frame afresh.
//
// Failures. Input errors (std::invalid_argument) and running out of memory before the first GL
// call of a frame (std::bad_alloc) leave the renderer usable. A failed GL or OSMesa call (a GL
// error such as GL_OUT_OF_MEMORY, an incomplete framebuffer, OSMesaMakeCurrent failing) throws
// std::runtime_error naming the call, and the renderer is then unusable: later render() calls
// throw, and its destructor makes no further OSMesa call on the failed context (it is abandoned
// until the process exits rather than released or destroyed, since either would flush whatever
// the failure left queued). Destroying a Renderer is safe after any failure.
class Renderer {
 public:
  // Frames up to max_width × max_height pixels can be rendered. `samples` is the requested
  // MSAA sample count, capped at what the implementation supports (GL_MAX_SAMPLES).
  // Throws std::invalid_argument for non-positive sizes and std::runtime_error if the OSMesa
  // context, shaders or framebuffers cannot be set up.
  explicit Renderer(int max_width = 1920, int max_height = 1080, int samples = 4);
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws the frame and returns its pixels (top row first). Throws std::invalid_argument for
  // an inconsistent frame (sizes out of range, index out of bounds, degenerate camera) and
  // std::runtime_error if GL reports an error.
  Image render(const Frame& frame);

  // Leaves the calling thread without a current context if this renderer's is current on it
  // (another thread can then render with it). Not after a failure (see above): a failed context
  // is never made current or released again. The next render() makes it current again.
  void release_context();

  const RendererInfo& info() const;
  // Phase timing of render() (off by default; for benchmarks): see RenderPhases.
  void set_phase_timing(bool on);
  // The phases of the last render() while phase timing was on.
  const RenderPhases& last_phases() const;
  int max_width() const;
  int max_height() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothsim::render

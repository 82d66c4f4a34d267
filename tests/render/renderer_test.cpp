// Renderer and camera framing: lit front and back faces, background, determinism, wireframe
// overlay, ground plane, input validation, and frame_bounds keeping a box inside the image.
#include "render/renderer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

// Mesa's llvmpipe keeps a few hundred bytes of global state alive until exit; under
// AddressSanitizer (debug preset) LeakSanitizer would report them. Suppress that library only.
extern "C" const char* __lsan_default_suppressions() { return "leak:libOSMesa.so\n"; }

namespace clothsim::render {
namespace {

constexpr int kWidth = 64;
constexpr int kHeight = 48;

// A triangle in the plane z = 0, counter-clockwise seen from +z, covering the image centre.
Mesh front_triangle() {
  Mesh mesh;
  mesh.positions = {-1.0f, -0.8f, 0.0f, 1.0f, -0.8f, 0.0f, 0.0f, 1.0f, 0.0f};
  mesh.triangles = {0, 1, 2};
  return mesh;
}

Frame triangle_frame(float eye_z) {
  Frame frame;
  frame.meshes.push_back(front_triangle());
  frame.camera.eye = {0, 0, eye_z};
  frame.camera.target = {0, 0, 0};
  frame.width = kWidth;
  frame.height = kHeight;
  return frame;
}

Renderer& shared_renderer() {
  static Renderer renderer(256, 256);
  return renderer;
}

bool red_dominant(const std::array<std::uint8_t, 3>& p) {
  return p[0] > 100 && p[0] > 2 * p[1] && p[0] > 2 * p[2];
}

TEST(RendererTest, ContextUsesCoreProfileAndMultisampling) {
  const RendererInfo& info = shared_renderer().info();
  EXPECT_GE(info.gl_major * 10 + info.gl_minor, 33);
  EXPECT_GE(info.samples, 1);
  EXPECT_LE(info.samples, 4);
  EXPECT_TRUE(info.core_profile);
}

TEST(RendererTest, FrontFacingTriangleShowsMeshColourOnBackground) {
  const Image image = shared_renderer().render(triangle_frame(3));
  ASSERT_EQ(image.width, kWidth);
  ASSERT_EQ(image.height, kHeight);
  ASSERT_EQ(image.rgb.size(), std::size_t{kWidth * kHeight * 3});
  const auto centre = pixel(image, kWidth / 2, kHeight / 2);
  EXPECT_TRUE(red_dominant(centre))
      << int{centre[0]} << " " << int{centre[1]} << " " << int{centre[2]};
  for (const auto& [x, y] : {std::pair{0, 0}, std::pair{kWidth - 1, 0}, std::pair{0, kHeight - 1},
                             std::pair{kWidth - 1, kHeight - 1}}) {
    const auto corner = pixel(image, x, y);
    EXPECT_EQ(corner, (std::array<std::uint8_t, 3>{255, 255, 255})) << x << ", " << y;
  }
}

TEST(RendererTest, BackgroundColourIsExact) {
  Frame frame = triangle_frame(3);
  frame.background = {0.0f, 0.0f, 1.0f};
  const Image image = shared_renderer().render(frame);
  EXPECT_EQ(pixel(image, 0, 0), (std::array<std::uint8_t, 3>{0, 0, 255}));
}

TEST(RendererTest, TriangleSeenFromBehindShowsBackColour) {
  const Image front = shared_renderer().render(triangle_frame(3));
  const Image back = shared_renderer().render(triangle_frame(-3));
  const auto f = pixel(front, kWidth / 2, kHeight / 2);
  const auto b = pixel(back, kWidth / 2, kHeight / 2);
  // Default colours: front (0.8, 0.1, 0.1), back (0.5, 0.1, 0.1), equally lit.
  EXPECT_TRUE(red_dominant(b));
  EXPECT_GT(int{f[0]} - int{b[0]}, 40) << int{f[0]} << " vs " << int{b[0]};

  Frame blue_back = triangle_frame(-3);
  blue_back.meshes[0].back_color = {0.1f, 0.2f, 0.9f};
  const auto p = pixel(shared_renderer().render(blue_back), kWidth / 2, kHeight / 2);
  EXPECT_GT(p[2], 150);
  EXPECT_LT(p[0], 60);
}

TEST(RendererTest, ExplicitNormalsAreUsedAndBackFacesFlipThem) {
  // Normals tilted away from the key light darken the front; the flipped normals seen from
  // behind are tilted the same way relative to the viewer's lights.
  Frame frame = triangle_frame(3);
  const Image automatic = shared_renderer().render(frame);
  frame.meshes[0].normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  const Image explicit_same = shared_renderer().render(frame);
  EXPECT_EQ(automatic.rgb, explicit_same.rgb);
  frame.meshes[0].normals = {0.7f, -0.7f, 0.1f, 0.7f, -0.7f, 0.1f, 0.7f, -0.7f, 0.1f};
  const Image tilted = shared_renderer().render(frame);
  EXPECT_LT(pixel(tilted, kWidth / 2, kHeight / 2)[0],
            pixel(automatic, kWidth / 2, kHeight / 2)[0]);
}

TEST(RendererTest, RenderingIsDeterministic) {
  Frame frame = triangle_frame(3);
  frame.ground = true;
  frame.ground_height = -1;
  Lines edges;
  edges.positions = frame.meshes[0].positions;
  edges.segments = {0, 1, 1, 2, 2, 0};
  frame.lines.push_back(edges);
  const Image first = shared_renderer().render(frame);
  const Image second = shared_renderer().render(frame);
  EXPECT_EQ(first.rgb, second.rgb);
  Renderer other(kWidth, kHeight);
  EXPECT_EQ(other.render(frame).rgb, first.rgb);
}

TEST(RendererTest, WireframeLinesAreDrawnOverCoplanarMesh) {
  Frame frame = triangle_frame(3);
  Lines edges;
  edges.positions = frame.meshes[0].positions;
  edges.segments = {0, 1, 1, 2, 2, 0};
  edges.color = {0, 0, 0};
  frame.lines.push_back(edges);
  const Image image = shared_renderer().render(frame);
  // The left edge from (-1, -0.8) to (0, 1): its midpoint pixel must be dark.
  const PixelPosition mid = project_to_pixel(frame.camera, kWidth, kHeight, {-0.5f, 0.1f, 0});
  int darkest = 3 * 255;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const auto p = pixel(image, static_cast<int>(mid.x) + dx, static_cast<int>(mid.y) + dy);
      darkest = std::min(darkest, int{p[0]} + int{p[1]} + int{p[2]});
    }
  }
  EXPECT_LT(darkest, 120);
  EXPECT_TRUE(red_dominant(pixel(image, kWidth / 2, kHeight / 2)));

  // Wider lines cover more pixels.
  const auto dark_pixels = [](const Image& im) {
    int count = 0;
    for (std::size_t i = 0; i < im.rgb.size(); i += 3) count += im.rgb[i] < 100 ? 1 : 0;
    return count;
  };
  frame.lines[0].width = 3;
  const Image wide = shared_renderer().render(frame);
  EXPECT_GT(dark_pixels(wide), dark_pixels(image) + 20);
}

TEST(RendererTest, EmptyFrameIsBackground) {
  Frame frame;
  frame.width = kWidth;
  frame.height = kHeight;
  frame.background = {0.2f, 0.4f, 0.6f};
  const Image image = shared_renderer().render(frame);
  const std::array<std::uint8_t, 3> expected{51, 102, 153};
  for (int y = 0; y < kHeight; y += 7) {
    for (int x = 0; x < kWidth; x += 7) EXPECT_EQ(pixel(image, x, y), expected);
  }
}

TEST(RendererTest, GroundPlaneIsVisibleBelowMesh) {
  Frame frame;
  Mesh mesh = front_triangle();
  for (std::size_t i = 1; i < mesh.positions.size(); i += 3) mesh.positions[i] += 1.5f;
  frame.meshes.push_back(mesh);
  frame.camera.eye = {0, 2.5f, 6};
  frame.camera.target = {0, 1, 0};
  frame.width = kWidth;
  frame.height = kHeight;
  frame.ground = false;
  const Image without = shared_renderer().render(frame);
  frame.ground = true;
  const Image with = shared_renderer().render(frame);

  // A ground point in front of the mesh, below it in the image.
  const PixelPosition g = project_to_pixel(frame.camera, kWidth, kHeight, {0, 0, 1.5f});
  ASSERT_GT(g.depth, 0);
  const int gx = static_cast<int>(g.x), gy = static_cast<int>(g.y);
  ASSERT_GT(gy, kHeight / 2);
  ASSERT_LT(gy, kHeight);
  EXPECT_EQ(pixel(without, gx, gy), (std::array<std::uint8_t, 3>{255, 255, 255}));
  const auto p = pixel(with, gx, gy);
  EXPECT_LT(p[0], 245);  // not the white background
  EXPECT_GT(p[0], 100);  // light grey
  EXPECT_EQ(p[0], p[1]);
  EXPECT_EQ(p[1], p[2]);
  // The mesh still shows in front of the ground.
  const PixelPosition m = project_to_pixel(frame.camera, kWidth, kHeight, {0, 1.5f, 0});
  EXPECT_TRUE(red_dominant(pixel(with, static_cast<int>(m.x), static_cast<int>(m.y))));
}

TEST(RendererTest, MeshLyingOnGroundStaysVisible) {
  Frame frame;
  Mesh mesh;  // a square in the ground plane, counter-clockwise seen from above
  mesh.positions = {-1, 0, -1, -1, 0, 1, 1, 0, 1, 1, 0, -1};
  mesh.triangles = {0, 1, 2, 0, 2, 3};
  frame.meshes.push_back(mesh);
  frame.ground = true;
  frame.camera.eye = {0, 3, 4};
  frame.camera.target = {0, 0, 0};
  frame.width = kWidth;
  frame.height = kHeight;
  const Image image = shared_renderer().render(frame);
  for (int y = kHeight / 2 - 3; y <= kHeight / 2 + 3; ++y) {
    for (int x = kWidth / 2 - 3; x <= kWidth / 2 + 3; ++x) {
      EXPECT_TRUE(red_dominant(pixel(image, x, y))) << x << ", " << y;
    }
  }
}

TEST(RendererTest, RejectsInconsistentFrames) {
  Renderer& renderer = shared_renderer();
  Frame frame = triangle_frame(3);
  frame.width = 257;
  EXPECT_THROW(renderer.render(frame), std::invalid_argument);
  frame = triangle_frame(3);
  frame.meshes[0].triangles = {0, 1, 3};
  EXPECT_THROW(renderer.render(frame), std::invalid_argument);
  frame = triangle_frame(3);
  frame.meshes[0].normals = {0, 0, 1};
  EXPECT_THROW(renderer.render(frame), std::invalid_argument);
  frame = triangle_frame(3);
  frame.camera.eye = frame.camera.target;
  EXPECT_THROW(renderer.render(frame), std::invalid_argument);
  frame = triangle_frame(3);
  frame.lines.push_back(Lines{{0, 0, 0}, {0, 1}, {0, 0, 0}, 1});
  EXPECT_THROW(renderer.render(frame), std::invalid_argument);
  // The renderer still works afterwards.
  EXPECT_TRUE(red_dominant(pixel(renderer.render(triangle_frame(3)), kWidth / 2, kHeight / 2)));
  EXPECT_THROW(Renderer(0, 10), std::invalid_argument);
}

TEST(RendererTest, TwoRenderersCanBeUsedAlternately) {
  Renderer a(kWidth, kHeight);
  Renderer b(kWidth, kHeight);
  const Image first = a.render(triangle_frame(3));
  const Image second = b.render(triangle_frame(-3));
  EXPECT_EQ(a.render(triangle_frame(3)).rgb, first.rgb);
  EXPECT_EQ(b.render(triangle_frame(-3)).rgb, second.rgb);
  Renderer moved = std::move(a);
  EXPECT_EQ(moved.render(triangle_frame(3)).rgb, first.rgb);
}

TEST(RendererTest, PhaseTimingReportsPhasesAndKeepsTheImage) {
  Frame frame = triangle_frame(3);
  frame.ground = true;
  frame.ground_height = -1;
  Renderer renderer(kWidth, kHeight);
  const Image untimed = renderer.render(frame);
  renderer.set_phase_timing(true);
  const Image timed = renderer.render(frame);
  const RenderPhases phases = renderer.last_phases();
  renderer.set_phase_timing(false);
  EXPECT_EQ(timed.rgb, untimed.rgb);  // the glFinish calls of timing change nothing drawn
  for (const double phase : {phases.prepare, phases.upload, phases.draw, phases.raster, phases.resolve,
                             phases.read, phases.convert})
    EXPECT_GE(phase, 0.0);
  EXPECT_GT(phases.total(), 0.0);
  EXPECT_GT(phases.raster + phases.resolve, 0.0);
}

// A frame of a small animation: the triangle raised by 1.2 and moved along x by `shift`, seen
// from above the ground, optionally with its edges as a 3-pixel wireframe.
Frame animation_frame(float shift, bool ground, bool wireframe, bool shadow = false) {
  Frame frame;
  Mesh mesh = front_triangle();
  for (std::size_t i = 0; i < mesh.positions.size(); i += 3) {
    mesh.positions[i] += shift;
    mesh.positions[i + 1] += 1.2f;
  }
  if (wireframe) {
    Lines edges;
    edges.positions = mesh.positions;
    edges.segments = {0, 1, 1, 2, 2, 0};
    edges.width = 3;
    frame.lines.push_back(edges);
  }
  frame.meshes.push_back(mesh);
  frame.camera.eye = {0, 2.5f, 6};
  frame.camera.target = {0, 1, 0};
  frame.width = 160;
  frame.height = 120;
  frame.ground = ground;
  frame.shadow = shadow;
  return frame;
}

Image drawn_afresh(const Frame& frame) {
  Renderer renderer(frame.width, frame.height);
  return renderer.render(frame);
}

// One renderer drawing an animation draws its frames over a kept backdrop (background and
// ground) and resolves only where their meshes and lines can be; each frame must still have
// the pixels that a renderer of its own gives it: nothing of the previous frame left behind,
// nothing cut off, also when the camera changes or a vertex lies behind the camera. With a
// shadow, which moves with the mesh, each frame also redraws the ground where it can fall.
TEST(RendererTest, AnimationFramesMatchFramesDrawnAfresh) {
  for (const auto& [ground, shadow] : {std::pair{true, false}, std::pair{true, true}, std::pair{false, false}}) {
    for (const bool wireframe : {false, true}) {
      SCOPED_TRACE(std::string(ground ? "ground" : "no ground") + (shadow ? ", shadow" : "") +
                   (wireframe ? ", wireframe" : ""));
      const Frame left = animation_frame(-1.6f, ground, wireframe, shadow);
      const Frame right = animation_frame(1.6f, ground, wireframe, shadow);
      Frame turned = left;  // another camera
      turned.camera.eye = {1.5f, 2.0f, 5.5f};
      Frame behind = left;  // a triangle reaching behind the camera: drawn and resolved whole
      behind.meshes[0].positions[2] = 8;
      Frame outside = left;  // nothing in the picture but the backdrop
      for (std::size_t i = 0; i < outside.meshes[0].positions.size(); i += 3) outside.meshes[0].positions[i] += 40;
      outside.lines.clear();
      const std::vector<std::pair<const Frame*, Image>> expected = {
          {&left, drawn_afresh(left)},     {&right, drawn_afresh(right)},
          {&turned, drawn_afresh(turned)}, {&behind, drawn_afresh(behind)},
          {&outside, drawn_afresh(outside)}};
      ASSERT_NE(expected[0].second.rgb, expected[1].second.rgb);
      auto reference = [&](const Frame* frame) -> const Image& {
        for (const auto& [f, image] : expected) {
          if (f == frame) return image;
        }
        throw std::logic_error("no reference image");
      };
      Renderer animated(160, 120);
      const std::vector<const Frame*> sequence = {&left,   &left,   &right,   &right,   &left,
                                                  &turned, &turned, &turned,  &left,    &left,
                                                  &behind, &right,  &outside, &outside, &right};
      for (std::size_t k = 0; k < sequence.size(); ++k) {
        EXPECT_EQ(animated.render(*sequence[k]).rgb, reference(sequence[k]).rgb) << "frame " << k;
      }
    }
  }
}

// The shadow darkens the ground where the mesh hides the light (30° off up, on the key light's
// side: upper left of the view, so it falls to the right and away), and nothing else: not the
// mesh, not the ground far from it. A ground normal to z gives the same picture as one normal to
// y when everything is turned with it.
TEST(RendererTest, ShadowDarkensOnlyTheGroundBelowTheMesh) {
  Frame plain = animation_frame(0, true, false, false);
  Frame shadowed = plain;
  shadowed.shadow = true;
  const Image a = shared_renderer().render(plain);
  const Image b = shared_renderer().render(shadowed);
  int darker = 0, lighter = 0, right_of_centre = 0;
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 160; ++x) {
      const auto p = pixel(a, x, y), q = pixel(b, x, y);
      if (q[1] + 20 < p[1]) {
        ++darker;
        right_of_centre += x > 80;
        EXPECT_EQ(p[0], p[1]) << "only the (grey) ground darkens, at " << x << ", " << y;
      }
      lighter += q[0] > p[0] || q[1] > p[1] || q[2] > p[2];
    }
  }
  EXPECT_GT(darker, 100);
  EXPECT_EQ(lighter, 0);
  EXPECT_GT(right_of_centre, darker / 2);
  // The mesh's own centre is untouched.
  const PixelPosition centre = project_to_pixel(plain.camera, 160, 120, {0, 1.2f + 0.2f, 0});
  EXPECT_EQ(pixel(a, static_cast<int>(centre.x), static_cast<int>(centre.y)),
            pixel(b, static_cast<int>(centre.x), static_cast<int>(centre.y)));
  // Turned by +90° about x (y to z): the same picture, but for the shadow map's texel grid.
  auto turn = [](Vec3f v) { return Vec3f{v[0], -v[2], v[1]}; };
  Frame z_up = shadowed;
  z_up.up = {0, 0, 1};
  z_up.camera.eye = turn(z_up.camera.eye);
  z_up.camera.target = turn(z_up.camera.target);
  z_up.camera.up = turn(z_up.camera.up);
  for (std::size_t i = 0; i < z_up.meshes[0].positions.size(); i += 3) {
    const Vec3f v = turn({z_up.meshes[0].positions[i], z_up.meshes[0].positions[i + 1], z_up.meshes[0].positions[i + 2]});
    std::copy(v.begin(), v.end(), z_up.meshes[0].positions.begin() + static_cast<std::ptrdiff_t>(i));
  }
  const Image c = shared_renderer().render(z_up);
  int differ = 0;
  for (std::size_t i = 0; i < b.rgb.size(); ++i) differ += std::abs(int(b.rgb[i]) - int(c.rgb[i])) > 16;
  EXPECT_LT(differ, 100);
}

// A renderer handed from thread to thread (release_context on the one that is done) draws the
// same pixels on each.
TEST(RendererTest, ReleasedContextRendersOnAnotherThread) {
  const Frame frame = animation_frame(0.5f, true, true);
  Renderer renderer(frame.width, frame.height);
  const Image here = renderer.render(frame);
  renderer.release_context();
  Image there;
  std::string error;
  std::thread other([&] {
    try {
      there = renderer.render(frame);
      there = renderer.render(frame);  // over the backdrop
      renderer.release_context();
    } catch (const std::exception& e) {
      error = e.what();
    }
  });
  other.join();
  ASSERT_EQ(error, "");
  EXPECT_EQ(there.rgb, here.rgb);
  EXPECT_EQ(renderer.render(frame).rgb, here.rgb);  // and back on this thread
}

// The 12 triangles of the box [lo, hi], outward-facing.
Mesh box_mesh(const Vec3f& lo, const Vec3f& hi) {
  Mesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.positions.push_back((i & 1) != 0 ? hi[0] : lo[0]);
    mesh.positions.push_back((i & 2) != 0 ? hi[1] : lo[1]);
    mesh.positions.push_back((i & 4) != 0 ? hi[2] : lo[2]);
  }
  mesh.triangles = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                    2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  return mesh;
}

TEST(FrameBoundsTest, BoxCornersProjectInsideImage) {
  const Vec3f lo{-1, 0, -2}, hi{3, 1, 0.5f};
  struct Case {
    int width, height;
    Vec3f direction;
  };
  for (const Case& c : {Case{128, 96, {-1, -0.5f, -1}}, Case{192, 64, {0, 0, -1}},
                        Case{64, 160, {1, -1, 0.2f}}, Case{128, 96, {0, -1, 0}}}) {  // margins of 2 px and more
    const float aspect = static_cast<float>(c.width) / static_cast<float>(c.height);
    const Camera camera = frame_bounds(lo, hi, 35, c.direction, {0, 1, 0}, aspect);
    float min_x = 1e9f, max_x = -1e9f, min_y = 1e9f, max_y = -1e9f;
    for (int i = 0; i < 8; ++i) {
      const Vec3f corner{(i & 1) != 0 ? hi[0] : lo[0], (i & 2) != 0 ? hi[1] : lo[1],
                         (i & 4) != 0 ? hi[2] : lo[2]};
      const PixelPosition p = project_to_pixel(camera, c.width, c.height, corner);
      EXPECT_GT(p.depth, 0);
      EXPECT_GT(p.x, 0);
      EXPECT_LT(p.x, static_cast<float>(c.width));
      EXPECT_GT(p.y, 0);
      EXPECT_LT(p.y, static_cast<float>(c.height));
      min_x = std::min(min_x, p.x);
      max_x = std::max(max_x, p.x);
      min_y = std::min(min_y, p.y);
      max_y = std::max(max_y, p.y);
    }
    // Tight: in the direction that binds, the box's corners span the image but for the 5 %
    // margin (1 / 1.05 of it), centred.
    const float fx = (max_x - min_x) / static_cast<float>(c.width), fy = (max_y - min_y) / static_cast<float>(c.height);
    EXPECT_NEAR(std::max(fx, fy), 1 / 1.05f, 2e-3f) << c.width << " x " << c.height;
    if (fx > fy) {
      EXPECT_NEAR(min_x + max_x, static_cast<float>(c.width), 0.05f);
    } else {
      EXPECT_NEAR(min_y + max_y, static_cast<float>(c.height), 0.05f);
    }

    // The renderer agrees: the box is drawn, and the image border is untouched background.
    Frame frame;
    frame.meshes.push_back(box_mesh(lo, hi));
    frame.camera = camera;
    frame.width = c.width;
    frame.height = c.height;
    const Image image = shared_renderer().render(frame);
    const std::array<std::uint8_t, 3> white{255, 255, 255};
    for (int x = 0; x < c.width; ++x) {
      EXPECT_EQ(pixel(image, x, 0), white);
      EXPECT_EQ(pixel(image, x, c.height - 1), white);
    }
    for (int y = 0; y < c.height; ++y) {
      EXPECT_EQ(pixel(image, 0, y), white);
      EXPECT_EQ(pixel(image, c.width - 1, y), white);
    }
    const PixelPosition centre = project_to_pixel(camera, c.width, c.height, {1, 0.5f, -0.75f});
    EXPECT_NE(pixel(image, static_cast<int>(centre.x), static_cast<int>(centre.y)), white);
  }
}

TEST(FrameBoundsTest, CubeSeenFaceOnFillsMostOfTheImage) {
  const Camera camera = frame_bounds({0, 0, 0}, {1, 1, 1}, 35, {0, 0, -1}, {0, 1, 0}, 1.0f);
  const PixelPosition lo = project_to_pixel(camera, 100, 100, {0, 0, 1});
  const PixelPosition hi = project_to_pixel(camera, 100, 100, {1, 1, 1});
  EXPECT_NEAR(lo.x + hi.x, 100, 1e-3);  // centred
  EXPECT_NEAR(lo.y + hi.y, 100, 1e-3);
  EXPECT_GT(hi.x - lo.x, 55);  // the near face spans more than half the image
  EXPECT_LT(hi.x - lo.x, 100);
  EXPECT_GT(lo.y - hi.y, 55);  // y grows downwards
}

TEST(FrameBoundsTest, RejectsInvalidArguments) {
  EXPECT_THROW(frame_bounds({0, 0, 0}, {1, 1, 1}, 35, {0, 0, 0}, {0, 1, 0}), std::invalid_argument);
  EXPECT_THROW(frame_bounds({0, 0, 0}, {1, 1, 1}, 0, {0, 0, -1}, {0, 1, 0}), std::invalid_argument);
  EXPECT_THROW(frame_bounds({0, 0, 0}, {1, 1, 1}, 35, {0, 0, -1}, {0, 1, 0}, 0),
               std::invalid_argument);
  // An up vector parallel to the view direction is replaced, not rejected.
  const Camera camera = frame_bounds({0, 0, 0}, {1, 1, 1}, 35, {0, -1, 0}, {0, 1, 0});
  EXPECT_GT(project_to_pixel(camera, 10, 10, {0.5f, 0.5f, 0.5f}).depth, 0);
}

}  // namespace
}  // namespace clothsim::render

// Plain data describing one picture to draw: triangle meshes, line overlays, a camera, the
// background and an optional ground plane. No GL, no Eigen: callers fill these from any source.
// Coordinates are world coordinates with y up; triangles are counter-clockwise seen from the
// front side.
#pragma once

#include <array>
#include <vector>

namespace clothsim::render {

using Vec3f = std::array<float, 3>;

// A perspective pinhole camera looking from `eye` at `target`; `fov_deg` is the vertical field
// of view in degrees (the horizontal one follows from the image aspect ratio).
struct Camera {
  Vec3f eye{0, 0, 5};
  Vec3f target{0, 0, 0};
  Vec3f up{0, 1, 0};
  float fov_deg = 35;
};

// A triangle mesh. `normals` (3 per vertex) may be empty: smooth area-weighted vertex normals
// are then computed from the triangles. The front side (counter-clockwise winding seen by the
// camera) is drawn in `color`, the back side in `back_color` with the normal flipped.
struct Mesh {
  std::vector<float> positions;     // 3 per vertex
  std::vector<float> normals;       // 3 per vertex, or empty
  std::vector<unsigned> triangles;  // 3 vertex indices per triangle
  Vec3f color{0.8f, 0.1f, 0.1f};
  Vec3f back_color{0.5f, 0.1f, 0.1f};
};

// Line segments drawn unlit on top of coplanar mesh surfaces (a wireframe overlay).
struct Lines {
  std::vector<float> positions;    // 3 per vertex
  std::vector<unsigned> segments;  // 2 vertex indices per segment
  Vec3f color{0, 0, 0};
  float width = 1;  // pixels; clamped to what the GL implementation supports
};

struct Frame {
  std::vector<Mesh> meshes;
  std::vector<Lines> lines;
  Camera camera;
  Vec3f background{1, 1, 1};
  // A large matte light grey plane {x : x · û = ground_height}, û = up / |up| (the ground's
  // normal, the side it is seen from; `up` need not be unit length), centred below the camera
  // target, sized from the eye-target distance d and fading into the background from 1.5 d to
  // 4 d around its centre and where the view grazes it (so it is the same in every frame of an
  // animation with a fixed camera).
  bool ground = false;
  float ground_height = 0;
  Vec3f up{0, 1, 0};
  // With a ground: the meshes cast a soft shadow on it (their coverage seen from a directional
  // light 30° off `up` on the key light's side, blurred over about 1 % of their extent; the
  // ground is taken to lie below them).
  bool shadow = false;
  int width = 960;
  int height = 720;
};

}  // namespace clothsim::render

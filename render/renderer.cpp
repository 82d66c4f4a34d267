// OSMesa-backed implementation of Renderer: context set-up, shaders, multisampled framebuffers,
// per-frame upload and drawing of meshes, ground and lines, and read-back.
#include "render/renderer.hpp"

#include "render/vec3d.hpp"

#include <GL/osmesa.h>  // includes GL/gl.h and GL/glext.h; GL_GLEXT_PROTOTYPES is set by CMake

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace clothsim::render {
namespace {

constexpr const char* kSurfaceVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_view;
uniform mat4 u_projection;
out vec3 v_view_position;
out vec3 v_view_normal;
out vec3 v_world_position;
void main() {
  vec4 p = u_view * vec4(a_position, 1.0);
  v_view_position = p.xyz;
  v_view_normal = mat3(u_view) * a_normal;  // the view transform is rigid
  v_world_position = a_position;
  gl_Position = u_projection * p;
}
)";

// Blinn-Phong with a key and a fill light fixed in camera space (the camera looks down -z).
// Back faces use the back colour and the flipped normal. Vertices without a usable normal fall
// back to the facet normal from screen-space derivatives. The ground is matte and fades into
// the background with distance from its centre.
// With SHADOW 1 the ground is darkened by the shadow map (u_shadow_map: the blurred fraction of
// the light that the meshes hold back, looked up bilinearly where the ground point lies as the
// light sees it). Where it is 0 the colour is exactly that without a shadow.
// The source is compiled three times, with GROUND defined as 0 (meshes) and as 1 (the ground,
// SHADOW 0 or 1), into separate programs: llvmpipe runs both sides of a branch under a mask, so one program with a
// uniform switch shaded every pixel of the ground with the cloth's lighting too (and every
// cloth pixel with the ground's fade). The arithmetic of each side is unchanged, and so is every
// pixel (checked on render_bench's frame and on the runs' frames).
constexpr const char* kSurfaceFragmentShaderBody = R"(
in vec3 v_view_position;
in vec3 v_view_normal;
in vec3 v_world_position;
uniform vec3 u_front_color;
uniform vec3 u_back_color;
const bool kIsGround = GROUND != 0;
uniform vec3 u_background;
uniform vec3 u_ground_centre;
uniform vec2 u_ground_fade;
#if SHADOW
uniform sampler2D u_shadow_map;
uniform mat4 u_light;             // world to shadow-map coordinates ([0, 1]^2 across the map)
uniform float u_shadow_strength;  // the darkening where the light is held back completely
#endif
out vec4 o_color;

const vec3 kKeyDirection = normalize(vec3(-0.45, 0.6, 0.75));
const vec3 kFillDirection = normalize(vec3(0.6, -0.2, 0.8));
const float kKey = 0.72;
const float kFill = 0.28;
const float kAmbient = 0.16;
const float kSpecular = 0.22;

// x^48 by repeated squaring (x^32 · x^16): llvmpipe evaluates pow() as exp2(48 log2 x) with
// polynomial approximations, several times the cost of these five products. With the facet
// normal below: 33 → 30 ms per render_bench frame; the same pixels there, and at most 1 of 255
// in 1–2 pixels of a sleeve_twist frame (docs/performance.md, "Rendering").
float pow48(float x) {
  float x2 = x * x, x4 = x2 * x2, x8 = x4 * x4, x16 = x8 * x8;
  return x16 * x16 * x16;
}

vec3 light(vec3 n, vec3 v, vec3 l, float strength, vec3 base) {
  float diffuse = max(dot(n, l), 0.0);
  vec3 h = normalize(l + v);
  float specular = diffuse > 0.0 ? pow48(max(dot(n, h), 0.0)) : 0.0;
  return strength * (diffuse * base + kSpecular * specular * vec3(1.0));
}

void main() {
  // The derivatives are taken in uniform control flow; the facet normal is formed only where a
  // fragment has no usable interpolated normal (llvmpipe skips a branch that no fragment takes).
  vec3 dx = dFdx(v_view_position), dy = dFdy(v_view_position);
  bool front = gl_FrontFacing;
  float normal_length = length(v_view_normal);
  vec3 n;
  if (normal_length > 1e-12) {
    n = v_view_normal / normal_length;
    if (!front) n = -n;
  } else {
    vec3 facet = cross(dx, dy);  // towards the viewer
    float facet_length = length(facet);
    n = facet_length > 0.0 ? facet / facet_length : vec3(0.0, 0.0, 1.0);
  }
  vec3 base = (kIsGround || front) ? u_front_color : u_back_color;
  vec3 v = normalize(-v_view_position);
  vec3 color;
  if (!kIsGround) {
    color = kAmbient * base + light(n, v, kKeyDirection, kKey, base) +
            light(n, v, kFillDirection, kFill, base);
  } else {
    // Matte and mostly ambient, so that it stays light grey from any viewing angle.
    color = base * (0.45 + 0.55 * max(dot(n, kKeyDirection), 0.0));
#if SHADOW
    vec4 s = u_light * vec4(v_world_position, 1.0);
    color *= 1.0 - u_shadow_strength * texture(u_shadow_map, s.xy).r;
#endif
    // Fading into the background far from the centre, and where the view grazes the ground
    // (below about 12° of elevation, gone at 2°), so that a low camera sees a floor that fades
    // out softly rather than a horizon line.
    float d = distance(v_world_position, u_ground_centre);
    float elevation = abs(dot(normalize(v_view_position), n));  // sine of the view's angle to the ground
    float fade = max(smoothstep(u_ground_fade.x, u_ground_fade.y, d), 1.0 - smoothstep(0.04, 0.2, elevation));
    color = mix(color, u_background, fade);
  }
  o_color = vec4(clamp(color, 0.0, 1.0), 1.0);
}
)";

constexpr const char* kLineVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_view;
uniform mat4 u_projection;
void main() { gl_Position = u_projection * (u_view * vec4(a_position, 1.0)); }
)";

constexpr const char* kLineFragmentShader = R"(#version 330 core
uniform vec3 u_color;
out vec4 o_color;
void main() { o_color = vec4(u_color, 1.0); }
)";

constexpr float kGroundGrey = 0.92f;

// The shadow: a square map of kShadowMapSize texels over the meshes as seen from the light,
// which comes from kShadowTiltDeg off the ground's normal towards the key light. A texel is 1
// where a mesh covers its centre; the map is then blurred by kShadowBlurPasses box filters of
// radius kShadowBlurRadius texels (close to a Gaussian of σ ≈ 2.4 texels, about 1 % of the
// meshes' extent, reaching 6 texels); kShadowStrength of the ground's light is taken where the
// shadow is full.
constexpr int kShadowMapSize = 256;
constexpr int kShadowBlurRadius = 2;
constexpr int kShadowBlurPasses = 3;
constexpr int kShadowReach = kShadowBlurRadius * kShadowBlurPasses;
constexpr double kShadowTiltDeg = 30;
constexpr float kShadowStrength = 0.45f;

// Triangles drawn per llvmpipe scene (see draw_mesh).
constexpr std::size_t kTrianglesPerScene = 8192;

std::string surface_fragment_source(bool ground, bool shadow) {
  return std::string("#version 330 core\n#define GROUND ") + (ground ? "1" : "0") +
         "\n#define SHADOW " + (shadow ? "1" : "0") + "\n" + kSurfaceFragmentShaderBody;
}

std::string gl_error_name(GLenum error) {
  switch (error) {
    case GL_INVALID_ENUM:
      return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE:
      return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION:
      return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION:
      return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY:
      return "GL_OUT_OF_MEMORY";
    default:
      return "GL error 0x" + std::to_string(error);
  }
}

std::string framebuffer_status_name(GLenum status) {
  switch (status) {
    case GL_FRAMEBUFFER_UNDEFINED:
      return "GL_FRAMEBUFFER_UNDEFINED";
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT:
      return "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT:
      return "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT";
    case GL_FRAMEBUFFER_UNSUPPORTED:
      return "GL_FRAMEBUFFER_UNSUPPORTED";
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE:
      return "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE";
    default:
      return "status 0x" + std::to_string(status);
  }
}

GLuint compile_shader(GLenum type, const char* source, const char* name) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
    glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteShader(shader);
    throw std::runtime_error(std::string("Renderer: compiling the ") + name +
                             " shader failed: " + log.c_str());
  }
  return shader;
}

GLuint link_program(const char* vertex_source, const char* fragment_source, const char* name) {
  const GLuint vs = compile_shader(GL_VERTEX_SHADER, vertex_source, name);
  GLuint fs = 0;
  try {
    fs = compile_shader(GL_FRAGMENT_SHADER, fragment_source, name);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
    glGetProgramInfoLog(program, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteProgram(program);
    throw std::runtime_error(std::string("Renderer: linking the ") + name +
                             " shader program failed: " + log.c_str());
  }
  return program;
}

GLint uniform(GLuint program, const char* name) {
  const GLint location = glGetUniformLocation(program, name);
  if (location < 0) {
    throw std::runtime_error(std::string("Renderer: shader uniform ") + name + " not found");
  }
  return location;
}

void require(bool condition, const std::string& message) {
  if (!condition) throw std::invalid_argument("Renderer::render: " + message);
}

bool finite3(const Vec3f& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

void validate_vertices(const std::vector<float>& positions, const std::string& what) {
  require(positions.size() % 3 == 0, what + ": positions.size() is not a multiple of 3");
  require(positions.size() / 3 <= std::numeric_limits<unsigned>::max(),
          what + ": too many vertices");
  const bool all_finite =
      std::all_of(positions.begin(), positions.end(), [](float x) { return std::isfinite(x); });
  require(all_finite, what + ": non-finite position");
}

void validate_indices(const std::vector<unsigned>& indices, std::size_t per_element,
                      std::size_t vertex_count, const std::string& what) {
  require(indices.size() % per_element == 0,
          what + ": index count is not a multiple of " + std::to_string(per_element));
  for (std::size_t i = 0; i < indices.size(); ++i) {
    if (indices[i] >= vertex_count) {  // message built only on failure: this loop is hot
      require(false, what + ": index " + std::to_string(indices[i]) + " at position " +
                         std::to_string(i) + " is out of range (" + std::to_string(vertex_count) +
                         " vertices)");
    }
  }
}

// Interleaved [x y z nx ny nz] per vertex. Missing normals are area-weighted sums of the
// adjacent triangle normals, normalised (zero for isolated vertices: the shader then uses the
// facet normal).
std::vector<float> interleave(const Mesh& mesh) {
  const std::size_t n = mesh.positions.size() / 3;
  std::vector<float> normals;
  const std::vector<float>* source = &mesh.normals;
  if (mesh.normals.empty()) {
    std::vector<double> sum(3 * n, 0.0);
    for (std::size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
      const std::size_t a = mesh.triangles[t], b = mesh.triangles[t + 1], c = mesh.triangles[t + 2];
      double e1[3], e2[3];
      for (std::size_t k = 0; k < 3; ++k) {
        e1[k] = static_cast<double>(mesh.positions[3 * b + k]) - mesh.positions[3 * a + k];
        e2[k] = static_cast<double>(mesh.positions[3 * c + k]) - mesh.positions[3 * a + k];
      }
      const double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                            e1[0] * e2[1] - e1[1] * e2[0]};
      for (const std::size_t v : {a, b, c}) {
        for (std::size_t k = 0; k < 3; ++k) sum[3 * v + k] += cr[k];
      }
    }
    normals.resize(3 * n);
    for (std::size_t v = 0; v < n; ++v) {
      const double len = std::sqrt(sum[3 * v] * sum[3 * v] + sum[3 * v + 1] * sum[3 * v + 1] +
                                   sum[3 * v + 2] * sum[3 * v + 2]);
      for (std::size_t k = 0; k < 3; ++k) {
        normals[3 * v + k] = len > 0 ? static_cast<float>(sum[3 * v + k] / len) : 0.0f;
      }
    }
    source = &normals;
  }
  std::vector<float> out(6 * n);
  for (std::size_t v = 0; v < n; ++v) {
    for (std::size_t k = 0; k < 3; ++k) {
      out[6 * v + k] = mesh.positions[3 * v + k];
      out[6 * v + 3 + k] = (*source)[3 * v + k];
    }
  }
  return out;
}

struct DepthRange {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(const Mat4f& view, float x, float y, float z) {
    const double depth = -(static_cast<double>(view[2]) * x + static_cast<double>(view[6]) * y +
                           static_cast<double>(view[10]) * z + static_cast<double>(view[14]));
    lo = std::min(lo, depth);
    hi = std::max(hi, depth);
  }
  void add_all(const Mat4f& view, const std::vector<float>& positions) {
    for (std::size_t i = 0; i + 2 < positions.size(); i += 3) {
      add(view, positions[i], positions[i + 1], positions[i + 2]);
    }
  }
};

// A rectangle of pixels [x0, x1) × [y0, y1) in GL window coordinates (rows from the bottom).
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
};

PixelRect whole(int width, int height) { return {0, 0, width, height}; }

using namespace detail;

// A unit vector perpendicular to the unit vector n: n × (the axis least aligned with n).
Vec3d perpendicular(const Vec3d& n) {
  const Vec3d axes[3] = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
  const Vec3d* best = &axes[0];
  for (const Vec3d& a : axes) {
    if (std::abs(dot(a, n)) < std::abs(dot(*best, n)) - 1e-12) best = &a;
  }
  return unit(cross(n, *best));
}

// The ground: the plane x · normal = height (normal the unit up), a square of half size
// `half_size` centred at `centre` below the camera target, spanned by `e1` and `e2` (e1 × e2 =
// −normal, so that its corners centre ∓ e1 ∓ e2 run counter-clockwise seen from above).
struct Ground {
  Vec3d normal{0, 1, 0};
  double height = 0;
  Vec3d centre;
  double half_size = 0;
  Vec3d e1{1, 0, 0}, e2{0, 0, 1};
  std::array<Vec3d, 4> corners() const {
    const Vec3d a = half_size * e1, b = half_size * e2;
    return {centre - a - b, centre - a + b, centre + a + b, centre + a - b};
  }
};

Ground ground_of(const Frame& frame) {
  Ground g;
  g.normal = unit(to_d(frame.up));
  g.height = frame.ground_height;
  const Vec3d target = to_d(frame.camera.target);
  g.centre = target - (dot(target, g.normal) - g.height) * g.normal;
  // Sized from the viewing distance, so that it (and its fade) stays fixed while the camera does.
  g.half_size = 12.0 * std::sqrt(dot(to_d(frame.camera.eye) - target, to_d(frame.camera.eye) - target));
  g.e1 = perpendicular(g.normal);
  g.e2 = cross(g.e1, g.normal);
  return g;
}

// The shadow map's light: where it looks from, the map and where on the ground a shadow can
// fall. `on` only with a ground, the shadow asked for, and triangles to cast it. The ground is
// taken to lie below the meshes (as the renderer's callers place it), so a ground point is in
// shadow iff a mesh lies on the ray from it towards the light: the map holds coverage, not
// depth.
struct ShadowSetup {
  bool on = false;
  Mat4f light{};                // world to map coordinates, [0, 1]^2 across the map
  std::vector<float> map;       // kShadowMapSize² occlusion in [0, 1], row by row
  std::array<Vec3d, 4> footprint;  // ground points around every place the map is not 0
};

// Marks the texels whose centre lies in the triangle (a, b, c) given in texel units (most of a
// refined surface's triangles are smaller than a texel and hold one centre or none).
void cover_triangle(const double (&a)[2], const double (&b)[2], const double (&c)[2], std::vector<float>& map) {
  const int n = kShadowMapSize;
  const double lo_x = std::min(a[0], std::min(b[0], c[0])), hi_x = std::max(a[0], std::max(b[0], c[0]));
  const double lo_y = std::min(a[1], std::min(b[1], c[1])), hi_y = std::max(a[1], std::max(b[1], c[1]));
  // Texel centres k + 0.5 inside [lo, hi]: k from ceil(lo − 0.5) to floor(hi − 0.5).
  const int i0 = std::max(0, static_cast<int>(std::ceil(lo_x - 0.5)));
  const int i1 = std::min(n - 1, static_cast<int>(std::floor(hi_x - 0.5)));
  if (i0 > i1) return;
  const int j0 = std::max(0, static_cast<int>(std::ceil(lo_y - 0.5)));
  const int j1 = std::min(n - 1, static_cast<int>(std::floor(hi_y - 0.5)));
  if (j0 > j1) return;
  const double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  if (area == 0) return;
  const double sign = area > 0 ? 1.0 : -1.0;
  auto edge = [sign](const double (&p)[2], const double (&q)[2], double x, double y) {
    return sign * ((q[0] - p[0]) * (y - p[1]) - (q[1] - p[1]) * (x - p[0]));
  };
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const double x = i + 0.5, y = j + 0.5;
      if (edge(a, b, x, y) >= 0 && edge(b, c, x, y) >= 0 && edge(c, a, x, y) >= 0) {
        map[static_cast<std::size_t>(j) * n + static_cast<std::size_t>(i)] = 1;
      }
    }
  }
}

// One box filter of radius kShadowBlurRadius (the sum, not the mean: integers stay exact) along
// rows or columns, as a running sum; the texels beyond the edge count as 0.
void box_sum(std::vector<int>& map, std::vector<int>& scratch, bool columns) {
  const int n = kShadowMapSize, r = kShadowBlurRadius;
  for (int line = 0; line < n; ++line) {
    auto at = [&](int k) -> std::size_t {
      return columns ? static_cast<std::size_t>(k) * n + static_cast<std::size_t>(line)
                     : static_cast<std::size_t>(line) * n + static_cast<std::size_t>(k);
    };
    int sum = 0;
    for (int k = 0; k < r && k < n; ++k) sum += map[at(k)];
    for (int k = 0; k < n; ++k) {
      if (k + r < n) sum += map[at(k + r)];
      if (k - r - 1 >= 0) sum -= map[at(k - r - 1)];
      scratch[at(k)] = sum;
    }
  }
  map.swap(scratch);
}

ShadowSetup shadow_setup(const Frame& frame, const Mat4f& view, const Ground& ground) {
  ShadowSetup setup;
  // The key light's direction in the world (it is fixed in camera space, see the shader), its
  // part along the ground, and the light kShadowTiltDeg off the normal on that side.
  const Vec3d key_view = unit({-0.45, 0.6, 0.75});
  const Vec3d right{view[0], view[4], view[8]}, up{view[1], view[5], view[9]}, back{view[2], view[6], view[10]};
  const Vec3d key = key_view.x * right + key_view.y * up + key_view.z * back;
  Vec3d side = key - dot(key, ground.normal) * ground.normal;
  side = dot(side, side) > 1e-12 ? unit(side) : ground.e1;
  const double tilt = kShadowTiltDeg * std::numbers::pi / 180.0;
  const Vec3d towards_light = std::cos(tilt) * ground.normal + std::sin(tilt) * side;
  const Vec3d lx = perpendicular(towards_light), ly = cross(towards_light, lx);
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const Mesh& mesh : frame.meshes) {
    if (mesh.triangles.empty()) continue;
    for (std::size_t i = 0; i + 2 < mesh.positions.size(); i += 3) {
      const Vec3d p{mesh.positions[i], mesh.positions[i + 1], mesh.positions[i + 2]};
      const double x = dot(p, lx), y = dot(p, ly);
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  }
  if (!(x0 <= x1)) return setup;  // nothing casts
  const double scale = std::max({std::abs(x0), std::abs(x1), std::abs(y0), std::abs(y1), 1e-30});
  const double extent = std::max({x1 - x0, y1 - y0, 1e-6 * scale});
  // The meshes lie kShadowReach + 2 texels inside the map's edges, so the blur is never cut.
  const int pad = kShadowReach + 2;
  const double texel = extent / (kShadowMapSize - 2 * pad);
  const double half = 0.5 * kShadowMapSize * texel;
  const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
  const double ox = cx - half, oy = cy - half;  // the map's corner, in light coordinates
  double m[16] = {};  // world to map, column-major
  m[0] = lx.x / (2 * half), m[4] = lx.y / (2 * half), m[8] = lx.z / (2 * half), m[12] = -ox / (2 * half);
  m[1] = ly.x / (2 * half), m[5] = ly.y / (2 * half), m[9] = ly.z / (2 * half), m[13] = -oy / (2 * half);
  m[10] = 1, m[15] = 1;
  for (std::size_t i = 0; i < 16; ++i) setup.light[i] = static_cast<float>(m[i]);
  // Coverage, then the blur.
  const auto n = static_cast<std::size_t>(kShadowMapSize);
  setup.map.assign(n * n, 0.0f);
  std::vector<double> texels;
  for (const Mesh& mesh : frame.meshes) {
    if (mesh.triangles.empty()) continue;
    texels.resize(2 * (mesh.positions.size() / 3));
    for (std::size_t v = 0; 3 * v + 2 < mesh.positions.size(); ++v) {
      const Vec3d p{mesh.positions[3 * v], mesh.positions[3 * v + 1], mesh.positions[3 * v + 2]};
      texels[2 * v] = (dot(p, lx) - ox) / texel;
      texels[2 * v + 1] = (dot(p, ly) - oy) / texel;
    }
    for (std::size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
      const double a[2] = {texels[2 * mesh.triangles[t]], texels[2 * mesh.triangles[t] + 1]};
      const double b[2] = {texels[2 * mesh.triangles[t + 1]], texels[2 * mesh.triangles[t + 1] + 1]};
      const double c[2] = {texels[2 * mesh.triangles[t + 2]], texels[2 * mesh.triangles[t + 2] + 1]};
      cover_triangle(a, b, c, setup.map);
    }
  }
  // The blur on counts, exact: 0 stays 0 wherever no covered texel is within reach.
  std::vector<int> counts(setup.map.begin(), setup.map.end()), scratch(n * n);
  int full = 1;
  for (int pass = 0; pass < kShadowBlurPasses; ++pass) {
    box_sum(counts, scratch, false);
    box_sum(counts, scratch, true);
    full *= (2 * kShadowBlurRadius + 1) * (2 * kShadowBlurRadius + 1);
  }
  for (std::size_t i = 0; i < counts.size(); ++i) setup.map[i] = static_cast<float>(counts[i]) / static_cast<float>(full);
  // Where the map can be non-zero (the meshes' box widened by the blur's reach and a texel for
  // the bilinear lookup), carried along the light onto the ground.
  const double wx = 0.5 * (x1 - x0) + (kShadowReach + 1) * texel, wy = 0.5 * (y1 - y0) + (kShadowReach + 1) * texel;
  const double rise = dot(towards_light, ground.normal);  // cos(tilt) > 0
  const double corners[4][2] = {{cx - wx, cy - wy}, {cx - wx, cy + wy}, {cx + wx, cy + wy}, {cx + wx, cy - wy}};
  for (std::size_t k = 0; k < 4; ++k) {
    const Vec3d p = corners[k][0] * lx + corners[k][1] * ly;
    setup.footprint[k] = p + ((ground.height - dot(p, ground.normal)) / rise) * towards_light;
  }
  setup.on = true;
  return setup;
}

// What the backdrop depends on: image size and background; with a ground also the ground and
// the camera matrices (without one the backdrop is the cleared buffers, whatever the camera and
// the near and far planes, which follow the meshes).
std::vector<float> backdrop_key_for(const Frame& frame, const Mat4f& view, const Mat4f& projection,
                                    const Ground& ground) {
  std::vector<float> key = {static_cast<float>(frame.width), static_cast<float>(frame.height),
                            frame.background[0], frame.background[1], frame.background[2],
                            frame.ground ? 1.0f : 0.0f};
  if (frame.ground) {
    // The program that drew it (with or without the shadow's code) is part of the ground.
    key.insert(key.end(), {frame.shadow ? 1.0f : 0.0f, static_cast<float>(ground.height),
                           static_cast<float>(ground.half_size)});
    for (const Vec3d& v : {ground.normal, ground.centre}) {
      key.insert(key.end(), {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)});
    }
    key.insert(key.end(), view.begin(), view.end());
    key.insert(key.end(), projection.begin(), projection.end());
  }
  return key;
}

// The pixels the frame's meshes and lines can touch: the bounding rectangle of their vertices'
// projections, widened by 2 pixels (sample positions, rounding) and by the widest line, within
// the image; the whole image if a vertex lies on or behind the camera's plane. A triangle or
// line with every vertex in front of the camera projects into the convex hull of its vertices'
// images, and so does whatever of it survives clipping.
// projection · view, column-major.
std::array<double, 16> clip_matrix(const Mat4f& view, const Mat4f& projection) {
  std::array<double, 16> m{};
  for (std::size_t c = 0; c < 4; ++c) {
    for (std::size_t r = 0; r < 4; ++r) {
      double sum = 0;
      for (std::size_t k = 0; k < 4; ++k) {
        sum += static_cast<double>(projection[4 * k + r]) * view[4 * c + k];
      }
      m[4 * c + r] = sum;
    }
  }
  return m;
}

// Normalised device coordinates to a pixel rectangle widened by `margin` pixels, within the
// image.
PixelRect ndc_rect(const Frame& frame, double lo_x, double hi_x, double lo_y, double hi_y, double margin) {
  const double w = frame.width, h = frame.height;
  // Clamped before converting to int.
  auto pixel = [](double ndc, double size, double shift) {
    return std::clamp((0.5 * ndc + 0.5) * size + shift, 0.0, size);
  };
  PixelRect rect;
  rect.x0 = static_cast<int>(std::floor(pixel(lo_x, w, -margin)));
  rect.x1 = static_cast<int>(std::ceil(pixel(hi_x, w, margin)));
  rect.y0 = static_cast<int>(std::floor(pixel(lo_y, h, -margin)));
  rect.y1 = static_cast<int>(std::ceil(pixel(hi_y, h, margin)));
  return rect.empty() ? PixelRect{} : rect;
}

// The smallest rectangle holding both.
PixelRect merge(const PixelRect& a, const PixelRect& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  return {std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1), std::max(a.y1, b.y1)};
}

// The pixels where the shadow can darken the ground: the bounding rectangle of its footprint's
// corners (the ground within them is a convex quadrilateral), widened by 2 pixels; the whole
// image if a corner lies on or behind the camera's plane.
PixelRect shadow_rect(const Frame& frame, const Mat4f& view, const Mat4f& projection, const ShadowSetup& shadow) {
  const std::array<double, 16> m = clip_matrix(view, projection);
  double lo_x = std::numeric_limits<double>::infinity(), lo_y = lo_x, hi_x = -lo_x, hi_y = -lo_x;
  for (const Vec3d& p : shadow.footprint) {
    const double w = m[3] * p.x + m[7] * p.y + m[11] * p.z + m[15];
    if (!(w > 0)) return whole(frame.width, frame.height);
    const double sx = (m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12]) / w;
    const double sy = (m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13]) / w;
    lo_x = std::min(lo_x, sx), hi_x = std::max(hi_x, sx), lo_y = std::min(lo_y, sy), hi_y = std::max(hi_y, sy);
  }
  return ndc_rect(frame, lo_x, hi_x, lo_y, hi_y, 2.0);
}

PixelRect drawn_rect(const Frame& frame, const Mat4f& view, const Mat4f& projection,
                     float widest_line) {
  const std::array<double, 16> m = clip_matrix(view, projection);
  double lo_x = std::numeric_limits<double>::infinity(), lo_y = lo_x;
  double hi_x = -lo_x, hi_y = -lo_x;
  bool behind = false;
  auto add_all = [&](const std::vector<float>& positions) {
    for (std::size_t i = 0; i + 2 < positions.size(); i += 3) {
      const double x = positions[i], y = positions[i + 1], z = positions[i + 2];
      const double w = m[3] * x + m[7] * y + m[11] * z + m[15];
      if (!(w > 0)) {
        behind = true;
        return;
      }
      const double sx = (m[0] * x + m[4] * y + m[8] * z + m[12]) / w;
      const double sy = (m[1] * x + m[5] * y + m[9] * z + m[13]) / w;
      lo_x = std::min(lo_x, sx);
      hi_x = std::max(hi_x, sx);
      lo_y = std::min(lo_y, sy);
      hi_y = std::max(hi_y, sy);
    }
  };
  bool lines = false;
  for (const Mesh& mesh : frame.meshes) {
    if (!mesh.triangles.empty() && !behind) add_all(mesh.positions);
  }
  for (const Lines& l : frame.lines) {
    if (l.segments.empty() || behind) continue;
    add_all(l.positions);
    lines = true;
  }
  if (behind) return whole(frame.width, frame.height);
  if (!(lo_x <= hi_x && lo_y <= hi_y)) return {};  // nothing is drawn
  const double margin = 2.0 + (lines ? std::ceil(widest_line) : 0.0);
  return ndc_rect(frame, lo_x, hi_x, lo_y, hi_y, margin);
}

}  // namespace

struct Renderer::Impl {
  OSMesaContext context = nullptr;
  // OSMesa's window buffer, 4 x 4 RGBA (unused: we draw to FBOs). Held by pointer so that a
  // context abandoned after a failure (see `failure`) keeps a valid buffer.
  std::unique_ptr<unsigned char[]> default_buffer;
  // Set when a GL or OSMesa call failed after the context was created. The context's state is
  // then unknown (a failed allocation may leave queued work that any flush would run, and
  // OSMesaMakeCurrent flushes): render() refuses to run and the destructor makes no further
  // OSMesa call on it, abandoning the context instead of crashing in its teardown.
  std::string failure;
  int max_width = 0;
  int max_height = 0;
  RendererInfo info;
  float line_width_range[2] = {1, 1};

  // A ground program and its uniforms (the shadow's only with SHADOW 1).
  struct GroundProgram {
    GLuint program = 0;
    GLint view = -1, projection = -1, color = -1, background = -1, centre = -1, fade = -1;
    GLint light = -1, strength = -1, map = -1;
  };

  GLuint surface_program = 0;  // meshes (GROUND 0)
  GroundProgram ground_plain;  // the ground (GROUND 1, SHADOW 0)
  GroundProgram ground_shadowed;  // the ground with the meshes' shadow (GROUND 1, SHADOW 1)
  GLuint line_program = 0;
  GLint surface_view = -1, surface_projection = -1, surface_front = -1, surface_back = -1;
  GLint line_view = -1, line_projection = -1, line_color = -1;
  // The shadow map's texture, made on first use.
  GLuint shadow_texture = 0;

  GLuint vao = 0;
  GLuint vertex_buffer = 0;
  GLuint index_buffer = 0;

  // Framebuffers, (re)allocated for the current frame size.
  int fb_width = 0;
  int fb_height = 0;
  GLuint ms_fbo = 0, ms_color = 0, ms_depth = 0;
  GLuint resolve_fbo = 0, resolve_color = 0;
  std::vector<std::uint8_t> read_buffer;  // bottom-up RGBA rows from glReadPixels

  // The backdrop: what a frame shows without its meshes and lines (background and ground),
  // multisampled (colour and depth, backdrop_fbo) and resolved (backdrop_rgb), kept for the
  // frames that share its size, background and ground (backdrop_key_for). It is
  // built by the second frame in a row with the same key. A frame drawn over it restores only
  // the part of ms_fbo that the previous frame drew on (ms_dirty) from backdrop_fbo, draws its
  // meshes and lines over the ground already there, and resolves and reads back only the
  // rectangle they can touch; the rest of the image is backdrop_rgb. The pixels are those of
  // drawing everything afresh: outside the rectangle ms_fbo holds the backdrop's samples, and
  // the ground drawn before instead of after the meshes loses or wins the same depth tests
  // (only a sample at exactly the same depth on both could differ).
  GLuint backdrop_fbo = 0, backdrop_color = 0, backdrop_depth = 0;
  std::vector<float> backdrop_key;         // of the built backdrop; empty: none
  std::vector<float> direct_key;           // of the last frame drawn without the backdrop
  std::vector<std::uint8_t> backdrop_rgb;  // the resolved backdrop, top row first
  PixelRect ms_dirty;                      // where ms_fbo may differ from backdrop_fbo

  // Phase timing (set_phase_timing): lap() charges the time since the previous lap to a phase.
  bool time_phases = false;
  RenderPhases phases;
  std::chrono::steady_clock::time_point lap_start;
  void lap(double RenderPhases::*phase) {
    if (!time_phases) return;
    const auto now = std::chrono::steady_clock::now();
    phases.*phase += std::chrono::duration<double, std::milli>(now - lap_start).count();
    lap_start = now;
  }

  Impl(int width, int height, int samples);
  ~Impl();
  void make_current();
  void create_context();
  void destroy_context() noexcept;
  void setup_pipeline(int requested_samples);
  void ensure_framebuffers(int width, int height);
  void delete_framebuffers();
  [[noreturn]] void fail(const std::string& message);
  void check(const char* what);
  Image render(const Frame& frame);
  void draw(const Frame& frame, const std::vector<std::vector<float>>& mesh_vertices, Image& image);
  void draw_mesh(const Mesh& mesh, const std::vector<float>& vertices);
  void draw_lines(const Lines& lines);
  GroundProgram link_ground(bool shadow);
  void draw_ground(const Frame& frame, const Mat4f& view, const Mat4f& projection, const Ground& ground,
                   const ShadowSetup& shadow, float strength);
  void upload_shadow_map(const ShadowSetup& shadow);
  void build_backdrop(const Frame& frame, const Mat4f& view, const Mat4f& projection, const Ground& ground,
                      const ShadowSetup& shadow);
  void read_back(const PixelRect& rect, std::uint8_t* rgb);
};

Renderer::Impl::Impl(int width, int height, int samples)
    : default_buffer(std::make_unique<unsigned char[]>(4 * 4 * 4)), max_width(width), max_height(height) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("Renderer: maximum size must be positive, got " +
                                std::to_string(width) + " x " + std::to_string(height));
  }
  create_context();
  try {
    setup_pipeline(samples);
  } catch (...) {
    destroy_context();
    throw;
  }
}

Renderer::Impl::~Impl() { destroy_context(); }

void Renderer::Impl::destroy_context() noexcept {
  if (context == nullptr) return;
  if (!failure.empty()) {
    // A failed context is abandoned, not destroyed: releasing it (OSMesaMakeCurrent) or
    // destroying it (which makes it current internally) flushes whatever the failure left
    // queued, and that flush is where a renderer that ran out of memory crashed. The context
    // and its window buffer stay allocated until the process exits.
    static_cast<void>(default_buffer.release());
    context = nullptr;
    return;
  }
  // Destroying the context frees every GL object it owns. Nothing is queued: every render()
  // ends with a read-back, which waits for the drawing.
  if (OSMesaGetCurrentContext() == context) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
  OSMesaDestroyContext(context);
  context = nullptr;
}

void Renderer::Impl::fail(const std::string& message) {
  if (failure.empty()) failure = message;
  throw std::runtime_error(message);
}

void Renderer::Impl::check(const char* what) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) fail(std::string("Renderer: ") + what + " failed: " + gl_error_name(error));
}

void Renderer::Impl::create_context() {
  // GL 3.3 core profile first, then a compatibility profile (which also runs the 330 core
  // shaders on Mesa), then a legacy context as a last resort.
  for (const int profile : {OSMESA_CORE_PROFILE, OSMESA_COMPAT_PROFILE}) {
    const int attributes[] = {OSMESA_FORMAT,
                              OSMESA_RGBA,
                              OSMESA_DEPTH_BITS,
                              0,
                              OSMESA_STENCIL_BITS,
                              0,
                              OSMESA_ACCUM_BITS,
                              0,
                              OSMESA_PROFILE,
                              profile,
                              OSMESA_CONTEXT_MAJOR_VERSION,
                              3,
                              OSMESA_CONTEXT_MINOR_VERSION,
                              3,
                              0};
    context = OSMesaCreateContextAttribs(attributes, nullptr);
    if (context != nullptr) {
      info.core_profile = profile == OSMESA_CORE_PROFILE;
      break;
    }
  }
  if (context == nullptr) context = OSMesaCreateContextExt(OSMESA_RGBA, 0, 0, 0, nullptr);
  if (context == nullptr) {
    throw std::runtime_error(
        "Renderer: OSMesa could not create an OpenGL context (is libOSMesa installed, and is "
        "libGL not linked next to it?)");
  }
  try {
    make_current();
  } catch (...) {
    destroy_context();
    throw;
  }
}

void Renderer::Impl::make_current() {
  if (OSMesaGetCurrentContext() == context) return;
  if (!OSMesaMakeCurrent(context, default_buffer.get(), GL_UNSIGNED_BYTE, 4, 4)) {
    fail("Renderer: OSMesaMakeCurrent failed (out of memory?)");
  }
}

void Renderer::Impl::setup_pipeline(int requested_samples) {
  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  if (glGetError() != GL_NO_ERROR || major < 3 || (major == 3 && minor < 3)) {
    const GLubyte* version = glGetString(GL_VERSION);
    throw std::runtime_error(
        std::string("Renderer: OpenGL 3.3 or newer is required, OSMesa provides ") +
        (version != nullptr ? reinterpret_cast<const char*>(version) : "an unknown version"));
  }
  info.gl_major = major;
  info.gl_minor = minor;

  GLint max_samples = 1, max_renderbuffer = 0, max_viewport[2] = {0, 0};
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_renderbuffer);
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, max_viewport);
  glGetFloatv(GL_ALIASED_LINE_WIDTH_RANGE, line_width_range);
  check("querying implementation limits");
  info.samples = std::clamp(requested_samples, 1, std::max(max_samples, 1));
  if (max_width > std::min(max_renderbuffer, max_viewport[0]) ||
      max_height > std::min(max_renderbuffer, max_viewport[1])) {
    throw std::runtime_error("Renderer: maximum size " + std::to_string(max_width) + " x " +
                             std::to_string(max_height) + " exceeds the GL limit of " +
                             std::to_string(std::min(max_renderbuffer, max_viewport[0])) + " x " +
                             std::to_string(std::min(max_renderbuffer, max_viewport[1])));
  }

  surface_program =
      link_program(kSurfaceVertexShader, surface_fragment_source(false, false).c_str(), "surface");
  surface_view = uniform(surface_program, "u_view");
  surface_projection = uniform(surface_program, "u_projection");
  surface_front = uniform(surface_program, "u_front_color");
  surface_back = uniform(surface_program, "u_back_color");
  ground_plain = link_ground(false);
  ground_shadowed = link_ground(true);
  line_program = link_program(kLineVertexShader, kLineFragmentShader, "line");
  line_view = uniform(line_program, "u_view");
  line_projection = uniform(line_program, "u_projection");
  line_color = uniform(line_program, "u_color");

  // The core profile draws nothing without a bound vertex array object.
  glGenVertexArrays(1, &vao);
  glGenBuffers(1, &vertex_buffer);
  glGenBuffers(1, &index_buffer);
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, index_buffer);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDisable(GL_CULL_FACE);
  glEnable(GL_MULTISAMPLE);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  check("setting up the GL pipeline");
}

Renderer::Impl::GroundProgram Renderer::Impl::link_ground(bool shadow) {
  GroundProgram g;
  g.program = link_program(kSurfaceVertexShader, surface_fragment_source(true, shadow).c_str(),
                           shadow ? "shadowed ground" : "ground");
  g.view = uniform(g.program, "u_view");
  g.projection = uniform(g.program, "u_projection");
  g.color = uniform(g.program, "u_front_color");
  g.background = uniform(g.program, "u_background");
  g.centre = uniform(g.program, "u_ground_centre");
  g.fade = uniform(g.program, "u_ground_fade");
  if (shadow) {
    g.light = uniform(g.program, "u_light");
    g.strength = uniform(g.program, "u_shadow_strength");
    g.map = uniform(g.program, "u_shadow_map");
  }
  return g;
}

void Renderer::Impl::delete_framebuffers() {
  glDeleteFramebuffers(1, &ms_fbo);
  glDeleteFramebuffers(1, &resolve_fbo);
  glDeleteFramebuffers(1, &backdrop_fbo);
  glDeleteRenderbuffers(1, &ms_color);
  glDeleteRenderbuffers(1, &ms_depth);
  glDeleteRenderbuffers(1, &resolve_color);
  glDeleteRenderbuffers(1, &backdrop_color);
  glDeleteRenderbuffers(1, &backdrop_depth);
  ms_fbo = resolve_fbo = ms_color = ms_depth = resolve_color = 0;
  backdrop_fbo = backdrop_color = backdrop_depth = 0;
  backdrop_key.clear();
  direct_key.clear();
  fb_width = fb_height = 0;
}

void Renderer::Impl::ensure_framebuffers(int width, int height) {
  if (width == fb_width && height == fb_height) return;
  delete_framebuffers();
  const GLsizei samples = info.samples;

  glGenRenderbuffers(1, &ms_color);
  glBindRenderbuffer(GL_RENDERBUFFER, ms_color);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
  glGenRenderbuffers(1, &ms_depth);
  glBindRenderbuffer(GL_RENDERBUFFER, ms_depth);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT32F, width, height);
  glGenFramebuffers(1, &ms_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, ms_fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, ms_color);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, ms_depth);
  GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    delete_framebuffers();
    fail("Renderer: the " + std::to_string(samples) + "-sample framebuffer of " +
         std::to_string(width) + " x " + std::to_string(height) +
         " is incomplete (out of memory?): " + framebuffer_status_name(status));
  }

  glGenRenderbuffers(1, &resolve_color);
  glBindRenderbuffer(GL_RENDERBUFFER, resolve_color);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glGenFramebuffers(1, &resolve_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_color);
  status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    delete_framebuffers();
    fail("Renderer: the resolve framebuffer of " + std::to_string(width) + " x " +
         std::to_string(height) + " is incomplete (out of memory?): " +
         framebuffer_status_name(status));
  }
  check("allocating framebuffers");
  fb_width = width;
  fb_height = height;
}

void Renderer::Impl::draw_mesh(const Mesh& mesh, const std::vector<float>& vertices) {
  if (mesh.triangles.empty()) return;
  lap(&RenderPhases::draw);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)),
               vertices.data(), GL_STREAM_DRAW);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(mesh.triangles.size() * sizeof(unsigned)),
               mesh.triangles.data(), GL_STREAM_DRAW);
  check("uploading a mesh");  // no draw call on a buffer without storage
  lap(&RenderPhases::upload);
  glEnableVertexAttribArray(0);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                        reinterpret_cast<const void*>(3 * sizeof(float)));
  glUniform3fv(surface_front, 1, mesh.color.data());
  glUniform3fv(surface_back, 1, mesh.back_color.data());
  // In scenes of at most kTrianglesPerScene triangles: llvmpipe bins a whole scene before
  // rasterising it, and a scene of 50 000 small triangles binned ~13 MB of memory that was
  // allocated and faulted in afresh every frame (110 000 page faults in 31 frames of
  // render_bench, 31 000 in scenes of 8192). glFlush hands each scene to the rasterising
  // threads, which draw it while the next one is binned; the triangles and their order are
  // unchanged, and so are the pixels.
  const std::size_t triangles = mesh.triangles.size() / 3;
  for (std::size_t first = 0; first < triangles; first += kTrianglesPerScene) {
    if (first > 0) glFlush();
    const std::size_t count = std::min(kTrianglesPerScene, triangles - first);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * count), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(3 * first * sizeof(unsigned)));
  }
  lap(&RenderPhases::draw);
}

void Renderer::Impl::draw_ground(const Frame& frame, const Mat4f& view, const Mat4f& projection,
                                 const Ground& ground, const ShadowSetup& shadow, float strength) {
  // Counter-clockwise seen from above (the side `normal` points to).
  const std::array<Vec3d, 4> corners = ground.corners();
  float vertices[24];
  for (std::size_t k = 0; k < 4; ++k) {
    const Vec3f p = to_f(corners[k]), n = to_f(ground.normal);
    std::copy(p.begin(), p.end(), vertices + 6 * k);
    std::copy(n.begin(), n.end(), vertices + 6 * k + 3);
  }
  const unsigned indices[] = {0, 1, 2, 0, 2, 3};
  lap(&RenderPhases::draw);
  glBufferData(GL_ARRAY_BUFFER, sizeof(vertices), vertices, GL_STREAM_DRAW);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, sizeof(indices), indices, GL_STREAM_DRAW);
  lap(&RenderPhases::upload);
  glEnableVertexAttribArray(0);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                        reinterpret_cast<const void*>(3 * sizeof(float)));
  const float grey[3] = {kGroundGrey, kGroundGrey, kGroundGrey};
  const GroundProgram& g = frame.shadow ? ground_shadowed : ground_plain;
  const Vec3f centre = to_f(ground.centre);
  const float half_size = static_cast<float>(ground.half_size);
  glUseProgram(g.program);
  glUniformMatrix4fv(g.view, 1, GL_FALSE, view.data());
  glUniformMatrix4fv(g.projection, 1, GL_FALSE, projection.data());
  glUniform3fv(g.background, 1, frame.background.data());
  glUniform3fv(g.color, 1, grey);
  glUniform3f(g.centre, centre[0], centre[1], centre[2]);
  // Fading out from 1.5 to 4 eye-target distances around the centre: a floor under the framed
  // things rather than a plain to the horizon (a low camera sees a soft edge, not a horizon line).
  glUniform2f(g.fade, 0.125f * half_size, (1.0f / 3.0f) * half_size);
  if (frame.shadow) {
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, shadow_texture);
    glUniform1i(g.map, 0);
    glUniformMatrix4fv(g.light, 1, GL_FALSE, shadow.light.data());
    glUniform1f(g.strength, shadow.on ? strength : 0.0f);
  }
  // Pushed further back than the meshes, so that cloth lying on it stays visible.
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(4.0f, 16.0f);
  glDrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_INT, nullptr);
  glDisable(GL_POLYGON_OFFSET_FILL);
  lap(&RenderPhases::draw);
}

// The shadow map's texture: the setup's map, or all 0 (no shadow) without one.
void Renderer::Impl::upload_shadow_map(const ShadowSetup& shadow) {
  if (shadow_texture == 0) {
    glGenTextures(1, &shadow_texture);
    glBindTexture(GL_TEXTURE_2D, shadow_texture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    const float border[4] = {0, 0, 0, 0};  // beyond the map: no shadow
    glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border);
  }
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, shadow_texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  if (shadow.on) {
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, kShadowMapSize, kShadowMapSize, 0, GL_RED, GL_FLOAT,
                 shadow.map.data());
  } else {
    const float none = 0;
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, 1, 1, 0, GL_RED, GL_FLOAT, &none);
  }
  check("uploading the shadow map");
  lap(&RenderPhases::shadow);
}

void Renderer::Impl::build_backdrop(const Frame& frame, const Mat4f& view,
                                    const Mat4f& projection, const Ground& ground,
                                    const ShadowSetup& shadow) {
  if (backdrop_fbo == 0) {
    glGenRenderbuffers(1, &backdrop_color);
    glBindRenderbuffer(GL_RENDERBUFFER, backdrop_color);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, info.samples, GL_RGBA8, fb_width, fb_height);
    glGenRenderbuffers(1, &backdrop_depth);
    glBindRenderbuffer(GL_RENDERBUFFER, backdrop_depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, info.samples, GL_DEPTH_COMPONENT32F,
                                     fb_width, fb_height);
    glGenFramebuffers(1, &backdrop_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, backdrop_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              backdrop_color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                              backdrop_depth);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      fail("Renderer: the " + std::to_string(info.samples) + "-sample backdrop framebuffer of " +
           std::to_string(fb_width) + " x " + std::to_string(fb_height) +
           " is incomplete (out of memory?): " + framebuffer_status_name(status));
    }
    check("allocating the backdrop framebuffer");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, backdrop_fbo);
  glViewport(0, 0, frame.width, frame.height);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  // Without the shadow, which each frame draws over it (with strength 0 the shadowed ground's
  // colour is exactly the unshadowed one).
  if (frame.ground) draw_ground(frame, view, projection, ground, shadow, 0.0f);
  check("drawing the backdrop");
  glBindFramebuffer(GL_READ_FRAMEBUFFER, backdrop_fbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo);
  glBlitFramebuffer(0, 0, frame.width, frame.height, 0, 0, frame.width, frame.height,
                    GL_COLOR_BUFFER_BIT, GL_NEAREST);
  read_back(whole(frame.width, frame.height), backdrop_rgb.data());
  ms_dirty = whole(frame.width, frame.height);  // ms_fbo holds whatever was drawn before
}

// Reads `rect` of the resolved image back into `rgb` (the whole image's rows, top row first;
// GL rows run bottom-up). RGBA is Mesa's fast read-back path (a plain copy); dropping alpha
// here is cheaper than letting GL convert to RGB.
void Renderer::Impl::read_back(const PixelRect& rect, std::uint8_t* rgb) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(rect.x0, rect.y0, rect.width(), rect.height(), GL_RGBA, GL_UNSIGNED_BYTE,
               read_buffer.data());
  check("reading back the image");
  lap(&RenderPhases::read);
  const std::size_t width = static_cast<std::size_t>(rect.width());
  const std::size_t stride = 3 * static_cast<std::size_t>(fb_width);
  for (int y = rect.y0; y < rect.y1; ++y) {
    const std::uint8_t* source = read_buffer.data() + 4 * width * static_cast<std::size_t>(y - rect.y0);
    std::uint8_t* target = rgb + stride * static_cast<std::size_t>(fb_height - 1 - y) +
                           3 * static_cast<std::size_t>(rect.x0);
    for (std::size_t x = 0; x < width; ++x) {
      target[3 * x] = source[4 * x];
      target[3 * x + 1] = source[4 * x + 1];
      target[3 * x + 2] = source[4 * x + 2];
    }
  }
  lap(&RenderPhases::convert);
}

void Renderer::Impl::draw_lines(const Lines& lines) {
  if (lines.segments.empty()) return;
  lap(&RenderPhases::draw);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(lines.positions.size() * sizeof(float)),
               lines.positions.data(), GL_STREAM_DRAW);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(lines.segments.size() * sizeof(unsigned)),
               lines.segments.data(), GL_STREAM_DRAW);
  check("uploading lines");
  lap(&RenderPhases::upload);
  glEnableVertexAttribArray(0);
  glDisableVertexAttribArray(1);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glUniform3fv(line_color, 1, lines.color.data());
  glLineWidth(std::clamp(lines.width, line_width_range[0], line_width_range[1]));
  glDrawElements(GL_LINES, static_cast<GLsizei>(lines.segments.size()), GL_UNSIGNED_INT, nullptr);
  lap(&RenderPhases::draw);
}

Image Renderer::Impl::render(const Frame& frame) {
  if (!failure.empty()) {
    throw std::runtime_error("Renderer: unusable after an earlier failure (" + failure +
                             "); create a new Renderer");
  }
  if (time_phases) {
    phases = RenderPhases{};
    lap_start = std::chrono::steady_clock::now();
  }
  // Validate everything before touching GL.
  require(
      frame.width > 0 && frame.height > 0 && frame.width <= max_width && frame.height <= max_height,
      "frame size " + std::to_string(frame.width) + " x " + std::to_string(frame.height) +
          " outside 1 x 1 .. " + std::to_string(max_width) + " x " + std::to_string(max_height));
  require(frame.camera.fov_deg > 0 && frame.camera.fov_deg < 180,
          "camera fov_deg must lie in (0, 180)");
  require(finite3(frame.background) && std::isfinite(frame.ground_height),
          "background and ground height must be finite");
  require(finite3(frame.up) && (frame.up[0] != 0 || frame.up[1] != 0 || frame.up[2] != 0),
          "up must be finite and non-zero");
  for (std::size_t i = 0; i < frame.meshes.size(); ++i) {
    const Mesh& mesh = frame.meshes[i];
    const std::string what = "mesh " + std::to_string(i);
    validate_vertices(mesh.positions, what);
    require(mesh.normals.empty() || mesh.normals.size() == mesh.positions.size(),
            what + ": normals must be empty or have as many entries as positions");
    validate_indices(mesh.triangles, 3, mesh.positions.size() / 3, what + " triangles");
  }
  for (std::size_t i = 0; i < frame.lines.size(); ++i) {
    const Lines& lines = frame.lines[i];
    const std::string what = "lines " + std::to_string(i);
    validate_vertices(lines.positions, what);
    validate_indices(lines.segments, 2, lines.positions.size() / 3, what + " segments");
  }
  const Mat4f view = view_matrix(frame.camera);  // throws for a degenerate camera

  const Ground ground = ground_of(frame);
  const double distance = ground.half_size / 12.0;  // eye to target
  const ShadowSetup shadow = frame.ground && frame.shadow ? shadow_setup(frame, view, ground) : ShadowSetup{};
  lap(&RenderPhases::shadow);

  // Near and far planes hugging the visible geometry.
  DepthRange range;
  for (const Mesh& mesh : frame.meshes) range.add_all(view, mesh.positions);
  for (const Lines& lines : frame.lines) range.add_all(view, lines.positions);
  if (frame.ground) {
    for (const Vec3d& c : ground.corners()) {
      const Vec3f p = to_f(c);
      range.add(view, p[0], p[1], p[2]);
    }
  }
  double far_plane = 100.0 * distance;  // nothing in front of the camera: any planes do
  double near_plane = 0.01 * distance;
  if (range.hi > 0) {
    far_plane = range.hi * 1.02 + 1e-6 * distance;
    near_plane = std::max(range.lo * 0.98, far_plane * 1e-4);
  }
  const Mat4f projection = projection_matrix(
      frame.camera.fov_deg, static_cast<float>(frame.width) / static_cast<float>(frame.height),
      static_cast<float>(near_plane), static_cast<float>(far_plane));

  // Every allocation of the frame comes before the first GL call, so that running out of memory
  // here (std::bad_alloc) leaves the context untouched and usable.
  std::vector<std::vector<float>> mesh_vertices;
  mesh_vertices.reserve(frame.meshes.size());
  for (const Mesh& mesh : frame.meshes) {
    mesh_vertices.push_back(mesh.triangles.empty() ? std::vector<float>() : interleave(mesh));
  }
  const PixelRect all = whole(frame.width, frame.height);
  const std::size_t pixels = static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height);
  std::vector<float> key = backdrop_key_for(frame, view, projection, ground);
  const bool over_backdrop = key == backdrop_key || key == direct_key;
  const bool new_backdrop = over_backdrop && key != backdrop_key;
  PixelRect drawn = all;
  if (over_backdrop) {
    float widest_line = 1;
    for (const Lines& lines : frame.lines) {
      widest_line = std::max(widest_line, std::clamp(lines.width, line_width_range[0], line_width_range[1]));
    }
    drawn = drawn_rect(frame, view, projection, widest_line);
  }
  // Over the backdrop, the shadow is drawn where it can fall (the ground redrawn there).
  const PixelRect shadowed = over_backdrop && shadow.on ? shadow_rect(frame, view, projection, shadow) : PixelRect{};
  drawn = merge(drawn, shadowed);
  read_buffer.resize(4 * pixels);
  if (new_backdrop) backdrop_rgb.resize(3 * pixels);
  Image image;
  image.width = frame.width;
  image.height = frame.height;
  if (over_backdrop && !new_backdrop) {
    image.rgb = backdrop_rgb;  // the pixels outside `drawn`
  } else {
    image.rgb.resize(3 * pixels);
  }
  lap(&RenderPhases::prepare);

  // Any failure from here on leaves the context in an unknown state (see `failure`).
  try {
    make_current();
    ensure_framebuffers(frame.width, frame.height);
    glClearColor(frame.background[0], frame.background[1], frame.background[2], 1.0f);
    glClearDepth(1.0);
    glDepthMask(GL_TRUE);
    glBindVertexArray(vao);
    if (frame.ground && frame.shadow) upload_shadow_map(shadow);
    if (over_backdrop) {
      if (new_backdrop) {
        build_backdrop(frame, view, projection, ground, shadow);
        backdrop_key = std::move(key);
        std::copy(backdrop_rgb.begin(), backdrop_rgb.end(), image.rgb.begin());
        lap(&RenderPhases::backdrop);
      }
      // Back to the backdrop where the previous frame drew.
      if (!ms_dirty.empty()) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, backdrop_fbo);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, ms_fbo);
        glBlitFramebuffer(ms_dirty.x0, ms_dirty.y0, ms_dirty.x1, ms_dirty.y1, ms_dirty.x0,
                          ms_dirty.y0, ms_dirty.x1, ms_dirty.y1,
                          GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT, GL_NEAREST);
        if (time_phases) glFinish();
        lap(&RenderPhases::restore);
      }
      ms_dirty = drawn;
      glBindFramebuffer(GL_FRAMEBUFFER, ms_fbo);
      glViewport(0, 0, frame.width, frame.height);
      if (!shadowed.empty()) {
        // The ground again where the shadow can fall, now with it, over the backdrop's ground
        // (the same program and vertices: the same samples, so no depth test is needed).
        glEnable(GL_SCISSOR_TEST);
        glScissor(shadowed.x0, shadowed.y0, shadowed.width(), shadowed.height());
        glDisable(GL_DEPTH_TEST);
        glDepthMask(GL_FALSE);
        draw_ground(frame, view, projection, ground, shadow, kShadowStrength);
        glDepthMask(GL_TRUE);
        glEnable(GL_DEPTH_TEST);
        glDisable(GL_SCISSOR_TEST);
      }
    } else {
      glBindFramebuffer(GL_FRAMEBUFFER, ms_fbo);
      glViewport(0, 0, frame.width, frame.height);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      direct_key = std::move(key);
      ms_dirty = all;
    }

    glUseProgram(surface_program);
    glUniformMatrix4fv(surface_view, 1, GL_FALSE, view.data());
    glUniformMatrix4fv(surface_projection, 1, GL_FALSE, projection.data());
    // Meshes are pushed slightly back so that coincident wireframe lines win the depth test.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 1.0f);
    for (std::size_t i = 0; i < frame.meshes.size(); ++i) {
      draw_mesh(frame.meshes[i], mesh_vertices[i]);
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    if (frame.ground && !over_backdrop) {
      draw_ground(frame, view, projection, ground, shadow, kShadowStrength);
    }

    if (!frame.lines.empty()) {
      glUseProgram(line_program);
      glUniformMatrix4fv(line_view, 1, GL_FALSE, view.data());
      glUniformMatrix4fv(line_projection, 1, GL_FALSE, projection.data());
      for (const Lines& lines : frame.lines) draw_lines(lines);
    }
    check("drawing");
    lap(&RenderPhases::draw);
    if (time_phases) {
      glFinish();
      lap(&RenderPhases::raster);
    }

    // Resolve the samples where the frame drew, then read them back.
    if (!drawn.empty()) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, ms_fbo);
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo);
      glBlitFramebuffer(drawn.x0, drawn.y0, drawn.x1, drawn.y1, drawn.x0, drawn.y0, drawn.x1,
                        drawn.y1, GL_COLOR_BUFFER_BIT, GL_NEAREST);
      if (time_phases) {
        glFinish();
        lap(&RenderPhases::resolve);
      }
      read_back(drawn, image.rgb.data());
    }
  } catch (const std::exception& e) {
    if (failure.empty()) failure = e.what();
    throw;
  } catch (...) {
    if (failure.empty()) failure = "Renderer: unknown error while drawing";
    throw;
  }
  return image;
}

Renderer::Renderer(int max_width, int max_height, int samples)
    : impl_(std::make_unique<Impl>(max_width, max_height, samples)) {}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

Image Renderer::render(const Frame& frame) {
  if (!impl_) throw std::logic_error("Renderer::render: renderer was moved from");
  return impl_->render(frame);
}

void Renderer::release_context() {
  if (!impl_ || impl_->context == nullptr || !impl_->failure.empty()) return;
  if (OSMesaGetCurrentContext() == impl_->context) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
}

const RendererInfo& Renderer::info() const { return impl_->info; }
void Renderer::set_phase_timing(bool on) { impl_->time_phases = on; }
const RenderPhases& Renderer::last_phases() const { return impl_->phases; }
int Renderer::max_width() const { return impl_->max_width; }
int Renderer::max_height() const { return impl_->max_height; }

}  // namespace clothsim::render

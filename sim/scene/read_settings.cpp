// The scene sections that are plain settings: see read_settings.hpp.
#include "sim/scene/read_settings.hpp"
#include "sim/scene/render_settings_json.hpp"

#include "sim/problem/validate.hpp"
#include "sim/shell/material_presets.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace clothsim {
namespace scene_io {
namespace {

// The orthotropic parts of "material" (scenes/README.md, Material): "stretch_modulus" and
// "bending_rigidity" as objects, or as numbers (isotropic) beside an object or an orthotropic
// preset. `base` is the material the other keys made (solid or preset); `poisson_json` the
// "poisson_ratio" key, if given.
ShellMaterial read_orthotropic(const Reader& r, const Json& j, const ShellMaterial& base, const Json* poisson_json,
                               double poisson) {
  Orthotropy o = base.orthotropic() ? *base.orthotropy : isotropic_orthotropy(base);
  bool twist_set = base.orthotropic();  // an orthotropic preset's twist stays unless its bending is replaced
  bool membrane_orthotropic = base.orthotropic();
  const Json* stretch = r.find(j, "stretch_modulus");
  if (stretch != nullptr && stretch->is_object()) {
    const std::string path = "material.stretch_modulus";
    r.check_object(*stretch, path, {"warp", "weft", "shear", "poisson"});
    o.warp_stretch = r.positive(r.require(*stretch, path, "warp"), path + ".warp", "[N/m]");
    o.weft_stretch = r.positive(r.require(*stretch, path, "weft"), path + ".weft", "[N/m]");
    o.shear_stretch = r.positive(r.require(*stretch, path, "shear"), path + ".shear", "[N/m]");
    o.poisson = r.non_negative(r.require(*stretch, path, "poisson"), path + ".poisson", "[-]");
    if (!(o.poisson * o.poisson < o.warp_stretch / o.weft_stretch))
      r.fail(path + ".poisson", "makes the membrane law indefinite: poisson^2 must be < warp/weft = " +
                                    format_number(o.warp_stretch / o.weft_stretch) + " (got " +
                                    format_number(o.poisson) + "; nu_warp,weft * nu_weft,warp must be < 1)");
    membrane_orthotropic = true;
  } else if (stretch != nullptr) {
    const double e = r.positive(*stretch, "material.stretch_modulus", "[N/m]");
    const double nu = poisson_json != nullptr ? poisson : o.poisson;
    o.warp_stretch = o.weft_stretch = e;
    o.shear_stretch = e / (2.0 * (1.0 + nu));
    o.poisson = nu;
    membrane_orthotropic = false;
  }
  if (poisson_json != nullptr && membrane_orthotropic)
    r.fail("material.poisson_ratio", std::string("cannot be combined with an orthotropic membrane (") +
                                         (stretch != nullptr ? "stretch_modulus as an object" : "an orthotropic preset") +
                                         "): give its Poisson ratio as stretch_modulus.poisson");
  const Json* bending = r.find(j, "bending_rigidity");
  if (bending != nullptr && bending->is_object()) {
    const std::string path = "material.bending_rigidity";
    r.check_object(*bending, path, {"warp", "weft", "twist"});
    o.warp_bending = r.positive(r.require(*bending, path, "warp"), path + ".warp", "[N·m]");
    o.weft_bending = r.positive(r.require(*bending, path, "weft"), path + ".weft", "[N·m]");
    twist_set = false;
    if (const Json* t = r.find(*bending, "twist")) {
      o.twist = r.positive(*t, path + ".twist", "[N·m]");
      twist_set = true;
    }
  } else if (bending != nullptr) {
    o.warp_bending = o.weft_bending = r.positive(*bending, "material.bending_rigidity", "[N·m]");
    twist_set = false;
  }
  if (!twist_set) o.twist = default_twist(o.warp_bending, o.weft_bending, o.poisson);
  if (!(o.poisson * o.poisson < o.warp_bending / o.weft_bending))
    r.fail("material.bending_rigidity", "with the membrane's poisson " + format_number(o.poisson) +
                                            " the bending law is indefinite: poisson^2 must be < warp/weft = " +
                                            format_number(o.warp_bending / o.weft_bending));
  ShellMaterial m = base;
  set_orthotropy(m, o);
  return m;
}

}  // namespace

long long read_max_vertices(const Reader& r, const Json& root) {
  const Json* mesh = r.find(root, "mesh");
  if (mesh == nullptr || !mesh->is_object()) return kDefaultMaxVertices;
  const Json* v = r.find(*mesh, "max_vertices");
  return v == nullptr ? kDefaultMaxVertices : r.integer_at_least(*v, "mesh.max_vertices", 3);
}

ShellMaterial read_material(const Reader& r, const Json* j, GrainSpec& grain) {
  double youngs = 1e7, poisson = 0.3, thickness = 0.001, density = 1000.0;
  if (j == nullptr) return ShellMaterial::from_solid(youngs, poisson, thickness, density);
  const std::string path = "material";
  r.check_object(*j, path,
                 {"preset", "youngs_modulus", "poisson_ratio", "thickness", "density", "stretch_modulus",
                  "bending_rigidity", "areal_density", "grain"});
  if (const Json* g = r.find(*j, "grain")) {
    r.check_object(*g, "material.grain", {"warp_deg"});
    grain.given = true;
    if (const Json* w = r.find(*g, "warp_deg")) grain.warp_deg = r.number(*w, "material.grain.warp_deg");
  }
  const Json* preset = r.find(*j, "preset");
  std::string preset_name;
  if (preset != nullptr) {
    preset_name = r.choice(*preset, "material.preset", material_preset_names(), "preset");
    // A preset is given by its stretch modulus, bending rigidity and areal density directly; it
    // has no Young's modulus, thickness or density to combine with.
    for (const char* solid : {"youngs_modulus", "thickness", "density"})
      if (r.find(*j, solid) != nullptr)
        r.fail(join_key(path, solid), "cannot be combined with \"preset\" (a preset sets stretch_modulus, "
                                      "bending_rigidity, poisson_ratio and areal_density; override those instead)");
  }
  if (const Json* v = r.find(*j, "youngs_modulus")) youngs = r.positive(*v, "material.youngs_modulus", "[Pa]");
  const Json* poisson_json = r.find(*j, "poisson_ratio");
  if (poisson_json != nullptr) {
    poisson = r.number(*poisson_json, "material.poisson_ratio");
    if (!(poisson >= 0 && poisson < 0.5))
      r.fail("material.poisson_ratio", "must be >= 0 and < 0.5 (got " + poisson_json->dump() + ")");
  }
  if (const Json* v = r.find(*j, "thickness")) thickness = r.positive(*v, "material.thickness", "[m]");
  if (const Json* v = r.find(*j, "density")) density = r.non_negative(*v, "material.density", "[kg/m³]");

  ShellMaterial m = ShellMaterial::from_solid(youngs, poisson, thickness, density);
  if (preset != nullptr) {
    m = *material_preset(preset_name);
    if (poisson_json != nullptr && !m.orthotropic()) m.poisson_ratio = poisson;
  }
  const Json* stretch = r.find(*j, "stretch_modulus");
  const Json* bending = r.find(*j, "bending_rigidity");
  const bool object_form = (stretch != nullptr && stretch->is_object()) || (bending != nullptr && bending->is_object());
  if (object_form || m.orthotropic()) {
    m = read_orthotropic(r, *j, m, poisson_json, poisson);
  } else {
    if (stretch != nullptr) m.stretch_modulus = r.positive(*stretch, "material.stretch_modulus", "[N/m]");
    if (bending != nullptr) m.bending_rigidity = r.positive(*bending, "material.bending_rigidity", "[N·m]");
  }
  if (const Json* v = r.find(*j, "areal_density"))
    m.areal_density = r.non_negative(*v, "material.areal_density", "[kg/m²]");
  const std::string problem = validate(m);
  if (!problem.empty()) r.fail(path, problem);
  return m;
}

Quadrature read_numerics(const Reader& r, const Json* j) {
  if (j == nullptr) return Quadrature::one_point;
  r.check_object(*j, "numerics", {"quadrature"});
  const Json* q = r.find(*j, "quadrature");
  if (q == nullptr) return Quadrature::one_point;
  const std::string s = r.choice(*q, "numerics.quadrature", {"one_point", "three_point", "six_point"});
  if (s == "three_point") return Quadrature::three_point;
  if (s == "six_point") return Quadrature::six_point;
  return Quadrature::one_point;
}

Motion read_motion(const Reader& r, const Json& item, const std::string& path) {
  if (!item.is_object()) r.fail(path, "expected an object (got " + describe(item) + ")");
  const std::string type = r.choice(r.require(item, path, "type"), join_key(path, "type"),
                                    {"rotate", "translate", "hold"}, "motion type");
  Motion m;
  if (type == "rotate") {
    r.check_object(item, path, {"type", "axis", "center", "angle_deg", "start", "end"});
    m.type = Motion::Type::rotate;
  } else if (type == "translate") {
    r.check_object(item, path, {"type", "displacement", "start", "end"});
    m.type = Motion::Type::translate;
  } else {
    r.check_object(item, path, {"type", "start", "end"});
    m.type = Motion::Type::hold;
  }
  m.start = r.non_negative(r.require(item, path, "start"), join_key(path, "start"), "[s]");
  const std::string end_path = join_key(path, "end");
  m.end = r.number(r.require(item, path, "end"), end_path);
  if (!(m.end >= m.start))
    r.fail(end_path, "must be >= start = " + format_number(m.start) + " [s] (got " + format_number(m.end) + ")");
  if (m.type == Motion::Type::rotate) {
    const std::string axis_path = join_key(path, "axis");
    m.axis = r.vec3(r.require(item, path, "axis"), axis_path);
    if (!(m.axis.norm() > 0)) r.fail(axis_path, "must be a non-zero vector (got " + format_point(m.axis) + ")");
    if (const Json* c = r.find(item, "center")) m.center = r.vec3(*c, join_key(path, "center"));
    m.angle_deg = r.number(r.require(item, path, "angle_deg"), join_key(path, "angle_deg"));
  } else if (m.type == Motion::Type::translate) {
    m.displacement = r.vec3(r.require(item, path, "displacement"), join_key(path, "displacement"));
  }
  const std::string problem = validate(m);
  if (!problem.empty()) r.fail(path, problem);
  return m;
}

TimeSettings read_time(const Reader& r, const Json* j) {
  TimeSettings t;
  if (j == nullptr) return t;
  r.check_object(*j, "time", {"dt", "end", "output_fps"});
  if (const Json* v = r.find(*j, "dt")) t.dt = r.positive(*v, "time.dt", "[s]");
  if (const Json* v = r.find(*j, "end")) t.end = r.positive(*v, "time.end", "[s]");
  if (t.end < t.dt)
    r.fail("time.end", "must be >= time.dt = " + format_number(t.dt) + " [s] (got " + format_number(t.end) + ")");
  if (const Json* v = r.find(*j, "output_fps")) t.output_fps = r.positive(*v, "time.output_fps", "[1/s]");
  if (const std::string problem = time_limit_problem(t); !problem.empty()) r.fail("time", problem);
  return t;
}

DampingSettings read_damping(const Reader& r, const Json* j) {
  DampingSettings d;
  if (j == nullptr) return d;
  r.check_object(*j, "damping", {"stiffness", "mass"});
  if (const Json* v = r.find(*j, "stiffness")) d.stiffness = r.non_negative(*v, "damping.stiffness", "[s]");
  if (const Json* v = r.find(*j, "mass")) d.mass = r.non_negative(*v, "damping.mass", "[1/s]");
  return d;
}

SolverSettings read_solver(const Reader& r, const Json* j) {
  SolverSettings s;
  if (j == nullptr) return s;
  r.check_object(*j, "solver",
                 {"type", "tolerance", "max_iterations", "newton_iterations", "rotation_tolerance_deg", "preconditioner",
                  "refresh_iterations", "tension_stiffening", "warm_start"});
  if (const Json* v = r.find(*j, "type")) {
    const std::string type = r.choice(*v, "solver.type", {"auto", "pcg", "cholmod"}, "solver type");
    s.type = type == "cholmod" ? LinearSolverType::cholmod
             : type == "pcg"   ? LinearSolverType::pcg
                               : LinearSolverType::automatic;
  }
  if (const Json* v = r.find(*j, "tolerance")) {
    s.tolerance = r.number(*v, "solver.tolerance");
    if (!(s.tolerance > 0 && s.tolerance < 1))
      r.fail("solver.tolerance", "must be > 0 and < 1 (got " + v->dump() + ")");
  }
  if (const Json* v = r.find(*j, "max_iterations")) s.max_iterations = r.integer_at_least(*v, "solver.max_iterations", 1);
  if (const Json* v = r.find(*j, "newton_iterations"))
    s.newton_iterations = r.integer_at_least(*v, "solver.newton_iterations", 1);
  if (const Json* v = r.find(*j, "rotation_tolerance_deg")) {
    s.rotation_tolerance_deg = r.number(*v, "solver.rotation_tolerance_deg");
    if (!(s.rotation_tolerance_deg > 0 && s.rotation_tolerance_deg <= 180))
      r.fail("solver.rotation_tolerance_deg", "must be > 0 and <= 180 [deg] (got " + v->dump() + ")");
  }
  if (const Json* v = r.find(*j, "preconditioner")) {
    const std::string p = r.choice(*v, "solver.preconditioner", {"auto", "block_jacobi", "cholesky"}, "preconditioner");
    s.preconditioner = p == "cholesky"       ? PreconditionerType::cholesky
                       : p == "block_jacobi" ? PreconditionerType::block_jacobi
                                             : PreconditionerType::automatic;
  }
  if (const Json* v = r.find(*j, "refresh_iterations"))
    s.refresh_iterations = r.integer_at_least(*v, "solver.refresh_iterations", 1);
  if (const Json* v = r.find(*j, "tension_stiffening")) s.tension_stiffening = r.boolean(*v, "solver.tension_stiffening");
  if (const Json* v = r.find(*j, "warm_start"))
    s.extrapolated_start =
        r.choice(*v, "solver.warm_start", {"extrapolated", "last_velocity"}, "warm start") == "extrapolated";
  return s;
}

InitialState read_initial(const Reader& r, const Json* j) {
  InitialState s;
  if (j == nullptr) return s;
  r.check_object(*j, "initial", {"velocity", "angular_velocity", "center"});
  if (const Json* v = r.find(*j, "velocity")) s.velocity = r.vec3(*v, "initial.velocity");
  if (const Json* v = r.find(*j, "angular_velocity")) s.angular_velocity = r.vec3(*v, "initial.angular_velocity");
  if (const Json* v = r.find(*j, "center")) s.center = r.vec3(*v, "initial.center");
  return s;
}

void read_output(const Reader& r, const Json* j, Scene& scene) {
  if (j == nullptr) return;
  r.check_object(*j, "output", {"obj", "obj_level", "checkpoint_every", "cache"});
  if (const Json* every = r.find(*j, "checkpoint_every"))
    scene.checkpoint_every = r.integer_at_least(*every, "output.checkpoint_every", 0);
  if (const Json* obj = r.find(*j, "obj")) scene.write_obj_frames = r.boolean(*obj, "output.obj");
  if (const Json* level = r.find(*j, "obj_level")) {
    scene.obj_level = r.integer_at_least(*level, "output.obj_level", 0);
    if (scene.obj_level > 4) r.fail("output.obj_level", "must be an integer from 0 to 4 (got " + level->dump() + ")");
  }
  if (const Json* cache = r.find(*j, "cache")) {
    scene.point_cache = r.choice(*cache, "output.cache", {"none", "pc2"}, "point cache");
    if (scene.point_cache != "none" && !scene.write_obj_frames)
      r.fail("output.cache", "\"" + scene.point_cache + "\" is built from the OBJ frames: needs \"obj\": true");
  }
}

SettleSettings read_settle(const Reader& r, const Json* j) {
  SettleSettings s;
  if (j == nullptr) return s;
  r.check_object(*j, "settle", {"time", "damping"});
  if (const Json* v = r.find(*j, "time")) s.time = r.non_negative(*v, "settle.time", "[s]");
  if (const Json* v = r.find(*j, "damping")) s.damping = r.positive(*v, "settle.damping", "[1/s]");
  return s;
}

Imperfection read_imperfection(const Reader& r, const Json* j) {
  Imperfection imp;
  if (j == nullptr) return imp;
  r.check_object(*j, "imperfection", {"amplitude", "seed", "wavelength"});
  imp.amplitude = r.non_negative(r.require(*j, "imperfection", "amplitude"), "imperfection.amplitude", "[m]");
  if (const Json* v = r.find(*j, "seed")) imp.seed = static_cast<std::uint64_t>(r.integer_at_least(*v, "imperfection.seed", 0));
  if (const Json* v = r.find(*j, "wavelength")) {
    const Json& w = r.sized_array(*v, "imperfection.wavelength", 2, "numbers [m] (shortest, longest)");
    imp.wavelength_min = r.positive(w[0], "imperfection.wavelength[0]", "[m]");
    imp.wavelength_max = r.positive(w[1], "imperfection.wavelength[1]", "[m]");
    if (imp.wavelength_min > imp.wavelength_max)
      r.fail("imperfection.wavelength", "the shortest wavelength (first) must not exceed the longest (got " + v->dump() + ")");
  }
  return imp;
}

void read_collision(const Reader& r, const Json* j, Problem& problem, bool& level_given) {
  level_given = false;
  if (j == nullptr) return;
  r.check_object(*j, "collision", {"self", "thickness", "friction", "tolerance", "surface_level", "method"});
  CollisionSettings& c = problem.collision;
  if (const Json* v = r.find(*j, "self")) c.self = r.boolean(*v, "collision.self");
  if (const Json* v = r.find(*j, "thickness")) c.thickness = r.positive(*v, "collision.thickness", "[m]");
  if (const Json* v = r.find(*j, "friction")) c.friction = r.non_negative(*v, "collision.friction", "[-]");
  if (const Json* v = r.find(*j, "tolerance")) {
    c.tolerance = r.positive(*v, "collision.tolerance", "[-]");
    if (c.tolerance > 0.1) r.fail("collision.tolerance", "must be > 0 and at most 0.1 (got " + v->dump() + ")");
  }
  if (const Json* v = r.find(*j, "method")) {
    if (!v->is_string() || (*v != "barrier" && *v != "constraints"))
      r.fail("collision.method", "must be \"barrier\" or \"constraints\" (got " + v->dump() + ")");
    c.barrier = *v == "barrier";
  }
  if (const Json* v = r.find(*j, "surface_level")) {
    problem.collision_level = r.integer_at_least(*v, "collision.surface_level", 0);
    if (problem.collision_level > 4)
      r.fail("collision.surface_level", "must be an integer from 0 to 4 (got " + v->dump() + ")");
    level_given = true;
  }
}

RenderSettings read_render(const Reader& r, const Json* j) {
  RenderSettings s;
  if (j == nullptr) return s;
  r.check_object(*j, "render",
                 {"width", "height", "refine", "color", "back_color", "background", "wireframe", "ground", "shadow",
                  "camera", "framing", "surface", "texture", "up"});
  if (const Json* v = r.find(*j, "width")) s.width = r.integer_at_least(*v, "render.width", 16);
  if (const Json* v = r.find(*j, "height")) s.height = r.integer_at_least(*v, "render.height", 16);
  if (s.width > 8192 || s.height > 8192) r.fail("render", "images larger than 8192 px are not supported");
  if (const Json* v = r.find(*j, "refine")) {
    s.refine = r.integer_at_least(*v, "render.refine", 0);
    if (s.refine > 4) r.fail("render.refine", "must be an integer from 0 to 4 (got " + v->dump() + ")");
  }
  auto colour = [&](const char* key, Eigen::Vector3d& out) {
    if (const Json* v = r.find(*j, key)) {
      const std::string path = std::string("render.") + key;
      out = r.vec3(*v, path);
      if ((out.array() < 0).any() || (out.array() > 1).any())
        r.fail(path, "colour components must lie in [0, 1] (got " + v->dump() + ")");
    }
  };
  colour("color", s.color);
  colour("back_color", s.back_color);
  colour("background", s.background);
  if (const Json* v = r.find(*j, "wireframe")) s.wireframe = r.boolean(*v, "render.wireframe");
  if (const Json* v = r.find(*j, "texture")) {
    s.texture = r.choice(*v, "render.texture", {"none", "grain", "checker"}, "texture");
    s.texture_given = true;
  }
  if (const Json* v = r.find(*j, "ground")) {
    s.ground = r.boolean(*v, "render.ground");
    s.ground_given = true;
  }
  if (const Json* v = r.find(*j, "shadow")) s.shadow = r.boolean(*v, "render.shadow");
  if (const Json* v = r.find(*j, "up")) {
    const Eigen::Vector3d up = r.vec3(*v, "render.up");
    if (!(up.norm() > 0)) r.fail("render.up", "must not be the zero vector");
    s.world_up = up.normalized();
    s.up_given = true;
  }
  if (const Json* v = r.find(*j, "surface")) {
    const std::string surface = r.choice(*v, "render.surface", {"method", "loop_limit", "flat"}, "surface");
    s.surface = surface == "loop_limit" ? DrawnSurface::loop_limit
                : surface == "flat"     ? DrawnSurface::flat
                                        : DrawnSurface::method;
  }
  if (const Json* v = r.find(*j, "framing"))
    s.framing = r.choice(*v, "render.framing", {"motion", "sequence"}, "framing") == "sequence" ? Framing::sequence
                                                                                             : Framing::motion;
  if (const Json* cam = r.find(*j, "camera")) {
    r.check_object(*cam, "render.camera", {"eye", "target", "up", "fov_deg"});
    s.has_camera = true;
    s.eye = r.vec3(r.require(*cam, "render.camera", "eye"), "render.camera.eye");
    s.target = r.vec3(r.require(*cam, "render.camera", "target"), "render.camera.target");
    if (const Json* v = r.find(*cam, "up")) s.up = r.vec3(*v, "render.camera.up");
    if (const Json* v = r.find(*cam, "fov_deg")) {
      s.fov_deg = r.number(*v, "render.camera.fov_deg");
      if (!(s.fov_deg > 1 && s.fov_deg < 170)) r.fail("render.camera.fov_deg", "must lie in (1, 170) degrees (got " + v->dump() + ")");
    }
    if ((s.eye - s.target).norm() <= 0) r.fail("render.camera", "eye and target must differ");
    if (s.up.cross(s.eye - s.target).norm() <= 1e-12 * s.up.norm() * (s.eye - s.target).norm())
      r.fail("render.camera.up", "must not be parallel to the viewing direction");
  }
  return s;
}

}  // namespace scene_io

using scene_io::format_number;

std::string time_limit_problem(const TimeSettings& t) {
  auto count = [](double n) {
    char buffer[48];
    std::snprintf(buffer, sizeof buffer, n < 1e15 ? "%.0f" : "%.3g", n);
    return std::string(buffer);
  };
  const double steps = std::ceil(t.end / t.dt - 1e-9);
  if (!(steps <= kMaxSteps))
    return "time.end / time.dt = " + format_number(t.end) + " / " + format_number(t.dt) + " needs " + count(steps) +
           " steps, more than the limit of " + count(kMaxSteps) + " (a larger time.dt or a shorter time.end)";
  const double frames = std::floor(t.end * t.output_fps + 1e-9) + 1.0;
  if (!(frames <= kMaxFrames))
    return "time.output_fps = " + format_number(t.output_fps) + " over time.end = " + format_number(t.end) +
           " s makes " + count(frames) + " frames, more than the limit of " + count(kMaxFrames);
  return "";
}

RenderSettings render_settings_from_json(const nlohmann::json& render, const std::string& where) {
  return scene_io::read_render(scene_io::Reader(where), &render);
}

}  // namespace clothsim

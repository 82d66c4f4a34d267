#include "sim/study/fabric_tests.hpp"

#include "sim/dynamics/simulator.hpp"
#include "sim/static/static_solve.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace clothsim {

using Json = nlohmann::json;
namespace {

constexpr double kGravity = 9.81;  // [m/s²], the shipped scenes' value
constexpr double kPi = 3.14159265358979323846;

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The material with the grain of a strip (or disc) cut at `angle_deg` to the warp: the grain's
// warp_deg is −angle, so the strip's axis (+x) makes `angle` with the warp.
Json with_grain(const FabricUnderTest& fabric, double warp_deg) {
  Json m = fabric.material;
  m["grain"] = Json{{"warp_deg", warp_deg}};
  return m;
}

}  // namespace

std::optional<FabricMeasurement> fabric_measurement(const std::string& preset) {
  // Matsudaira, Yamazaki & Hayashi, J. Textile Eng. 61(6):69 (2015): KES-FB2 bending rigidity
  // (mean of warp and weft) and areal density (Table 1), Cusick drape coefficient and node count
  // of a 30 cm specimen on an 18 cm support.
  static const char* kSource = "Matsudaira et al. 2015 (KES-FB2 B, Cusick DC and nodes)";
  static const std::vector<std::pair<std::string, FabricMeasurement>> kFabrics = {
      {"cotton_broadcloth", {"cotton broadcloth", 1.157e-5, 0.1238, 0.829, 2, kSource}},
      {"wool_tropical", {"wool tropical", 6.57e-6, 0.1629, 0.498, 5, kSource}},
      {"polyester_tropical", {"polyester tropical", 7.55e-6, 0.1165, 0.507, 5, kSource}},
      {"polyester_faille", {"polyester faille", 1.86e-6, 0.1043, 0.283, 7, kSource}},
  };
  std::string base = preset;
  if (base.size() > 6 && base.compare(base.size() - 6, 6, "_ortho") == 0) base.resize(base.size() - 6);
  for (const auto& [name, m] : kFabrics)
    if (name == base) return m;
  return std::nullopt;
}

FabricUnderTest fabric_under_test(const std::string& preset_or_scene) {
  FabricUnderTest f;
  const bool is_file = preset_or_scene.size() > 5 && preset_or_scene.compare(preset_or_scene.size() - 5, 5, ".json") == 0;
  std::filesystem::path scene_file = "fabric_test.json";
  if (is_file) {
    scene_file = preset_or_scene;
    Json scene;
    try {
      scene = Json::parse(read_file(scene_file));
    } catch (const Json::exception& e) {
      throw SceneError(scene_file.string() + ": " + e.what());
    }
    if (!scene.is_object() || !scene.contains("material") || !scene["material"].is_object())
      throw SceneError(scene_file.string() + ": material: the scene has no \"material\" object to test");
    f.material = scene["material"];
    f.label = scene_file.stem().string();
    if (f.material.contains("preset") && f.material["preset"].is_string())
      f.measured = fabric_measurement(f.material["preset"].get<std::string>());
  } else {
    f.material = Json{{"preset", preset_or_scene}};
    f.label = preset_or_scene;
    f.measured = fabric_measurement(preset_or_scene);
  }
  f.material.erase("grain");
  // Read the material as a scene reads it (its errors name the key), on a small grid.
  const Json probe = {{"name", "fabric_test"},
                      {"analysis", "static"},
                      {"mesh", {{"primitive", "grid"}, {"size", {0.1, 0.1}}, {"divisions", {2, 2}}}},
                      {"material", with_grain(f, 0.0)}};
  f.law = load_scene_text(probe.dump(), scene_file, {}).problem.material;
  return f;
}

double strip_bending_rigidity(const ShellMaterial& m, double angle_deg) {
  if (!m.orthotropic()) return m.bending_rigidity;
  const double a = angle_deg * kPi / 180.0;
  return directional_modulus(m.bending_law(), std::cos(a), std::sin(a));
}

double strip_stretch_modulus(const ShellMaterial& m, double angle_deg) {
  const double a = angle_deg * kPi / 180.0;
  return directional_modulus(m.membrane_law(), std::cos(a), std::sin(a));
}

double shear_modulus(const ShellMaterial& m) { return m.membrane_law()(2, 2); }

// ---- Cantilever ----------------------------------------------------------------------------------

Json cantilever_scene(const FabricUnderTest& fabric, double angle_deg, double overhang, const CantileverSettings& s,
                      const std::string& apparatus_obj) {
  const double w = s.width;
  Json scene = {
      {"name", "cantilever"},
      {"description", "ASTM D1388 cantilever: a strip cut at " + std::to_string(angle_deg) +
                          " deg to the warp, held flat on the platform up to its edge (x = 0) and hanging over it"},
      {"analysis", "dynamic"},
      // The grid lies in z = 0 with its width along y; turned by 90° about x its width runs
      // along z and the strip lies in the horizontal x–z plane, hanging over +x.
      {"mesh",
       {{"primitive", "grid"},
        {"size", {overhang, w}},
        {"divisions", {s.cells_along, s.cells_across}},
        {"rotate", {{"axis", {1, 0, 0}}, {"angle_deg", 90}}},
        {"translate", {overhang / 2, 0, 0}}}},
      {"material", with_grain(fabric, -angle_deg)},
      {"boundary",
       {{{"select", {{"box", {{-1e-6 * overhang, -1, -1}, {1e-6 * overhang, 1, 1}}}}},
         {"fix", {"x", "y", "z"}},
         {"rotation", "clamped"}}}},
      {"loads", {{"gravity", {0, -kGravity, 0}}}},
      {"time", {{"dt", s.dt}, {"end", s.settle}, {"output_fps", 2.0 / s.settle}}},
      {"damping", {{"stiffness", 0.0}, {"mass", s.mass_damping}}},
      {"probes", {{{"name", "tip"}, {"at", {overhang, 0, 0}}}}},
      {"render",
       {{"background", {1, 1, 1}},
        {"camera", {{"eye", {overhang * 1.2, overhang * 0.6, overhang * 2.4}}, {"target", {overhang * 0.4, -overhang * 0.35, 0}}}}}},
  };
  if (!apparatus_obj.empty()) {
    scene["collision"] = Json{{"self", false}, {"thickness", 0.0005}, {"friction", 0.3}};
    scene["obstacles"] = Json::array({Json{{"name", "apparatus"}, {"obj", apparatus_obj}}});
  }
  return scene;
}

std::string cantilever_apparatus_obj(double incline_deg, double gap, double width) {
  // The profile in x–y (counter-clockwise seen from +z), extruded over z ∈ [−width, width].
  const double depth = 0.06, back = 0.05;
  const double run = depth / std::tan(incline_deg * kPi / 180.0);
  const std::vector<std::pair<double, double>> profile = {
      {-back, -gap - depth}, {run, -gap - depth}, {0.0, -gap}, {-back, -gap}};
  std::ostringstream o;
  o << std::setprecision(10) << "# cantilever tester: platform (top y = " << -gap << " m, edge x = 0) and incline ("
    << incline_deg << " deg)\n";
  for (const double z : {width, -width})
    for (const auto& [x, y] : profile) o << "v " << x << ' ' << y << ' ' << z << '\n';
  // Front cap (z = +width, counter-clockwise seen from +z), back cap reversed, four sides.
  o << "f 1 2 3\nf 1 3 4\nf 5 7 6\nf 5 8 7\n";
  for (int i = 0; i < 4; ++i) {
    const int a = i + 1, b = (i + 1) % 4 + 1;  // front edge a→b; back vertices +4
    o << "f " << a << ' ' << a + 4 << ' ' << b + 4 << "\nf " << a << ' ' << b + 4 << ' ' << b << '\n';
  }
  return o.str();
}

CantileverRun run_cantilever(const FabricUnderTest& fabric, double angle_deg, double overhang,
                             const CantileverSettings& s) {
  const auto t0 = std::chrono::steady_clock::now();
  const Scene scene = load_scene_text(cantilever_scene(fabric, angle_deg, overhang, s).dump(), "cantilever.json", {});
  Simulator sim(scene.problem);
  const int steps = static_cast<int>(std::lround(s.settle / s.dt));
  for (int i = 0; i < steps; ++i) sim.step();
  const int tip = scene.probes.at(0).vertex;
  const Eigen::Vector3d p = sim.node_points().row(tip).transpose();
  CantileverRun run;
  run.overhang = overhang;
  run.chord_deg = std::atan2(-p.y(), p.x()) * 180.0 / kPi;
  sim.step();  // one more: the tip's speed at rest
  run.tip_speed = (sim.node_points().row(tip).transpose() - p).norm() / s.dt;
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

CantileverResult cantilever_test(const FabricUnderTest& fabric, double angle_deg, const CantileverSettings& s,
                                 const std::function<void(const std::string&)>& log) {
  CantileverResult r;
  r.angle_deg = angle_deg;
  const double weight = fabric.law.areal_density * kGravity;  // w [N/m²]
  r.expected_length = std::cbrt(strip_bending_rigidity(fabric.law, angle_deg) / weight);
  const auto measure = [&](double length) {
    CantileverRun run = run_cantilever(fabric, angle_deg, length, s);
    if (log) {
      std::ostringstream line;
      line << std::fixed << std::setprecision(2) << "cantilever " << angle_deg << " deg: overhang " << length * 1000
           << " mm -> chord " << std::setprecision(3) << run.chord_deg << " deg (" << std::setprecision(1)
           << run.seconds << " s)";
      log(line.str());
    }
    r.runs.push_back(run);
    return run.chord_deg;
  };
  // The secant method on (log L, angle): the angle grows like (L/c)³ at first, smoothly after.
  double x0 = std::log(2 * r.expected_length * 0.9), x1 = std::log(2 * r.expected_length * 1.1);
  double f0 = measure(std::exp(x0)) - s.incline_deg, f1 = measure(std::exp(x1)) - s.incline_deg;
  while (std::abs(f1) > s.tolerance_deg) {
    if (static_cast<int>(r.runs.size()) >= s.max_runs)
      throw std::runtime_error("cantilever test at " + std::to_string(angle_deg) + " deg: the chord angle did not reach " +
                               std::to_string(s.incline_deg) + " deg within " + std::to_string(s.max_runs) + " runs");
    if (f1 == f0) throw std::runtime_error("cantilever test: the chord angle does not change with the overhang");
    double x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
    x2 = std::clamp(x2, x1 - 0.7, x1 + 0.7);  // at most a factor 2 per run
    x0 = x1;
    f0 = f1;
    x1 = x2;
    f1 = measure(std::exp(x1)) - s.incline_deg;
  }
  r.overhang = std::exp(x1);
  r.bending_length = r.overhang / 2;
  r.flexural_rigidity = weight * r.bending_length * r.bending_length * r.bending_length;
  return r;
}

// ---- Tensile -------------------------------------------------------------------------------------

Json tensile_scene(const FabricUnderTest& fabric, double angle_deg, const TensileSettings& s) {
  const double L = s.length, W = s.width;
  const double force = strip_stretch_modulus(fabric.law, angle_deg) * s.strain * W;
  Json point_loads = Json::array();
  for (int j = 0; j <= s.cells_across; ++j) {
    const double share = (j == 0 || j == s.cells_across) ? 0.5 : 1.0;
    point_loads.push_back({{"at", {L / 2, -W / 2 + W * j / s.cells_across, 0}},
                           {"force", {share * force / s.cells_across, 0, 0}}});
  }
  const double e = 1e-6 * L;
  return Json{
      {"name", "tensile"},
      {"description", "uniaxial tensile test at small strain: a strip cut at " + std::to_string(angle_deg) +
                          " deg to the warp, its left end on rollers, pulled along x"},
      {"analysis", "static"},
      {"mesh", {{"primitive", "grid"}, {"size", {L, W}}, {"divisions", {s.cells_along, s.cells_across}}}},
      {"material", with_grain(fabric, -angle_deg)},
      {"boundary",
       {{{"select", {{"box", {{-L / 2 - e, -1, -1}, {-L / 2 + e, 1, 1}}}}}, {"fix", {"x"}}},
        {{"select", {{"box", {{-L / 2 - e, -e, -1}, {-L / 2 + e, e, 1}}}}}, {"fix", {"y"}}},
        {{"select", {{"box", {{-1, -1, -1}, {1, 1, 1}}}}}, {"fix", {"z"}}}}},
      {"loads", {{"point_loads", point_loads}}},
      {"probes", {{{"name", "a"}, {"at", {-L / 4, 0, 0}}}, {{"name", "b"}, {"at", {L / 4, 0, 0}}}}},
      {"render", {{"background", {1, 1, 1}}, {"texture", "grain"}}},
  };
}

TensileResult tensile_test(const FabricUnderTest& fabric, double angle_deg, const TensileSettings& s) {
  const Scene scene = load_scene_text(tensile_scene(fabric, angle_deg, s).dump(), "tensile.json", {});
  const StaticResult r = solve_static(scene.problem);
  const int a = scene.probes.at(0).vertex, b = scene.probes.at(1).vertex;
  TensileResult t;
  t.angle_deg = angle_deg;
  t.expected = strip_stretch_modulus(fabric.law, angle_deg);
  t.force = t.expected * s.strain * s.width;
  t.strain = (r.limit_displacement(b, 0) - r.limit_displacement(a, 0)) / (r.limit_rest(b, 0) - r.limit_rest(a, 0));
  t.modulus = t.force / s.width / t.strain;
  return t;
}

double shear_from_bias(double e45, double e_warp, double e_weft, double poisson) {
  return 1.0 / (4.0 / e45 - 1.0 / e_warp - 1.0 / e_weft + 2.0 * poisson / e_warp);
}

// ---- Cusick --------------------------------------------------------------------------------------

namespace {

// A specimen's OBJ: the vertices (x–z plane, normal +y), texture coordinates u = (x/R + 1)/2,
// v = (1 − z/R)/2 (the warp along +x) and the triangles.
std::string specimen_obj(const std::string& header, const std::vector<Eigen::Vector3d>& v,
                         const std::vector<std::array<int, 3>>& f, double radius) {
  std::ostringstream o;
  o << std::setprecision(12) << "# " << header << ", " << v.size() << " vertices; vt: u along +x (warp), v along -z\n";
  for (const auto& p : v) o << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const auto& p : v) o << "vt " << (p.x() / radius + 1) / 2 << ' ' << (1 - p.z() / radius) / 2 << '\n';
  for (const auto& t : f)
    o << "f " << t[0] + 1 << '/' << t[0] + 1 << ' ' << t[1] + 1 << '/' << t[1] + 1 << ' ' << t[2] + 1 << '/' << t[2] + 1
      << '\n';
  return o.str();
}

}  // namespace

std::string disc_obj(double radius, int rings) {
  if (rings < 1 || !(radius > 0)) throw std::invalid_argument("disc_obj: need radius > 0 and rings >= 1");
  std::vector<Eigen::Vector3d> v = {Eigen::Vector3d::Zero()};
  std::vector<int> start = {0};
  for (int k = 1; k <= rings; ++k) {
    start.push_back(static_cast<int>(v.size()));
    const double r = radius * k / rings;
    for (int j = 0; j < 6 * k; ++j) {
      const double t = 2 * kPi * j / (6 * k);
      v.emplace_back(r * std::cos(t), 0.0, -r * std::sin(t));
    }
  }
  const auto at = [&](int k, int j) { return k == 0 ? 0 : start[static_cast<size_t>(k)] + j % (6 * k); };
  std::vector<std::array<int, 3>> f;
  // Between rings k and k+1, sector s: the outer ring has 2k+1 vertices in it, the inner k+1
  // (the next sector's first shared); a hexagonal lattice, counter-clockwise seen from +y.
  for (int k = 0; k < rings; ++k)
    for (int sct = 0; sct < 6; ++sct) {
      for (int i = 0; i <= k; ++i) {
        const int o = sct * (k + 1) + i, in = sct * k + i;
        f.push_back({at(k, in), at(k + 1, o), at(k + 1, o + 1)});
        if (i < k) f.push_back({at(k, in), at(k + 1, o + 1), at(k, in + 1)});
      }
    }
  std::ostringstream header;
  header << "Cusick specimen: disc of radius " << radius << " m, " << rings << " rings";
  return specimen_obj(header.str(), v, f, radius);
}

std::vector<int> default_cusick_rings(bool clamped) {
  return clamped ? std::vector<int>{12, 16, 24} : std::vector<int>{16, 24, 32};
}

int annulus_around(double inner, double outer, int rings) {
  const double q = std::pow(outer / inner, 1.0 / rings);
  return static_cast<int>(std::lround(std::sqrt(3.0) * kPi / (q - 1)));
}

std::string annulus_obj(double inner, double outer, int rings, int inner_rings) {
  if (!(inner > 0) || !(outer > inner) || rings < 1 || inner_rings < 0)
    throw std::invalid_argument("annulus_obj: need 0 < inner < outer, rings >= 1 and inner_rings >= 0");
  const double q = std::pow(outer / inner, 1.0 / rings);
  const int m = annulus_around(inner, outer, rings);
  if (m < 6) throw std::invalid_argument("annulus_obj: too few rings for an annulus this narrow");
  std::vector<Eigen::Vector3d> v;
  // Ring k (−inner_rings ≤ k ≤ rings) at radius inner·q^k, its m vertices turned by half a step
  // from the ring inside: rows of nearly equilateral triangles.
  for (int k = -inner_rings; k <= rings; ++k) {
    const double r = k == rings ? outer : inner * std::pow(q, k);
    for (int j = 0; j < m; ++j) {
      const double t = 2 * kPi * (j + 0.5 * (k + inner_rings)) / m;
      v.emplace_back(r * std::cos(t), 0.0, -r * std::sin(t));
    }
  }
  const auto at = [&](int k, int j) { return (k + inner_rings) * m + j % m; };
  std::vector<std::array<int, 3>> f;
  for (int k = -inner_rings; k < rings; ++k)
    for (int j = 0; j < m; ++j) {
      // Counter-clockwise seen from +y (the angle grows from +x towards −z).
      f.push_back({at(k, j), at(k + 1, j), at(k, j + 1)});
      f.push_back({at(k + 1, j), at(k + 1, j + 1), at(k, j + 1)});
    }
  std::ostringstream header;
  header << "Cusick specimen: annulus from " << inner << " m (" << inner_rings << " rings inside) to " << outer << " m, "
         << rings << " rings of " << m;
  return specimen_obj(header.str(), v, f, outer);
}

int cusick_vertices(const CusickSettings& s, int rings) {
  if (!s.clamped) return 1 + 3 * rings * (rings + 1);
  return (rings + 1 + s.clamped_rings) * annulus_around(s.support_radius, s.specimen_radius, rings);
}

std::string cusick_specimen_obj(const CusickSettings& s, int rings) {
  return s.clamped ? annulus_obj(s.support_radius, s.specimen_radius, rings, s.clamped_rings)
                   : disc_obj(s.specimen_radius, rings);
}

Json cusick_scene(const FabricUnderTest& fabric, const std::string& disc_file, const CusickSettings& s) {
  const double h = s.height;
  Json scene = {
      {"name", "cusick"},
      {"description", s.clamped ? "Cusick drape test (ISO 9073-9): the specimen disc is clamped centred between the "
                                  "support disc and an upper disc of the same size and drapes under gravity"
                                : "Cusick drape test, loose: the specimen disc lies centred on the support disc (no upper "
                                  "disc) and drapes under gravity"},
      {"analysis", "dynamic"},
      // An imperfection moves points by up to its amplitude either way: the disc is raised by it so
      // that it starts clear of the support.
      {"mesh", {{"obj", disc_file}, {"translate", {0, h + s.imperfection, 0}}}},
      {"material", with_grain(fabric, 0.0)},
      {"loads", {{"gravity", {0, -kGravity, 0}}, {"ramp_time", s.ramp}}},
      {"time", {{"dt", s.dt}, {"end", s.ramp + s.end}, {"output_fps", 4.0 / (s.ramp + s.end)}}},  // frames at every quarter
      {"damping", {{"stiffness", 0.001}, {"mass", 1.0}}},
      {"collision", {{"self", true}, {"thickness", s.thickness}, {"friction", 0.3}}},
      {"obstacles",
       {{{"name", "ground"}, {"primitive", "plane"}, {"point", {0, 0, 0}}, {"normal", {0, 1, 0}}, {"friction", 0.5}},
        {{"name", "support"},
         {"primitive", "cylinder"},
         {"from", {0, 0, 0}},
         // Clamped, the specimen's middle is held by the clamp, not by contact: the support's top
         // lies out of the contact's reach (2 thicknesses below it).
         {"to", {0, h - (s.clamped ? 2 : 1) * s.thickness, 0}},
         {"radius", s.support_radius},
         {"friction", 0.4}}}},
      {"output", {{"obj", true}, {"obj_level", 2}}},
      {"render",
       // From straight above, as the shadow is measured; no grain lines (one per control
       // triangle, they cover a fine disc).
       {{"background", {1, 1, 1}}, {"camera", {{"eye", {0.0, h + 0.5, 0.001}}, {"target", {0, h - 0.05, 0}}}}}},
  };
  if (s.imperfection > 0) scene["imperfection"] = Json{{"amplitude", s.imperfection}, {"seed", 1}};
  if (s.clamped) {
    // The upper disc (the picture shows it over the clamped middle), 5 mm thick, its underside
    // out of the contact's reach of the clamped part, which an imperfection moves by up to its
    // amplitude either way from h + amplitude.
    scene["obstacles"].push_back({{"name", "clamp"},
                                  {"primitive", "cylinder"},
                                  {"from", {0, h + 2 * s.imperfection + 2 * s.thickness, 0}},
                                  {"to", {0, h + 2 * s.imperfection + 2 * s.thickness + 0.005, 0}},
                                  {"radius", s.support_radius},
                                  {"friction", 0.4}});
    // The clamp: every vertex up to the rim (the rim's ring lies at the support's radius, the next
    // one at least 0.5 % farther out; selected on the flat placed disc, before any imperfection).
    scene["boundary"] = Json::array({{{"select", {{"ball", {{"center", {0, h + s.imperfection, 0}},
                                                            {"radius", s.support_radius * (1 + 1e-6)}}}}},
                                      {"fix", {"x", "y", "z"}}}});
  }
  return scene;
}

}  // namespace clothsim

#include "app/fabric_test.hpp"

#include "app/command_output.hpp"
#include "app/output_folders.hpp"
#include "app/run.hpp"
#include "sim/mesh/obj_io.hpp"
#include "sim/study/fabric_tests.hpp"
#include "sim/study/report_format.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace clothsim {

using Json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

std::string fixed(double v, int digits) { return format_fixed(v, digits); }
std::string sci(double v) { return format_significant(v, 4); }
std::string percent(double value, double reference) { return fixed(100.0 * (value / reference - 1.0), 2); }

void say(const std::string& line) { std::cerr << "clothsim: fabric-test: " << line << '\n'; }

// Writes `scene` as runs/<name>.json and runs it with the command's own runner into runs/<name>/.
fs::path run_scene(const Json& scene, const fs::path& runs, const FabricTestOptions& o) {
  const std::string name = scene.at("name").get<std::string>();
  const fs::path file = runs / (name + ".json");
  write_text_file(file, scene.dump(2) + "\n");
  RunOptions run;
  run.render = o.render;
  if (o.quick) {
    run.width = 320;
    run.height = 240;
  }
  if (run_scene_file(file, runs, run) != 0) throw std::runtime_error("the run of " + file.string() + " failed");
  return runs / name;
}

// Copies the last PNG frame of a dynamic run (or a static run's limit.png) to `picture`.
void keep_picture(const fs::path& run_dir, const fs::path& picture) {
  std::vector<fs::path> frames = files_like(run_dir, "frame_", ".png");
  if (frames.empty() && fs::exists(run_dir / "limit.png")) frames.push_back(run_dir / "limit.png");
  if (frames.empty()) return;
  fs::copy_file(frames.back(), picture, fs::copy_options::overwrite_existing);
}

// The least-squares line y = a + b x through the points, and the largest |residual|.
struct LineFit {
  double intercept = 0, slope = 0, largest_residual = 0;
};
LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  LineFit f;
  f.slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  f.intercept = (sy - f.slope * sx) / n;
  for (size_t i = 0; i < x.size(); ++i) f.largest_residual = std::max(f.largest_residual, std::abs(y[i] - f.intercept - f.slope * x[i]));
  return f;
}

struct Row {
  std::string test, quantity, unit;
  double direction = 0, value = 0;
  std::optional<double> law, measured;
};

struct Report {
  std::vector<Row> rows;
  std::ostringstream md;
};

void cantilever_part(const FabricUnderTest& f, const FabricTestOptions& o, const fs::path& dir, Report& rep) {
  CantileverSettings s;
  if (o.quick) {
    s.cells_along = 16;
    s.cells_across = 4;
    s.dt = 0.01;
    s.settle = 2.0;
    s.tolerance_deg = 0.3;
  }
  rep.md << "## Cantilever bending (ASTM D1388)\n\n"
         << "A strip " << fixed(s.width * 1000, 0) << " mm wide, held flat on the platform up to its edge, "
         << "hangs over it under its own weight (dt " << s.dt << " s, " << s.settle << " s to rest, "
         << s.cells_along << " × " << s.cells_across << " cells). The overhang L whose tip reaches the "
         << s.incline_deg << "° incline is found by the secant method on the chord angle; then the bending length "
         << "c = L / 2 and the flexural rigidity G = ρ_A g c³. Expected: c = (B_θ / (ρ_A g))^(1/3) with B_θ the law's "
         << "rigidity of a strip cut along that direction.\n\n"
         << "| strip along | runs | overhang L [mm] | c [mm] | expected c [mm] | c − expected | G [N·m] | B_θ of the law [N·m] | measured B [N·m] | tip speed at rest [mm/s] |\n"
         << "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n";
  // The platform and the incline, an obstacle of the picture runs (the strip 1 mm above the platform).
  write_text_file(dir / "runs" / "apparatus.obj", cantilever_apparatus_obj(s.incline_deg, 0.001, s.width));
  for (const auto& [name, angle] : std::vector<std::pair<std::string, double>>{{"warp", 0.0}, {"weft", 90.0}}) {
    const CantileverResult r = cantilever_test(f, angle, s, say);
    const double law_b = strip_bending_rigidity(f.law, angle);
    rep.rows.push_back({"cantilever", "bending_length", "m", angle, r.bending_length, r.expected_length, std::nullopt});
    std::optional<double> measured_b;
    if (f.measured) measured_b = f.measured->bending_rigidity;
    rep.rows.push_back({"cantilever", "flexural_rigidity", "N*m", angle, r.flexural_rigidity, law_b, measured_b});
    rep.md << "| " << name << " | " << r.runs.size() << " | " << fixed(r.overhang * 1000, 2) << " | "
           << fixed(r.bending_length * 1000, 2) << " | " << fixed(r.expected_length * 1000, 2) << " | "
           << percent(r.bending_length, r.expected_length) << " % | " << sci(r.flexural_rigidity) << " | " << sci(law_b)
           << " | " << (measured_b ? sci(*measured_b) : std::string("–")) << " | "
           << fixed(r.runs.back().tip_speed * 1000, 3) << " |\n";
    // The picture: the strip at the found overhang over the platform and the incline (obstacles).
    Json scene = cantilever_scene(f, angle, r.overhang, s, "apparatus.obj");
    scene["name"] = "cantilever_" + name;
    keep_picture(run_scene(scene, dir / "runs", o), dir / ("cantilever_" + name + ".png"));
  }
  rep.md << "\n![cantilever along the warp](cantilever_warp.png) ![cantilever along the weft](cantilever_weft.png)\n\n";
}

void bias_part(const FabricUnderTest& f, const FabricTestOptions& o, const fs::path& dir, Report& rep) {
  TensileSettings s;
  if (o.quick) {
    s.cells_along = 20;
    s.cells_across = 4;
  }
  rep.md << "## Tensile and bias extension at small strain\n\n"
         << "A strip " << fixed(s.length * 1000, 0) << " × " << fixed(s.width * 1000, 0) << " mm (" << s.cells_along
         << " × " << s.cells_across << " cells) cut at 0° (warp), 90° (weft) and 45° (bias) to the warp, one end "
         << "on rollers (free to contract), pulled at the other by the force that stretches it by "
         << fixed(s.strain * 100, 1) << " % under the law; static (linear) analysis. Modulus = (F / width) / "
         << "(axial strain between ±L/4). Expected: E_θ of the law, 1/E_θ = cos⁴θ/E_w + sin⁴θ/E_f + "
         << "(1/G − 2ν/E_w) sin²θ cos²θ. The shear modulus follows from the three: "
         << "1/G = 4/E₄₅ − 1/E_w − 1/E_f + 2ν/E_w.\n\n"
         << "| cut | force [N] | strain | modulus [N/m] | E_θ of the law [N/m] | difference |\n|---|--:|--:|--:|--:|--:|\n";
  std::vector<TensileResult> t;
  for (const auto& [name, angle] : std::vector<std::pair<std::string, double>>{{"warp", 0.0}, {"weft", 90.0}, {"bias", 45.0}}) {
    t.push_back(tensile_test(f, angle, s));
    const TensileResult& r = t.back();
    rep.rows.push_back({"tensile", "stretch_modulus", "N/m", angle, r.modulus, r.expected, std::nullopt});
    rep.md << "| " << name << " (" << angle << "°) | " << sci(r.force) << " | " << sci(r.strain) << " | "
           << fixed(r.modulus, 2) << " | " << fixed(r.expected, 2) << " | " << percent(r.modulus, r.expected) << " % |\n";
    Json scene = tensile_scene(f, angle, s);
    scene["name"] = "tensile_" + name;
    keep_picture(run_scene(scene, dir / "runs", o), dir / ("tensile_" + name + ".png"));
  }
  const double nu = f.law.orthotropic() ? f.law.orthotropy->poisson : f.law.poisson_ratio;
  const double g = shear_from_bias(t[2].modulus, t[0].modulus, t[1].modulus, nu);
  rep.rows.push_back({"bias", "shear_modulus", "N/m", 45.0, g, shear_modulus(f.law), std::nullopt});
  rep.md << "\nShear modulus from the bias test: G = " << fixed(g, 2) << " N/m (the law's " << fixed(shear_modulus(f.law), 2)
         << " N/m, " << percent(g, shear_modulus(f.law)) << " %; 1 gf/cm/deg = 56.19 N/m).\n\n"
         << "![warp](tensile_warp.png) ![weft](tensile_weft.png) ![bias](tensile_bias.png)\n\n";
}

void cusick_part(const FabricUnderTest& f, const FabricTestOptions& o, const fs::path& dir, Report& rep) {
  CusickSettings s;
  s.rings = o.rings.empty() ? default_cusick_rings(!o.loose) : o.rings;
  s.end = o.cusick_end;
  s.imperfection = o.imperfection;
  s.ramp = o.cusick_ramp;
  s.clamped = !o.loose;
  const fs::path runs = dir / "runs";
  struct Level {
    int rings = 0, vertices = 0;
    DrapeMeasure m;
    double speed = 0, seconds = 0;
  };
  std::vector<Level> levels;
  for (const int rings : s.rings) {
    Level l;
    l.rings = rings;
    l.vertices = cusick_vertices(s, rings);
    const std::string name = "cusick_r" + std::to_string(rings);
    write_text_file(runs / (name + ".obj"), cusick_specimen_obj(s, rings));
    Json scene = cusick_scene(f, name + ".obj", s);
    scene["name"] = name;
    say("Cusick drape, " + std::to_string(rings) + " rings (" + std::to_string(l.vertices) + " vertices), " +
        (s.ramp > 0 ? "gravity ramped in over " + fixed(s.ramp, 2) + " s, then " : std::string()) + fixed(s.end, 2) + " s");
    const auto t0 = std::chrono::steady_clock::now();
    const fs::path run = run_scene(scene, runs, o);
    l.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::vector<fs::path> frames = files_like(run / "frames", "mesh_", ".obj");
    if (frames.empty()) throw std::runtime_error(run.string() + ": the run wrote no OBJ frame to measure");
    const TriMesh last = read_obj(frames.back().string());
    DrapeMeasureSettings ms;
    ms.support_radius = s.support_radius;
    ms.specimen_radius = s.specimen_radius;
    ms.support_center = Eigen::Vector3d(0, s.height, 0);
    l.m = measure_drape(last.vertices, last.triangles, ms);
    if (frames.size() >= 2) {
      const TriMesh before = read_obj(frames[frames.size() - 2].string());
      const double interval = 1.0 / scene.at("time").at("output_fps").get<double>();
      l.speed = (last.vertices - before.vertices).rowwise().norm().maxCoeff() / interval;
    }
    keep_picture(run, dir / (name + ".png"));
    levels.push_back(l);
  }
  const Level& fine = levels.back();
  std::optional<double> measured_dc, measured_nodes;
  if (f.measured && f.measured->drape_coefficient) measured_dc = *f.measured->drape_coefficient;
  if (f.measured && f.measured->nodes) measured_nodes = *f.measured->nodes;
  rep.rows.push_back({"cusick", "drape_coefficient", "-", 0, fine.m.drape_coefficient, std::nullopt, measured_dc});
  rep.rows.push_back({"cusick", "nodes", "-", 0, static_cast<double>(fine.m.nodes), std::nullopt, measured_nodes});
  rep.md << "## Cusick drape (ISO 9073-9)\n\n"
         << "A disc of " << fixed(2 * s.specimen_radius * 100, 0) << " cm "
         << (s.clamped ? "clamped between the support disc and an upper disc, both of "
                       : "lying loose on a support disc (no upper disc) of ")
         << fixed(2 * s.support_radius * 100, 0) << " cm, "
         << (s.ramp > 0 ? "gravity ramped in over " + fixed(s.ramp, 2) + " s, then " : std::string()) << fixed(s.end, 2)
         << " s under gravity (dt " << s.dt
         << " s, self-collision, contact thickness " << s.thickness * 1000 << " mm"
         << (s.imperfection > 0 ? ", seeded imperfection " + fixed(s.imperfection * 1000, 2) + " mm" : std::string())
         << "), on meshes of increasing refinement. DC = (A_shadow − A_support) / (A_specimen − A_support) from the vertical projection of the "
         << "drawn surface (the limit surface refined twice; raster cell 0.5 mm); nodes: maxima of the shadow's outline "
         << "radius standing out by at least 5 mm. Rest: the largest vertex speed over the last quarter of the run.\n\n"
         << (s.clamped ? "The mesh is the hanging annulus (rings across it, graded: the finest at the rim) and "
                         + std::to_string(s.clamped_rings) + " rings inside the rim, held by the clamp.\n\n"
                       : std::string("The mesh is the whole disc (rings from its centre).\n\n"))
         << "| rings | vertices | DC | ± raster | nodes | change of DC from the previous mesh | largest speed at the end [mm/s] | wall [s] |\n"
         << "|--:|--:|--:|--:|--:|--:|--:|--:|\n";
  for (size_t i = 0; i < levels.size(); ++i) {
    const Level& l = levels[i];
    const double bound = l.m.area_bound / (M_PI * (s.specimen_radius * s.specimen_radius - s.support_radius * s.support_radius));
    rep.md << "| " << l.rings << " | " << l.vertices << " | " << fixed(l.m.drape_coefficient, 3) << " | "
           << fixed(bound, 3) << " | " << l.m.nodes << " | "
           << (i == 0 ? std::string("–") : fixed(l.m.drape_coefficient - levels[i - 1].m.drape_coefficient, 3)) << " | "
           << fixed(l.speed * 1000, 2) << " | " << fixed(l.seconds, 1) << " |\n";
  }
  if (levels.size() >= 2) {
    const double change = std::abs(fine.m.drape_coefficient - levels[levels.size() - 2].m.drape_coefficient);
    rep.md << "\nConverged (the finest mesh changes DC by at most 0.02 from the one before): "
           << (change <= 0.02 ? "yes" : "**no**") << " (" << fixed(change, 3) << ").\n";
  }
  if (levels.size() >= 3) {
    // DC against the element size h ∝ 1/N, a least-squares line through every mesh: its value at
    // h = 0 and how far the meshes lie from it.
    std::vector<double> h, dc;
    for (const Level& l : levels) {
      h.push_back(1.0 / l.rings);
      dc.push_back(l.m.drape_coefficient);
    }
    const LineFit fit = fit_line(h, dc);
    rep.rows.push_back({"cusick", "drape_coefficient_extrapolated", "-", 0, fit.intercept, std::nullopt, measured_dc});
    rep.md << "\nExtrapolated to zero element size (DC linear in 1/N through the " << levels.size()
           << " meshes, largest residual " << fixed(fit.largest_residual, 4) << "): DC " << fixed(fit.intercept, 3)
           << ". An extrapolation of the trend, not a run: trust it only where the residual is small and the "
           << "meshes are fine.\n";
  }
  if (measured_dc)
    rep.md << "\nMeasured (" << f.measured->source << ", " << f.measured->fabric << "): DC " << fixed(*measured_dc, 3)
           << ", " << *measured_nodes << " nodes; virtual on the finest mesh: DC " << fixed(fine.m.drape_coefficient, 3)
           << " (" << (fine.m.drape_coefficient - *measured_dc >= 0 ? "+" : "") << fixed(fine.m.drape_coefficient - *measured_dc, 3)
           << "), " << fine.m.nodes << " nodes.\n";
  rep.md << "\n![Cusick drape, finest mesh, from above](cusick_r" << fine.rings << ".png)\n\n";
}

std::string csv_of(const Report& rep) {
  std::ostringstream c;
  c << "test,direction_deg,quantity,unit,virtual,law,measured\n";
  for (const Row& r : rep.rows)
    c << r.test << ',' << format_shortest(r.direction) << ',' << r.quantity << ',' << r.unit << ','
      << format_shortest(r.value) << ',' << (r.law ? format_shortest(*r.law) : std::string()) << ','
      << (r.measured ? format_shortest(*r.measured) : std::string()) << '\n';
  return c.str();
}

}  // namespace

int run_fabric_test(const FabricTestOptions& o) {
  try {
    for (const std::string& t : o.tests)
      if (t != "cantilever" && t != "bias" && t != "cusick")
        throw std::invalid_argument("--tests: no test \"" + t + "\" (allowed: cantilever, bias, cusick)");
    for (size_t i = 0; i < o.rings.size(); ++i)
      if (o.rings[i] < 2 || o.rings[i] > 200 || (i > 0 && o.rings[i] <= o.rings[i - 1]))
        throw std::invalid_argument("--rings: expected increasing ring counts between 2 and 200");
    if (!(o.cusick_end > 0) || o.cusick_end > 60) throw std::invalid_argument("--end: expected 0 < T <= 60 s");
    if (!(o.cusick_ramp >= 0) || o.cusick_ramp > 60) throw std::invalid_argument("--ramp: expected 0 <= T <= 60 s");
    if (!(o.imperfection >= 0) || o.imperfection > 0.01)
      throw std::invalid_argument("--imperfection: expected 0 <= A <= 0.01 m");
    const FabricUnderTest f = fabric_under_test(o.target);
    const fs::path target = output_folder_path(o.out_root / ("fabric_test_" + f.label), "--out");
    const auto t0 = std::chrono::steady_clock::now();
    publish_folder(target, "fabric_test.md", "fabric-test", [&](const fs::path& dir) {
      fs::create_directories(dir / "runs");
      Report rep;
      rep.md << "# Virtual fabric tests: " << f.label << "\n\n"
             << "Material: `" << f.material.dump() << "`"
             << (f.law.orthotropic() ? " (orthotropic)" : " (isotropic)") << ". Areal density "
             << f.law.areal_density << " kg/m². ";
      if (f.measured) rep.md << "Measured values: " << f.measured->source << " (" << f.measured->fabric << ").";
      rep.md << "\n\n";
      const auto has = [&](const char* t) { return std::find(o.tests.begin(), o.tests.end(), t) != o.tests.end(); };
      if (has("cantilever")) cantilever_part(f, o, dir, rep);
      if (has("bias")) bias_part(f, o, dir, rep);
      if (has("cusick")) cusick_part(f, o, dir, rep);
      rep.md << "Wall time: " << fixed(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1)
             << " s" << (o.quick ? " (--quick: coarse meshes and short runs; the numbers are not the test's)" : "")
             << ".\n";
      write_text_file(dir / "fabric_test.csv", csv_of(rep));
      write_text_file(dir / "fabric_test.md", rep.md.str());
    });
    std::cout << "fabric-test: wrote " << (target / "fabric_test.md").string() << '\n';
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: fabric-test: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace clothsim

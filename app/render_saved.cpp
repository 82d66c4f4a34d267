// clothsim render DIR: the saved geometry, the saved settings and their overrides, the pictures.
#include "app/render_saved.hpp"

#include "app/command_output.hpp"
#include "app/limit_surface_drawer.hpp"
#include "app/output_folders.hpp"
#include "render/png_io.hpp"
#include "render/renderer.hpp"
#include "sim/core/layout.hpp"
#include "sim/mesh/obj_io.hpp"
#include "sim/scene/render_settings_json.hpp"
#include "sim/scene/scene.hpp"
#include "sim/setup/setup.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace clothsim {
namespace {

namespace fs = std::filesystem;

// One saved shape and the picture it becomes.
struct SavedShape {
  fs::path obj;
  std::string png;  // file name in the output folder
};

// A dynamic run's frames/mesh_NNNN.obj in frame order (by number), or a static run's limit.obj.
// Sets `settings_file` to the file that holds the run's settings.
std::vector<SavedShape> saved_shapes(const fs::path& dir, fs::path& settings_file) {
  const fs::path frames = dir / "frames";
  std::vector<std::pair<long, SavedShape>> numbered;
  if (fs::is_directory(frames)) {
    settings_file = dir / "summary.json";
    for (const auto& entry : fs::directory_iterator(frames)) {
      const std::string name = entry.path().filename().string();
      if (name.size() <= 9 || name.rfind("mesh_", 0) != 0 || entry.path().extension() != ".obj") continue;
      const std::string digits = name.substr(5, name.size() - 9);
      if (digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); }))
        continue;
      const long k = std::stol(digits);
      char png[32];
      std::snprintf(png, sizeof png, "frame_%04ld.png", k);
      numbered.push_back({k, {entry.path(), png}});
    }
    std::sort(numbered.begin(), numbered.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    if (numbered.empty()) throw std::runtime_error(frames.string() + ": no mesh_NNNN.obj frames");
  } else if (fs::is_regular_file(dir / "limit.obj")) {
    settings_file = dir / "result.json";
    numbered.push_back({0, {dir / "limit.obj", "limit.png"}});
  } else {
    throw std::runtime_error(dir.string() + ": no saved geometry: neither frames/mesh_NNNN.obj (a dynamic run with "
                             "\"output\": {\"obj\": true}) nor limit.obj (a static run)");
  }
  std::vector<SavedShape> shapes;
  for (auto& [k, shape] : numbered) shapes.push_back(std::move(shape));
  // Frames of the refined surface (output.obj_level > 0) are not control meshes.
  std::ifstream first(shapes.front().obj);
  std::string comment;
  std::getline(first, comment);
  if (comment.find("(refined ") != std::string::npos)
    throw std::runtime_error(shapes.front().obj.string() +
                             ": holds the refined surface (\"output.obj_level\" > 0); clothsim render draws frames "
                             "written with obj_level 0 (the limit points at the control connectivity)");
  return shapes;
}

// The settings the run saved under "render" in `file`, or the defaults (with a notice) for a run
// made before they were saved. `drawn` receives the run's "drawn_surface.surface" ("" if none).
RenderSettings saved_settings(const fs::path& file, std::string& drawn) {
  if (!fs::exists(file)) {
    std::cerr << "clothsim: " << file.string() << " not found: drawing with the default render settings\n";
    return {};
  }
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(read_text_file(file));
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(file.string() + ": malformed JSON (" + e.what() + ")");
  }
  if (!j.is_object()) throw std::runtime_error(file.string() + ": expected a JSON object");
  if (const auto d = j.find("drawn_surface"); d != j.end() && d->is_object()) {
    const auto s = d->find("surface");
    if (s != d->end() && s->is_string()) drawn = s->get<std::string>();
  }
  const auto r = j.find("render");
  if (r == j.end()) {
    std::cerr << "clothsim: " << file.string()
              << " has no \"render\" settings (a run made before they were saved): drawing with the defaults\n";
    return {};
  }
  return render_settings_from_json(*r, file.string());
}

}  // namespace

int render_saved_run(const fs::path& dir, const RenderSavedOptions& options) {
  try {
    if (!fs::is_directory(dir)) throw std::runtime_error(dir.string() + ": no such folder (the output folder of a run)");
    fs::path settings_file;
    const std::vector<SavedShape> shapes = saved_shapes(dir, settings_file);
    std::string drawn;
    RenderSettings settings = saved_settings(settings_file, drawn);
    if (options.width > 0) settings.width = options.width;
    if (options.height > 0) settings.height = options.height;
    if (options.refine) {
      if (*options.refine < 0 || *options.refine > 4) throw std::runtime_error("--refine: must be from 0 to 4");
      settings.refine = *options.refine;
    }
    if (options.surface) settings.surface = *options.surface;
    // The saved shapes are drawn as the control meshes of a Loop surface; "method" means the
    // surface the run's method drew (saved as drawn_surface.surface).
    if (settings.surface == DrawnSurface::method)
      settings.surface = drawn == "flat" ? DrawnSurface::flat : DrawnSurface::loop_limit;
    settings.framing = Framing::sequence;  // what the camera frames (unless the run had one): all saved shapes
    const fs::path out = output_folder_path(options.out.empty() ? dir / "render" : options.out, "--out");

    std::size_t written = 0;
    publish_folder(out, kRenderRecord, "--out", [&](const fs::path& staging) {
      // Two passes over the files, so that only one shape is in memory at a time: the bounds of
      // the whole sequence for the camera, then the pictures.
      std::shared_ptr<Discretization> surface;  // the saved mesh as a Loop control mesh
      std::unique_ptr<LimitSurfaceDrawer> drawer;
      render::Vec3f lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
      std::vector<Triangle> first_triangles;
      for (const SavedShape& shape : shapes) {
        const TriMesh mesh = read_obj(shape.obj.string());
        if (!drawer) {
          first_triangles = mesh.triangles;
          Problem control;  // no boundary, default material: only the surface operators are used
          control.method = "loop_kl";
          control.mesh = mesh;
          surface = make_discretization(control);
          drawer = std::make_unique<LimitSurfaceDrawer>(*surface, settings, settings.width, settings.height);
        } else if (mesh.triangles != first_triangles) {
          throw std::runtime_error(shape.obj.string() + ": its triangles differ from " + shapes.front().obj.string());
        }
        LimitSurfaceDrawer::extend_bounds(drawer->snapshot(to_flat(mesh.vertices)), lo, hi);
      }
      render::Renderer renderer(settings.width, settings.height);
      const render::Camera camera = drawer->camera(lo, hi);
      for (const SavedShape& shape : shapes) {
        const TriMesh mesh = read_obj(shape.obj.string());
        if (mesh.triangles != first_triangles)  // changed since the first pass
          throw std::runtime_error(shape.obj.string() + ": its triangles differ from " + shapes.front().obj.string());
        const SurfaceSnapshot snapshot = drawer->snapshot(to_flat(mesh.vertices));
        render::write_png((staging / shape.png).string(), renderer.render(drawer->frame(snapshot, camera, lo, hi)));
        ++written;
      }
      nlohmann::ordered_json record = {
          {"source", fs::absolute(dir).lexically_normal().string()},
          {"shapes", shapes.size() == 1 && shapes.front().png == "limit.png" ? "limit.obj" : "frames/mesh_NNNN.obj"},
          {"pictures", written},
          {"render", render_settings_json(settings)},
          {"camera", settings.has_camera ? "render.camera" : "framed on the whole sequence"}};
      write_text_file(staging / kRenderRecord, record.dump(2) + "\n");
    });
    std::cout << "rendered " << written << " picture(s) of " << settings.width << "x" << settings.height << " from "
              << dir.string() << " into " << out.string() << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "clothsim: error: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace clothsim

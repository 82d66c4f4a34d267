// The `clothsim` Python module (pybind11; docs/python.md): load a scene (a file or a dict), step
// it, read positions, velocities, energies and contact figures as NumPy arrays, render a frame to
// an array, and run a scene with the usual outputs. A thin layer over the library the program
// uses: the same scene loader, Simulator, drawer and renderer, so a scene stepped here gives the
// numbers the program's run gives.
#include "app/limit_surface_drawer.hpp"
#include "app/run.hpp"
#include "render/renderer.hpp"
#include "sim/dynamics/simulator.hpp"
#include "sim/scene/scene.hpp"
#include "sim/shell/material_presets.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace py = pybind11;
namespace fs = std::filesystem;

namespace clothsim {
namespace {

// A (rows × 3) float64 NumPy array holding a copy of `m`.
py::array_t<double> rows3(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& m) {
  py::array_t<double> out({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(3)});
  auto a = out.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (int k = 0; k < 3; ++k) a(i, k) = m(i, k);
  return out;
}

// A dynamic scene being stepped from Python.
class Simulation {
 public:
  // `scene`: a path (str or os.PathLike) or a dict (the scene's JSON; relative mesh paths are
  // resolved against `folder`). `overrides`: `--set` arguments.
  Simulation(const py::object& scene, const std::vector<std::string>& overrides, const fs::path& folder) {
    if (py::isinstance<py::dict>(scene)) {
      const std::string text = py::module_::import("json").attr("dumps")(scene).cast<std::string>();
      scene_ = load_scene_text(text, folder / "scene_from_python.json", LogFn(), overrides);
    } else {
      scene_ = load_scene(scene.cast<fs::path>(), LogFn(), overrides);
    }
    if (scene_.analysis != "dynamic")
      throw std::invalid_argument(scene_.file.string() + ": a Simulation needs a dynamic scene (\"analysis\": \"dynamic\")");
    sim_ = std::make_unique<Simulator>(scene_.problem);
  }

  // Advances `n` steps (or until time.end); returns the last step's figures as a dict.
  py::dict step(int n) {
    if (n < 1) throw std::invalid_argument("step: n must be at least 1");
    StepStats s;
    for (int k = 0; k < n; ++k) {
      py::gil_scoped_release release;
      s = sim_->step();
    }
    last_ = s;
    return stats_dict(s);
  }

  // Steps until the time reaches `t` (default: the scene's time.end); returns the number taken.
  int run(std::optional<double> t) {
    const double until = t.value_or(scene_.problem.time.end);
    const double dt = scene_.problem.time.dt;
    int taken = 0;
    py::gil_scoped_release release;
    while (sim_->state().t + 0.5 * dt < until) {
      last_ = sim_->step();
      ++taken;
    }
    return taken;
  }

  double time() const { return sim_->state().t; }
  int steps_taken() const { return sim_->state().step; }
  int num_steps() const { return sim_->num_steps(); }
  double dt() const { return scene_.problem.time.dt; }
  std::string name() const { return scene_.name; }
  py::array_t<double> positions() const { return rows3(sim_->state().positions()); }
  py::array_t<double> velocities() const { return rows3(sim_->state().velocities()); }
  py::array_t<double> surface_points() const { return rows3(sim_->node_points()); }
  py::array_t<int> triangles() const {
    const auto& t = scene_.problem.mesh.triangles;
    py::array_t<int> out({static_cast<py::ssize_t>(t.size()), static_cast<py::ssize_t>(3)});
    auto a = out.mutable_unchecked<2>();
    for (std::size_t i = 0; i < t.size(); ++i)
      for (int k = 0; k < 3; ++k) a(static_cast<py::ssize_t>(i), k) = t[i][static_cast<std::size_t>(k)];
    return out;
  }
  py::array_t<double> vertex_mass() const {
    const Eigen::VectorXd& m = sim_->vertex_mass();
    py::array_t<double> out(static_cast<py::ssize_t>(m.size()));
    auto a = out.mutable_unchecked<1>();
    for (Eigen::Index i = 0; i < m.size(); ++i) a(i) = m(i);
    return out;
  }

  py::dict energies() const {
    py::dict d;
    d["kinetic"] = sim_->kinetic_energy();
    d["elastic"] = sim_->elastic_energy();
    d["contact"] = sim_->contact_energy();
    d["external_work"] = sim_->external_work();
    d["boundary_work"] = sim_->boundary_work();
    return d;
  }

  py::dict contact() const {
    py::dict d;
    d["enabled"] = scene_.problem.has_contact();
    d["energy"] = sim_->contact_energy();
    d["active_pairs"] = last_ ? last_->contact_active_pairs : 0;
    d["friction_pairs"] = last_ ? last_->contact_friction_pairs : 0;
    d["pairs_tested"] = last_ ? last_->contact.pairs_tested : 0;
    d["newton_iterations"] = last_ ? last_->contact.newton_iterations : 0;
    d["unresolved"] = last_ ? last_->contact.unresolved : 0;
    d["ms"] = last_ ? last_->contact.ms : 0.0;
    return d;
  }

  double max_membrane_strain() const { return sim_->max_membrane_strain(); }

  // The drawn surface now, as the program draws it (the scene's render settings; width × height
  // pixels, default the scene's), framed on the current shape unless the scene fixes a camera:
  // a (height, width, 3) uint8 array.
  py::array_t<std::uint8_t> render(std::optional<int> width, std::optional<int> height) const {
    const int w = width.value_or(scene_.render.width), h = height.value_or(scene_.render.height);
    if (w < 1 || h < 1 || w > 8192 || h > 8192) throw std::invalid_argument("render: width and height must be 1 to 8192");
    LimitSurfaceDrawer drawer(sim_->discretization(), scene_.render, w, h);
    drawer.set_obstacles(scene_.problem.obstacles);
    const SurfaceSnapshot snapshot = drawer.snapshot(sim_->state().x, sim_->state().t);
    render::Vec3f lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
    LimitSurfaceDrawer::extend_bounds(snapshot, lo, hi);
    render::Renderer renderer(w, h);
    const render::Image image = renderer.render(drawer.frame(snapshot, drawer.camera(lo, hi), lo, hi));
    py::array_t<std::uint8_t> out({static_cast<py::ssize_t>(h), static_cast<py::ssize_t>(w), static_cast<py::ssize_t>(3)});
    std::memcpy(out.mutable_data(), image.rgb.data(), image.rgb.size());
    return out;
  }

 private:
  static py::dict stats_dict(const StepStats& s) {
    py::dict d;
    d["step"] = s.step;
    d["t"] = s.t;
    d["solver_iterations"] = s.solver_iterations;
    d["residual"] = s.residual;
    d["kinetic_energy"] = s.kinetic_energy;
    d["elastic_energy"] = s.elastic_energy;
    d["contact_energy"] = s.contact_energy;
    d["contact_active_pairs"] = s.contact_active_pairs;
    return d;
  }

  Scene scene_;
  std::unique_ptr<Simulator> sim_;
  std::optional<StepStats> last_;
};

}  // namespace
}  // namespace clothsim

PYBIND11_MODULE(clothsim, m) {
  using clothsim::Simulation;
  m.doc() = "clothsim: Kirchhoff-Love thin-shell cloth on Loop-subdivision surfaces (docs/python.md)";
  py::register_exception<clothsim::SceneError>(m, "SceneError", PyExc_ValueError);
  py::class_<Simulation>(m, "Simulation",
                         "A dynamic scene being stepped: Simulation(scene, set=[], folder='.'), scene a path or a dict")
      .def(py::init<const py::object&, const std::vector<std::string>&, const fs::path&>(), py::arg("scene"),
           py::arg("set") = std::vector<std::string>{}, py::arg("folder") = fs::path("."))
      .def("step", &Simulation::step, py::arg("n") = 1, "Advance n time steps; the last step's figures as a dict")
      .def("run", &Simulation::run, py::arg("until") = py::none(),
           "Step until time `until` [s] (default: the scene's time.end); returns the steps taken")
      .def_property_readonly("time", &Simulation::time, "Simulated time [s]")
      .def_property_readonly("steps_taken", &Simulation::steps_taken)
      .def_property_readonly("num_steps", &Simulation::num_steps, "Steps to the scene's time.end")
      .def_property_readonly("dt", &Simulation::dt, "Time step [s]")
      .def_property_readonly("name", &Simulation::name)
      .def_property_readonly("positions", &Simulation::positions, "Node (control vertex) positions, (N, 3) [m]")
      .def_property_readonly("velocities", &Simulation::velocities, "Node velocities, (N, 3) [m/s]")
      .def_property_readonly("surface_points", &Simulation::surface_points,
                             "The surface point of every node (the Loop limit point), (N, 3) [m]")
      .def_property_readonly("triangles", &Simulation::triangles, "Control triangles, (T, 3) vertex indices")
      .def_property_readonly("vertex_mass", &Simulation::vertex_mass, "Lumped mass per node, (N,) [kg]")
      .def("energies", &Simulation::energies,
           "kinetic, elastic and contact energy and the work of loads and boundaries so far [J]")
      .def("contact", &Simulation::contact, "Contact figures of the last step")
      .def("max_membrane_strain", &Simulation::max_membrane_strain, "Largest principal membrane strain [-]")
      .def("render", &Simulation::render, py::arg("width") = py::none(), py::arg("height") = py::none(),
           "The drawn surface as the program draws it: a (height, width, 3) uint8 array");
  m.def(
      "presets",
      [] {
        py::dict d;
        for (const std::string& name : clothsim::material_preset_names()) {
          const clothsim::ShellMaterial mat = *clothsim::material_preset(name);
          py::dict p;
          p["stretch_modulus"] = mat.stretch_modulus;
          p["bending_rigidity"] = mat.bending_rigidity;
          p["poisson_ratio"] = mat.poisson_ratio;
          p["areal_density"] = mat.areal_density;
          p["orthotropic"] = mat.orthotropic();
          d[py::str(name)] = p;
        }
        return d;
      },
      "The material presets: name -> stretch_modulus [N/m], bending_rigidity [N m], poisson_ratio, areal_density "
      "[kg/m^2] (for a woven preset the geometric means of warp and weft), orthotropic");
  m.def(
      "run",
      [](const fs::path& scene, const fs::path& out, const std::vector<std::string>& overrides, bool render,
         std::optional<double> end) {
        clothsim::RunOptions o;
        o.overrides = overrides;
        o.render = render;
        o.end = end;
        py::gil_scoped_release release;
        return clothsim::run_scene_file(scene, out, o);
      },
      py::arg("scene"), py::arg("out") = fs::path("out"), py::arg("set") = std::vector<std::string>{},
      py::arg("render") = true, py::arg("end") = py::none(),
      "Run a scene file as the program does, writing out/<name>/; returns the exit code (0: success)");
}

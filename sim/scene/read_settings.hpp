// The scene sections that are plain settings (internal to sim/scene/): each reader knows its
// section's keys, types, defaults and ranges (scenes/README.md) and turns the JSON into the
// settings it describes, without the mesh. Every failure is a SceneError naming the key.
#pragma once

#include "sim/mesh/imperfection.hpp"
#include "sim/scene/json_reader.hpp"

#include <string>

namespace clothsim::scene_io {

// "material.grain": {"warp_deg": deg} (docs/materials.md, Grain): how the warp lies on the mesh.
struct GrainSpec {
  bool given = false;     // the key is present
  double warp_deg = 0.0;  // [deg], from the mesh's reference direction
  std::string needed_by;  // the key that needs the grain when it is not given ("material", "render.texture")
};

// "mesh.max_vertices": the largest vertex count the scene may have (default kDefaultMaxVertices),
// read first so that no mesh (nor obstacle OBJ) larger than that is ever allocated.
long long read_max_vertices(const Reader& r, const Json& root);

ShellMaterial read_material(const Reader& r, const Json* j, GrainSpec& grain);

Quadrature read_numerics(const Reader& r, const Json* j);

Motion read_motion(const Reader& r, const Json& item, const std::string& path);

TimeSettings read_time(const Reader& r, const Json* j);

DampingSettings read_damping(const Reader& r, const Json* j);

SolverSettings read_solver(const Reader& r, const Json* j);

InitialState read_initial(const Reader& r, const Json* j);

// "output": {"obj": bool, "obj_level": int, "checkpoint_every": int}: whether OBJ frames are
// wanted, the refinement level of the surface they hold, and how often (in frames) a checkpoint
// is written for --resume.
void read_output(const Reader& r, const Json* j, Scene& scene);

// "settle": {"time": s >= 0, "damping": 1/s > 0}.
SettleSettings read_settle(const Reader& r, const Json* j);

// "imperfection": {"amplitude": m, "seed": int >= 0, "wavelength": [min, max] m}.
Imperfection read_imperfection(const Reader& r, const Json* j);

// "collision": {"self": bool, "thickness": m, "friction": -, "tolerance": -, "surface_level": int,
//               "method": "barrier" | "constraints"}.
void read_collision(const Reader& r, const Json* j, Problem& problem, bool& level_given);

RenderSettings read_render(const Reader& r, const Json* j);

}  // namespace clothsim::scene_io

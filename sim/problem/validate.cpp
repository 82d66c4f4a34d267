#include "sim/problem/validate.hpp"

#include "sim/core/layout.hpp"

#include <charconv>
#include <cmath>
#include <stdexcept>

namespace clothsim {

namespace {

// A double as a JSON number in its shortest round-trip form ("0.0", "1e-05").
std::string format_number(double v) {
  char buffer[64];
  const auto end = std::to_chars(buffer, buffer + sizeof(buffer), v).ptr;
  std::string s(buffer, end);
  if (std::isfinite(v) && s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

std::string index_key(const std::string& key, size_t i) { return key + "[" + std::to_string(i) + "]"; }

}  // namespace

std::optional<ProblemIssue> find_issue(const Problem& p, Analysis analysis) {
  if (const std::string bad = validate(p.material); !bad.empty()) return ProblemIssue{"material", bad};
  const int n = p.mesh.num_vertices();
  const bool dynamic = analysis == Analysis::dynamics;
  if (dynamic && !(p.material.areal_density > 0))
    return ProblemIssue{"material", "a dynamic analysis needs a positive areal density (mass) [kg/m²] (got " +
                                        format_number(p.material.areal_density) + ")"};
  // A flat spring network has no stiffness against out-of-plane displacements at rest, so the
  // linear statics of a flat sheet under a transverse load would be singular (docs/mass_spring.md).
  if (!dynamic && p.method == "mass_spring")
    return ProblemIssue{"method", "\"mass_spring\" needs \"analysis\": \"dynamic\": a spring's length changes only at "
                                  "second order when its ends move across it, so a flat spring network has no stiffness "
                                  "against out-of-plane displacements at rest and a linear static analysis has no answer; "
                                  "run the scene as a dynamic one with damping"};
  // A network of central springs cannot take an orthotropic law (docs/materials.md, What each
  // method can represent): its shear stiffness and Poisson ratio follow from the lattice.
  if (p.method == "mass_spring" && p.material.orthotropic())
    return ProblemIssue{"material", "an orthotropic material (stretch_modulus or bending_rigidity as an object, or an "
                                    "orthotropic preset) cannot be represented by \"mass_spring\": a network of central "
                                    "springs has no shear modulus or Poisson ratio of its own to set (they follow from the "
                                    "lattice), so woven cloth's soft shear would be lost; use \"loop_kl\" or \"linear_fe\""};
  if (p.material.orthotropic() && p.mesh.warp.size() != p.mesh.triangles.size())
    return ProblemIssue{"material", "an orthotropic material needs the grain: a warp direction per triangle of the mesh "
                                    "(the mesh has " + std::to_string(p.mesh.warp.size()) + " for " +
                                    std::to_string(p.mesh.triangles.size()) + " triangles)"};
  if (p.settle.time > 0 && p.rest != RestShape::pattern)
    return ProblemIssue{"settle", "needs a rest state of its own (\"rest\": \"pattern\"): the settled positions become the "
                                  "start, and with \"rest\": \"initial\" the start is the rest state"};
  if (!(std::isfinite(p.settle.time) && p.settle.time >= 0)) return ProblemIssue{"settle.time", "must be >= 0 [s]"};
  if (!(std::isfinite(p.settle.damping) && p.settle.damping > 0)) return ProblemIssue{"settle.damping", "must be > 0 [1/s]"};
  if (p.rest == RestShape::pattern) {
    // The flat rest state differs from the start: only the corotational Loop element in a dynamic
    // analysis measures its strains against a rest state of its own (linear statics would linearise
    // about a start that is not at rest).
    if (p.method != "loop_kl")
      return ProblemIssue{"rest", "\"pattern\" (a flat rest state) needs \"method\": \"loop_kl\" (got \"" + p.method + "\")"};
    if (!dynamic) return ProblemIssue{"rest", "\"pattern\" (a flat rest state) needs \"analysis\": \"dynamic\""};
    if (!p.corotational) return ProblemIssue{"rest", "\"pattern\" (a flat rest state) needs \"corotational\": true"};
    if (p.mesh.uv.size() != p.mesh.triangles.size())
      return ProblemIssue{"rest", "\"pattern\" (a flat rest state) needs the pattern coordinates in metres as texture "
                                  "coordinates on every triangle (a pattern mesh, or an OBJ with vt on every face)"};
  }
  for (size_t i = 0; i < p.boundary.size(); ++i) {
    const BoundaryCondition& bc = p.boundary[i];
    const std::string key = index_key("boundary", i);
    for (int v : bc.vertices)
      if (v < 0 || v >= n) return ProblemIssue{key, "vertex " + std::to_string(v) + " is not a vertex of the mesh"};
    if (!bc.motion.empty() && !dynamic) return ProblemIssue{key + ".motion", "needs \"analysis\": \"dynamic\" (this scene is static)"};
    if ((p.method == "linear_fe" || p.method == "mass_spring") && (bc.clamped || bc.symmetric))
      return ProblemIssue{key + ".rotation", std::string(bc.clamped ? "\"clamped\"" : "\"symmetry\"") +
                                                " is not supported by the " + p.method + " method (its nodes have no rotational "
                                                "degrees of freedom and its borders are hinged); use \"free\", or hold a "
                                                "slope by fixing two rows of vertices"};
    if (!bc.motion.empty() && bc.clamped)
      return ProblemIssue{key + ".rotation", "\"clamped\" cannot be combined with a motion yet (the clamped border rule is "
                                             "linear in the displacement); use \"free\" (hinged)"};
    for (size_t k = 0; k < bc.motion.size(); ++k)
      if (const std::string bad = validate(bc.motion[k]); !bad.empty()) return ProblemIssue{index_key(key + ".motion", k), bad};
  }
  for (size_t i = 0; i < p.point_loads.size(); ++i) {
    const int v = p.point_loads[i].vertex;
    if (v < 0 || v >= n)
      return ProblemIssue{index_key("loads.point_loads", i), "point load at vertex " + std::to_string(v) + ": no such vertex"};
  }
  const Eigen::VectorXd rest = to_flat(p.mesh.vertices);
  for (size_t i = 0; i < p.moments.size(); ++i) {
    const std::string key = index_key("loads.moments", i) + ".select";
    for (int v : p.moments[i].vertices)
      if (v < 0 || v >= n) return ProblemIssue{key, "vertex " + std::to_string(v) + " is not a vertex of the mesh"};
    Eigen::VectorXd f = Eigen::VectorXd::Zero(rest.size());
    if (!add_moment_forces(p.moments[i], rest, f))
      return ProblemIssue{key, "the selected vertices lie on one line parallel to the moment; select at least two rows of "
                               "vertices across it"};
  }
  if (!dynamic) return std::nullopt;
  if (!(std::isfinite(p.time.dt) && p.time.dt > 0)) return ProblemIssue{"time.dt", "must be > 0 [s]"};
  if (!(std::isfinite(p.time.end) && p.time.end > 0)) return ProblemIssue{"time.end", "must be > 0 [s]"};
  if (!(p.damping.stiffness >= 0)) return ProblemIssue{"damping.stiffness", "must be >= 0 [s]"};
  if (!(p.damping.mass >= 0)) return ProblemIssue{"damping.mass", "must be >= 0 [1/s]"};
  if (!(p.ramp_time >= 0)) return ProblemIssue{"loads.ramp_time", "must be >= 0 [s]"};
  if (!(p.solver.tolerance > 0 && p.solver.tolerance < 1)) return ProblemIssue{"solver.tolerance", "must be > 0 and < 1"};
  if (p.solver.max_iterations < 1) return ProblemIssue{"solver.max_iterations", "must be an integer >= 1"};
  if (p.solver.newton_iterations < 1) return ProblemIssue{"solver.newton_iterations", "must be an integer >= 1"};
  if (!(p.solver.rotation_tolerance_deg > 0 && p.solver.rotation_tolerance_deg <= 180))
    return ProblemIssue{"solver.rotation_tolerance_deg", "must be > 0 and <= 180 [deg]"};
  if (p.solver.refresh_iterations < 1) return ProblemIssue{"solver.refresh_iterations", "must be an integer >= 1"};
  return std::nullopt;
}

void check_problem(const Problem& problem, Analysis analysis) {
  if (const auto issue = find_issue(problem, analysis)) throw std::runtime_error(issue->text());
}

}  // namespace clothsim

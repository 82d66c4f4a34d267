// Writing RenderSettings as a scene file's "render" object (read back by the scene loader's own
// reader, see render_settings_from_json in scene.cpp).
#include "sim/scene/render_settings_json.hpp"

#include <nlohmann/json.hpp>

namespace clothsim {
namespace {

nlohmann::ordered_json vec3(const Eigen::Vector3d& v) { return nlohmann::ordered_json::array({v[0], v[1], v[2]}); }

}  // namespace

nlohmann::ordered_json render_settings_json(const RenderSettings& s) {
  nlohmann::ordered_json j = {{"width", s.width},
                              {"height", s.height},
                              {"refine", s.refine},
                              {"surface", drawn_surface_key(s.surface)},
                              {"color", vec3(s.color)},
                              {"back_color", vec3(s.back_color)},
                              {"background", vec3(s.background)},
                              {"wireframe", s.wireframe},
                              {"ground", s.ground},
                              {"shadow", s.shadow},
                              {"framing", s.framing == Framing::sequence ? "sequence" : "motion"}};
  if (s.texture != "none") j["texture"] = s.texture;  // (only when set: older outputs stay as they were)
  if (s.world_up != Eigen::Vector3d(0, 1, 0)) j["up"] = vec3(s.world_up);  // likewise
  if (s.has_camera)
    j["camera"] = {{"eye", vec3(s.eye)}, {"target", vec3(s.target)}, {"up", vec3(s.up)}, {"fov_deg", s.fov_deg}};
  return j;
}

}  // namespace clothsim

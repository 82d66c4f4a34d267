// The scene's "render" settings as JSON, and back: a run saves the settings it drew with
// (summary.json, result.json) so that `clothsim render DIR` can draw its saved frames again the
// same way. The JSON is the scene file's "render" object (scenes/README.md, "render") with every
// key written out.
#pragma once

#include "sim/scene/scene.hpp"

#include <nlohmann/json_fwd.hpp>

#include <string>

namespace clothsim {

// Every setting of `settings` as a scene file's "render" object: width, height, refine, surface,
// color, back_color, background, wireframe, ground, framing, and camera (eye, target, up, fov_deg)
// only if the settings have one. Numbers in their shortest round-trip form, so
// render_settings_from_json reads back identical settings.
nlohmann::ordered_json render_settings_json(const RenderSettings& settings);

// Reads a "render" object exactly as the scene loader does (the same keys, types, ranges and
// defaults for keys it lacks). Throws SceneError "<where>: render.<key>: <problem>" naming the
// bad key; `where` is usually the file the object came from. Defined in scene.cpp, next to the
// scene loader's reader of that object.
RenderSettings render_settings_from_json(const nlohmann::json& render, const std::string& where);

}  // namespace clothsim

// The "render" settings saved with a run (sim/scene/render_settings_json.hpp): written and read
// back identically (defaults, every key changed, a camera), read with the scene loader's checks
// (the error names the source and the key), and missing keys take the scene defaults.
#include "sim/scene/render_settings_json.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

namespace clothsim {
namespace {

void expect_same(const RenderSettings& a, const RenderSettings& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.refine, b.refine);
  EXPECT_EQ(a.surface, b.surface);
  EXPECT_EQ(a.color, b.color);
  EXPECT_EQ(a.back_color, b.back_color);
  EXPECT_EQ(a.background, b.background);
  EXPECT_EQ(a.wireframe, b.wireframe);
  EXPECT_EQ(a.texture, b.texture);
  EXPECT_EQ(a.ground, b.ground);
  EXPECT_EQ(a.shadow, b.shadow);
  EXPECT_EQ(a.has_camera, b.has_camera);
  EXPECT_EQ(a.eye, b.eye);
  EXPECT_EQ(a.target, b.target);
  EXPECT_EQ(a.up, b.up);
  EXPECT_EQ(a.fov_deg, b.fov_deg);
  EXPECT_EQ(a.framing, b.framing);
}

// Through text, as a run's summary.json is written and read.
RenderSettings round_trip(const RenderSettings& s) {
  return render_settings_from_json(nlohmann::json::parse(render_settings_json(s).dump(2)), "summary.json");
}

std::string error_of(const std::string& render_text) {
  try {
    render_settings_from_json(nlohmann::json::parse(render_text), "run/summary.json");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(RenderSettingsJson, DefaultsRoundTrip) {
  const RenderSettings defaults;
  expect_same(round_trip(defaults), defaults);
  EXPECT_EQ(render_settings_json(defaults).dump(),
            R"({"width":960,"height":720,"refine":2,"surface":"method","color":[0.8,0.1,0.1],)"
            R"("back_color":[0.5,0.1,0.1],"background":[1.0,1.0,1.0],"wireframe":false,"ground":false,)"
            R"("shadow":true,"framing":"motion"})");
}

TEST(RenderSettingsJson, EveryKeyChangedRoundTrips) {
  RenderSettings s;
  s.width = 64;
  s.height = 48;
  s.refine = 4;
  s.surface = DrawnSurface::flat;
  s.color = {0.1, 0.2, 1.0 / 3.0};
  s.back_color = {0, 0.25, 0.5};
  s.background = {0.9, 0.95, 1};
  s.wireframe = true;
  s.texture = "grain";
  s.ground = true;
  s.shadow = false;
  s.has_camera = true;
  s.eye = {0.3, -0.3, 0.6};
  s.target = {0, 0, -0.05};
  s.up = {0, 0, 1};
  s.fov_deg = 27.5;
  s.framing = Framing::sequence;
  const RenderSettings back = round_trip(s);
  expect_same(back, s);
  EXPECT_TRUE(render_settings_json(s).contains("camera"));
  s.surface = DrawnSurface::loop_limit;
  EXPECT_EQ(round_trip(s).surface, DrawnSurface::loop_limit);
}

TEST(RenderSettingsJson, MissingKeysTakeTheSceneDefaults) {
  const RenderSettings s = render_settings_from_json(nlohmann::json::parse(R"({"width": 64, "height": 48})"), "x");
  EXPECT_EQ(s.width, 64);
  EXPECT_EQ(s.height, 48);
  RenderSettings expected;
  expected.width = 64;
  expected.height = 48;
  expect_same(s, expected);
}

TEST(RenderSettingsJson, ErrorsNameTheSourceAndTheKey) {
  EXPECT_EQ(error_of(R"({"width": 8})").rfind("run/summary.json: render.width: ", 0), 0u) << error_of(R"({"width": 8})");
  EXPECT_NE(error_of(R"({"refine": 9})").find("run/summary.json: render.refine: must be an integer from 0 to 4"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"colour": [1, 0, 0]})").find("run/summary.json: render.colour: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"color": [2, 0, 0]})").find("render.color: colour components must lie in [0, 1]"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"surface": "smooth"})").find("render.surface"), std::string::npos);
  EXPECT_NE(error_of(R"({"camera": {"eye": [0, 0, 1], "target": [0, 0, 1]}})").find("render.camera: eye and target must differ"),
            std::string::npos);
  EXPECT_NE(error_of("[1, 2]").find("run/summary.json: render: expected an object"), std::string::npos);
}

}  // namespace
}  // namespace clothsim

// Which surface the pictures show (the scene key "render.surface"), and its name in the outputs.
//  - method:     the method's own surface — for loop_kl the Loop limit surface of the control
//                mesh with its ghost layer, for linear_fe and mass_spring the flat triangles;
//  - loop_limit: the Loop limit surface whose control vertices are the nodes, with the ghost
//                layer at open borders built as loop_kl builds it for free borders (for loop_kl
//                the same as `method`);
//  - flat:       the flat triangles over the nodes (for loop_kl: its control mesh drawn flat).
// Each is refined `levels` times for display (Discretization::drawn_display). Header only: the
// scene reader (sim/scene/) names these without depending on the discretisations.
#pragma once

#include <string>

namespace clothsim {

enum class DrawnSurface { method, loop_limit, flat };

// The scene-format value ("method", "loop_limit", "flat").
inline const char* drawn_surface_key(DrawnSurface s) {
  switch (s) {
    case DrawnSurface::loop_limit: return "loop_limit";
    case DrawnSurface::flat: return "flat";
    case DrawnSurface::method: break;
  }
  return "method";
}

// `method` resolved for a method ("loop_kl" draws its Loop limit surface, the flat methods their
// flat triangles); loop_limit and flat stay as they are.
inline DrawnSurface resolve_drawn_surface(const std::string& method, DrawnSurface s) {
  if (s != DrawnSurface::method) return s;
  return method == "loop_kl" ? DrawnSurface::loop_limit : DrawnSurface::flat;
}

// In words, for summaries and captions: "Loop limit surface refined 2x" or "flat mesh refined
// 2x" (midpoint subdivision: the flat triangles themselves); `s` is resolved for `method` first.
inline std::string drawn_surface_description(const std::string& method, DrawnSurface s, int levels) {
  const std::string what =
      resolve_drawn_surface(method, s) == DrawnSurface::loop_limit ? "Loop limit surface" : "flat mesh";
  return what + " refined " + std::to_string(levels) + "x";
}

}  // namespace clothsim

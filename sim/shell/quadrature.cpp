#include "sim/shell/quadrature.hpp"

namespace clothsim {

std::vector<QuadraturePoint> quadrature_points(Quadrature rule) {
  switch (rule) {
    case Quadrature::one_point:
      return {{1.0 / 3, 1.0 / 3, 0.5}};
    case Quadrature::three_point:
      return {{1.0 / 6, 1.0 / 6, 1.0 / 6}, {2.0 / 3, 1.0 / 6, 1.0 / 6}, {1.0 / 6, 2.0 / 3, 1.0 / 6}};
    case Quadrature::six_point: {
      // Dunavant (1985), degree 4: two orbits (a, a, 1 − 2a).
      const double a = 0.445948490915965, wa = 0.223381589678011 / 2;
      const double b = 0.091576213509771, wb = 0.109951743655322 / 2;
      return {{a, a, wa}, {1 - 2 * a, a, wa}, {a, 1 - 2 * a, wa},
              {b, b, wb}, {1 - 2 * b, b, wb}, {b, 1 - 2 * b, wb}};
    }
  }
  return {};
}

const char* to_string(Quadrature rule) {
  switch (rule) {
    case Quadrature::one_point: return "one_point";
    case Quadrature::three_point: return "three_point";
    case Quadrature::six_point: return "six_point";
  }
  return "?";
}

}  // namespace clothsim

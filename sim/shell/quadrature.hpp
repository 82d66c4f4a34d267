// Quadrature rules on the element's parameter triangle {v, w ≥ 0, v + w ≤ 1} (area 1/2).
#pragma once

#include <string>
#include <vector>

namespace clothsim {

enum class Quadrature {
  one_point,    // barycentre, weight 1/2: the paper's and Cirak et al.'s choice (exact for degree 1)
  three_point,  // interior points (1/6, 1/6), (2/3, 1/6), (1/6, 2/3), weights 1/6 (degree 2)
  six_point,    // Dunavant's rule (degree 4)
};

struct QuadraturePoint {
  double v, w;    // parameters
  double weight;  // weights sum to 1/2
};

std::vector<QuadraturePoint> quadrature_points(Quadrature rule);
const char* to_string(Quadrature rule);

}  // namespace clothsim

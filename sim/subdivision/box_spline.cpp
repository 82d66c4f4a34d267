#include "sim/subdivision/box_spline.hpp"

#include <array>

namespace clothsim {

namespace {

// A term c · u^a v^b w^c of a quartic polynomial in barycentric coordinates.
struct Term {
  double coefficient;
  int a, b, c;
};

// docs/formulas.md §2, Regular patches (Cirak et al. 2000, appendix A.1), before the common
// factor 1/12.
const std::array<std::vector<Term>, 12>& polynomials() {
  static const std::array<std::vector<Term>, 12> p = {{
      {{1, 4, 0, 0}, {2, 3, 1, 0}},
      {{1, 4, 0, 0}, {2, 3, 0, 1}},
      {{1, 4, 0, 0}, {2, 3, 0, 1}, {6, 3, 1, 0}, {6, 2, 1, 1}, {12, 2, 2, 0}, {6, 1, 2, 1}, {6, 1, 3, 0},
       {2, 0, 3, 1}, {1, 0, 4, 0}},
      {{6, 4, 0, 0}, {24, 3, 0, 1}, {24, 2, 0, 2}, {8, 1, 0, 3}, {1, 0, 0, 4}, {24, 3, 1, 0},
       {60, 2, 1, 1}, {36, 1, 1, 2}, {6, 0, 1, 3}, {24, 2, 2, 0}, {36, 1, 2, 1}, {12, 0, 2, 2},
       {8, 1, 3, 0}, {6, 0, 3, 1}, {1, 0, 4, 0}},
      {{1, 4, 0, 0}, {6, 3, 0, 1}, {12, 2, 0, 2}, {6, 1, 0, 3}, {1, 0, 0, 4}, {2, 3, 1, 0},
       {6, 2, 1, 1}, {6, 1, 1, 2}, {2, 0, 1, 3}},
      {{2, 1, 3, 0}, {1, 0, 4, 0}},
      {{1, 4, 0, 0}, {6, 3, 0, 1}, {12, 2, 0, 2}, {6, 1, 0, 3}, {1, 0, 0, 4}, {8, 3, 1, 0},
       {36, 2, 1, 1}, {36, 1, 1, 2}, {8, 0, 1, 3}, {24, 2, 2, 0}, {60, 1, 2, 1}, {24, 0, 2, 2},
       {24, 1, 3, 0}, {24, 0, 3, 1}, {6, 0, 4, 0}},
      {{1, 4, 0, 0}, {8, 3, 0, 1}, {24, 2, 0, 2}, {24, 1, 0, 3}, {6, 0, 0, 4}, {6, 3, 1, 0},
       {36, 2, 1, 1}, {60, 1, 1, 2}, {24, 0, 1, 3}, {12, 2, 2, 0}, {36, 1, 2, 1}, {24, 0, 2, 2},
       {6, 1, 3, 0}, {8, 0, 3, 1}, {1, 0, 4, 0}},
      {{2, 1, 0, 3}, {1, 0, 0, 4}},
      {{2, 0, 3, 1}, {1, 0, 4, 0}},
      {{2, 1, 0, 3}, {1, 0, 0, 4}, {6, 1, 1, 2}, {6, 0, 1, 3}, {6, 1, 2, 1}, {12, 0, 2, 2},
       {2, 1, 3, 0}, {6, 0, 3, 1}, {1, 0, 4, 0}},
      {{1, 0, 0, 4}, {2, 0, 1, 3}},
  }};
  return p;
}

// x^n and its first and second derivative.
inline double pw(double x, int n) {
  double r = 1.0;
  for (int i = 0; i < n; ++i) r *= x;
  return r;
}

}  // namespace

BoxSplineBasis box_spline_basis(double v, double w) {
  const double u = 1.0 - v - w;
  BoxSplineBasis out = BoxSplineBasis::Zero();
  for (int i = 0; i < 12; ++i) {
    for (const Term& t : polynomials()[i]) {
      // Partial derivatives of f = u^a v^b w^c in (u, v, w).
      const int a = t.a, b = t.b, c = t.c;
      const double fu = a > 0 ? a * pw(u, a - 1) * pw(v, b) * pw(w, c) : 0.0;
      const double fv = b > 0 ? b * pw(u, a) * pw(v, b - 1) * pw(w, c) : 0.0;
      const double fw = c > 0 ? c * pw(u, a) * pw(v, b) * pw(w, c - 1) : 0.0;
      const double fuu = a > 1 ? a * (a - 1) * pw(u, a - 2) * pw(v, b) * pw(w, c) : 0.0;
      const double fvv = b > 1 ? b * (b - 1) * pw(u, a) * pw(v, b - 2) * pw(w, c) : 0.0;
      const double fww = c > 1 ? c * (c - 1) * pw(u, a) * pw(v, b) * pw(w, c - 2) : 0.0;
      const double fuv = (a > 0 && b > 0) ? a * b * pw(u, a - 1) * pw(v, b - 1) * pw(w, c) : 0.0;
      const double fuw = (a > 0 && c > 0) ? a * c * pw(u, a - 1) * pw(v, b) * pw(w, c - 1) : 0.0;
      const double fvw = (b > 0 && c > 0) ? b * c * pw(u, a) * pw(v, b - 1) * pw(w, c - 1) : 0.0;
      // Chain rule with ∂u/∂v = ∂u/∂w = −1.
      const double k = t.coefficient / 12.0;
      out(kValue, i) += k * pw(u, a) * pw(v, b) * pw(w, c);
      out(kDv, i) += k * (fv - fu);
      out(kDw, i) += k * (fw - fu);
      out(kDvv, i) += k * (fvv - 2.0 * fuv + fuu);
      out(kDvw, i) += k * (fvw - fuv - fuw + fuu);
      out(kDww, i) += k * (fww - 2.0 * fuw + fuu);
    }
  }
  return out;
}

}  // namespace clothsim

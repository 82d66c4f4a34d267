// Boundary conditions on control vertices (paper §4.4; docs/formulas.md §4, Borders).
#pragma once

#include "sim/boundary/motion.hpp"

#include <array>
#include <vector>

namespace clothsim {

struct BoundaryCondition {
  std::vector<int> vertices;                  // selected control vertices
  std::array<bool, 3> fix{true, true, true};  // displacement components held at zero (x, y, z)
  bool clamped = false;                       // false: hinged (rotation free); true: slope held
                                              // across border edges whose two ends are selected
  bool symmetric = false;                     // plane of symmetry: across border edges whose two
                                              // ends are selected, fixed components are mirrored
                                              // oddly and free components evenly
  std::vector<Motion> motion;                 // dynamic analysis: the fixed components follow
                                              // this chain instead of staying at rest
};

}  // namespace clothsim

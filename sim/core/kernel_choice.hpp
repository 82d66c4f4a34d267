// Whether the x86-64 vector kernels (AVX2 + FMA; the corotational assembly's gather and the
// supernodal solves, each chosen at run time by what the processor supports) may run at all.
// CLOTHSIM_KERNELS=portable in the environment makes every dispatcher take its portable path, as
// on a processor without AVX2: the same build then runs both, so that results (goldens of folded
// states, tests/golden/README.md) can be checked against the arithmetic of other machines.
// Read once per process.
#pragma once

#include <cstdlib>
#include <string_view>

namespace clothsim {

inline bool vector_kernels_allowed() {
  static const bool allowed = [] {
    const char* choice = std::getenv("CLOTHSIM_KERNELS");
    return choice == nullptr || std::string_view(choice) != "portable";
  }();
  return allowed;
}

}  // namespace clothsim

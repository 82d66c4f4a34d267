// The corotational gather's inner loop without vector instructions, and the choice between it
// and the AVX2 + FMA kernel (assembly_kernels_avx2.cpp, compiled only where the compiler targets
// x86-64: CLOTHSIM_X86_KERNELS, set in sim/CMakeLists.txt).
#include "sim/corotation/assembly_kernels.hpp"

#include "sim/core/kernel_choice.hpp"

#include <Eigen/Core>

#include <cstdlib>

namespace clothsim {

namespace {
using assembly_avx2::kLanes;
using Lanes = Eigen::Array<double, kLanes, 1>;
}  // namespace

#if defined(CLOTHSIM_X86_KERNELS)
bool assembly_avx2::supported() {
  __builtin_cpu_init();
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && vector_kernels_allowed();
  return has;
}
#else
bool assembly_avx2::supported() { return false; }
// Never called (supported() is false); defined so that the dispatching code links.
void assembly_avx2::sum_block(int, const int*, const double*, const double*, const double*, const double*, const int*, int,
                              double*) {
  std::abort();
}
#endif

void assembly_avx2::sum_block_portable(int groups, const int* element, const double* rotations, const double* stiffness, const double* rows,
                        const double* tension, const int* point_offset, int points, double* out) {
  Lanes acc[9], r[9];
  for (Lanes& a : acc) a.setZero();
  for (int g = 0; g < groups; ++g, element += kLanes, stiffness += 9 * kLanes) {
    for (int c = 0; c < 9; ++c)
      for (int l = 0; l < kLanes; ++l) r[c](l) = rotations[9 * static_cast<long>(element[l]) + c];
    auto k = [stiffness](int c) { return Eigen::Map<const Lanes>(stiffness + kLanes * c); };
    for (int j = 0; j < 3; ++j) {
      const Lanes t0 = k(0) * r[j] + k(3) * r[j + 3] + k(6) * r[j + 6];
      const Lanes t1 = k(1) * r[j] + k(4) * r[j + 3] + k(7) * r[j + 6];
      const Lanes t2 = k(2) * r[j] + k(5) * r[j + 3] + k(8) * r[j + 6];
      for (int i = 0; i < 3; ++i) acc[i + 3 * j] += r[i] * t0 + r[i + 3] * t1 + r[i + 6] * t2;
    }
    if (!tension) continue;
    const double* products = rows + static_cast<long>(g) * 3 * kLanes * points;
    for (int q = 0; q < points; ++q, products += 3 * kLanes) {
      Lanes n11, n12, n22;
      for (int l = 0; l < kLanes; ++l) {
        const double* t = tension + 3 * static_cast<long>(point_offset[element[l]] + q);
        n11(l) = t[0], n12(l) = t[1], n22(l) = t[2];
      }
      const Lanes geometric = Eigen::Map<const Lanes>(products) * n11 + Eigen::Map<const Lanes>(products + kLanes) * n12 +
                              Eigen::Map<const Lanes>(products + 2 * kLanes) * n22;
      for (int i = 0; i < 3; ++i) acc[4 * i] += geometric;
    }
  }
  for (int c = 0; c < 9; ++c) out[c] = (acc[c](0) + acc[c](1)) + (acc[c](2) + acc[c](3));
}

}  // namespace clothsim

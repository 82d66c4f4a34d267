// Compiled with -mavx2 -mfma (sim/CMakeLists.txt); called only when supported() says so.
#include "sim/corotation/assembly_kernels.hpp"

#include <immintrin.h>

namespace clothsim::assembly_avx2 {

void sum_block(int groups, const int* element, const double* rotations, const double* stiffness, const double* rows,
               const double* tension, const int* point_offset, int points, double* out) {
  __m256d acc[9];
  for (__m256d& a : acc) a = _mm256_setzero_pd();
  for (int g = 0; g < groups; ++g, element += kLanes, stiffness += 9 * kLanes) {
    const double* r0 = rotations + 9 * static_cast<long>(element[0]);
    const double* r1 = rotations + 9 * static_cast<long>(element[1]);
    const double* r2 = rotations + 9 * static_cast<long>(element[2]);
    const double* r3 = rotations + 9 * static_cast<long>(element[3]);
    __m256d r[9];
    for (int c = 0; c < 9; ++c) r[c] = _mm256_set_pd(r3[c], r2[c], r1[c], r0[c]);
    auto k = [stiffness](int c) { return _mm256_loadu_pd(stiffness + kLanes * c); };
    // t = K Rᵀ one column at a time, then acc += R t.
    for (int j = 0; j < 3; ++j) {
      const __m256d t0 = _mm256_fmadd_pd(k(6), r[j + 6], _mm256_fmadd_pd(k(3), r[j + 3], _mm256_mul_pd(k(0), r[j])));
      const __m256d t1 = _mm256_fmadd_pd(k(7), r[j + 6], _mm256_fmadd_pd(k(4), r[j + 3], _mm256_mul_pd(k(1), r[j])));
      const __m256d t2 = _mm256_fmadd_pd(k(8), r[j + 6], _mm256_fmadd_pd(k(5), r[j + 3], _mm256_mul_pd(k(2), r[j])));
      for (int i = 0; i < 3; ++i)
        acc[i + 3 * j] = _mm256_add_pd(acc[i + 3 * j], _mm256_fmadd_pd(r[i + 6], t2, _mm256_fmadd_pd(r[i + 3], t1, _mm256_mul_pd(r[i], t0))));
    }
    if (!tension) continue;
    const double* products = rows + static_cast<long>(g) * 3 * kLanes * points;
    for (int q = 0; q < points; ++q, products += 3 * kLanes) {
      const double* t[kLanes];
      for (int l = 0; l < kLanes; ++l) t[l] = tension + 3 * static_cast<long>(point_offset[element[l]] + q);
      const __m256d n11 = _mm256_set_pd(t[3][0], t[2][0], t[1][0], t[0][0]);
      const __m256d n12 = _mm256_set_pd(t[3][1], t[2][1], t[1][1], t[0][1]);
      const __m256d n22 = _mm256_set_pd(t[3][2], t[2][2], t[1][2], t[0][2]);
      const __m256d geometric = _mm256_fmadd_pd(_mm256_loadu_pd(products + 2 * kLanes), n22,
                                                _mm256_fmadd_pd(_mm256_loadu_pd(products + kLanes), n12,
                                                                _mm256_mul_pd(_mm256_loadu_pd(products), n11)));
      for (int i = 0; i < 3; ++i) acc[4 * i] = _mm256_add_pd(acc[4 * i], geometric);
    }
  }
  for (int c = 0; c < 9; ++c) {
    alignas(32) double lane[kLanes];
    _mm256_store_pd(lane, acc[c]);
    out[c] = (lane[0] + lane[1]) + (lane[2] + lane[3]);
  }
}

}  // namespace clothsim::assembly_avx2

// Compiled with -mavx2 -mfma -mf16c (sim/CMakeLists.txt); called only when supported() says so.
#include "sim/solver/supernodal_kernels.hpp"

#include <immintrin.h>

namespace clothsim::supernodal_avx2 {

namespace {

float horizontal_sum(__m256 v) {
  const __m128 low = _mm256_castps256_ps128(v), high = _mm256_extractf128_ps(v, 1);
  __m128 s = _mm_add_ps(low, high);
  s = _mm_add_ps(s, _mm_movehl_ps(s, s));
  s = _mm_add_ss(s, _mm_shuffle_ps(s, s, 1));
  return _mm_cvtss_f32(s);
}

// Eight entries (unaligned) of a factor stored in single or half precision, as single precision.
__m256 load8(const float* p) { return _mm256_loadu_ps(p); }
__m256 load8(const unsigned short* p) { return _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))); }
float value(float x) { return x; }
float value(unsigned short h) { return _cvtsh_ss(h); }

template <typename T>
float dot(const T* a, const float* b, int n) {
  __m256 s0 = _mm256_setzero_ps(), s1 = _mm256_setzero_ps();
  int i = 0;
  for (; i + 16 <= n; i += 16) {
    s0 = _mm256_fmadd_ps(load8(a + i), _mm256_loadu_ps(b + i), s0);
    s1 = _mm256_fmadd_ps(load8(a + i + 8), _mm256_loadu_ps(b + i + 8), s1);
  }
  for (; i + 8 <= n; i += 8) s0 = _mm256_fmadd_ps(load8(a + i), _mm256_loadu_ps(b + i), s0);
  float sum = horizontal_sum(_mm256_add_ps(s0, s1));
  for (; i < n; ++i) sum += value(a[i]) * b[i];
  return sum;
}

// y += a x over n entries.
template <typename T>
void axpy(float a, const T* x, float* y, int n) {
  const __m256 va = _mm256_set1_ps(a);
  int i = 0;
  for (; i + 8 <= n; i += 8) _mm256_storeu_ps(y + i, _mm256_fmadd_ps(va, load8(x + i), _mm256_loadu_ps(y + i)));
  for (; i < n; ++i) y[i] += a * value(x[i]);
}

// The solves of one supernode, for both storages. `pivot(j, y)` divides y by the diagonal entry
// of column j (a division for the single-precision factor, a product with the stored inverse for
// the scaled half-precision one: each keeps the arithmetic it was tested with).
template <typename T, typename Pivot>
void forward_block(const T* block, int height, int cols, Pivot pivot, float* ys, float* below) {
  for (int j = 0; j < cols; ++j) {
    const T* col = block + static_cast<long>(j) * height;
    const float yj = pivot(j, ys[j]);
    ys[j] = yj;
    axpy(-yj, col + j + 1, ys + j + 1, cols - j - 1);
  }
  const int rows = height - cols;
  if (rows <= 0) return;
  for (int i = 0; i < rows; ++i) below[i] = 0.0f;
  int j = 0;
  for (; j + 4 <= cols; j += 4) {  // four columns per pass over `below`
    const T* c0 = block + static_cast<long>(j) * height + cols;
    const T* c1 = c0 + height;
    const T* c2 = c1 + height;
    const T* c3 = c2 + height;
    const __m256 y0 = _mm256_set1_ps(ys[j]), y1 = _mm256_set1_ps(ys[j + 1]), y2 = _mm256_set1_ps(ys[j + 2]),
                 y3 = _mm256_set1_ps(ys[j + 3]);
    int i = 0;
    for (; i + 8 <= rows; i += 8) {
      __m256 acc = _mm256_loadu_ps(below + i);
      acc = _mm256_fmadd_ps(y0, load8(c0 + i), acc);
      acc = _mm256_fmadd_ps(y1, load8(c1 + i), acc);
      acc = _mm256_fmadd_ps(y2, load8(c2 + i), acc);
      acc = _mm256_fmadd_ps(y3, load8(c3 + i), acc);
      _mm256_storeu_ps(below + i, acc);
    }
    for (; i < rows; ++i)
      below[i] += ys[j] * value(c0[i]) + ys[j + 1] * value(c1[i]) + ys[j + 2] * value(c2[i]) + ys[j + 3] * value(c3[i]);
  }
  for (; j < cols; ++j) axpy(ys[j], block + static_cast<long>(j) * height + cols, below, rows);
}

template <typename T, typename Pivot>
void backward_block(const T* block, int height, int cols, Pivot pivot, float* ys, const float* known) {
  const int rows = height - cols;
  if (rows > 0)
    for (int j = 0; j < cols; ++j) ys[j] -= dot(block + static_cast<long>(j) * height + cols, known, rows);
  for (int j = cols - 1; j >= 0; --j) {
    const T* col = block + static_cast<long>(j) * height;
    ys[j] = pivot(j, ys[j] - dot(col + j + 1, ys + j + 1, cols - j - 1));
  }
}

}  // namespace

void forward(const float* block, int height, int cols, float* ys, float* below) {
  forward_block(block, height, cols, [&](int j, float y) { return y / block[static_cast<long>(j) * height + j]; }, ys, below);
}

void backward(const float* block, int height, int cols, float* ys, const float* known) {
  backward_block(block, height, cols, [&](int j, float y) { return y / block[static_cast<long>(j) * height + j]; }, ys, known);
}

void forward(const unsigned short* block, int height, int cols, const float* inverse_diagonal, float* ys, float* below) {
  forward_block(block, height, cols, [&](int j, float y) { return y * inverse_diagonal[j]; }, ys, below);
}

void backward(const unsigned short* block, int height, int cols, const float* inverse_diagonal, float* ys, const float* known) {
  backward_block(block, height, cols, [&](int j, float y) { return y * inverse_diagonal[j]; }, ys, known);
}

void to_half(const float* values, const float* row_scale, const int* rows, int height, int cols, unsigned short* out) {
  for (int j = 0; j < cols; ++j) {
    const float* column = values + static_cast<long>(j) * height;
    unsigned short* target = out + static_cast<long>(j) * height;
    int i = 0;
    for (; i + 8 <= height; i += 8) {
      const __m256 scale = _mm256_set_ps(row_scale[rows[i + 7]], row_scale[rows[i + 6]], row_scale[rows[i + 5]], row_scale[rows[i + 4]],
                                         row_scale[rows[i + 3]], row_scale[rows[i + 2]], row_scale[rows[i + 1]], row_scale[rows[i]]);
      const __m128i h = _mm256_cvtps_ph(_mm256_mul_ps(_mm256_loadu_ps(column + i), scale), _MM_FROUND_TO_NEAREST_INT);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(target + i), h);
    }
    for (; i < height; ++i) target[i] = _cvtss_sh(column[i] * row_scale[rows[i]], _MM_FROUND_TO_NEAREST_INT);
  }
}

}  // namespace clothsim::supernodal_avx2

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

float dot(const float* a, const float* b, int n) {
  __m256 s0 = _mm256_setzero_ps(), s1 = _mm256_setzero_ps();
  int i = 0;
  for (; i + 16 <= n; i += 16) {
    s0 = _mm256_fmadd_ps(_mm256_loadu_ps(a + i), _mm256_loadu_ps(b + i), s0);
    s1 = _mm256_fmadd_ps(_mm256_loadu_ps(a + i + 8), _mm256_loadu_ps(b + i + 8), s1);
  }
  for (; i + 8 <= n; i += 8) s0 = _mm256_fmadd_ps(_mm256_loadu_ps(a + i), _mm256_loadu_ps(b + i), s0);
  float sum = horizontal_sum(_mm256_add_ps(s0, s1));
  for (; i < n; ++i) sum += a[i] * b[i];
  return sum;
}

// y += a x over n entries.
void axpy(float a, const float* x, float* y, int n) {
  const __m256 va = _mm256_set1_ps(a);
  int i = 0;
  for (; i + 8 <= n; i += 8) _mm256_storeu_ps(y + i, _mm256_fmadd_ps(va, _mm256_loadu_ps(x + i), _mm256_loadu_ps(y + i)));
  for (; i < n; ++i) y[i] += a * x[i];
}

// Eight half-precision values (unaligned) widened to single precision.
__m256 load_half(const unsigned short* p) { return _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))); }
float half_value(unsigned short h) { return _cvtsh_ss(h); }

float dot(const unsigned short* a, const float* b, int n) {
  __m256 s0 = _mm256_setzero_ps(), s1 = _mm256_setzero_ps();
  int i = 0;
  for (; i + 16 <= n; i += 16) {
    s0 = _mm256_fmadd_ps(load_half(a + i), _mm256_loadu_ps(b + i), s0);
    s1 = _mm256_fmadd_ps(load_half(a + i + 8), _mm256_loadu_ps(b + i + 8), s1);
  }
  for (; i + 8 <= n; i += 8) s0 = _mm256_fmadd_ps(load_half(a + i), _mm256_loadu_ps(b + i), s0);
  float sum = horizontal_sum(_mm256_add_ps(s0, s1));
  for (; i < n; ++i) sum += half_value(a[i]) * b[i];
  return sum;
}

void axpy(float a, const unsigned short* x, float* y, int n) {
  const __m256 va = _mm256_set1_ps(a);
  int i = 0;
  for (; i + 8 <= n; i += 8) _mm256_storeu_ps(y + i, _mm256_fmadd_ps(va, load_half(x + i), _mm256_loadu_ps(y + i)));
  for (; i < n; ++i) y[i] += a * half_value(x[i]);
}

}  // namespace

void forward(const float* block, int height, int cols, float* ys, float* below) {
  for (int j = 0; j < cols; ++j) {
    const float* col = block + static_cast<long>(j) * height;
    const float yj = ys[j] / col[j];
    ys[j] = yj;
    axpy(-yj, col + j + 1, ys + j + 1, cols - j - 1);
  }
  const int rows = height - cols;
  if (rows <= 0) return;
  for (int i = 0; i < rows; ++i) below[i] = 0.0f;
  int j = 0;
  for (; j + 4 <= cols; j += 4) {  // four columns per pass over `below`
    const float* c0 = block + static_cast<long>(j) * height + cols;
    const float* c1 = c0 + height;
    const float* c2 = c1 + height;
    const float* c3 = c2 + height;
    const __m256 y0 = _mm256_set1_ps(ys[j]), y1 = _mm256_set1_ps(ys[j + 1]), y2 = _mm256_set1_ps(ys[j + 2]),
                 y3 = _mm256_set1_ps(ys[j + 3]);
    int i = 0;
    for (; i + 8 <= rows; i += 8) {
      __m256 acc = _mm256_loadu_ps(below + i);
      acc = _mm256_fmadd_ps(y0, _mm256_loadu_ps(c0 + i), acc);
      acc = _mm256_fmadd_ps(y1, _mm256_loadu_ps(c1 + i), acc);
      acc = _mm256_fmadd_ps(y2, _mm256_loadu_ps(c2 + i), acc);
      acc = _mm256_fmadd_ps(y3, _mm256_loadu_ps(c3 + i), acc);
      _mm256_storeu_ps(below + i, acc);
    }
    for (; i < rows; ++i) below[i] += ys[j] * c0[i] + ys[j + 1] * c1[i] + ys[j + 2] * c2[i] + ys[j + 3] * c3[i];
  }
  for (; j < cols; ++j) axpy(ys[j], block + static_cast<long>(j) * height + cols, below, rows);
}

void backward(const float* block, int height, int cols, float* ys, const float* known) {
  const int rows = height - cols;
  if (rows > 0)
    for (int j = 0; j < cols; ++j) ys[j] -= dot(block + static_cast<long>(j) * height + cols, known, rows);
  for (int j = cols - 1; j >= 0; --j) {
    const float* col = block + static_cast<long>(j) * height;
    ys[j] = (ys[j] - dot(col + j + 1, ys + j + 1, cols - j - 1)) / col[j];
  }
}

void forward(const unsigned short* block, int height, int cols, const float* inverse_diagonal, float* ys, float* below) {
  for (int j = 0; j < cols; ++j) {
    const unsigned short* col = block + static_cast<long>(j) * height;
    const float yj = ys[j] * inverse_diagonal[j];
    ys[j] = yj;
    axpy(-yj, col + j + 1, ys + j + 1, cols - j - 1);
  }
  const int rows = height - cols;
  if (rows <= 0) return;
  for (int i = 0; i < rows; ++i) below[i] = 0.0f;
  int j = 0;
  for (; j + 4 <= cols; j += 4) {  // four columns per pass over `below`
    const unsigned short* c0 = block + static_cast<long>(j) * height + cols;
    const unsigned short* c1 = c0 + height;
    const unsigned short* c2 = c1 + height;
    const unsigned short* c3 = c2 + height;
    const __m256 y0 = _mm256_set1_ps(ys[j]), y1 = _mm256_set1_ps(ys[j + 1]), y2 = _mm256_set1_ps(ys[j + 2]),
                 y3 = _mm256_set1_ps(ys[j + 3]);
    int i = 0;
    for (; i + 8 <= rows; i += 8) {
      __m256 acc = _mm256_loadu_ps(below + i);
      acc = _mm256_fmadd_ps(y0, load_half(c0 + i), acc);
      acc = _mm256_fmadd_ps(y1, load_half(c1 + i), acc);
      acc = _mm256_fmadd_ps(y2, load_half(c2 + i), acc);
      acc = _mm256_fmadd_ps(y3, load_half(c3 + i), acc);
      _mm256_storeu_ps(below + i, acc);
    }
    for (; i < rows; ++i)
      below[i] += ys[j] * half_value(c0[i]) + ys[j + 1] * half_value(c1[i]) + ys[j + 2] * half_value(c2[i]) +
                  ys[j + 3] * half_value(c3[i]);
  }
  for (; j < cols; ++j) axpy(ys[j], block + static_cast<long>(j) * height + cols, below, rows);
}

void backward(const unsigned short* block, int height, int cols, const float* inverse_diagonal, float* ys, const float* known) {
  const int rows = height - cols;
  if (rows > 0)
    for (int j = 0; j < cols; ++j) ys[j] -= dot(block + static_cast<long>(j) * height + cols, known, rows);
  for (int j = cols - 1; j >= 0; --j) {
    const unsigned short* col = block + static_cast<long>(j) * height;
    ys[j] = (ys[j] - dot(col + j + 1, ys + j + 1, cols - j - 1)) * inverse_diagonal[j];
  }
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

// Dense kernels of the single-precision supernodal triangular solves (CholeskyPreconditioner),
// compiled for AVX2 + FMA + F16C in their own translation unit and chosen at run time where the processor
// has them. The unit uses raw pointers and intrinsics only (no Eigen, no standard-library
// templates), so no inline function is compiled twice with different instruction sets.
//
// A supernode's block is column-major, `height` rows by `cols` columns, leading dimension
// `height`; its first `cols` rows hold the lower-triangular diagonal block.
#pragma once

namespace clothsim::supernodal_avx2 {

// Whether this build and processor can run the kernels below (AVX2, FMA, F16C) (defined in
// supernodal_dispatch.cpp, which is compiled for the baseline instruction set).
bool supported();
// Forward step: ys ← D⁻¹ ys (D the diagonal block), below ← (rows under D) · ys.
void forward(const float* block, int height, int cols, float* ys, float* below);
// Backward step: ys ← D⁻ᵀ (ys − (rows under D)ᵀ · known).
void backward(const float* block, int height, int cols, float* ys, const float* known);


// The same on a factor stored in half precision (IEEE binary16, rows scaled: see
// CholeskyPreconditioner), its diagonal given apart, inverted, in single precision
// (`inverse_diagonal`: the supernode's `cols` values).
void forward(const unsigned short* block, int height, int cols, const float* inverse_diagonal, float* ys, float* below);
void backward(const unsigned short* block, int height, int cols, const float* inverse_diagonal, float* ys, const float* known);
// out ← half(values · row_scale[rows[i]]) for a block's entries, row i of every column scaled by
// row_scale[rows[i]] (round to nearest).
void to_half(const float* values, const float* row_scale, const int* rows, int height, int cols, unsigned short* out);

}  // namespace clothsim::supernodal_avx2

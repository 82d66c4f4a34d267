// The corotational stiffness gather's inner loop (CorotationalElements::assemble_stiffness) for
// AVX2 + FMA, in its own translation unit compiled for them and chosen at run time where the
// processor has them (raw pointers and intrinsics only: no inline function is compiled twice with
// different instruction sets).
//
// Layout (built by CorotationalElements): a block's contributions come in groups of kLanes
// elements (a short group is padded with zero blocks); group g has element[kLanes g + lane], its
// oriented K blocks interleaved (entry (i, j) at stiffness[kLanes (9 g + i + 3 j) + lane]) and, per
// quadrature point q, the basis-row products that turn an element's tension into its geometric
// stiffness (N_a,1 N_b,1, N_a,1 N_b,2 + N_a,2 N_b,1, N_a,2 N_b,2 at
// rows[kLanes (3 (points g + q) + k) + lane]).
#pragma once

namespace clothsim::assembly_avx2 {

constexpr int kLanes = 4;

// Whether this build and processor run the kernel (defined in assembly_kernels.cpp, compiled for
// the baseline instruction set).
bool supported();

// out (3 × 3, column-major) = Σ over groups [0, groups) and lanes of R K Rᵀ (R = rotations[9 e …],
// column-major, of the lane's element e) plus, with `tension` (3 per quadrature point, element e's
// from point_offset[e]), the geometric stiffness Σ_q (products · tension) on the diagonal. Each
// lane sums its groups in order; the lanes are added as (0 + 1) + (2 + 3).
void sum_block(int groups, const int* element, const double* rotations, const double* stiffness, const double* rows,
               const double* tension, const int* point_offset, int points, double* out);

// The same for processors without AVX2 + FMA (defined in assembly_kernels.cpp): the same sums in the
// same order, without fused multiply-adds (so equal up to round-off, not bitwise).
void sum_block_portable(int groups, const int* element, const double* rotations, const double* stiffness, const double* rows,
                        const double* tension, const int* point_offset, int points, double* out);

}  // namespace clothsim::assembly_avx2

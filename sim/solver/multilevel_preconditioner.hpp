// A multilevel (algebraic multigrid) preconditioner for the conjugate gradients of the implicit
// step: smoothed aggregation with the rigid-body modes as near-null space (Vaněk, Mandel &
// Brezina 1996), Chebyshev smoothing with the inverse node-block diagonal, and a Cholesky
// factorisation (CHOLMOD, double) of the coarsest level. The same interface as
// CholeskyPreconditioner: set up on a matrix with a free mask, then z = P⁻¹ r.
//
// What it achieves on the compressed sleeve at 2.5k–100k vertices (docs/performance.md,
// "Multilevel preconditioners"): 27–32 PCG iterations to 1e-8 with a fresh hierarchy at every
// size, memory linear in size (about 8 KiB per vertex), but one V-cycle costs about 7 products
// with A and a set-up about 300, so per step it is slower than the Cholesky factor up to ~100k
// vertices, where the two cost about the same and this uses 2.7× less memory. Not used by
// LinearSolver (yet).
//
// Results are deterministic: the hierarchy is built in a fixed order (sequentially, or by
// parallel loops over fixed chunks of rows in which each output entry comes from a fixed sequence
// of operations), and so is every loop of the cycle: the same inputs give the same bytes for any
// number of threads. apply() uses work vectors held by the object: not for concurrent calls.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string>
#include <vector>

namespace clothsim {

struct MultilevelSettings {
  // Near-null space of the finest level: 6 (three translations and three rotations about the
  // centroid, from the vertex positions) or 3 (translations only; also used without positions).
  int near_null_space = 6;
  // Strength of connection for aggregation: nodes i ≠ j are connected when
  // ‖A_ij‖_F ≥ threshold · √(‖A_ii‖_F ‖A_jj‖_F) (0: every entry of the pattern).
  double threshold = 0.08;
  // Jacobi steps smoothing the tentative prolongator (0: plain aggregation), and their weight
  // ω / λ_max(D⁻¹A).
  int prolongation_smoothing = 1;
  double prolongation_omega = 4.0 / 3.0;
  // Coarsening stops when a level has at most this many unknowns (it is then factorised) or after
  // max_levels levels.
  int coarse_size = 1500;
  int max_levels = 12;
  // Chebyshev smoothing with the inverse node-block diagonal: `smoothing_steps` products with the
  // level's matrix before and after the coarse correction, on the interval
  // [λ_max / chebyshev_ratio, 1.1 λ_max] of D⁻¹A.
  int smoothing_steps = 2;
  double chebyshev_ratio = 10.0;
  // 1: V-cycle; 2: W-cycle.
  int cycle = 1;
  // Power iterations estimating λ_max(D⁻¹A) on each level.
  int power_iterations = 12;
};

// "key=value key=value ..." (the field names above) on the defaults, for benchmarks; throws
// std::invalid_argument on an unknown key or a bad value.
MultilevelSettings parse_multilevel_settings(const std::string& text);

class MultilevelPreconditioner {
 public:
  explicit MultilevelPreconditioner(const MultilevelSettings& settings = {});
  ~MultilevelPreconditioner();
  MultilevelPreconditioner(const MultilevelPreconditioner&) = delete;
  MultilevelPreconditioner& operator=(const MultilevelPreconditioner&) = delete;

  // Builds the hierarchy for A (symmetric, full storage, 3 rows per vertex) on the rows and
  // columns with free[i] != 0 (the others are ignored: z is zero there). `positions`: the
  // vertices (3 per vertex, [m]) for the rotational near-null modes; empty: translations only.
  // Returns false when the coarsest level is not positive definite (no hierarchy is kept).
  bool setup(const Eigen::SparseMatrix<double>& a, const std::vector<char>& free, const Eigen::VectorXd& positions);
  // The same with the interface of CholeskyPreconditioner::factorize (translations only when
  // there are no positions; all rows free without a mask).
  bool factorize(const Eigen::SparseMatrix<double>& a, const std::vector<char>* free = nullptr,
                 const Eigen::VectorXd* positions = nullptr);
  bool ready() const;
  // Takes the values of a new matrix with the pattern of the last set-up's (a later step's):
  // level 0 (matrix, block diagonal, λ_max) always; with `galerkin`, also every coarser level's
  // matrix Pᵀ A P and the coarsest factorisation, the prolongators kept. Returns false if a block
  // or the coarsest level is not positive definite.
  bool refresh(const Eigen::SparseMatrix<double>& a, bool galerkin);
  // z = P⁻¹ r: one cycle from a zero start (z is resized; zero at the constrained rows).
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;

  int levels() const;
  // Unknowns of each level, finest first.
  std::vector<long> level_sizes() const;
  // Entries of all levels' matrices over those of the finest.
  double operator_complexity() const;
  // Bytes held by the hierarchy (matrices, prolongators, smoother data, coarse factor estimate).
  long memory_bytes() const;
  // One line: levels, sizes, complexity.
  std::string describe() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothsim

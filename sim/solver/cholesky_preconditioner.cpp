#include "sim/solver/cholesky_preconditioner.hpp"

#include "sim/solver/blas_single.hpp"

#include "sim/solver/direct_solver.hpp"
#include "sim/solver/supernodal_kernels.hpp"

#include <Eigen/CholmodSupport>

#include <cholmod.h>
#include <dlfcn.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_invoke.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace clothsim {

namespace {

// OpenBLAS runs each call on all cores by default; the factorisation below calls it from threads
// of its own (concurrent subtrees), so while it runs it asks for single-threaded calls where the
// library offers the switch (found at run time: libblas.so.3 may be another implementation, which
// is then left alone). OpenBLAS's own threads would compete for the same cores and spin.
class SingleThreadedBlas {
 public:
  SingleThreadedBlas() {
    static const auto get = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
    set_ = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    if (get && set_) {
      previous_ = get();
      if (previous_ > 1) set_(1);
    }
  }
  ~SingleThreadedBlas() {
    if (set_ && previous_ > 1) set_(previous_);
  }
  SingleThreadedBlas(const SingleThreadedBlas&) = delete;
  SingleThreadedBlas& operator=(const SingleThreadedBlas&) = delete;

 private:
  void (*set_)(int) = nullptr;
  int previous_ = 0;
};

}  // namespace

struct CholeskyPreconditioner::Impl {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  bool ready = false;
  double flops = 0.0;
  bool avx2 = false;
  bool single_precision = true;  // factorise in single precision (else: CHOLMOD in double, copied)
  bool single = false;           // the current factor was computed in single precision
  bool half_storage = true;      // keep the solves' copy of the factor in half precision (with avx2)
  bool half = false;             // the current factor's solves use the half-precision copy
  // The supernodal structure (copied once after the analysis) and the values in single precision.
  // Supernode s holds columns super[s] … super[s+1]−1 of L as a dense column-major block with
  // rows[row_start[s]] … rows[row_start[s+1]−1] (the first of them the diagonal block), whose
  // values start at value_start[s].
  std::vector<int> super, row_start, value_start, rows, perm;
  std::vector<float> values;
  // The half-precision copy for the solves: L̃ = S L with S = diag(row_scale), row_scale[k] =
  // 1/√(P A Pᵀ)_kk (1 in rows of the identity), so that every row of L̃ has unit norm and its
  // entries lie in [−1, 1], well inside binary16's range; the diagonal apart, as 1/L̃_kk in single
  // precision. Then A⁻¹ = Pᵀ S (L̃ L̃ᵀ)⁻¹ S P.
  std::vector<unsigned short> half_values;
  std::vector<float> row_scale, inverse_diagonal;
  // Two-core triangular solves: the supernodal elimination tree (postordered, so a subtree is a
  // contiguous range of supernodes ending at its root) is cut into a top part and two groups of
  // disjoint subtrees of about equal work. A subtree's updates reach only its own rows and the
  // top part's, so the groups run concurrently, each adding its updates of the top rows to its
  // own buffer; the top part then runs alone. Fixed summation order: deterministic.
  std::vector<std::pair<int, int>> group_ranges[2];  // [first, last] supernodes of each subtree
  std::vector<int> top;                              // supernodes of the top part, ascending
  int top_first_column = 0;                          // the top part's columns are the last ones
  mutable std::vector<float> work, gathered[2], top_update[2];

  // Single-precision numeric factorisation on CHOLMOD's symbolic analysis (supernodal,
  // left-looking): supernode s gathers its columns of P A Pᵀ, subtracts the updates of the
  // supernodes below it (descendants d whose rows reach s's columns: L_d,rows≥s · L_d,rows∈sᵀ), then
  // factorises its diagonal block and solves for the rows under it. Disjoint subtrees of the
  // supernodal elimination tree do not touch each other's blocks and run concurrently; within a
  // supernode the order of operations is fixed, so the result does not depend on the schedule.
  std::vector<int> tree_parent, tree_child_start, tree_children;  // supernodal elimination tree (CSR children)
  std::vector<int> update_start;                       // updates of s: [update_start[s], update_start[s+1])
  std::vector<int> update_from, update_first, update_end;  // d, first row of d at/after s's columns, first after them
  std::vector<int> gather_start;                       // entries of A gathered into s (CSR)
  std::vector<long> gather_src, gather_dst;            // A's value index → values index
  std::vector<int> gather_row, gather_col;             // A's row and column of the entry
  const char* free_mask = nullptr;                     // during numeric(): factorize()'s `free`
  long a_nonzeros = -1;
  std::vector<double> subtree_flops;
  struct Scratch {
    std::vector<int> local;      // row → position in the current supernode
    std::vector<float> update;   // one descendant's update block
  };
  tbb::enumerable_thread_specific<Scratch> scratch;
  void plan_numeric(const Eigen::SparseMatrix<double>& a);
  bool numeric_supernode(int s, const double* a_values);
  bool numeric_subtree(int s, const double* a_values);
  bool numeric(const Eigen::SparseMatrix<double>& a);
  void plan_split();
  void store_half(const Eigen::SparseMatrix<double>& a, const char* free);
  void forward(int first, int last, float* y, float* top_rows, float* gather) const;
  void backward(int first, int last, float* y, float* gather) const;

  Impl() {
    cholmod_start(&common);
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_METIS;
    common.postorder = 1;
    common.supernodal = CHOLMOD_SUPERNODAL;
    common.final_asis = 1;  // keep the supernodal LLᵀ
    common.print = 0;
  }
  ~Impl() {
    if (factor) cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
  }
};

CholeskyPreconditioner::CholeskyPreconditioner(bool vector_kernels, bool single_precision_factorization,
                                               bool half_precision_storage)
    : impl_(std::make_unique<Impl>()) {
  impl_->avx2 = vector_kernels && supernodal_avx2::supported();
  impl_->single_precision = single_precision_factorization;
  impl_->half_storage = half_precision_storage;
}
CholeskyPreconditioner::~CholeskyPreconditioner() = default;

bool CholeskyPreconditioner::ready() const { return impl_->ready; }
bool CholeskyPreconditioner::factored_in_single_precision() const { return impl_->ready && impl_->single; }
bool CholeskyPreconditioner::stored_in_half_precision() const { return impl_->ready && impl_->half; }
long CholeskyPreconditioner::factor_entries() const { return impl_->ready ? static_cast<long>(impl_->values.size()) : 0; }
double CholeskyPreconditioner::factor_flops() const { return impl_->ready ? impl_->flops : 0.0; }

bool CholeskyPreconditioner::factorize(const Eigen::SparseMatrix<double>& a, const std::vector<char>* free) {
  Impl& m = *impl_;
  m.ready = false;
  m.half = false;
  if (free && static_cast<Eigen::Index>(free->size()) != a.rows()) return false;
  Eigen::SparseMatrix<double>& matrix = const_cast<Eigen::SparseMatrix<double>&>(a);  // CHOLMOD reads only
  cholmod_sparse view = Eigen::viewAsCholmod(matrix);
  view.stype = -1;  // symmetric: the lower triangle is used
  if (!m.factor) {
    // Nested dissection (METIS) orders the cloth's meshes with less fill than AMD (the
    // 2542-vertex sleeve: 2.96 M entries and 1.54 GFlop against 3.14 M and 1.82 GFlop); AMD where
    // the library was built without METIS.
    m.factor = cholmod_analyze(&view, &m.common);
    if (!m.factor && m.common.method[0].ordering == CHOLMOD_METIS) {
      m.common.method[0].ordering = CHOLMOD_AMD;
      m.common.status = CHOLMOD_OK;
      m.factor = cholmod_analyze(&view, &m.common);
    }
    if (!m.factor) return false;
    m.flops = m.common.fl;
  }
  const cholmod_factor& l = *m.factor;
  if (m.super.empty()) {
    if (!l.is_super) return false;
    const auto nsuper = static_cast<size_t>(l.nsuper);
    const auto* super = static_cast<const int*>(l.super);
    const auto* pi = static_cast<const int*>(l.pi);
    const auto* px = static_cast<const int*>(l.px);
    m.super.assign(super, super + nsuper + 1);
    m.row_start.assign(pi, pi + nsuper + 1);
    m.value_start.assign(px, px + nsuper + 1);
    m.rows.assign(static_cast<const int*>(l.s), static_cast<const int*>(l.s) + pi[nsuper]);
    m.perm.assign(static_cast<const int*>(l.Perm), static_cast<const int*>(l.Perm) + l.n);
    m.work.resize(l.n);
    for (int g = 0; g < 2; ++g) m.gathered[g].resize(l.n);
    m.plan_split();
    m.plan_numeric(a);
  }
  m.free_mask = free ? free->data() : nullptr;
  m.single = m.single_precision && a.nonZeros() == m.a_nonzeros && m.numeric(a);
  m.free_mask = nullptr;
  if (m.single) {
    m.store_half(a, free ? free->data() : nullptr);
    m.ready = true;
    return true;
  }
  // CHOLMOD in double precision: without the single-precision option, or where it met a pivot
  // that is not positive (a matrix too ill-conditioned for single precision).
  Eigen::SparseMatrix<double> dirichlet;
  if (free) {
    dirichlet = a;
    set_dirichlet_identity(dirichlet, *free);
    view = Eigen::viewAsCholmod(dirichlet);
    view.stype = -1;
  }
  if (!cholmod_factorize(&view, m.factor, &m.common) || m.common.status != CHOLMOD_OK || !m.factor->is_super ||
      !m.factor->is_ll || m.factor->minor < m.factor->n)
    return false;
  const auto* x = static_cast<const double*>(l.x);
  m.values.assign(x, x + m.value_start.back());
  m.store_half(a, free ? free->data() : nullptr);
  m.ready = true;
  return true;
}

void CholeskyPreconditioner::Impl::store_half(const Eigen::SparseMatrix<double>& a, const char* free) {
  half = avx2 && half_storage;
  if (!half) return;
  const int n = static_cast<int>(perm.size());
  row_scale.resize(n);
  for (int k = 0; k < n; ++k) {
    const int j = perm[k];
    const double diagonal = free && !free[j] ? 1.0 : a.coeff(j, j);
    row_scale[k] = diagonal > 0.0 ? static_cast<float>(1.0 / std::sqrt(diagonal)) : 1.0f;
  }
  half_values.resize(values.size());
  inverse_diagonal.resize(n);
  const int nsuper = static_cast<int>(super.size()) - 1;
  tbb::parallel_for(tbb::blocked_range<int>(0, nsuper, 4), [&](const tbb::blocked_range<int>& range) {
    for (int s = range.begin(); s != range.end(); ++s) {
      const int col0 = super[s], cols = super[s + 1] - col0, height = row_start[s + 1] - row_start[s];
      const float* block = values.data() + value_start[s];
      supernodal_avx2::to_half(block, row_scale.data(), rows.data() + row_start[s], height, cols, half_values.data() + value_start[s]);
      for (int c = 0; c < cols; ++c) inverse_diagonal[col0 + c] = 1.0f / (block[static_cast<long>(c) * height + c] * row_scale[col0 + c]);
    }
  });
}

void CholeskyPreconditioner::Impl::plan_numeric(const Eigen::SparseMatrix<double>& a) {
  const int nsuper = static_cast<int>(super.size()) - 1;
  const int n = static_cast<int>(perm.size());
  std::vector<int> owner(n), pinv(n);
  for (int k = 0; k < n; ++k) pinv[perm[k]] = k;
  for (int s = 0; s < nsuper; ++s)
    for (int k = super[s]; k < super[s + 1]; ++k) owner[k] = s;
  tree_parent.assign(nsuper, -1);
  std::vector<std::vector<int>> kids(nsuper);
  std::vector<std::vector<std::array<int, 3>>> lists(nsuper);
  for (int d = 0; d < nsuper; ++d) {
    const int cols = super[d + 1] - super[d];
    const int begin = row_start[d] + cols, end = row_start[d + 1];
    if (begin < end) {
      tree_parent[d] = owner[rows[begin]];
      kids[tree_parent[d]].push_back(d);
    }
    for (int p = begin; p < end;) {
      const int s = owner[rows[p]];
      int q = p;
      while (q < end && rows[q] < super[s + 1]) ++q;
      lists[s].push_back({d, p, q});
      p = q;
    }
  }
  tree_child_start.assign(1, 0);
  tree_children.clear();
  update_start.assign(1, 0);
  update_from.clear(), update_first.clear(), update_end.clear();
  for (int s = 0; s < nsuper; ++s) {
    tree_children.insert(tree_children.end(), kids[s].begin(), kids[s].end());
    tree_child_start.push_back(static_cast<int>(tree_children.size()));
    for (const auto& [d, p, q] : lists[s]) update_from.push_back(d), update_first.push_back(p), update_end.push_back(q);
    update_start.push_back(static_cast<int>(update_from.size()));
  }
  // Work per subtree (for the split into concurrent tasks): the flops of its own updates and
  // factorisation, approximately.
  subtree_flops.assign(nsuper, 0.0);
  for (int s = 0; s < nsuper; ++s) {
    const double cols = super[s + 1] - super[s], height = row_start[s + 1] - row_start[s];
    subtree_flops[s] += cols * cols * cols / 3.0 + (height - cols) * cols * cols;
    for (int u = update_start[s]; u < update_start[s + 1]; ++u) {
      const int d = update_from[u];
      const double dcols = super[d + 1] - super[d];
      subtree_flops[s] += 2.0 * dcols * (update_end[u] - update_first[u]) * (row_start[d + 1] - update_first[u]);
    }
    if (tree_parent[s] >= 0) subtree_flops[tree_parent[s]] += subtree_flops[s];
  }
  // Where each entry of A's lower triangle (in the permuted order) goes in the factor's blocks.
  gather_start.assign(1, 0);
  gather_src.clear(), gather_dst.clear(), gather_row.clear(), gather_col.clear();
  std::vector<int> local(n, -1);
  for (int s = 0; s < nsuper; ++s) {
    const int height = row_start[s + 1] - row_start[s];
    for (int p = row_start[s]; p < row_start[s + 1]; ++p) local[rows[p]] = p - row_start[s];
    for (int k = super[s]; k < super[s + 1]; ++k) {
      const int j = perm[k];
      for (auto e = static_cast<long>(a.outerIndexPtr()[j]); e < a.outerIndexPtr()[j + 1]; ++e) {
        const int i = pinv[a.innerIndexPtr()[e]];
        if (i < k) continue;
        gather_src.push_back(e);
        gather_row.push_back(a.innerIndexPtr()[e]);
        gather_col.push_back(j);
        gather_dst.push_back(value_start[s] + static_cast<long>(k - super[s]) * height + local[i]);
      }
    }
    gather_start.push_back(static_cast<int>(gather_src.size()));
  }
  a_nonzeros = a.nonZeros();
  values.assign(static_cast<size_t>(value_start.back()), 0.0f);
}

namespace {

const char kLower = 'L', kNo = 'N', kTranspose = 'T', kRight = 'R';
const float kOne = 1.0f, kZero = 0.0f, kMinusOne = -1.0f;

// Subtracts the update of descendant rows x (m2 rows from the first of s's columns, dcols columns,
// leading dimension ld) restricted to x's rows ja … jb−1 as columns: block[local[row i], row j − col0]
// −= Σ_c x(i, c) x(j, c) for ja ≤ j < jb, j ≤ i < m2. `r` are the rows' global indices.
void subtract_update(const float* x, int ld, int dcols, int m2, int ja, int jb, const int* r, const int* local, int col0,
                     float* block, int height, std::vector<float>& buffer) {
  const int width = jb - ja, tall = m2 - ja;
  if (width <= 0) return;
  if (buffer.size() < static_cast<size_t>(width) * tall) buffer.resize(static_cast<size_t>(width) * tall);
  float* w = buffer.data();
  const float* xa = x + ja;
  ssyrk_(&kLower, &kNo, &width, &dcols, &kOne, xa, &ld, &kZero, w, &tall, 1, 1);
  const int below = tall - width;
  if (below > 0) sgemm_(&kNo, &kTranspose, &below, &width, &dcols, &kOne, xa + width, &ld, xa, &ld, &kZero, w + width, &tall, 1, 1);
  for (int j = 0; j < width; ++j) {
    float* target = block + static_cast<long>(r[ja + j] - col0) * height;
    const float* source = w + static_cast<long>(j) * tall;
    for (int i = j; i < tall; ++i) target[local[r[ja + i]]] -= source[i];
  }
}

// Columns per task in the parallel path of a large supernode (also the block size of its
// factorisation). Fixed, so the arithmetic does not depend on the number of threads.
constexpr int kChunk = 64;

}  // namespace

bool CholeskyPreconditioner::Impl::numeric_supernode(int s, const double* a_values) {
  Scratch& tmp = scratch.local();
  if (tmp.local.size() < perm.size()) tmp.local.assign(perm.size(), 0);
  const int col0 = super[s], cols = super[s + 1] - col0, height = row_start[s + 1] - row_start[s];
  float* block = values.data() + value_start[s];
  std::fill(block, block + static_cast<long>(height) * cols, 0.0f);
  for (int g = gather_start[s]; g < gather_start[s + 1]; ++g) {
    const int i = gather_row[g], j = gather_col[g];
    const bool identity = free_mask && !(free_mask[i] && free_mask[j]);
    values[gather_dst[g]] = identity ? (i == j ? 1.0f : 0.0f) : static_cast<float>(a_values[gather_src[g]]);
  }
  for (int p = row_start[s]; p < row_start[s + 1]; ++p) tmp.local[rows[p]] = p - row_start[s];
  const int* local = tmp.local.data();
  const int below = height - cols;
  if (cols < 2 * kChunk) {
    for (int u = update_start[s]; u < update_start[s + 1]; ++u) {
      const int d = update_from[u], first = update_first[u];
      subtract_update(values.data() + value_start[d] + (first - row_start[d]), row_start[d + 1] - row_start[d],
                      super[d + 1] - super[d], row_start[d + 1] - first, 0, update_end[u] - first, rows.data() + first, local,
                      col0, block, height, tmp.update);
    }
    int info = 0;
    spotrf_(&kLower, &cols, block, &height, &info, 1);
    if (info != 0) return false;
    if (below > 0) strsm_(&kRight, &kLower, &kTranspose, &kNo, &below, &cols, &kOne, block, &height, block + cols, &height, 1, 1, 1, 1);
    return true;
  }
  // A large supernode (the top separators: on the 2542-vertex sleeve a chain of five with 192 …
  // 993 columns holds most of the flops and has nothing to run beside it): both cores share it.
  // The updates go by chunks of its columns (each chunk takes every descendant's rows that fall
  // into it), then a blocked right-looking factorisation with the rows under the diagonal block
  // solved along. Isolated, so a waiting thread does not pick up another supernode's task (which
  // would refill its row map in use here).
  const int chunks = (cols + kChunk - 1) / kChunk;
  bool ok = true;
  tbb::this_task_arena::isolate([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, chunks, 1), [&](const tbb::blocked_range<int>& range) {
      std::vector<float>& buffer = scratch.local().update;
      for (int c = range.begin(); c != range.end(); ++c) {
        const int lo = col0 + c * kChunk, hi = std::min(col0 + cols, lo + kChunk);
        for (int u = update_start[s]; u < update_start[s + 1]; ++u) {
          const int d = update_from[u], first = update_first[u];
          const int* r = rows.data() + first;
          const int m1 = update_end[u] - first;
          const int ja = static_cast<int>(std::lower_bound(r, r + m1, lo) - r);
          const int jb = static_cast<int>(std::lower_bound(r + ja, r + m1, hi) - r);
          subtract_update(values.data() + value_start[d] + (first - row_start[d]), row_start[d + 1] - row_start[d],
                          super[d + 1] - super[d], row_start[d + 1] - first, ja, jb, r, local, col0, block, height, buffer);
        }
      }
    }, tbb::simple_partitioner());
    for (int k = 0; k < cols && ok; k += kChunk) {
      const int kb = std::min(kChunk, cols - k);
      float* diagonal = block + k + static_cast<long>(k) * height;
      int info = 0;
      spotrf_(&kLower, &kb, diagonal, &height, &info, 1);
      if (info != 0) {
        ok = false;
        break;
      }
      const int rest = height - k - kb;  // rows under this diagonal block
      if (rest <= 0) break;
      const int row_chunks = (rest + 2 * kChunk - 1) / (2 * kChunk);
      tbb::parallel_for(tbb::blocked_range<int>(0, row_chunks, 1), [&](const tbb::blocked_range<int>& range) {
        for (int c = range.begin(); c != range.end(); ++c) {
          const int first_row = k + kb + c * 2 * kChunk, count = std::min(2 * kChunk, height - first_row);
          strsm_(&kRight, &kLower, &kTranspose, &kNo, &count, &kb, &kOne, diagonal, &height, block + first_row + static_cast<long>(k) * height,
                 &height, 1, 1, 1, 1);
        }
      }, tbb::simple_partitioner());
      // Trailing columns of the diagonal block: A[j…, j…j+w) −= L[j…, k…k+kb) L[j…j+w, k…k+kb)ᵀ.
      const int trailing = cols - k - kb;
      if (trailing <= 0) continue;
      const int column_chunks = (trailing + kChunk - 1) / kChunk;
      tbb::parallel_for(tbb::blocked_range<int>(0, column_chunks, 1), [&](const tbb::blocked_range<int>& range) {
        for (int c = range.begin(); c != range.end(); ++c) {
          const int j = k + kb + c * kChunk, w = std::min(kChunk, cols - j), tall = height - j;
          const float* lj = block + j + static_cast<long>(k) * height;
          float* target = block + j + static_cast<long>(j) * height;
          ssyrk_(&kLower, &kNo, &w, &kb, &kMinusOne, lj, &height, &kOne, target, &height, 1, 1);
          const int under = tall - w;
          if (under > 0)
            sgemm_(&kNo, &kTranspose, &under, &w, &kb, &kMinusOne, lj + w, &height, lj, &height, &kOne, target + w, &height, 1, 1);
        }
      }, tbb::simple_partitioner());
    }
  });
  return ok;
}

bool CholeskyPreconditioner::Impl::numeric_subtree(int s, const double* a_values) {
  // Children with much work run as tasks; the rest here.
  bool ok = true;
  const int first = tree_child_start[s], last = tree_child_start[s + 1];
  if (last - first >= 2 && subtree_flops[s] > 2e6) {
    std::vector<char> result(static_cast<size_t>(last - first), 1);
    tbb::task_group group;
    for (int c = first; c < last; ++c) group.run([&, c] { result[c - first] = numeric_subtree(tree_children[c], a_values); });
    group.wait();
    for (char r : result) ok = ok && r;
  } else {
    for (int c = first; c < last; ++c) ok = ok && numeric_subtree(tree_children[c], a_values);
  }
  return ok && numeric_supernode(s, a_values);
}

bool CholeskyPreconditioner::Impl::numeric(const Eigen::SparseMatrix<double>& a) {
  const SingleThreadedBlas blas;
  const int nsuper = static_cast<int>(super.size()) - 1;
  bool ok = true;
  for (int s = 0; s < nsuper; ++s)
    if (tree_parent[s] < 0) ok = ok && numeric_subtree(s, a.valuePtr());
  return ok;
}

void CholeskyPreconditioner::Impl::plan_split() {
  const int nsuper = static_cast<int>(super.size()) - 1;
  std::vector<int> owner(perm.size());  // column → supernode
  for (int s = 0; s < nsuper; ++s)
    for (int k = super[s]; k < super[s + 1]; ++k) owner[k] = s;
  std::vector<int> parent(nsuper, -1), first(nsuper);
  std::vector<double> work_of(nsuper);  // entries of the subtree's blocks
  std::vector<std::vector<int>> children(nsuper);
  std::vector<int> roots;
  for (int s = 0; s < nsuper; ++s) {
    const int cols = super[s + 1] - super[s], height = row_start[s + 1] - row_start[s];
    first[s] = s;
    work_of[s] += static_cast<double>(cols) * height;
    if (height > cols) parent[s] = owner[rows[row_start[s] + cols]];
    if (parent[s] >= 0) {
      children[parent[s]].push_back(s);
      work_of[parent[s]] += work_of[s];
    } else {
      roots.push_back(s);
    }
  }
  for (int s = 0; s < nsuper; ++s)
    for (int c : children[s]) first[s] = std::min(first[s], first[c]);
  // Open the heaviest subtree of the frontier until two balanced groups exist (or the top part
  // would hold more than a third of the work).
  std::vector<int> frontier = roots;
  double total = 0.0;
  for (int r : roots) total += work_of[r];
  double top_work = 0.0;
  for (;;) {
    std::vector<int> sorted = frontier;
    std::sort(sorted.begin(), sorted.end(), [&](int a, int b) { return work_of[a] > work_of[b] || (work_of[a] == work_of[b] && a < b); });
    double load[2] = {0.0, 0.0};
    for (int g = 0; g < 2; ++g) group_ranges[g].clear();
    for (int r : sorted) {
      const int g = load[0] <= load[1] ? 0 : 1;
      load[g] += work_of[r];
      group_ranges[g].emplace_back(first[r], r);
    }
    const double heaviest = std::max(load[0], load[1]);
    if (heaviest <= 0.55 * (load[0] + load[1]) || sorted.empty()) break;
    const int open = sorted.front();
    const double own = static_cast<double>(super[open + 1] - super[open]) * (row_start[open + 1] - row_start[open]);
    if (top_work + own > total / 3.0) break;
    top_work += own;
    top.push_back(open);
    frontier.erase(std::find(frontier.begin(), frontier.end(), open));
    frontier.insert(frontier.end(), children[open].begin(), children[open].end());
  }
  std::sort(top.begin(), top.end());
  // The top part must be the last supernodes (ancestors come after descendants in a postorder):
  // check, else run everything as one group.
  const int expected_first = nsuper - static_cast<int>(top.size());
  bool tail = true;
  for (size_t i = 0; i < top.size(); ++i) tail = tail && top[i] == expected_first + static_cast<int>(i);
  if (!tail || top.empty()) {
    top.clear();
    group_ranges[0].assign(1, {0, nsuper - 1});
    group_ranges[1].clear();
  }
  top_first_column = top.empty() ? static_cast<int>(perm.size()) : super[top.front()];
  for (int g = 0; g < 2; ++g) top_update[g].assign(perm.size() - static_cast<size_t>(top_first_column), 0.0f);
}

namespace {
using Block = Eigen::Map<const Eigen::MatrixXf, 0, Eigen::OuterStride<>>;
}

// Forward substitution over supernodes first … last; updates of rows at or beyond the top part's
// first column go to top_rows (indexed from that column) when given.
void CholeskyPreconditioner::Impl::forward(int first, int last, float* y, float* top_rows, float* gather) const {
  for (int s = first; s <= last; ++s) {
    const int col0 = super[s], cols = super[s + 1] - col0, height = row_start[s + 1] - row_start[s];
    const int below = height - cols;
    if (half) {
      supernodal_avx2::forward(half_values.data() + value_start[s], height, cols, inverse_diagonal.data() + col0, y + col0, gather);
    } else if (avx2) {
      supernodal_avx2::forward(values.data() + value_start[s], height, cols, y + col0, gather);
    } else {
      const Block block(values.data() + value_start[s], height, cols, Eigen::OuterStride<>(height));
      Eigen::Map<Eigen::VectorXf> ys(y + col0, cols);
      block.topRows(cols).triangularView<Eigen::Lower>().solveInPlace(ys);
      if (below > 0) Eigen::Map<Eigen::VectorXf>(gather, below).noalias() = block.bottomRows(below) * ys;
    }
    if (below == 0) continue;
    const float* update = gather;
    const int* r = rows.data() + row_start[s] + cols;
    for (int i = 0; i < below; ++i) {
      if (top_rows && r[i] >= top_first_column)
        top_rows[r[i] - top_first_column] += update[i];
      else
        y[r[i]] -= update[i];
    }
  }
}

void CholeskyPreconditioner::Impl::backward(int first, int last, float* y, float* gather) const {
  for (int s = last; s >= first; --s) {
    const int col0 = super[s], cols = super[s + 1] - col0, height = row_start[s + 1] - row_start[s];
    const int below = height - cols;
    const int* r = rows.data() + row_start[s] + cols;
    for (int i = 0; i < below; ++i) gather[i] = y[r[i]];
    if (half) {
      supernodal_avx2::backward(half_values.data() + value_start[s], height, cols, inverse_diagonal.data() + col0, y + col0, gather);
      continue;
    }
    if (avx2) {
      supernodal_avx2::backward(values.data() + value_start[s], height, cols, y + col0, gather);
      continue;
    }
    const Block block(values.data() + value_start[s], height, cols, Eigen::OuterStride<>(height));
    Eigen::Map<Eigen::VectorXf> ys(y + col0, cols);
    if (below > 0) ys.noalias() -= block.bottomRows(below).transpose() * Eigen::Map<const Eigen::VectorXf>(gather, below);
    block.topRows(cols).transpose().triangularView<Eigen::Upper>().solveInPlace(ys);
  }
}

void CholeskyPreconditioner::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  const Impl& m = *impl_;
  const int n = static_cast<int>(m.perm.size());
  float* y = m.work.data();
  if (m.half)
    for (int k = 0; k < n; ++k) y[k] = static_cast<float>(r[m.perm[k]]) * m.row_scale[k];
  else
    for (int k = 0; k < n; ++k) y[k] = static_cast<float>(r[m.perm[k]]);
  // L y = P r: the two groups of subtrees, then the top part.
  auto forward_group = [&](int g) {
    for (const auto& [first, last] : m.group_ranges[g]) m.forward(first, last, y, m.top.empty() ? nullptr : m.top_update[g].data(), m.gathered[g].data());
  };
  if (m.group_ranges[1].empty())
    forward_group(0);
  else
    tbb::parallel_invoke([&] { forward_group(0); }, [&] { forward_group(1); });
  if (!m.top.empty()) {
    for (int g = 0; g < 2; ++g)
      for (int k = m.top_first_column; k < n; ++k) {
        y[k] -= m.top_update[g][k - m.top_first_column];
        m.top_update[g][k - m.top_first_column] = 0.0f;
      }
    m.forward(m.top.front(), m.top.back(), y, nullptr, m.gathered[0].data());
    // Lᵀ x = y: the top part, then the groups.
    m.backward(m.top.front(), m.top.back(), y, m.gathered[0].data());
  }
  auto backward_group = [&](int g) {
    for (const auto& [first, last] : m.group_ranges[g]) m.backward(first, last, y, m.gathered[g].data());
  };
  if (m.group_ranges[1].empty())
    backward_group(0);
  else
    tbb::parallel_invoke([&] { backward_group(0); }, [&] { backward_group(1); });
  z.resize(n);
  if (m.half)
    for (int k = 0; k < n; ++k) z[m.perm[k]] = y[k] * m.row_scale[k];
  else
    for (int k = 0; k < n; ++k) z[m.perm[k]] = y[k];
}

}  // namespace clothsim

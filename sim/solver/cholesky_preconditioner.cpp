#include "sim/solver/cholesky_preconditioner.hpp"

#include "sim/solver/supernodal_kernels.hpp"

#include <Eigen/CholmodSupport>

#include <cholmod.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <vector>

namespace clothsim {

bool supernodal_avx2::supported() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}

struct CholeskyPreconditioner::Impl {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  bool ready = false;
  double flops = 0.0;
  bool avx2 = false;
  // The supernodal structure (copied once after the analysis) and the values in single precision.
  // Supernode s holds columns super[s] … super[s+1]−1 of L as a dense column-major block with
  // rows[row_start[s]] … rows[row_start[s+1]−1] (the first of them the diagonal block), whose
  // values start at value_start[s].
  std::vector<int> super, row_start, value_start, rows, perm;
  std::vector<float> values;
  // Two-core triangular solves: the supernodal elimination tree (postordered, so a subtree is a
  // contiguous range of supernodes ending at its root) is cut into a top part and two groups of
  // disjoint subtrees of about equal work. A subtree's updates reach only its own rows and the
  // top part's, so the groups run concurrently, each adding its updates of the top rows to its
  // own buffer; the top part then runs alone. Fixed summation order: deterministic.
  std::vector<std::pair<int, int>> group_ranges[2];  // [first, last] supernodes of each subtree
  std::vector<int> top;                              // supernodes of the top part, ascending
  int top_first_column = 0;                          // the top part's columns are the last ones
  mutable std::vector<float> work, gathered[2], top_update[2];

  void plan_split();
  void forward(int first, int last, float* y, float* top_rows, float* gather) const;
  void backward(int first, int last, float* y, float* gather) const;

  Impl() {
    cholmod_start(&common);
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_AMD;
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

CholeskyPreconditioner::CholeskyPreconditioner(bool vector_kernels) : impl_(std::make_unique<Impl>()) {
  impl_->avx2 = vector_kernels && supernodal_avx2::supported();
}
CholeskyPreconditioner::~CholeskyPreconditioner() = default;

bool CholeskyPreconditioner::ready() const { return impl_->ready; }
long CholeskyPreconditioner::factor_entries() const { return impl_->ready ? static_cast<long>(impl_->values.size()) : 0; }
double CholeskyPreconditioner::factor_flops() const { return impl_->ready ? impl_->flops : 0.0; }

bool CholeskyPreconditioner::factorize(const Eigen::SparseMatrix<double>& a) {
  Impl& m = *impl_;
  m.ready = false;
  Eigen::SparseMatrix<double>& matrix = const_cast<Eigen::SparseMatrix<double>&>(a);  // CHOLMOD reads only
  cholmod_sparse view = Eigen::viewAsCholmod(matrix);
  view.stype = -1;  // symmetric: the lower triangle is used
  if (!m.factor) {
    m.factor = cholmod_analyze(&view, &m.common);
    if (!m.factor) return false;
    m.flops = m.common.fl;
  }
  if (!cholmod_factorize(&view, m.factor, &m.common) || m.common.status != CHOLMOD_OK || !m.factor->is_super ||
      !m.factor->is_ll || m.factor->minor < m.factor->n)
    return false;
  const cholmod_factor& l = *m.factor;
  const auto* super = static_cast<const int*>(l.super);
  const auto* pi = static_cast<const int*>(l.pi);
  const auto* px = static_cast<const int*>(l.px);
  if (m.super.empty()) {
    const auto nsuper = static_cast<size_t>(l.nsuper);
    m.super.assign(super, super + nsuper + 1);
    m.row_start.assign(pi, pi + nsuper + 1);
    m.value_start.assign(px, px + nsuper + 1);
    m.rows.assign(static_cast<const int*>(l.s), static_cast<const int*>(l.s) + pi[nsuper]);
    m.perm.assign(static_cast<const int*>(l.Perm), static_cast<const int*>(l.Perm) + l.n);
    m.work.resize(l.n);
    for (int g = 0; g < 2; ++g) m.gathered[g].resize(l.n);
    m.plan_split();
  }
  const auto* x = static_cast<const double*>(l.x);
  m.values.assign(x, x + m.value_start.back());
  m.ready = true;
  return true;
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
    if (avx2) {
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
  for (int k = 0; k < n; ++k) z[m.perm[k]] = y[k];
}

}  // namespace clothsim

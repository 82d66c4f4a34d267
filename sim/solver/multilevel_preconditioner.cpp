#include "sim/solver/multilevel_preconditioner.hpp"

#include "sim/solver/direct_solver.hpp"

#include <Eigen/Dense>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace clothsim {

namespace {

using Csr = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;
using Index = Eigen::Index;

// Rows per parallel task: fixed, so that the work split (and nothing else) depends on the threads.
constexpr Index kChunk = 512;

template <class Body>
void parallel_rows(Index n, Body body) {
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, kChunk), [&](const tbb::blocked_range<Index>& r) {
    for (Index i = r.begin(); i != r.end(); ++i) body(i);
  });
}

// y = A x, rows in parallel; each y_i sums its row in storage order.
void multiply(const Csr& a, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  y.resize(a.rows());
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  parallel_rows(a.rows(), [&](Index i) {
    double sum = 0.0;
    for (int k = outer[i]; k < outer[i + 1]; ++k) sum += values[k] * x[inner[k]];
    y[i] = sum;
  });
}

// r = b − A x.
void residual(const Csr& a, const Eigen::VectorXd& b, const Eigen::VectorXd& x, Eigen::VectorXd& r) {
  r.resize(a.rows());
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  parallel_rows(a.rows(), [&](Index i) {
    double sum = b[i];
    for (int k = outer[i]; k < outer[i + 1]; ++k) sum -= values[k] * x[inner[k]];
    r[i] = sum;
  });
}

// C = A B (both compressed rows), rows in parallel (Gustavson: row i of C accumulates
// a_ik · (row k of B) in storage order, then its columns are sorted). Deterministic for any
// number of threads.
Csr product(const Csr& a, const Csr& b) {
  const Index rows = a.rows(), cols = b.cols();
  const int* a_outer = a.outerIndexPtr();
  const int* a_inner = a.innerIndexPtr();
  const double* a_values = a.valuePtr();
  const int* b_outer = b.outerIndexPtr();
  const int* b_inner = b.innerIndexPtr();
  const double* b_values = b.valuePtr();
  // Pass 1: entries per row.
  std::vector<int> count(static_cast<std::size_t>(rows) + 1, 0);
  tbb::parallel_for(tbb::blocked_range<Index>(0, rows, kChunk), [&](const tbb::blocked_range<Index>& range) {
    std::vector<Index> marker(static_cast<std::size_t>(cols), -1);
    for (Index i = range.begin(); i != range.end(); ++i) {
      int c = 0;
      for (int k = a_outer[i]; k < a_outer[i + 1]; ++k)
        for (int l = b_outer[a_inner[k]]; l < b_outer[a_inner[k] + 1]; ++l)
          if (marker[static_cast<std::size_t>(b_inner[l])] != i) {
            marker[static_cast<std::size_t>(b_inner[l])] = i;
            ++c;
          }
      count[static_cast<std::size_t>(i) + 1] = c;
    }
  });
  for (Index i = 0; i < rows; ++i) count[static_cast<std::size_t>(i) + 1] += count[static_cast<std::size_t>(i)];
  Csr c(rows, cols);
  c.resizeNonZeros(count.back());
  int* c_outer = c.outerIndexPtr();
  for (Index i = 0; i <= rows; ++i) c_outer[i] = count[static_cast<std::size_t>(i)];
  int* c_inner = c.innerIndexPtr();
  double* c_values = c.valuePtr();
  // Pass 2: values.
  tbb::parallel_for(tbb::blocked_range<Index>(0, rows, kChunk), [&](const tbb::blocked_range<Index>& range) {
    std::vector<double> accumulator(static_cast<std::size_t>(cols), 0.0);
    std::vector<Index> marker(static_cast<std::size_t>(cols), -1);
    for (Index i = range.begin(); i != range.end(); ++i) {
      int* row = c_inner + c_outer[i];
      int n = 0;
      for (int k = a_outer[i]; k < a_outer[i + 1]; ++k) {
        const double aik = a_values[k];
        for (int l = b_outer[a_inner[k]]; l < b_outer[a_inner[k] + 1]; ++l) {
          const int j = b_inner[l];
          if (marker[static_cast<std::size_t>(j)] != i) {
            marker[static_cast<std::size_t>(j)] = i;
            accumulator[static_cast<std::size_t>(j)] = aik * b_values[l];
            row[n++] = j;
          } else {
            accumulator[static_cast<std::size_t>(j)] += aik * b_values[l];
          }
        }
      }
      std::sort(row, row + n);
      for (int q = 0; q < n; ++q) c_values[c_outer[i] + q] = accumulator[static_cast<std::size_t>(row[q])];
    }
  });
  return c;
}

// Pᵀ A P, made exactly symmetric (the mean of it and its transpose).
Csr galerkin_product(const Csr& a, const Csr& p, const Csr& pt) {
  const Csr ap = product(a, p);
  const Csr ac = product(pt, ap);
  const Csr act = ac.transpose();
  Csr out = 0.5 * (ac + act);
  out.makeCompressed();
  return out;
}

// A deterministic pseudo-random value in [−1, 1] for index i (power-iteration starts).
double hash_unit(std::uint64_t i) {
  std::uint64_t z = i * 0x9E3779B97F4A7C15ULL + 0x632BE59BD9B4E019ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

struct Level {
  Csr a;
  std::vector<int> node_start;      // unknowns of node k: [node_start[k], node_start[k + 1])
  std::vector<int> node_of;         // node of each unknown
  std::vector<long> inverse_offset;  // node k's inverse diagonal block (row-major) at inverse[offset]
  std::vector<double> inverse;
  double lambda_max = 1.0;  // of D⁻¹A (estimate)
  Csr p;                    // prolongation from the next coarser level
  Csr pt;                   // its transpose (restriction)
  // Work vectors of the cycle.
  mutable Eigen::VectorXd x, b, r, d, w, t;

  Index size() const { return a.rows(); }
  int nodes() const { return static_cast<int>(node_start.size()) - 1; }

  // z = D⁻¹ r with D the node-block diagonal.
  void block_solve(const Eigen::VectorXd& r_in, Eigen::VectorXd& z) const {
    z.resize(r_in.size());
    const Index n = nodes();
    tbb::parallel_for(tbb::blocked_range<Index>(0, n, kChunk / 4), [&](const tbb::blocked_range<Index>& range) {
      for (Index k = range.begin(); k != range.end(); ++k) {
        const int s = node_start[static_cast<std::size_t>(k)], m = node_start[static_cast<std::size_t>(k) + 1] - s;
        const double* inv = inverse.data() + inverse_offset[static_cast<std::size_t>(k)];
        for (int i = 0; i < m; ++i) {
          double sum = 0.0;
          for (int j = 0; j < m; ++j) sum += inv[i * m + j] * r_in[s + j];
          z[s + i] = sum;
        }
      }
    });
  }
};

// The inverse of each node's diagonal block. Returns false if a block is not positive definite.
bool invert_blocks(Level& level) {
  const int n = level.nodes();
  level.inverse_offset.resize(static_cast<std::size_t>(n) + 1);
  long total = 0;
  for (int k = 0; k < n; ++k) {
    level.inverse_offset[static_cast<std::size_t>(k)] = total;
    const long m = level.node_start[static_cast<std::size_t>(k) + 1] - level.node_start[static_cast<std::size_t>(k)];
    total += m * m;
  }
  level.inverse_offset[static_cast<std::size_t>(n)] = total;
  level.inverse.assign(static_cast<std::size_t>(total), 0.0);
  bool ok = true;
  for (int k = 0; k < n; ++k) {
    const int s = level.node_start[static_cast<std::size_t>(k)], m = level.node_start[static_cast<std::size_t>(k) + 1] - s;
    Eigen::MatrixXd block = Eigen::MatrixXd::Zero(m, m);
    for (int i = 0; i < m; ++i)
      for (Csr::InnerIterator it(level.a, s + i); it; ++it)
        if (it.col() >= s && it.col() < s + m) block(i, it.col() - s) = it.value();
    Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (block + block.transpose()));
    if (llt.info() != Eigen::Success) {
      ok = false;
      continue;
    }
    const Eigen::MatrixXd inv = llt.solve(Eigen::MatrixXd::Identity(m, m));
    double* out = level.inverse.data() + level.inverse_offset[static_cast<std::size_t>(k)];
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) out[i * m + j] = inv(i, j);
  }
  return ok;
}

// λ_max(D⁻¹A) by power iteration from a fixed pseudo-random start (a lower estimate).
double estimate_lambda_max(const Level& level, int iterations) {
  const Index n = level.size();
  Eigen::VectorXd v(n), av(n), w(n);
  for (Index i = 0; i < n; ++i) v[i] = hash_unit(static_cast<std::uint64_t>(i));
  double lambda = 1.0;
  for (int k = 0; k < std::max(iterations, 1); ++k) {
    v /= v.norm();
    multiply(level.a, v, av);
    level.block_solve(av, w);
    // |D⁻¹A v| for |v| = 1: tends to λ_max (D⁻¹A is similar to the symmetric D^-½ A D^-½).
    lambda = w.norm();
    v = w;
  }
  return lambda;
}

// Aggregates of the level's nodes (greedy, in node order; Vaněk, Mandel & Brezina's three phases).
// Returns the aggregate of each node and sets `count`.
std::vector<int> aggregate(const Level& level, double threshold, int& count) {
  const int n = level.nodes();
  // Block norms: diagonal and neighbours.
  std::vector<double> diag(static_cast<std::size_t>(n), 0.0);
  std::vector<std::vector<std::pair<int, double>>> neighbours(static_cast<std::size_t>(n));
  {
    std::vector<double> acc(static_cast<std::size_t>(n), 0.0);
    std::vector<int> touched;
    for (int k = 0; k < n; ++k) {
      touched.clear();
      for (int row = level.node_start[static_cast<std::size_t>(k)]; row < level.node_start[static_cast<std::size_t>(k) + 1]; ++row)
        for (Csr::InnerIterator it(level.a, row); it; ++it) {
          const int j = level.node_of[static_cast<std::size_t>(it.col())];
          if (acc[static_cast<std::size_t>(j)] == 0.0) touched.push_back(j);
          acc[static_cast<std::size_t>(j)] += it.value() * it.value() + 1e-300;
        }
      std::sort(touched.begin(), touched.end());
      for (int j : touched) {
        const double norm = std::sqrt(acc[static_cast<std::size_t>(j)]);
        if (j == k) diag[static_cast<std::size_t>(k)] = norm;
        else neighbours[static_cast<std::size_t>(k)].emplace_back(j, norm);
        acc[static_cast<std::size_t>(j)] = 0.0;
      }
    }
  }
  std::vector<std::vector<std::pair<int, double>>> strong(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k)
    for (const auto& [j, norm] : neighbours[static_cast<std::size_t>(k)])
      if (norm >= threshold * std::sqrt(diag[static_cast<std::size_t>(k)] * diag[static_cast<std::size_t>(j)]))
        strong[static_cast<std::size_t>(k)].emplace_back(j, norm);

  std::vector<int> agg(static_cast<std::size_t>(n), -1);
  count = 0;
  // Phase 1: a node whose strong neighbours are all free starts an aggregate with them.
  for (int k = 0; k < n; ++k) {
    if (agg[static_cast<std::size_t>(k)] >= 0) continue;
    bool all_free = true;
    for (const auto& [j, norm] : strong[static_cast<std::size_t>(k)])
      if (agg[static_cast<std::size_t>(j)] >= 0) {
        all_free = false;
        break;
      }
    if (!all_free || strong[static_cast<std::size_t>(k)].empty()) continue;
    agg[static_cast<std::size_t>(k)] = count;
    for (const auto& [j, norm] : strong[static_cast<std::size_t>(k)]) agg[static_cast<std::size_t>(j)] = count;
    ++count;
  }
  // Phase 2: the others join the aggregate of their strongest aggregated neighbour (phase 1's).
  const std::vector<int> first = agg;
  for (int k = 0; k < n; ++k) {
    if (first[static_cast<std::size_t>(k)] >= 0) continue;
    double best = -1.0;
    for (const auto& [j, norm] : strong[static_cast<std::size_t>(k)])
      if (first[static_cast<std::size_t>(j)] >= 0 && norm > best) {
        best = norm;
        agg[static_cast<std::size_t>(k)] = first[static_cast<std::size_t>(j)];
      }
  }
  // Phase 3: what is left forms aggregates with its unaggregated strong neighbours.
  for (int k = 0; k < n; ++k) {
    if (agg[static_cast<std::size_t>(k)] >= 0) continue;
    agg[static_cast<std::size_t>(k)] = count;
    for (const auto& [j, norm] : strong[static_cast<std::size_t>(k)])
      if (agg[static_cast<std::size_t>(j)] < 0) agg[static_cast<std::size_t>(j)] = count;
    ++count;
  }
  return agg;
}

Csr block_inverse_matrix(const Level& level) {
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(level.inverse.size());
  for (int k = 0; k < level.nodes(); ++k) {
    const int s = level.node_start[static_cast<std::size_t>(k)], m = level.node_start[static_cast<std::size_t>(k) + 1] - s;
    const double* inv = level.inverse.data() + level.inverse_offset[static_cast<std::size_t>(k)];
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) t.emplace_back(s + i, s + j, inv[i * m + j]);
  }
  Csr d(level.size(), level.size());
  d.setFromTriplets(t.begin(), t.end());
  return d;
}

}  // namespace

MultilevelSettings parse_multilevel_settings(const std::string& text) {
  MultilevelSettings s;
  std::istringstream in(text);
  std::string item;
  while (in >> item) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("multilevel settings: expected key=value, got " + item);
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    double number = 0.0;
    try {
      std::size_t used = 0;
      number = std::stod(value, &used);
      if (used != value.size()) throw std::invalid_argument(value);
    } catch (const std::exception&) {
      throw std::invalid_argument("multilevel settings: " + key + " needs a number, got " + value);
    }
    const int integer = static_cast<int>(number);
    if (key == "near_null_space") s.near_null_space = integer;
    else if (key == "threshold") s.threshold = number;
    else if (key == "prolongation_smoothing") s.prolongation_smoothing = integer;
    else if (key == "prolongation_omega") s.prolongation_omega = number;
    else if (key == "coarse_size") s.coarse_size = integer;
    else if (key == "max_levels") s.max_levels = integer;
    else if (key == "smoothing_steps") s.smoothing_steps = integer;
    else if (key == "chebyshev_ratio") s.chebyshev_ratio = number;
    else if (key == "cycle") s.cycle = integer;
    else if (key == "power_iterations") s.power_iterations = integer;
    else throw std::invalid_argument("multilevel settings: unknown key " + key);
  }
  return s;
}

struct MultilevelPreconditioner::Impl {
  MultilevelSettings settings;
  std::vector<Level> levels;
  std::vector<int> free_rows;  // rows of the full system that are unknowns of level 0
  Index full_size = 0;
  DirectSolver coarse{false};
  bool ready = false;

  void smooth(const Level& l, const Eigen::VectorXd& b, Eigen::VectorXd& x, bool zero_start) const;
  void cycle(std::size_t k, const Eigen::VectorXd& b, Eigen::VectorXd& x) const;
};

// Chebyshev iteration on D⁻¹A over [λ_max / ratio, 1.1 λ_max], `smoothing_steps` products.
void MultilevelPreconditioner::Impl::smooth(const Level& l, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                            bool zero_start) const {
  const int steps = settings.smoothing_steps;
  if (steps <= 0) return;
  const double hi = 1.1 * l.lambda_max, lo = l.lambda_max / settings.chebyshev_ratio;
  const double theta = 0.5 * (hi + lo), delta = 0.5 * (hi - lo), sigma = theta / delta;
  double rho = 1.0 / sigma;
  Eigen::VectorXd& r = l.r;
  Eigen::VectorXd& d = l.d;
  if (zero_start) {
    x.setZero(b.size());
    r = b;
  } else {
    residual(l.a, b, x, r);
  }
  l.block_solve(r, d);
  d /= theta;
  for (int k = 1; k <= steps; ++k) {
    x += d;
    if (k == steps) break;
    multiply(l.a, d, l.w);
    r -= l.w;
    const double rho_next = 1.0 / (2.0 * sigma - rho);
    l.block_solve(r, l.w);
    d = (rho_next * rho) * d + (2.0 * rho_next / delta) * l.w;
    rho = rho_next;
  }
}

// One cycle on level k from a zero start: pre-smoothing, coarse correction (twice per level for
// a W-cycle), post-smoothing. Uses the levels' work vectors only.
void MultilevelPreconditioner::Impl::cycle(std::size_t k, const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  const Level& l = levels[k];
  if (k + 1 == levels.size()) {
    x = coarse.solve(b);
    return;
  }
  const Level& c = levels[k + 1];
  smooth(l, b, x, true);
  const int corrections = k + 2 == levels.size() ? 1 : settings.cycle;  // the coarsest solve is exact
  for (int repeat = 0; repeat < corrections; ++repeat) {
    residual(l.a, b, x, l.t);
    multiply(l.pt, l.t, c.b);
    cycle(k + 1, c.b, c.x);
    multiply(l.p, c.x, l.t);
    x += l.t;
  }
  smooth(l, b, x, false);
}

MultilevelPreconditioner::MultilevelPreconditioner(const MultilevelSettings& settings) : impl_(std::make_unique<Impl>()) {
  impl_->settings = settings;
}
MultilevelPreconditioner::~MultilevelPreconditioner() = default;

bool MultilevelPreconditioner::factorize(const Eigen::SparseMatrix<double>& a, const std::vector<char>* free,
                                         const Eigen::VectorXd* positions) {
  std::vector<char> all;
  if (!free) all.assign(static_cast<std::size_t>(a.rows()), 1);
  return setup(a, free ? *free : all, positions ? *positions : Eigen::VectorXd());
}

bool MultilevelPreconditioner::setup(const Eigen::SparseMatrix<double>& a, const std::vector<char>& free,
                                     const Eigen::VectorXd& positions) {
  Impl& m = *impl_;
  const MultilevelSettings& s = m.settings;
  m.ready = false;
  m.levels.clear();
  m.full_size = a.rows();
  if (a.rows() % 3 != 0 || static_cast<Index>(free.size()) != a.rows())
    throw std::invalid_argument("MultilevelPreconditioner: 3 rows per vertex and one free flag per row expected");
  // Level 0: the free rows and columns. A is symmetric: column j of its compressed columns is row j.
  std::vector<int> index(static_cast<std::size_t>(a.rows()), -1);
  m.free_rows.clear();
  for (Index i = 0; i < a.rows(); ++i)
    if (free[static_cast<std::size_t>(i)]) {
      index[static_cast<std::size_t>(i)] = static_cast<int>(m.free_rows.size());
      m.free_rows.push_back(static_cast<int>(i));
    }
  const Index n0 = static_cast<Index>(m.free_rows.size());
  m.levels.emplace_back();
  {
    Level& l = m.levels.back();
    l.a.resize(n0, n0);
    Eigen::VectorXi counts(n0);
    for (Index r = 0; r < n0; ++r) {
      int c = 0;
      for (Eigen::SparseMatrix<double>::InnerIterator it(a, m.free_rows[static_cast<std::size_t>(r)]); it; ++it)
        c += index[static_cast<std::size_t>(it.row())] >= 0;
      counts[r] = c;
    }
    l.a.reserve(counts);
    for (Index r = 0; r < n0; ++r)
      for (Eigen::SparseMatrix<double>::InnerIterator it(a, m.free_rows[static_cast<std::size_t>(r)]); it; ++it) {
        const int c = index[static_cast<std::size_t>(it.row())];
        if (c >= 0) l.a.insert(r, c) = it.value();
      }
    l.a.makeCompressed();
    // Nodes: the free components of each vertex.
    l.node_start.push_back(0);
    for (Index v = 0; v < a.rows() / 3; ++v) {
      int count = 0;
      for (int c = 0; c < 3; ++c) count += free[static_cast<std::size_t>(3 * v + c)] != 0;
      if (count > 0) l.node_start.push_back(l.node_start.back() + count);
    }
  }
  // Near-null space of level 0: translations and (with positions) rotations about the centroid,
  // scaled by the radius of the free vertices.
  const bool rotations = s.near_null_space >= 6 && positions.size() == a.rows();
  const int modes = rotations ? 6 : 3;
  Eigen::MatrixXd b(n0, modes);
  {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double radius = 0.0;
    if (rotations) {
      const Index vertices = a.rows() / 3;
      for (Index v = 0; v < vertices; ++v) centre += positions.segment<3>(3 * v);
      centre /= static_cast<double>(vertices);
      for (Index v = 0; v < vertices; ++v) radius = std::max(radius, (positions.segment<3>(3 * v) - centre).norm());
    }
    radius = std::max(radius, 1e-300);
    b.setZero();
    for (Index r = 0; r < n0; ++r) {
      const int row = m.free_rows[static_cast<std::size_t>(r)], c = row % 3, v = row / 3;
      b(r, c) = 1.0;
      if (rotations) {
        const Eigen::Vector3d y = (positions.segment<3>(3 * v) - centre) / radius;
        // Rotation about axis e_k: e_k × y.
        for (int k = 0; k < 3; ++k) {
          Eigen::Vector3d e = Eigen::Vector3d::Zero();
          e[k] = 1.0;
          b(r, 3 + k) = e.cross(y)[c];
        }
      }
    }
  }

  // Coarsening.
  while (true) {
    Level& l = m.levels.back();
    l.node_of.resize(static_cast<std::size_t>(l.size()));
    for (int k = 0; k < l.nodes(); ++k)
      for (int i = l.node_start[static_cast<std::size_t>(k)]; i < l.node_start[static_cast<std::size_t>(k) + 1]; ++i)
        l.node_of[static_cast<std::size_t>(i)] = k;
    if (!invert_blocks(l)) return false;
    l.lambda_max = estimate_lambda_max(l, s.power_iterations);
    if (l.size() <= s.coarse_size || static_cast<int>(m.levels.size()) >= s.max_levels) break;
    int count = 0;
    const std::vector<int> agg = aggregate(l, s.threshold, count);
    // Members of each aggregate, in node order.
    std::vector<std::vector<int>> members(static_cast<std::size_t>(count));
    for (int k = 0; k < l.nodes(); ++k) members[static_cast<std::size_t>(agg[static_cast<std::size_t>(k)])].push_back(k);
    // Tentative prolongator: an orthonormal basis of the near-null space on each aggregate.
    std::vector<Eigen::Triplet<double>> t;
    std::vector<int> coarse_start{0};
    std::vector<Eigen::MatrixXd> coarse_b;
    const int k_modes = static_cast<int>(b.cols());
    for (int g = 0; g < count; ++g) {
      std::vector<int> rows;
      for (int node : members[static_cast<std::size_t>(g)])
        for (int i = l.node_start[static_cast<std::size_t>(node)]; i < l.node_start[static_cast<std::size_t>(node) + 1]; ++i) rows.push_back(i);
      Eigen::MatrixXd local(static_cast<Index>(rows.size()), k_modes);
      for (std::size_t i = 0; i < rows.size(); ++i) local.row(static_cast<Index>(i)) = b.row(rows[i]);
      Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(local);
      qr.setThreshold(1e-10);
      const int rank = static_cast<int>(qr.rank());
      const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(local.rows(), rank);
      const Eigen::MatrixXd r = qr.matrixR().topRows(rank).triangularView<Eigen::Upper>();
      const Eigen::MatrixXd rb = r * qr.colsPermutation().transpose();
      const int c0 = coarse_start.back();
      for (std::size_t i = 0; i < rows.size(); ++i)
        for (int j = 0; j < rank; ++j) t.emplace_back(rows[i], c0 + j, q(static_cast<Index>(i), j));
      coarse_start.push_back(c0 + rank);
      coarse_b.push_back(rb);
    }
    const Index nc = coarse_start.back();
    Csr p(l.size(), nc);
    p.setFromTriplets(t.begin(), t.end());
    if (s.prolongation_smoothing > 0) {
      const Csr dinv = block_inverse_matrix(l);
      for (int k = 0; k < s.prolongation_smoothing; ++k) {
        const Csr ap = product(l.a, p);
        const Csr dap = product(dinv, ap);
        p = p - (s.prolongation_omega / l.lambda_max) * dap;
      }
    }
    Eigen::MatrixXd bc(nc, k_modes);
    for (int g = 0; g < count; ++g) bc.middleRows(coarse_start[static_cast<std::size_t>(g)], coarse_b[static_cast<std::size_t>(g)].rows()) = coarse_b[static_cast<std::size_t>(g)];
    l.p = p;
    l.pt = p.transpose();
    Level next;
    next.a = galerkin_product(l.a, l.p, l.pt);
    next.node_start = coarse_start;
    b = bc;
    m.levels.push_back(std::move(next));
    if (nc >= static_cast<Index>(0.9 * static_cast<double>(m.levels[m.levels.size() - 2].size()))) break;  // no coarsening
  }
  // Coarsest level: Cholesky.
  const Eigen::SparseMatrix<double> coarsest = m.levels.back().a;
  if (!m.coarse.factorize(coarsest)) return false;
  m.ready = true;
  return true;
}

bool MultilevelPreconditioner::ready() const { return impl_->ready; }

bool MultilevelPreconditioner::refresh(const Eigen::SparseMatrix<double>& a, bool galerkin) {
  Impl& m = *impl_;
  if (m.levels.empty()) return false;
  Level& l0 = m.levels.front();
  std::vector<int> index(static_cast<std::size_t>(a.rows()), -1);
  for (std::size_t i = 0; i < m.free_rows.size(); ++i) index[static_cast<std::size_t>(m.free_rows[i])] = static_cast<int>(i);
  double* values = l0.a.valuePtr();
  long k = 0;
  for (Index r = 0; r < l0.size(); ++r)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, m.free_rows[static_cast<std::size_t>(r)]); it; ++it)
      if (index[static_cast<std::size_t>(it.row())] >= 0) values[k++] = it.value();
  if (!invert_blocks(l0)) return false;
  l0.lambda_max = estimate_lambda_max(l0, m.settings.power_iterations);
  if (!galerkin) return true;
  for (std::size_t j = 0; j + 1 < m.levels.size(); ++j) {
    m.levels[j + 1].a = galerkin_product(m.levels[j].a, m.levels[j].p, m.levels[j].pt);
    if (!invert_blocks(m.levels[j + 1])) return false;
    m.levels[j + 1].lambda_max = estimate_lambda_max(m.levels[j + 1], m.settings.power_iterations);
  }
  const Eigen::SparseMatrix<double> coarsest = m.levels.back().a;
  m.ready = m.coarse.factorize(coarsest);
  return m.ready;
}

void MultilevelPreconditioner::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  const Impl& m = *impl_;
  if (!m.ready) throw std::logic_error("MultilevelPreconditioner::apply before a successful set-up");
  const Level& l = m.levels.front();
  l.b.resize(l.size());
  for (Index i = 0; i < l.size(); ++i) l.b[i] = r[m.free_rows[static_cast<std::size_t>(i)]];
  m.cycle(0, l.b, l.x);
  z.setZero(r.size());
  for (Index i = 0; i < l.size(); ++i) z[m.free_rows[static_cast<std::size_t>(i)]] = l.x[i];
}

int MultilevelPreconditioner::levels() const { return static_cast<int>(impl_->levels.size()); }

std::vector<long> MultilevelPreconditioner::level_sizes() const {
  std::vector<long> out;
  for (const Level& l : impl_->levels) out.push_back(static_cast<long>(l.size()));
  return out;
}

double MultilevelPreconditioner::operator_complexity() const {
  if (impl_->levels.empty()) return 0.0;
  double total = 0.0;
  for (const Level& l : impl_->levels) total += static_cast<double>(l.a.nonZeros());
  return total / static_cast<double>(impl_->levels.front().a.nonZeros());
}

long MultilevelPreconditioner::memory_bytes() const {
  long bytes = 0;
  for (const Level& l : impl_->levels) {
    bytes += static_cast<long>(l.a.nonZeros()) * 12 + static_cast<long>(l.a.rows()) * 4;
    bytes += static_cast<long>(l.p.nonZeros() + l.pt.nonZeros()) * 12;
    bytes += static_cast<long>(l.inverse.size()) * 8;
  }
  return bytes;
}

std::string MultilevelPreconditioner::describe() const {
  std::ostringstream o;
  o << levels() << " levels [";
  const std::vector<long> sizes = level_sizes();
  for (std::size_t k = 0; k < sizes.size(); ++k) o << (k ? ", " : "") << sizes[k];
  o << "], operator complexity " << operator_complexity();
  if (!impl_->levels.empty() && impl_->levels.size() > 1)
    o << ", P entries/row " << static_cast<double>(impl_->levels.front().p.nonZeros()) / static_cast<double>(impl_->levels.front().size());
  o << ", " << static_cast<double>(memory_bytes()) / 1048576.0 << " MiB";
  return o.str();
}

}  // namespace clothsim

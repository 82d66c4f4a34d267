#include "sim/solver/pcg.hpp"

#include <Eigen/Cholesky>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace clothsim {

// y = A x for symmetric A in compressed-column storage: y_j = (column j) · x, so the columns can
// be shared among threads without write conflicts. Rows of constrained entries give zero.
void symmetric_product(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& x, const Eigen::VectorXd& mask,
                       Eigen::VectorXd& y) {
  y.resize(a.outerSize());
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, a.outerSize(), 512), [&](const tbb::blocked_range<Eigen::Index>& r) {
    for (Eigen::Index j = r.begin(); j != r.end(); ++j) {
      double sum = 0.0;
      for (int k = outer[j]; k < outer[j + 1]; ++k) sum += values[k] * x[inner[k]];
      y[j] = sum * mask[j];
    }
  });
}

namespace {

// r = (b − A x) on the free entries, in parallel over the columns like symmetric_product (A is
// symmetric up to round-off: row j of A x is taken as column j · x). r_j starts from b_j and
// subtracts column j's products in order: a fixed order, deterministic.
void residual(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& b, const Eigen::VectorXd& x, const Eigen::VectorXd& mask,
              Eigen::VectorXd& r) {
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, a.outerSize(), 512), [&](const tbb::blocked_range<Eigen::Index>& range) {
    for (Eigen::Index j = range.begin(); j != range.end(); ++j) {
      double sum = b[j];
      for (int k = outer[j]; k < outer[j + 1]; ++k) sum -= values[k] * x[inner[k]];
      r[j] = sum * mask[j];
    }
  });
}

}  // namespace

namespace {

// Conjugate gradients from the residual r = b − A x (zero at the constrained entries), with
// `apply` giving q = A p on the free entries and `precondition` z = P⁻¹ r.
PcgResult iterate(const LinearOperator& apply, const Preconditioner& precondition, double b_norm, Eigen::VectorXd& r,
                  Eigen::VectorXd& x, double tolerance, int max_iterations, double forcing = 0.0) {
  const Eigen::Index n = r.size();
  const double scale = b_norm > 0 ? b_norm : 1.0;
  PcgResult result;
  result.residual = r.norm() / scale;
  // (With a forcing term, also converged once the residual is that fraction of the start's.)
  tolerance = std::max(tolerance, forcing * result.residual);
  if (result.residual <= tolerance) {
    result.converged = true;
    return result;
  }
  Eigen::VectorXd z(n), p(n), q(n);
  precondition(r, z);
  p = z;
  double rz = r.dot(z);
  for (int k = 1; k <= max_iterations; ++k) {
    apply(p, q);
    const double pq = p.dot(q);
    if (!(pq > 0.0) || !std::isfinite(pq)) {  // not positive definite on the free entries
      result.iterations = k;
      return result;
    }
    const double alpha = rz / pq;
    x += alpha * p;
    r -= alpha * q;
    result.iterations = k;
    result.residual = r.norm() / scale;
    if (result.residual <= tolerance) {
      result.converged = true;
      return result;
    }
    precondition(r, z);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return result;
}

}  // namespace

Eigen::VectorXd free_mask(const std::vector<char>& free) {
  Eigen::VectorXd mask(static_cast<Eigen::Index>(free.size()));
  for (size_t i = 0; i < free.size(); ++i) mask(static_cast<Eigen::Index>(i)) = free[i] ? 1.0 : 0.0;
  return mask;
}

Preconditioner block_jacobi(const Eigen::SparseMatrix<double>& a, const std::vector<char>& free) {
  const Eigen::Index blocks = a.rows() / 3;
  auto inverse = std::make_shared<std::vector<Eigen::Matrix3d>>(static_cast<size_t>(blocks));
  for (Eigen::Index v = 0; v < blocks; ++v) {
    Eigen::Matrix3d block = Eigen::Matrix3d::Identity();
    for (int c = 0; c < 3; ++c)
      for (int d = 0; d < 3; ++d)
        if (free[static_cast<size_t>(3 * v + c)] && free[static_cast<size_t>(3 * v + d)]) block(c, d) = a.coeff(3 * v + c, 3 * v + d);
    Eigen::LDLT<Eigen::Matrix3d> ldlt(block);
    Eigen::Matrix3d& inv = (*inverse)[static_cast<size_t>(v)];
    inv = ldlt.solve(Eigen::Matrix3d::Identity());
    for (int c = 0; c < 3; ++c)
      if (!free[static_cast<size_t>(3 * v + c)]) inv.row(c).setZero(), inv.col(c).setZero();
  }
  return [inverse, blocks](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
    z.resize(r.size());
    for (Eigen::Index v = 0; v < blocks; ++v) z.segment<3>(3 * v) = (*inverse)[static_cast<size_t>(v)] * r.segment<3>(3 * v);
  };
}

PcgResult solve_pcg(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& b, const std::vector<char>& free,
                    Eigen::VectorXd& x, double tolerance, int max_iterations, const Preconditioner& preconditioner) {
  const Eigen::VectorXd mask = free_mask(free);
  Preconditioner precondition;
  if (preconditioner) {
    precondition = [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
      preconditioner(r, z);
      z = z.cwiseProduct(mask);
    };
  } else {
    precondition = block_jacobi(a, free);
  }
  Eigen::VectorXd r(b.size());
  residual(a, b, x, mask, r);
  const LinearOperator apply = [&](const Eigen::VectorXd& p, Eigen::VectorXd& q) { symmetric_product(a, p, mask, q); };
  return iterate(apply, precondition, b.cwiseProduct(mask).norm(), r, x, tolerance, max_iterations);
}

PcgResult solve_pcg(const LinearOperator& a, const Eigen::VectorXd& b, const std::vector<char>& free, Eigen::VectorXd& x,
                    double tolerance, int max_iterations, const Preconditioner& preconditioner,
                    const Eigen::VectorXd* initial_residual, double forcing) {
  const Eigen::VectorXd mask = free_mask(free);
  const Preconditioner precondition = [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
    preconditioner(r, z);
    z = z.cwiseProduct(mask);
  };
  Eigen::VectorXd r(b.size());
  if (initial_residual != nullptr) {
    if (initial_residual->size() != b.size()) throw std::invalid_argument("solve_pcg: the initial residual's size differs from b's");
    r = initial_residual->cwiseProduct(mask);
  } else {
    a(x, r);
    r = (b - r).cwiseProduct(mask);
  }
  const LinearOperator apply = [&](const Eigen::VectorXd& p, Eigen::VectorXd& q) {
    a(p, q);
    q = q.cwiseProduct(mask);
  };
  return iterate(apply, precondition, b.cwiseProduct(mask).norm(), r, x, tolerance, max_iterations, forcing);
}

}  // namespace clothsim

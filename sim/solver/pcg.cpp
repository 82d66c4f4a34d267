#include "sim/solver/pcg.hpp"

#include <Eigen/Cholesky>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

namespace clothsim {

namespace {

// y = A x for symmetric A in compressed-column storage: y_j = (column j) · x, so the columns can
// be shared among threads without write conflicts. Rows of constrained entries give zero.
void symmetric_product(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& x, const Eigen::VectorXd& mask,
                       Eigen::VectorXd& y) {
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

PcgResult solve_pcg(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& b, const std::vector<char>& free,
                    Eigen::VectorXd& x, double tolerance, int max_iterations, const Preconditioner& preconditioner) {
  const Eigen::Index n = b.size();
  const Eigen::Index blocks = n / 3;
  Eigen::VectorXd mask(n);
  for (Eigen::Index i = 0; i < n; ++i) mask(i) = free[i] ? 1.0 : 0.0;

  // Block-Jacobi preconditioner on the free entries (unless one is given).
  std::vector<Eigen::Matrix3d> inverse(preconditioner ? 0 : blocks);
  for (Eigen::Index v = 0; v < static_cast<Eigen::Index>(inverse.size()); ++v) {
    Eigen::Matrix3d block = Eigen::Matrix3d::Identity();
    for (int c = 0; c < 3; ++c)
      for (int d = 0; d < 3; ++d)
        if (free[3 * v + c] && free[3 * v + d]) block(c, d) = a.coeff(3 * v + c, 3 * v + d);
    Eigen::LDLT<Eigen::Matrix3d> ldlt(block);
    inverse[v] = ldlt.solve(Eigen::Matrix3d::Identity());
    for (int c = 0; c < 3; ++c)
      if (!free[3 * v + c]) inverse[v].row(c).setZero(), inverse[v].col(c).setZero();
  }
  auto precondition = [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
    if (preconditioner) {
      preconditioner(r, z);
      z = z.cwiseProduct(mask);
      return;
    }
    for (Eigen::Index v = 0; v < blocks; ++v) z.segment<3>(3 * v) = inverse[v] * r.segment<3>(3 * v);
  };

  Eigen::VectorXd r(n);
  residual(a, b, x, mask, r);
  const double b_norm = b.cwiseProduct(mask).norm();
  const double scale = b_norm > 0 ? b_norm : 1.0;
  PcgResult result;
  result.residual = r.norm() / scale;
  if (result.residual <= tolerance) {
    result.converged = true;
    return result;
  }
  Eigen::VectorXd z(n), p(n), q(n);
  precondition(r, z);
  p = z;
  double rz = r.dot(z);
  for (int k = 1; k <= max_iterations; ++k) {
    symmetric_product(a, p, mask, q);
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

}  // namespace clothsim

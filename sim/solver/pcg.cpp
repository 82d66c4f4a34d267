#include "sim/solver/pcg.hpp"

#include <Eigen/Cholesky>

#include <cmath>

namespace clothsim {

PcgResult solve_pcg(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXd& b, const std::vector<char>& free,
                    Eigen::VectorXd& x, double tolerance, int max_iterations) {
  const Eigen::Index n = b.size();
  const Eigen::Index blocks = n / 3;
  Eigen::VectorXd mask(n);
  for (Eigen::Index i = 0; i < n; ++i) mask(i) = free[i] ? 1.0 : 0.0;

  // Block-Jacobi preconditioner on the free entries.
  std::vector<Eigen::Matrix3d> inverse(blocks);
  for (Eigen::Index v = 0; v < blocks; ++v) {
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
    for (Eigen::Index v = 0; v < blocks; ++v) z.segment<3>(3 * v) = inverse[v] * r.segment<3>(3 * v);
  };

  Eigen::VectorXd r = (b - a * x).cwiseProduct(mask);
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
    q.noalias() = a * p;
    q = q.cwiseProduct(mask);
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

// The scalar functions of the contact potential (sim/contact/barrier.hpp) against finite
// differences and their defining properties: the cubic barrier is zero with its first two
// derivatives at the thickness, has stiffness k at half of it and pushes apart; the smoothed
// friction's f₀' = f₁, f₁ reaches 1 at ε and stays, and its gradient and Hessian in w are those of
// μ λ f₀(|w|) (central differences), the Hessian positive semi-definite.
#include "sim/contact/barrier.hpp"

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace clothsim::contact {
namespace {

TEST(ContactBarrier, DerivativesMatchFiniteDifferences) {
  {
    const CubicBarrier b{2e-3, 350.0};
    for (double d : {-5e-4, 1e-5, 3e-4, 1e-3, 1.7e-3, 1.99e-3}) {
      const double step = 1e-8;
      const double fd_first = (b.value(d + step) - b.value(d - step)) / (2 * step);
      const double fd_second = (b.first(d + step) - b.first(d - step)) / (2 * step);
      EXPECT_NEAR(b.first(d), fd_first, 1e-6 * std::abs(b.first(d)) + 1e-12) << "d = " << d;
      EXPECT_NEAR(b.second(d), fd_second, 1e-6 * std::abs(b.second(d)) + 1e-9) << "d = " << d;
      EXPECT_LT(b.first(d), 0.0) << "the barrier pushes apart inside the layer";
      EXPECT_GT(b.second(d), 0.0);
    }
  }
}

TEST(ContactBarrier, CubicStartsSmoothlyAtTheThicknessWithStiffnessKAtHalfOfIt) {
  const double dhat = 1e-3, k = 42.0;
  const CubicBarrier b{dhat, k};
  EXPECT_EQ(b.value(dhat), 0.0);
  EXPECT_EQ(b.first(dhat), 0.0);
  EXPECT_EQ(b.second(dhat), 0.0);
  EXPECT_EQ(b.value(2 * dhat), 0.0);
  // Just inside: value, force and stiffness go to zero as (d̂ − d)³, (d̂ − d)², (d̂ − d).
  const double e = 1e-9;
  EXPECT_NEAR(b.value(dhat - e), k * e * e * e / (3 * dhat), 1e-30);
  EXPECT_NEAR(b.second(0.5 * dhat), k, 1e-12 * k);
  // Finite at contact, growing beyond it (a crossed pair is pushed back harder).
  EXPECT_TRUE(std::isfinite(b.value(0.0)));
  EXPECT_GT(b.second(-1e-4), b.second(0.0));
}

TEST(ContactFriction, SmoothedFrictionIsCoulombBeyondEpsilonAndItsDerivativesMatch) {
  const SmoothedFriction f{1e-3};
  for (double s : {0.0, 1e-5, 3e-4, 9.99e-4, 1e-3, 2e-3, 0.5}) {
    EXPECT_GE(f.f1(s), 0.0);
    EXPECT_LE(f.f1(s), 1.0);
    if (s >= 1e-3) {
      EXPECT_EQ(f.f1(s), 1.0);
    }
    if (s > 1e-6) {
      const double step = 1e-9;
      EXPECT_NEAR((f.f0(s + step) - f.f0(s - step)) / (2 * step), f.f1(s), 1e-6) << "s = " << s;
      EXPECT_NEAR(f.f1_over_s(s), f.f1(s) / s, 1e-9 * f.f1_over_s(s));
    }
  }
  EXPECT_NEAR(f.f0(1e-3), 1e-3 - 1e-3 / 3.0, 1e-15);  // continuous at ε
  EXPECT_EQ(f.f0(0.0), 0.0);

  // Gradient and Hessian of μλ f₀(|w|) for w in a tangent plane, against central differences.
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.2, 0.9).normalized();
  const Eigen::Matrix3d tangent = Eigen::Matrix3d::Identity() - n * n.transpose();
  const double bound = 0.37;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double scale : {2e-4, 8e-4, 5e-3}) {
    const Eigen::Vector3d w = scale * (tangent * Eigen::Vector3d(u(rng), u(rng), u(rng))).normalized();
    auto potential = [&](const Eigen::Vector3d& y) { return bound * f.f0((tangent * y).norm()); };
    auto gradient = [&](const Eigen::Vector3d& y) { return Eigen::Vector3d(tangent * f.gradient(tangent * y, bound)); };
    const Eigen::Matrix3d hessian = f.hessian(w, tangent, bound);
    const double step = 1e-9;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e = step * Eigen::Vector3d::Unit(k);
      EXPECT_NEAR(gradient(w)(k), (potential(w + e) - potential(w - e)) / (2 * step), 1e-6 * bound) << "scale " << scale;
      const Eigen::Vector3d column = (gradient(w + e) - gradient(w - e)) / (2 * step);
      for (int r = 0; r < 3; ++r)
        EXPECT_NEAR(hessian(r, k), column(r), 1e-4 * hessian.norm()) << "scale " << scale << ", entry " << r << "," << k;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(hessian);
    EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12 * hessian.norm());
  }
}

}  // namespace
}  // namespace clothsim::contact

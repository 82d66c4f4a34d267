// The scalar functions of the contact potential inside the implicit step (docs/contact.md,
// "Contact inside the step"): the barrier of a pair's distance and the smoothed friction of a
// pair's tangential velocity.
//
// Barrier (cubic, after Ando 2024): for a distance d below the thickness d̂,
//     b(d) = k (d̂ − d)³ / (3 d̂),   b'(d) = −k (d̂ − d)² / d̂,   b''(d) = 2 k (d̂ − d) / d̂,
// and 0 from d̂ on: twice continuously differentiable at d̂ (value, force and stiffness all start
// from zero, so a pair entering the layer does not switch on a jump in the Newton matrix), with
// stiffness k at half the thickness. It is finite at d = 0: what keeps surfaces from crossing is
// the continuous collision detection behind it, not the barrier.
//
// Friction (lagged, smoothed; Li et al. 2020, IPC): a pair pressed with normal force λ [N] and
// tangential relative velocity w [m/s] dissipates through the potential μ λ f₀(|w|) [W] with
//     f₁(s) = 2 s / ε − s² / ε²  (s < ε),  1  (s ≥ ε),     f₀' = f₁,  f₀(0) = 0,
//     f₀(s) = s² / ε − s³ / (3 ε²)  (s < ε),  s − ε / 3  (s ≥ ε),
// convex, so its Hessian μ λ [f₁'(s) ŵŵᵀ + f₁(s)/s (I − ŵŵᵀ)] (in the tangent plane) is positive
// semi-definite: Coulomb's law |f| ≤ μ λ, exact for |w| ≥ ε, and below ε a viscous stick whose
// creep speed on a slope of angle θ is ε tan θ / (2μ).
#pragma once

#include <Eigen/Core>

#include <algorithm>

namespace clothsim::contact {

struct CubicBarrier {
  double thickness = 1e-3;  // d̂ [m]
  double stiffness = 1.0;   // k [N/m], the stiffness at d̂ / 2

  double value(double d) const {  // [J]
    if (!(d < thickness)) return 0.0;
    const double g = thickness - d;
    return stiffness * g * g * g / (3.0 * thickness);
  }
  double first(double d) const {  // b'(d) [N] (≤ 0: it pushes apart)
    if (!(d < thickness)) return 0.0;
    const double g = thickness - d;
    return -stiffness * g * g / thickness;
  }
  double second(double d) const {  // b''(d) [N/m] (≥ 0)
    if (!(d < thickness)) return 0.0;
    return 2.0 * stiffness * (thickness - d) / thickness;
  }
};

struct SmoothedFriction {
  double epsilon = 1e-3;  // ε [m/s]

  double f0(double s) const {
    if (s >= epsilon) return s - epsilon / 3.0;
    return s * s / epsilon - s * s * s / (3.0 * epsilon * epsilon);
  }
  double f1(double s) const {
    if (s >= epsilon) return 1.0;
    return 2.0 * s / epsilon - s * s / (epsilon * epsilon);
  }
  // f₁(s) / s, finite at 0 (2 / ε).
  double f1_over_s(double s) const {
    if (s >= epsilon) return 1.0 / s;
    return 2.0 / epsilon - s / (epsilon * epsilon);
  }
  double f1_derivative(double s) const {
    if (s >= epsilon) return 0.0;
    return 2.0 / epsilon - 2.0 * s / (epsilon * epsilon);
  }
  // The potential's gradient and Hessian in the tangential velocity w (3-vector in the tangent
  // plane of projector `tangent`), for the bound μ λ.
  Eigen::Vector3d gradient(const Eigen::Vector3d& w, double bound) const {
    return bound * f1_over_s(w.norm()) * w;
  }
  Eigen::Matrix3d hessian(const Eigen::Vector3d& w, const Eigen::Matrix3d& tangent, double bound) const {
    const double s = w.norm();
    if (!(s > 0)) return bound * (2.0 / epsilon) * tangent;
    const Eigen::Vector3d e = w / s;
    const Eigen::Matrix3d along = e * e.transpose();
    return bound * (f1_derivative(s) * along + f1_over_s(s) * (tangent - along));
  }
};

}  // namespace clothsim::contact

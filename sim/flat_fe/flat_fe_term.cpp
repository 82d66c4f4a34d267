#include "sim/flat_fe/flat_fe_term.hpp"

#include "sim/flat_fe/flat_fe.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

namespace clothsim {

namespace {

using Frame = Eigen::Matrix<double, 3, 2>;

// The rotation R (orthonormal columns) of the polar decomposition F = R S, S symmetric positive
// semidefinite, of a 3 × 2 deformation gradient. Closed form R = F (FᵀF)^(−1/2) with the 2 × 2
// square root √C = (C + √det C · I) / √(tr C + 2 √det C); a (nearly) collapsed triangle falls back
// to the SVD, R = U Vᵀ.
Frame polar_rotation(const Frame& f) {
  const Eigen::Matrix2d c = f.transpose() * f;
  const double det = c.determinant(), trace = c.trace();
  if (det > 1e-16 * trace * trace) {
    const double s = std::sqrt(det);
    const Eigen::Matrix2d root = (c + s * Eigen::Matrix2d::Identity()) / std::sqrt(trace + 2.0 * s);
    return f * root.inverse();
  }
  const Eigen::JacobiSVD<Frame> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU().leftCols<2>() * svd.matrixV().transpose();
}

}  // namespace

LinearFeElastic::LinearFeElastic(const LinearFeDiscretization& d, bool corotational) : d_(d), corotational_(corotational) {
  const TriMesh& mesh = d.mesh();
  const ShellMaterial& material = d.material();
  const double km = material.membrane_stiffness(), nu = material.poisson_ratio;
  if (material.orthotropic() && mesh.warp.size() != mesh.triangles.size())
    throw std::invalid_argument("linear_fe: an orthotropic material needs a warp direction per triangle (the mesh has " +
                                std::to_string(mesh.warp.size()) + " for " + std::to_string(mesh.triangles.size()) +
                                " triangles)");
  Eigen::Matrix3d c;
  c << 1.0, nu, 0.0,  //
      nu, 1.0, 0.0,   //
      0.0, 0.0, 0.5 * (1.0 - nu);
  c *= km;
  const size_t nt = mesh.triangles.size();
  k_.resize(nt);
  rest2d_.resize(nt);
  inverse_edges_.resize(nt);
  rest_frame_.resize(nt);
  std::vector<double> area(nt);
  for (size_t t = 0; t < nt; ++t) {
    const Triangle& tri = mesh.triangles[t];
    const Eigen::Vector3d x0 = mesh.vertices.row(tri[0]), x1 = mesh.vertices.row(tri[1]), x2 = mesh.vertices.row(tri[2]);
    const Eigen::Vector3d e1 = (x1 - x0).normalized();
    const Eigen::Vector3d normal = (x1 - x0).cross(x2 - x0).normalized();
    Frame frame;
    frame << e1, normal.cross(e1);
    rest_frame_[t] = frame;
    Eigen::Matrix<double, 2, 3> p;
    p << Eigen::Vector2d::Zero(), frame.transpose() * (x1 - x0), frame.transpose() * (x2 - x0);
    rest2d_[t] = p;
    Eigen::Matrix2d edges;
    edges << p.col(1) - p.col(0), p.col(2) - p.col(0);
    area[t] = 0.5 * edges.determinant();
    const Eigen::Matrix2d inv = edges.inverse();
    inverse_edges_[t] = inv;
    // Shape-function gradients (rest frame): ∇N₁ = row 0 of D⁻¹, ∇N₂ = row 1, ∇N₀ = −∇N₁ − ∇N₂.
    const Eigen::Vector2d g[3] = {-(inv.row(0) + inv.row(1)).transpose(), inv.row(0).transpose(), inv.row(1).transpose()};
    Eigen::Matrix<double, 3, 6> b = Eigen::Matrix<double, 3, 6>::Zero();
    for (int i = 0; i < 3; ++i) {
      b(0, 2 * i) = g[i](0);
      b(1, 2 * i + 1) = g[i](1);
      b(2, 2 * i) = g[i](1);
      b(2, 2 * i + 1) = g[i](0);
    }
    if (material.orthotropic()) {
      // The law about the triangle's warp direction, projected into its rest plane.
      const Eigen::Vector3d w = mesh.warp[t] - mesh.warp[t].dot(normal) * normal;
      if (!(w.norm() > 1e-6 * mesh.warp[t].norm()))
        throw std::invalid_argument("linear_fe: triangle " + std::to_string(t) +
                                    ": its warp direction is normal to it (or zero)");
      const Eigen::Vector2d grain = (frame.transpose() * w).normalized();
      k_[t] = area[t] * b.transpose() * law_in_frame(material.membrane_law(), grain(0), grain(1)) * b;
      continue;
    }
    k_[t] = area[t] * b.transpose() * c * b;
  }
  const std::vector<Hinge>& hinges = d.hinges();
  hinge_k_.resize(hinges.size());
  rest_angle_.resize(hinges.size());
  for (size_t h = 0; h < hinges.size(); ++h) {
    const HingePositions x = hinge_positions(h, d.rest());
    const double edge2 = (x[1] - x[0]).squaredNorm();
    const double areas = area[static_cast<size_t>(hinges[h].triangle_a)] + area[static_cast<size_t>(hinges[h].triangle_b)];
    double rigidity = material.bending_rigidity;
    if (material.orthotropic()) {
      // The rigidity of bending across the edge: curvature along m = n × ê, in the frame of
      // triangle a's warp (its other moments free: the directional rigidity).
      const size_t ta = static_cast<size_t>(hinges[h].triangle_a);
      const Frame& f = rest_frame_[ta];
      const Eigen::Vector3d n = f.col(0).cross(f.col(1));
      const Eigen::Vector3d w = mesh.warp[ta] - mesh.warp[ta].dot(n) * n;
      const Eigen::Vector3d g1 = w.normalized(), g2 = n.cross(g1);
      const Eigen::Vector3d m = n.cross((x[1] - x[0]).normalized());
      rigidity = directional_modulus(material.bending_law(), m.dot(g1), m.dot(g2));
    }
    hinge_k_[h] = rigidity * edge2 / (2.0 * areas);
    rest_angle_[h] = dihedral_angle(x);
  }
  rotation_ = rest_frame_;
  angle_ = rest_angle_;
  gradient_.assign(hinges.size(), HingeVector::Zero());
}

HingePositions LinearFeElastic::hinge_positions(size_t h, const Eigen::VectorXd& x) const {
  const Hinge& hinge = d_.hinges()[h];
  HingePositions p;
  for (size_t k = 0; k < 4; ++k) p[k] = x.segment<3>(3 * hinge.nodes[k]);
  return p;
}

void LinearFeElastic::freeze_rotations(bool on) {
  frozen_ = on;
  if (!on) evaluated_ = false;
}

void LinearFeElastic::update(const Eigen::VectorXd& x, const Eigen::VectorXd& /*u*/, double /*t*/) {
  if (evaluated_ && x.size() == x_.size() && x == x_) return;
  const TriMesh& mesh = d_.mesh();
  const size_t nt = mesh.triangles.size(), nh = d_.hinges().size();
  const bool extract = corotational_ && !(frozen_ && evaluated_);
  std::vector<Eigen::Matrix3d> triangle_force(nt);  // column i: the force on node i
  std::vector<double> triangle_energy(nt);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nt, 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t t = range.begin(); t != range.end(); ++t) {
      const Triangle& tri = mesh.triangles[t];
      Eigen::Matrix3d xe;
      for (int i = 0; i < 3; ++i) xe.col(i) = x.segment<3>(3 * tri[static_cast<size_t>(i)]);
      if (extract) {
        Frame edges;
        edges << xe.col(1) - xe.col(0), xe.col(2) - xe.col(0);
        rotation_[t] = polar_rotation(edges * inverse_edges_[t]);
      } else if (!corotational_) {
        rotation_[t] = rest_frame_[t];
      }
      const Frame& r = rotation_[t];
      // d relative to node 0 (K_e annihilates translations): no offset of the size of the
      // coordinates to cancel, so the energy keeps its precision far from the origin.
      Eigen::Matrix<double, 6, 1> dvec;
      dvec.segment<2>(0).setZero();
      for (int i = 1; i < 3; ++i) dvec.segment<2>(2 * i) = r.transpose() * (xe.col(i) - xe.col(0)) - rest2d_[t].col(i);
      const Eigen::Matrix<double, 6, 1> stress = k_[t] * dvec;
      triangle_energy[t] = 0.5 * dvec.dot(stress);
      for (int i = 0; i < 3; ++i) triangle_force[t].col(i) = -(r * stress.segment<2>(2 * i));
    }
  });
  std::vector<double> hinge_energy(nh);
  std::atomic<long long> degenerate{-1};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nh, 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t h = range.begin(); h != range.end(); ++h) {
      const HingePositions p = hinge_positions(h, x);
      if (hinge_is_degenerate(p)) {
        degenerate = static_cast<long long>(h);
        continue;
      }
      angle_[h] = dihedral_angle(p);
      gradient_[h] = dihedral_gradient(p);
      const double delta = std::remainder(angle_[h] - rest_angle_[h], 2.0 * M_PI);
      hinge_energy[h] = hinge_k_[h] * delta * delta;
    }
  });
  if (degenerate >= 0) {
    evaluated_ = false;
    const Hinge& hinge = d_.hinges()[static_cast<size_t>(degenerate.load())];
    throw std::runtime_error("linear FE bending: a triangle at the edge (" + std::to_string(hinge.nodes[0]) + ", " +
                             std::to_string(hinge.nodes[1]) + ") has collapsed to zero area, so its dihedral angle is "
                             "undefined");
  }
  force_ = Eigen::VectorXd::Zero(x.size());
  membrane_energy_ = 0.0;
  for (size_t t = 0; t < nt; ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (int i = 0; i < 3; ++i) force_.segment<3>(3 * tri[static_cast<size_t>(i)]) += triangle_force[t].col(i);
    membrane_energy_ += triangle_energy[t];
  }
  bending_energy_ = 0.0;
  for (size_t h = 0; h < nh; ++h) {
    const Hinge& hinge = d_.hinges()[h];
    const double delta = std::remainder(angle_[h] - rest_angle_[h], 2.0 * M_PI);
    const double scale = -2.0 * hinge_k_[h] * delta;
    for (size_t k = 0; k < 4; ++k) force_.segment<3>(3 * hinge.nodes[k]) += scale * gradient_[h].segment<3>(3 * static_cast<Eigen::Index>(k));
    bending_energy_ += hinge_energy[h];
  }
  x_ = x;
  evaluated_ = true;
}

void LinearFeElastic::add_matrix(const MatrixWeights& w, Eigen::SparseMatrix<double>& a) const {
  if (w.stiffness == 0.0) return;
  const NodeBlockPattern& blocks = d_.blocks();
  double* values = a.valuePtr();
  const int nt = static_cast<int>(d_.mesh().triangles.size());
  for (int t = 0; t < nt; ++t) {
    const Frame& r = rotation_[static_cast<size_t>(t)];
    const Frame rw = w.stiffness * r;
    const Eigen::Matrix<double, 6, 6>& k = k_[static_cast<size_t>(t)];
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) blocks.add_block(t, i, j, rw * k.block<2, 2>(2 * i, 2 * j) * r.transpose(), values);
  }
  const std::vector<Hinge>& hinges = d_.hinges();
  for (size_t h = 0; h < hinges.size(); ++h) {
    const double scale = 2.0 * hinge_k_[h] * w.stiffness;
    const HingeVector& g = gradient_[h];
    HingeMatrix m = scale * g * g.transpose();
    if (exact_hessian_) {
      const double delta = std::remainder(angle_[h] - rest_angle_[h], 2.0 * M_PI);
      m += (scale * delta) * dihedral_hessian(hinge_positions(h, x_));
    }
    const int group = nt + static_cast<int>(h);
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) blocks.add_block(group, i, j, m.block<3, 3>(3 * i, 3 * j), values);
  }
}

}  // namespace clothsim

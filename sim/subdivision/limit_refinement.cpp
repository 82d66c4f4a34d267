#include "sim/subdivision/limit_refinement.hpp"

#include "sim/mesh/topology.hpp"
#include "sim/subdivision/loop.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <stdexcept>

namespace clothsim {

LimitRefinement build_limit_refinement(const Eigen::MatrixX3d& control, const std::vector<Triangle>& triangles,
                                       int num_output_triangles, int levels) {
  if (levels < 0) throw std::invalid_argument("build_limit_refinement: levels must be >= 0");
  const Eigen::Index n0 = control.rows();
  // Compose the subdivision steps: positions_k = S · control.
  Eigen::SparseMatrix<double, Eigen::RowMajor> s(n0, n0);
  s.setIdentity();
  Eigen::MatrixX3d x = control;
  std::vector<Triangle> tris = triangles;
  for (int level = 0; level < levels; ++level) {
    const SubdivisionStep step = loop_subdivision_step(x, tris);
    const Eigen::SparseMatrix<double, Eigen::RowMajor> m = step.matrix;
    s = m * s;
    x = m * x;
    tris = step.triangles;
  }
  // Output: the descendants of the first num_output_triangles control triangles, which are the
  // first num_output_triangles · 4^levels fine triangles.
  std::size_t per = 1;
  for (int level = 0; level < levels; ++level) per *= 4;
  const std::size_t count = static_cast<std::size_t>(num_output_triangles) * per;
  const Topology top(static_cast<int>(x.rows()), tris);
  std::vector<int> fine_id(static_cast<std::size_t>(x.rows()), -1);
  std::vector<int> used;
  LimitRefinement out;
  out.levels = levels;
  out.triangles.reserve(count);
  for (std::size_t t = 0; t < count; ++t) {
    Triangle ft;
    for (int k = 0; k < 3; ++k) {
      const int v = tris[t][k];
      if (fine_id[v] < 0) {
        if (top.is_boundary(v))
          throw std::invalid_argument("build_limit_refinement: vertex " + std::to_string(v) +
                                      " of an output triangle has an open one-ring");
        fine_id[v] = static_cast<int>(used.size());
        used.push_back(v);
      }
      ft[k] = fine_id[v];
    }
    out.triangles.push_back(ft);
  }
  // Limit masks of the used fine vertices (rows over the level-k vertices), then composed with S.
  using Triplet = Eigen::Triplet<double>;
  std::vector<Triplet> lp, l1, l2;
  for (std::size_t i = 0; i < used.size(); ++i) {
    const int v = used[i];
    const std::vector<int>& ring = top.ring(v);
    const int valence = static_cast<int>(ring.size());
    const double w = limit_neighbour_weight(valence);
    const int row = static_cast<int>(i);
    lp.emplace_back(row, v, 1.0 - valence * w);
    const std::vector<double> c1 = limit_tangent_mask(valence, 0), c2 = limit_tangent_mask(valence, 1);
    for (int k = 0; k < valence; ++k) {
      lp.emplace_back(row, ring[k], w);
      if (c1[k] != 0.0) l1.emplace_back(row, ring[k], c1[k]);
      if (c2[k] != 0.0) l2.emplace_back(row, ring[k], c2[k]);
    }
  }
  auto compose = [&](const std::vector<Triplet>& entries) {
    Eigen::SparseMatrix<double, Eigen::RowMajor> mask(static_cast<Eigen::Index>(used.size()), x.rows());
    mask.setFromTriplets(entries.begin(), entries.end());
    Eigen::SparseMatrix<double, Eigen::RowMajor> op = mask * s;
    op.prune(0.0, 1e-14);
    return op;
  };
  out.position = compose(lp);
  out.tangent1 = compose(l1);
  out.tangent2 = compose(l2);
  return out;
}

void evaluate_limit(const LimitRefinement& refinement, const Eigen::MatrixX3d& x, Eigen::MatrixX3d& positions,
                    Eigen::MatrixX3d& normals) {
  positions = refinement.position * x;
  const Eigen::MatrixX3d t1 = refinement.tangent1 * x, t2 = refinement.tangent2 * x;
  normals.resize(positions.rows(), 3);
  for (Eigen::Index i = 0; i < positions.rows(); ++i) {
    const Eigen::Vector3d n = Eigen::Vector3d(t1.row(i)).cross(Eigen::Vector3d(t2.row(i)));
    const double len = n.norm();
    normals.row(i) = len > 0 ? Eigen::RowVector3d(n.transpose() / len) : Eigen::RowVector3d(0, 0, 0);
  }
}

}  // namespace clothsim

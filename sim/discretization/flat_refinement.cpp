#include "sim/discretization/flat_refinement.hpp"

#include "sim/subdivision/loop.hpp"

#include <stdexcept>
#include <utility>
#include <vector>

namespace clothsim {

SurfaceOperator midpoint_display(const TriMesh& mesh, int levels, Eigen::Index num_columns) {
  if (levels < 0) throw std::invalid_argument("display: levels must be >= 0");
  const Eigen::Index n0 = mesh.num_vertices();
  if (num_columns < n0) throw std::invalid_argument("midpoint_display: fewer columns than mesh vertices");
  // Midpoint subdivision, composed: fine vertex positions = S · vertices. The topology of each
  // step (vertex and triangle numbering, child order) is Loop's (sim/subdivision/loop.hpp); only
  // the weights differ: old vertices stay, edge vertices are the edge midpoints.
  using Sparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  Sparse s(n0, n0);
  s.setIdentity();
  std::vector<Triangle> tris = mesh.triangles;
  Eigen::MatrixX3d x = mesh.vertices;
  for (int level = 0; level < levels; ++level) {
    const SubdivisionStep step = loop_subdivision_step(x, tris);
    const Eigen::Index n = x.rows(), fine = step.matrix.rows();
    std::vector<Eigen::Triplet<double>> w;
    for (Eigen::Index v = 0; v < n; ++v) w.emplace_back(static_cast<int>(v), static_cast<int>(v), 1.0);
    std::vector<char> done(static_cast<size_t>(fine), 0);
    for (size_t t = 0; t < tris.size(); ++t) {
      // Children: (a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca).
      const Triangle& parent = tris[t];
      const int ab = step.triangles[4 * t][1], ca = step.triangles[4 * t][2], bc = step.triangles[4 * t + 1][1];
      const std::pair<int, std::pair<int, int>> mids[3] = {{ab, {parent[0], parent[1]}},
                                                          {bc, {parent[1], parent[2]}},
                                                          {ca, {parent[2], parent[0]}}};
      for (const auto& [mid, ends] : mids) {
        if (done[static_cast<size_t>(mid)]) continue;
        done[static_cast<size_t>(mid)] = 1;
        w.emplace_back(mid, ends.first, 0.5);
        w.emplace_back(mid, ends.second, 0.5);
      }
    }
    Sparse m(fine, n);
    m.setFromTriplets(w.begin(), w.end());
    s = Sparse(m * s);
    x = m * x;
    tris = step.triangles;
  }
  // Points in order of first use by the fine triangles; each takes the tangents of the mesh
  // triangle of the first fine triangle that uses it.
  const size_t per = size_t{1} << (2 * levels);
  std::vector<int> point_of(static_cast<size_t>(x.rows()), -1);
  std::vector<int> used, facet;
  SurfaceOperator op;
  op.levels = levels;
  op.triangles.reserve(tris.size());
  for (size_t t = 0; t < tris.size(); ++t) {
    Triangle ft;
    for (int k = 0; k < 3; ++k) {
      const int v = tris[t][static_cast<size_t>(k)];
      if (point_of[static_cast<size_t>(v)] < 0) {
        point_of[static_cast<size_t>(v)] = static_cast<int>(used.size());
        used.push_back(v);
        facet.push_back(static_cast<int>(t / per));
      }
      ft[static_cast<size_t>(k)] = point_of[static_cast<size_t>(v)];
    }
    op.triangles.push_back(ft);
  }
  const Eigen::Index np = static_cast<Eigen::Index>(used.size());
  std::vector<Eigen::Triplet<double>> pick, t1, t2;
  for (Eigen::Index p = 0; p < np; ++p) {
    pick.emplace_back(static_cast<int>(p), used[static_cast<size_t>(p)], 1.0);
    const Triangle& tri = mesh.triangles[static_cast<size_t>(facet[static_cast<size_t>(p)])];
    t1.emplace_back(static_cast<int>(p), tri[1], 1.0);
    t1.emplace_back(static_cast<int>(p), tri[0], -1.0);
    t2.emplace_back(static_cast<int>(p), tri[2], 1.0);
    t2.emplace_back(static_cast<int>(p), tri[0], -1.0);
  }
  Sparse select(np, x.rows());
  select.setFromTriplets(pick.begin(), pick.end());
  op.position = select * s;
  op.position.prune(0.0, 1e-14);
  op.position.conservativeResize(np, num_columns);
  op.tangent1.resize(np, num_columns);
  op.tangent1.setFromTriplets(t1.begin(), t1.end());
  op.tangent2.resize(np, num_columns);
  op.tangent2.setFromTriplets(t2.begin(), t2.end());
  return op;
}

}  // namespace clothsim

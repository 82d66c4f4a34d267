#include "sim/discretization/discretization.hpp"

#include <Eigen/Geometry>

namespace clothsim {

void SurfaceOperator::evaluate(const Eigen::MatrixX3d& net, Eigen::MatrixX3d& positions, Eigen::MatrixX3d& normals) const {
  positions = position * net;
  const Eigen::MatrixX3d t1 = tangent1 * net, t2 = tangent2 * net;
  normals.resize(positions.rows(), 3);
  for (Eigen::Index i = 0; i < positions.rows(); ++i) {
    const Eigen::Vector3d n = Eigen::Vector3d(t1.row(i)).cross(Eigen::Vector3d(t2.row(i)));
    const double len = n.norm();
    normals.row(i) = len > 0 ? Eigen::RowVector3d(n.transpose() / len) : Eigen::RowVector3d(0, 0, 0);
  }
}

SurfaceOperator Discretization::drawn_display(int levels, DrawnSurface surface) const {
  switch (surface) {
    case DrawnSurface::loop_limit: return loop_limit_display(levels);
    case DrawnSurface::flat: return flat_display(levels);
    case DrawnSurface::method: break;
  }
  return display(levels);
}

}  // namespace clothsim

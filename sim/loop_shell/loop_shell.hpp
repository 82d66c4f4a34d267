// The Loop-subdivision Kirchhoff–Love shell as a Discretization (paper §4; Cirak, Ortiz &
// Schröder 2000): the nodes are the control vertices of the prepared mesh; the control net is the
// mesh with its ghost layer at borders (sim/shell/ghost_layer.hpp), whose positions follow from
// the nodes through the boundary rules (sim/shell/dof_map.hpp); the surface is the limit surface
// of Loop subdivision of that net, evaluated with the box-spline basis on regular patches
// (sim/subdivision/). Internal forces: the corotated subdivision element
// (sim/forces/corotated_shell.hpp). Mass: lumped, a third of each incident triangle's rest area.
#pragma once

#include "sim/boundary/boundary_condition.hpp"
#include "sim/core/log.hpp"
#include "sim/discretization/discretization.hpp"
#include "sim/shell/material.hpp"
#include "sim/shell/quadrature.hpp"
#include "sim/shell/shell_model.hpp"

#include <vector>

namespace clothsim {

class LoopShellDiscretization final : public Discretization {
 public:
  // The mesh the element needs: `mesh` itself, or refined once by Loop subdivision (crease rules
  // on borders, corners kept) if any triangle has more than one irregular vertex (valence ≠ 6,
  // counting the ghost layer at borders); logs what it did. Throws MeshError for invalid meshes
  // (naming the element). Boundary selections and probes refer to the prepared mesh's vertices.
  static TriMesh prepare_mesh(const TriMesh& mesh, const LogFn& log);

  // `mesh` must be prepared (prepare_mesh); `boundary` holds vertex ids of it. Throws
  // std::runtime_error (MeshError for mesh problems) naming the problem.
  // `rest`: the elements' rest state (sim/shell/flat_rest.hpp); with RestShape::pattern the mass
  // too comes from the texture-coordinate areas.
  LoopShellDiscretization(const TriMesh& mesh, const std::vector<BoundaryCondition>& boundary,
                          const ShellMaterial& material, Quadrature quadrature, RestShape rest = RestShape::initial);

  std::string method() const override { return "loop_kl"; }
  const TriMesh& mesh() const override { return mesh_; }
  const Eigen::VectorXd& rest() const override { return rest_; }
  DofStatus status(int dof) const override { return model_.dofs().status(dof / 3, dof % 3); }
  void make_consistent(Eigen::VectorXd& u) const override;
  std::vector<std::string> unrestrained_rigid_motions() const override { return model_.unrestrained_rigid_motions(); }

  Eigen::VectorXd lumped_mass(double areal_density) const override;
  Eigen::VectorXd traction_load(const std::function<Eigen::Vector3d(const Eigen::Vector3d& normal)>& traction) const override;
  std::unique_ptr<ForceTerm> elastic_term(bool corotational, bool tension_stiffening) const override;
  const Eigen::SparseMatrix<double>& matrix_pattern() const override { return model_.pattern(); }

  Eigen::MatrixX3d control_net(const Eigen::VectorXd& x) const override;
  const std::vector<Triangle>& control_triangles() const override { return model_.extended().triangles; }
  int num_surface_triangles() const override { return model_.extended().num_real_triangles; }
  SurfaceOperator node_points(const std::vector<int>& nodes) const override;
  SurfaceOperator samples(const std::vector<SurfaceSample>& samples) const override;
  SurfaceOperator display(int levels) const override;
  // The same as display(levels): the drawn surface already is the Loop limit surface.
  SurfaceOperator loop_limit_display(int levels) const override { return display(levels); }
  // The control mesh (the prepared mesh's triangles over the nodes, no ghost layer) drawn flat,
  // midpoint-refined; its columns are the control net's (the ghosts' columns stay empty).
  SurfaceOperator flat_display(int levels) const override;
  // Of the limit surface at each element's barycentre: the eigenvalues of G⁻¹E with
  // E = ½ (g − G), g_αβ = a_α·a_β and G_αβ = A_α·A_β from the current and rest limit tangents
  // (the strain CorotationalElements::membrane_principal_strains reports).
  double max_membrane_strain(const Eigen::VectorXd& u) const override;
  void add_point_forces(const SurfaceOperator& op, const Eigen::MatrixX3d& forces, Eigen::VectorXd& f) const override;
  Eigen::SparseMatrix<double, Eigen::RowMajor> point_jacobian(const SurfaceOperator& op) const override;

  // The shell model underneath (elements, ghost layer, DOF map): for the element's own tests.
  const ShellModel& model() const { return model_; }

 private:
  TriMesh mesh_;
  ShellModel model_;
  Eigen::VectorXd rest_;
  std::vector<int> dependent_;  // dependent DOFs, ascending
  // The limit tangents ∂x/∂v, ∂x/∂w at each real triangle's barycentre (#triangles × #control
  // net points) and their rest values (#triangles × 3) [m], for max_membrane_strain.
  Eigen::SparseMatrix<double, Eigen::RowMajor> centre_dv_, centre_dw_;
  Eigen::MatrixX3d rest_dv_, rest_dw_;
};

}  // namespace clothsim

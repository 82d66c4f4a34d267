// The piecewise-flat discretisation shared by two methods (docs/linear_fe.md, docs/mass_spring.md):
// flat triangles whose nodes are the mesh vertices. FlatDiscretization holds everything the two
// have in common — nodes, DOFs, mass, loads, the matrix pattern, hinges and the surface operators —
// and each method adds its elastic force term:
//  - "linear_fe" (LinearFeDiscretization), the baseline the paper compares against:
//    - membrane: constant-strain triangles in plane stress, corotated per triangle (Etzmuss,
//      Keckeisen & Straßer 2003);
//    - bending: dihedral-angle hinges on the interior edges (discrete shells, Grinspun et al.
//      2003; hinge bending in cloth, Bridson, Marino & Fedkiw 2003).
//    Its force term is sim/flat_fe/flat_fe_term.hpp; docs/linear_fe.md has the formulation, the
//    calibration of the hinges and the limitations.
//  - "mass_spring" (sim/flat_fe/mass_spring.hpp): linear springs on the edges and across the
//    hinges, the way popular cloth tools model cloth (docs/mass_spring.md).
//
// Nodes and DOFs: the mesh vertices, 3 DOFs each, free or fixed (the boundary conditions' fixed
// components; a scripted `motion` of fixed components is the integrator's, as for loop_kl). No DOF
// is dependent. The control net is the nodes themselves; the surface is the flat triangles.
// Borders are hinged by nature (no rotational DOF, no ghost layer): "clamped" and "symmetry"
// borders are not supported (the constructor throws). Hold a slope by fixing two rows of nodes.
#pragma once

#include "sim/boundary/boundary_condition.hpp"
#include "sim/core/log.hpp"
#include "sim/discretization/discretization.hpp"
#include "sim/flat_fe/node_pattern.hpp"
#include "sim/shell/material.hpp"

#include <array>
#include <string>
#include <vector>

namespace clothsim {

// An interior edge and its two triangles: nodes (x0, x1, x2, x3) as in sim/flat_fe/dihedral.hpp —
// x0 → x1 the edge as it runs in triangle A = (x0, x1, x2), x3 the apex of the other triangle B.
struct Hinge {
  std::array<int, 4> nodes{};
  int triangle_a = -1, triangle_b = -1;  // indices into the mesh's triangles
};

// The shared part: a Discretization without its elastic term.
class FlatDiscretization : public Discretization {
 public:
  // The mesh as given, checked (check_triangles, and a manifold, consistently oriented topology
  // without isolated vertices: sim/mesh/topology.hpp); no refinement. Logs that, naming `method`.
  // Throws MeshError naming the element.
  static TriMesh prepare_flat_mesh(const std::string& method, const TriMesh& mesh, const LogFn& log);

  // The method's name as in the scene format ("linear_fe", "mass_spring").
  std::string method() const override { return method_; }
  const TriMesh& mesh() const override { return mesh_; }
  const Eigen::VectorXd& rest() const override { return rest_; }
  DofStatus status(int dof) const override { return status_[static_cast<size_t>(dof)]; }
  void make_consistent(Eigen::VectorXd& /*u*/) const override {}  // no dependent DOFs
  std::vector<std::string> unrestrained_rigid_motions() const override;

  // A third of each incident triangle's rest area × `areal_density` [kg/m²], per node [kg].
  Eigen::VectorXd lumped_mass(double areal_density) const override;
  // f_I = ∫ N_I t dA over the flat rest triangles with the linear shape functions N_I; `traction`
  // gets each triangle's rest unit normal (constant over it), so f_I = Σ (A/3) t(n) over I's
  // triangles, exact.
  Eigen::VectorXd traction_load(const std::function<Eigen::Vector3d(const Eigen::Vector3d& normal)>& traction) const override;
  // 3 × 3 blocks for every pair of nodes sharing a triangle or a hinge.
  const Eigen::SparseMatrix<double>& matrix_pattern() const override { return blocks_.pattern(); }

  Eigen::MatrixX3d control_net(const Eigen::VectorXd& x) const override { return as_rows(x); }
  const std::vector<Triangle>& control_triangles() const override { return mesh_.triangles; }
  int num_surface_triangles() const override { return mesh_.num_triangles(); }
  // The nodes themselves (identity rows).
  SurfaceOperator node_points(const std::vector<int>& nodes) const override;
  // Barycentric interpolation on the flat triangles.
  SurfaceOperator samples(const std::vector<SurfaceSample>& samples) const override;
  // The flat triangles refined `levels` times by midpoint subdivision, with loop_kl's conventions
  // (sim/discretization/flat_refinement.hpp, midpoint_display): surface triangle i has the fine
  // triangles [i·4^levels, (i + 1)·4^levels), the points lie on the flat triangles, and each
  // point's normal is the normal of the first facet it lies on (flat shading).
  SurfaceOperator display(int levels) const override;
  SurfaceOperator flat_display(int levels) const override { return display(levels); }
  // The Loop limit surface with the nodes as control vertices (what loop_kl would draw for the
  // same mesh, node positions and free borders; the ghost layer of sim/shell/ghost_layer.hpp,
  // composed into the operator so that its columns are the nodes). Only a picture: forces,
  // contact, probes and loads stay on the flat triangles. Throws MeshError (naming
  // "render.surface") when the ghost layer cannot be built (a vertex of valence above 12).
  SurfaceOperator loop_limit_display(int levels) const override;
  // Of the flat triangles: the largest |eigenvalue| of ½(FᵀF − I) over the triangles, F the
  // triangle's deformation gradient from its rest plane (constant strain per triangle).
  double max_membrane_strain(const Eigen::VectorXd& u) const override;
  void add_point_forces(const SurfaceOperator& op, const Eigen::MatrixX3d& forces, Eigen::VectorXd& f) const override;
  Eigen::SparseMatrix<double, Eigen::RowMajor> point_jacobian(const SurfaceOperator& op) const override;

  // For the force terms and their tests.
  const ShellMaterial& material() const { return material_; }
  const std::vector<Hinge>& hinges() const { return hinges_; }
  // The pattern's groups: triangle t is group t, hinge h is group #triangles + h (its nodes in
  // Hinge::nodes order).
  const NodeBlockPattern& blocks() const { return blocks_; }

 protected:
  // `method` names the method in messages. `boundary` holds vertex ids of `mesh`. Throws
  // MeshError for an invalid mesh and std::runtime_error for a boundary condition it cannot take
  // (a clamped or symmetry border, a vertex out of range), naming the condition and the method.
  FlatDiscretization(std::string method, const TriMesh& mesh, const std::vector<BoundaryCondition>& boundary,
                     const ShellMaterial& material);

 private:
  std::string method_;
  TriMesh mesh_;
  ShellMaterial material_;
  Eigen::VectorXd rest_;
  std::vector<DofStatus> status_;  // 3 per node
  std::vector<Hinge> hinges_;
  NodeBlockPattern blocks_;
};

// The baseline "linear_fe": corotated constant-strain membrane and hinge bending.
class LinearFeDiscretization final : public FlatDiscretization {
 public:
  // FlatDiscretization::prepare_flat_mesh for "linear_fe".
  static TriMesh prepare_mesh(const TriMesh& mesh, const LogFn& log) { return prepare_flat_mesh("linear_fe", mesh, log); }

  // See FlatDiscretization's constructor.
  LinearFeDiscretization(const TriMesh& mesh, const std::vector<BoundaryCondition>& boundary, const ShellMaterial& material)
      : FlatDiscretization("linear_fe", mesh, boundary, material) {}

  // The corotated (or, `corotational` false, linear) membrane plus the hinge bending
  // (LinearFeElastic). `tension_stiffening` is ignored: the method has no geometric stiffness
  // term (docs/linear_fe.md).
  std::unique_ptr<ForceTerm> elastic_term(bool corotational, bool tension_stiffening) const override;
};

}  // namespace clothsim

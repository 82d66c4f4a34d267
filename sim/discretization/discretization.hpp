// The map from a cloth's degrees of freedom to its surface, and everything that depends on it:
// the DOF layout and its constraints, the lumped mass, the internal force term, the consistent
// surface loads, the sparsity pattern of the system matrix, and ONE family of sparse operators
// from the control DOFs to points of the surface (probes, OBJ frames, rendering, the studies'
// sampling, point loads, and collision geometry). The integrator, the outputs and the renderer
// adapter see only this interface; the Loop-subdivision Kirchhoff–Love shell
// (sim/loop_shell/loop_shell.hpp) is one implementation; the piecewise-flat discretisation
// (sim/flat_fe/flat_fe.hpp) serves two more, the baseline "linear_fe" (linear triangles with hinge
// bending) and "mass_spring" (edge and bending springs, sim/flat_fe/mass_spring.hpp).
//
// Nodes and DOFs. The discretisation has #nodes nodes (for the Loop shell: the control vertices of
// the prepared mesh) with 3 DOFs each, flat as in sim/core/layout.hpp. Each DOF is free (an
// unknown), fixed (prescribed: held, or following a scripted motion) or dependent (derived from
// the others, e.g. the tied components of a clamped border).
//
// The control net. The surface is a linear function of a control net of #C points: for the Loop
// shell the control mesh with its ghost layer (#C ≥ #nodes, ghosts derived from the nodes), for a
// flat discretisation the nodes themselves. control_net(x) gives the net for node positions x;
// a SurfaceOperator maps net positions to surface points, P · net (#P × 3) [m].
#pragma once

#include "sim/core/layout.hpp"
#include "sim/discretization/drawn_surface.hpp"
#include "sim/core/force_term.hpp"
#include "sim/mesh/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace clothsim {

// A point of the surface's parameter domain: triangle `triangle` = (a, b, c) of the prepared mesh
// at barycentric parameters (v, w), the point (1 − v − w)·a + v·b + w·c of the parameter domain.
struct SurfaceSample {
  int triangle = 0;
  double v = 0.0, w = 0.0;
};

// Sparse linear maps from the control net (#C points) to #P surface points: positions, and for
// display operators the two tangents (normal = t₁ × t₂) and the triangles over the points.
struct SurfaceOperator {
  Eigen::SparseMatrix<double, Eigen::RowMajor> position;  // #P × #C
  Eigen::SparseMatrix<double, Eigen::RowMajor> tangent1;  // #P × #C (display operators; else empty)
  Eigen::SparseMatrix<double, Eigen::RowMajor> tangent2;  // #P × #C (display operators; else empty)
  std::vector<Triangle> triangles;  // display operators: triangles over the points
  int levels = 0;                   // display operators: surface triangle i has fine triangles
                                    // [i·4^levels, (i + 1)·4^levels)

  int num_points() const { return static_cast<int>(position.rows()); }
  // Positions (#P × 3) [m] of the points for a control net (#C × 3) [m].
  Eigen::MatrixX3d positions(const Eigen::MatrixX3d& net) const { return position * net; }
  // Positions and unit normals (#P × 3) for a control net (display operators).
  void evaluate(const Eigen::MatrixX3d& net, Eigen::MatrixX3d& positions, Eigen::MatrixX3d& normals) const;
};

class Discretization {
 public:
  virtual ~Discretization() = default;

  // The method's name as in the scene format ("loop_kl", "linear_fe", "mass_spring").
  virtual std::string method() const = 0;

  // --- Nodes and DOFs -------------------------------------------------------------------------
  // The prepared mesh whose vertices are the nodes (#nodes × 3 rest positions [m]).
  virtual const TriMesh& mesh() const = 0;
  int num_nodes() const { return mesh().num_vertices(); }
  // Rest positions, flat (3·#nodes) [m].
  virtual const Eigen::VectorXd& rest() const = 0;
  virtual DofStatus status(int dof) const = 0;
  // Sets the dependent components of displacements u (3·#nodes, from the rest state) [m] from the
  // others.
  virtual void make_consistent(Eigen::VectorXd& u) const = 0;
  // Rigid motions the constraints leave free, in words ("translation along y"); empty when the
  // structure is supported (a static analysis needs that).
  virtual std::vector<std::string> unrestrained_rigid_motions() const = 0;

  // --- Mass, forces, matrix -------------------------------------------------------------------
  // Lumped mass per node [kg] for an areal density [kg/m²].
  virtual Eigen::VectorXd lumped_mass(double areal_density) const = 0;
  // Consistent nodal forces of a traction t over the rest surface, f_I = ∫ N_I t dA (3·#nodes)
  // [N]; `traction` gets the rest surface's unit normal at each integration point and returns
  // t there [N/m²].
  virtual Eigen::VectorXd traction_load(const std::function<Eigen::Vector3d(const Eigen::Vector3d& normal)>& traction) const = 0;
  // The internal (elastic) force term of the discretisation's material: membrane and bending;
  // `corotational` false gives the linear element; `tension_stiffening` adds the membrane
  // geometric stiffness of the tensile stress to its matrix. It refers to this discretisation,
  // which must outlive it.
  virtual std::unique_ptr<ForceTerm> elastic_term(bool corotational, bool tension_stiffening) const = 0;
  // The sparsity pattern of every system matrix (3·#nodes square, compressed, zero values).
  virtual const Eigen::SparseMatrix<double>& matrix_pattern() const = 0;

  // --- The surface ----------------------------------------------------------------------------
  // The control net (#C × 3) [m] for node positions x (3·#nodes, constrained components
  // consistent) [m].
  virtual Eigen::MatrixX3d control_net(const Eigen::VectorXd& x) const = 0;
  // Triangles of the control net; the first num_surface_triangles() are the surface's own (the
  // prepared mesh's triangles, in its order), any others (a ghost layer) only support them.
  virtual const std::vector<Triangle>& control_triangles() const = 0;
  virtual int num_surface_triangles() const = 0;
  // The surface point of each listed node (#P = nodes.size()): the point a probe reports and a
  // point load acts on (the limit point for the Loop shell).
  virtual SurfaceOperator node_points(const std::vector<int>& nodes) const = 0;
  // Points of the parameter domain (#P = samples.size()).
  virtual SurfaceOperator samples(const std::vector<SurfaceSample>& samples) const = 0;
  // The surface refined for display: `levels` ≥ 0 steps of the method's refinement, then its
  // surface points, with tangents and triangles.
  virtual SurfaceOperator display(int levels) const = 0;
  // The Loop limit surface whose control vertices are the nodes, refined for display `levels`
  // steps (k Loop steps, then the limit masks; sim/subdivision/limit_refinement.hpp), with the
  // ghost layer at open borders built by the free-border rule x_g = x_a + x_b − x_c
  // (sim/shell/ghost_layer.hpp) — an operator over this discretisation's control net. The Loop
  // shell's own display(levels); for a flat discretisation a picture of the smooth surface its
  // nodes span (not the surface it computes with).
  virtual SurfaceOperator loop_limit_display(int levels) const = 0;
  // The flat triangles of the prepared mesh over the nodes, refined `levels` times by midpoint
  // subdivision (sim/discretization/flat_refinement.hpp) — an operator over the control net. A
  // flat discretisation's own display(levels); for the Loop shell its control mesh drawn flat.
  virtual SurfaceOperator flat_display(int levels) const = 0;
  // The surface drawn for `surface` ("render.surface"): display, loop_limit_display or
  // flat_display.
  SurfaceOperator drawn_display(int levels, DrawnSurface surface) const;
  // f += Jᵀ F: the nodal forces (3·#nodes) [N] equivalent to forces F (#P × 3) [N] applied at the
  // operator's points (J the derivative of the points' positions with respect to the node
  // positions, the transpose of the operator composed with the control net).
  virtual void add_point_forces(const SurfaceOperator& op, const Eigen::MatrixX3d& forces, Eigen::VectorXd& f) const = 0;
  // J, the derivative of the operator's points (flat, 3·#P) with respect to the node positions
  // (3·#nodes): 3·#P × 3·#nodes, row-major. The points are affine in x, P(x) = P(X) + J (x − X),
  // so their velocities are J v. Its entries name free and fixed components only (dependent
  // ones are folded in through their rule), so a change of the free components moves the points
  // by J δv exactly once make_consistent() has derived the dependent ones.
  virtual Eigen::SparseMatrix<double, Eigen::RowMajor> point_jacobian(const SurfaceOperator& op) const = 0;

  // --- Strain ---------------------------------------------------------------------------------
  // Largest |principal Green–Lagrange membrane strain| [-] over the surface for displacements u
  // (3·#nodes, from the rest state; dependent components are derived here) [m]: for the Loop
  // shell of its limit surface at each element's barycentre, for a flat discretisation of each
  // flat triangle (constant over it). A uniform stretch by λ gives ½(λ² − 1); a rigid motion 0.
  virtual double max_membrane_strain(const Eigen::VectorXd& u) const = 0;

  // Convenience: positions (#P × 3) [m] of an operator's points for node positions x.
  Eigen::MatrixX3d surface_positions(const SurfaceOperator& op, const Eigen::VectorXd& x) const {
    return op.positions(control_net(x));
  }
};

}  // namespace clothsim

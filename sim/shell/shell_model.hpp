// A Kirchhoff–Love subdivision shell on a control mesh: the ghost layer, the boundary
// conditions folded into each element, per-element basis data at the quadrature points, the
// rest-state element stiffness, and sparse assembly over the real vertices (paper eqs. 26–27).
//
// Global vectors are flat over the real control vertices, [x0 y0 z0 x1 ...] (3·#V); matrices are
// 3·#V square. Fixed components couple like free ones (they may carry prescribed motion);
// components tied by a clamped border have empty rows and columns. restrict_to_free() turns a
// matrix and load into the system for the free components alone.
#pragma once

#include "sim/mesh/mesh.hpp"
#include "sim/boundary/boundary_condition.hpp"
#include "sim/shell/dof_map.hpp"
#include "sim/shell/element.hpp"
#include "sim/shell/flat_rest.hpp"
#include "sim/shell/ghost_layer.hpp"
#include "sim/shell/material.hpp"
#include "sim/shell/quadrature.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace clothsim {

struct ShellElement {
  Triangle triangle;                // real vertices (a, b, c)
  std::vector<int> patch;           // extended-mesh control vertices of the patch
  std::vector<BasisMatrix> basis;   // per quadrature point, columns as `patch`
  std::vector<double> weights;      // quadrature weights (sum 1/2)
  std::vector<int> real;            // real vertices the patch's displacements depend on
  bool identity = false;            // patch == real and every component free and itself
  Eigen::Vector3d warp = Eigen::Vector3d::Zero();  // rest warp direction (TriMesh::warp; zero: none),
                                                   // in the frame of `reference`
  Eigen::MatrixX3d reference;       // the patch at rest (#patch × 3): the mesh's positions, or the
                                    // flat layout (RestShape::pattern, flat_rest.hpp)
  Eigen::SparseMatrix<double> fold;  // 3·#patch × 3·#real weights (when !identity; most rows
                                     // are unit rows)
};

// The rigid motions left free, in words ("translation along y", "rotation about x + rotation
// about z"), from the Gram matrix of the six basis motions (translations along x, y, z, then
// rotations about x, y, z, in units of the structure's size) sampled where the structure is held:
// its null space (eigenvalues below 1e-9 of the largest, or of 1) is what the constraints leave
// free. Used by every discretisation's unrestrained_rigid_motions().
std::vector<std::string> free_rigid_motions(const Eigen::Matrix<double, 6, 6>& gram);

class ShellModel {
 public:
  // An orthotropic material needs the mesh's per-triangle warp directions (TriMesh::warp; throws
  // std::invalid_argument naming what is missing otherwise). With RestShape::pattern every
  // element rests flat in its layout from the texture coordinates (flat_rest.hpp; throws MeshError
  // naming the triangle when the layout cannot be made); the mesh's positions are still the
  // configuration displacements are measured from.
  ShellModel(const TriMesh& mesh, const ShellMaterial& material, const std::vector<BoundaryCondition>& conditions,
             Quadrature quadrature, RestShape rest = RestShape::initial);

  int num_vertices() const { return ext_.num_real; }
  const ExtendedMesh& extended() const { return ext_; }
  const DofMap& dofs() const { return dofs_; }
  const std::vector<ShellElement>& elements() const { return elements_; }
  const ShellMaterial& material() const { return material_; }

  // Rest-state stiffness over the real vertices (3·#V square, symmetric), including the rows
  // and columns of fixed components.
  Eigen::SparseMatrix<double> stiffness() const;
  // Keeps only the coupling between free components: rows and columns of the others become a
  // unit diagonal (zero prescribed displacement), load entries zero.
  void restrict_to_free(Eigen::SparseMatrix<double>& k) const;
  void restrict_to_free(Eigen::VectorXd& f) const;
  // Element stiffness folded onto the element's real vertices (3·#real square).
  Eigen::MatrixXd folded_element_stiffness(int e) const;
  // Rigid motions (translations, infinitesimal rotations about the centroid) that the boundary
  // conditions leave free, described in words (e.g. "translation along y"); empty when the
  // structure is supported. A non-empty answer means the stiffness is singular.
  std::vector<std::string> unrestrained_rigid_motions() const;
  // Number of colour groups used for parallel assembly (elements of one group share no vertex).
  int num_colors() const { return static_cast<int>(colors_.size()); }
  const std::vector<std::vector<int>>& color_groups() const { return colors_; }

  // Building blocks for other assemblies (the corotational dynamics):
  // the zero-valued matrix with the stiffness pattern (3·#V square);
  Eigen::SparseMatrix<double> zero_matrix() const { return pattern_; }
  // that pattern itself (to check or refill a matrix without copying it);
  const Eigen::SparseMatrix<double>& pattern() const { return pattern_; }
  // the rest stiffness of element e in patch coordinates (3·#patch square, not folded);
  Eigen::MatrixXd patch_stiffness(int e) const;
  // the element's patch displacements (3·#patch) from real displacements (3·#V);
  Eigen::VectorXd patch_vector(int e, const Eigen::VectorXd& real) const;
  // folds a patch-coordinate matrix into the values of a matrix with the stiffness pattern
  // (elements of one colour group may do this concurrently);
  void add_patch_matrix(int e, const Eigen::MatrixXd& k_patch, Eigen::SparseMatrix<double>& global) const;
  // adds a 3 × 3 block for the pair (a, b) of element e's real vertices (indices into
  // ShellElement::real, which equal patch indices for identity elements) to matrix values;
  void add_block(int e, size_t a, size_t b, const Eigen::Matrix3d& block, double* values) const {
    const size_t m = elements_[e].real.size();
    double* target = values + slots_[e][a + m * b];
    const int stride = block_stride_[elements_[e].real[b]];
    for (int d = 0; d < 3; ++d)
      for (int c = 0; c < 3; ++c) target[d * stride + c] += block(c, d);
  }
  // the value offsets of element e's blocks (a, b) at [a + m·b], m = #real (as add_block), and
  // the entries in one column of vertex v's block column (the stride between a block's columns);
  const int* block_slots(int e) const { return slots_[e].data(); }
  int block_stride(int v) const { return block_stride_[v]; }
  // folds a patch-coordinate vector into a global vector.
  void add_patch_vector(int e, const Eigen::VectorXd& f_patch, Eigen::VectorXd& global) const {
    scatter_vector(elements_[e], f_patch, global);
  }

  RestShape rest_shape() const { return rest_shape_; }

  // Consistent load of a force per unit reference area q [N/m²]: f_I = ∫ N_I q dA.
  Eigen::VectorXd area_load(const Eigen::Vector3d& q) const;
  // Pressure p [N/m²] along the reference surface's unit normal a₃: f_I = ∫ N_I p a₃ dA.
  Eigen::VectorXd pressure_load(double p) const;
  // ∫ N_I t(x) dA for a traction t [N/m²] given at each quadrature point's reference geometry.
  Eigen::VectorXd surface_traction_load(const std::function<Eigen::Vector3d(const SurfacePoint&)>& traction) const;
  // A force [N] at the limit point of real vertex v, spread with the limit-mask weights.
  Eigen::VectorXd point_load(int v, const Eigen::Vector3d& force) const;

  // Limit points of the real vertices of the surface with control positions `ext_positions`
  // (#ext × 3): the limit position mask over each vertex's (closed, extended) one-ring.
  Eigen::MatrixX3d limit_points(const Eigen::MatrixX3d& ext_positions) const;

 private:
  // Folds a patch-local vector (3·#patch) into the global vector.
  void scatter_vector(const ShellElement& el, const Eigen::VectorXd& local, Eigen::VectorXd& global) const;
  void build_pattern();
  void build_colors();
  template <class Matrix>
  void scatter_matrix(int e, const Matrix& local, double* values) const;

  ExtendedMesh ext_;
  DofMap dofs_;
  ShellMaterial material_;
  RestShape rest_shape_ = RestShape::initial;
  std::vector<ShellElement> elements_;
  // Sparsity of the stiffness (3 × 3 blocks between vertices sharing an element) and, per
  // element, the value offset of each block (a, b) of its real vertices at slots[a + m·b].
  Eigen::SparseMatrix<double> pattern_;
  std::vector<std::vector<int>> slots_;
  std::vector<int> block_stride_;          // per vertex j: entries in one column of block column j
  std::vector<std::vector<int>> colors_;   // element ids per colour group
};

}  // namespace clothsim

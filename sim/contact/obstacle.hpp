// Kinematic rigid obstacles of a dynamic scene (the ground, spheres, capsules, boxes, cylinders,
// triangle meshes from OBJ files) and the collision settings of the cloth. An obstacle moves
// rigidly along a chain of motions (sim/boundary/motion.hpp: rotate, translate, hold), the same
// chains a scripted boundary follows; the cloth cannot move it.
//
// Geometry. A plane is exact: the half-space behind it is solid, and contact keeps every point of
// the cloth's collision surface at least the collision thickness in front of it (for a plane this
// is exact for whole triangles: a triangle whose corners are in front is in front). Every other
// primitive is a closed triangle mesh — a tessellation fine enough that its chords are within
// 0.2 % of the radius of the curved surface (its vertices lie on the true surface, so the mesh
// lies inside it) — and that mesh is what collides and what is drawn, so pictures show exactly the
// geometry the cloth touched. An OBJ obstacle is its triangles as read (open or closed).
#pragma once

#include "sim/boundary/motion.hpp"
#include "sim/mesh/mesh.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace clothsim {

// "collision": how the cloth meets itself and the obstacles.
struct CollisionSettings {
  bool self = false;          // self-collision of the cloth
  double thickness = 1e-3;    // [m] the distance contact keeps between surfaces
  double friction = 0.3;      // [-] Coulomb coefficient cloth–cloth, and the obstacles' default
  double tolerance = 1e-3;    // [-] of the contact response, in velocity: this fraction of the
                              // thickness per step (docs/contact.md)
  // How proximity is treated (scene key collision.method): "barrier", a barrier energy of the
  // step's end positions with lagged friction, minimised inside the implicit step with the
  // elastic model, the constraints of the velocity filter being the fail-safe only; or
  // "constraints", every pair within the thickness a constraint of the velocity filter
  // (the method before 2026-11-28; docs/contact.md).
  bool barrier = true;
  // Not a scene key. Two patches of the collision surface in one star of a control vertex, or in
  // the two stars of a control edge, are not tested against each other while the normals of that
  // region stay within a cone of this half-angle [rad] over the whole step (docs/contact.md,
  // "Flat regions"); 0 tests every pair. At least 0 and below π/2.
  double flat_region_angle = 1.0471975511965976;  // 60°
};

struct Obstacle {
  enum class Shape { plane, sphere, capsule, box, cylinder, mesh };
  std::string name;
  Shape shape = Shape::plane;
  // Parameters at rest [m] (those of the shape):
  Eigen::Vector3d point = Eigen::Vector3d::Zero();        // plane: a point on it
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();      // plane: towards the free side (unit)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();       // sphere, box
  double radius = 0.0;                                    // sphere, capsule, cylinder
  Eigen::Vector3d from = Eigen::Vector3d::Zero();         // capsule, cylinder: axis end points
  Eigen::Vector3d to = Eigen::Vector3d::UnitY();
  Eigen::Vector3d size = Eigen::Vector3d::Ones();         // box: edge lengths along x, y, z
  std::string file;                                       // mesh: the OBJ file, as given
  double friction = 0.3;                                  // [-] Coulomb coefficient against the cloth
  std::vector<Motion> motion;                             // rigid motion chain (empty: at rest)
  TriMesh mesh;  // every shape but the plane: the triangles at rest (tessellated or read)
};

// Tessellates a primitive (sphere, capsule, box, cylinder) into its closed triangle mesh at rest,
// outward-facing (counter-clockwise seen from outside). Throws std::invalid_argument for a plane
// or a mesh obstacle, or a non-positive radius or size.
TriMesh tessellate(const Obstacle& obstacle);

// An obstacle's position at time t [s] of a point with rest position `rest` [m].
inline Eigen::Vector3d obstacle_point(const Obstacle& o, const Eigen::Vector3d& rest, double t) {
  return apply_motions(o.motion, rest, t);
}

// The plane's point and unit normal at time t [s].
void plane_at(const Obstacle& o, double t, Eigen::Vector3d& point, Eigen::Vector3d& normal);

// The obstacle mesh's vertices at time t (#V × 3) [m].
Eigen::MatrixX3d mesh_at(const Obstacle& o, double t);

const char* to_string(Obstacle::Shape shape);

}  // namespace clothsim

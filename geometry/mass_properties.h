// Mass, centre of mass and inertia tensor of a solid shape at a density: closed forms for the analytic shapes
// (their entries in geometry/shapes.cpp), the volume integrals of a closed triangle mesh (the divergence
// theorem over signed tetrahedra) for a mesh. In 2D a shape is its cross-section in the plane z = 0, the density
// is per area and the mass per metre of depth; only the inertia about z counts there.
#pragma once

#include <Eigen/Core>

#include "geometry/collider_shape.h"

namespace surge {

struct MassProperties {
  double volume = 0;  // m^3 (m^2 in 2D)
  double mass = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();   // in the shape's frame, scaled
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about the centre, in the shape's frame, scaled
};

// The shape scaled by `scale` at `density`. A box, sphere, capsule or cylinder in 2D or 3D; a mesh in 3D (its
// triangles must close a volume: isClosedManifold).
MassProperties massProperties(const ColliderShape& shape, double scale, int dimensions, double density);

// A triangle mesh's volume, centre and inertia at unit density (Eigen's row order of the triangles does not
// matter; the orientation must be outward).
MassProperties meshMassProperties(const TriangleMesh& mesh);

}  // namespace surge

// The shape of one collider in its own frame: a signed distance to its solid (exact for the analytic shapes,
// a first-order estimate for a heightfield, a baked grid for a mesh) and a triangle mesh to draw and export.
// The simulator places it with a Pose (geometry/pose.h); nothing here knows about particles.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "core/ply.h"
#include "core/scene.h"
#include "geometry/distance_grid.h"
#include "geometry/pose.h"
#include "geometry/triangle_mesh.h"

namespace surge {

// Every kind has its entry in geometry/shapes.h (its name, builder, mass); keep Mesh last.
enum class ShapeKind { Plane, Box, Sphere, Capsule, Cylinder, Heightfield, Mesh };
constexpr size_t kShapeKinds = size_t(ShapeKind::Mesh) + 1;

// Heights from a greyscale image over [-size_x / 2, size_x / 2] x [-size_z / 2, size_z / 2]: pixel (0, 0) at
// (-x, -z), black at 0, white at `height`; bilinear between pixel centres, held beyond the edges.
struct Heightfield {
  int width = 0, depth = 0;
  float sizeX = 1, sizeZ = 1;
  std::vector<float> heights;  // row-major, x fastest

  // The height at (x, z) and its slopes dh/dx, dh/dz.
  float heightAt(float x, float z, float& slopeX, float& slopeZ) const;
  float minHeight() const;
  float maxHeight() const;
};

class ColliderShape {
 public:
  ShapeKind kind = ShapeKind::Box;
  bool container = false;  // the solid is the outside of the shape
  Eigen::Vector3f halfExtents = Eigen::Vector3f::Zero();  // box
  float radius = 0, halfHeight = 0;                      // sphere, capsule, cylinder
  Eigen::Vector3f planeNormal = Eigen::Vector3f::UnitY();  // unit
  Heightfield heightfield;
  DistanceGrid grid;  // mesh
  Eigen::AlignedBox3f bounds;  // of the shape (not of a container's outside), in its frame
  TriangleMesh mesh;           // in its frame, outward normals per vertex
  std::string note;            // a line for the user (an open mesh given a thickness), or empty

  // Signed distance from q (in the shape's frame, unscaled) to the solid's surface, negative inside the solid;
  // `normal` gets the unit direction in which the distance grows (out of the solid, into the fluid).
  float distance(const Eigen::Vector3f& q, Eigen::Vector3f& normal) const;
  float distance(const Eigen::Vector3f& q) const {
    Eigen::Vector3f unused;
    return distance(q, unused);
  }
  // False where distance() is an estimate that a point's distance less how far it moves need not bound (the
  // heightfield's first-order one, which a curved slope breaks): a solver that would skip a sweep on that bound
  // must sweep (sim/colliders.h, Colliders::nothingStops).
  bool distanceBoundsMoves() const { return kind != ShapeKind::Heightfield; }
  // Bytes held (the mesh's distance grid, the heightfield and the drawing mesh).
  size_t memoryBytes() const;
};

// The world box holding a shape's bounds placed by `pose` (its eight corners placed).
Eigen::AlignedBox3d worldBounds(const ColliderShape& shape, const Pose& pose);

// Builds collider `index` of the scene, reading its file if it has one. Throws InputError naming the scene file
// and the key: a missing or unreadable file, a mesh without triangles, a distance grid too large, a collider
// entirely outside the domain.
ColliderShape buildColliderShape(const Scene& scene, size_t index);
// Body `index` likewise; a body's mesh must be closed, and the body must start inside the domain.
ColliderShape buildBodyShape(const Scene& scene, size_t index);
// Either, from its settings; `key` ("colliders[2]") names it in errors, `key`.shape a shape that the part
// does not take (a plane body, a mesh body in 2D, a name not in geometry/shapes.h).
ColliderShape buildSolidShape(const Scene& scene, const ColliderSettings& settings, const std::string& key,
                              bool body);

// A mesh's signed distance on a grid of `voxel` covering its box plus `band` on every side (geometry/mesh_sdf.cpp,
// OpenVDB's mesh to volume). A closed mesh gets its true inside; an open one (shellThickness > 0) becomes a shell
// of that thickness about its triangles.
DistanceGrid bakeMeshDistance(const TriangleMesh& mesh, float voxel, float band, float shellThickness);

// Triangle meshes of the analytic shapes in their frames (outward normals), for drawing and export.
TriangleMesh boxMesh(const Eigen::Vector3f& halfExtents);
TriangleMesh sphereMesh(float radius, int segments = 32);
TriangleMesh capsuleMesh(float radius, float halfHeight, int segments = 32);
TriangleMesh cylinderMesh(float radius, float halfHeight, int segments = 48);

}  // namespace surge

// Where the water meets a collider. `surge sim` leaves each collider's world mesh in DIR/colliders/<name>.ply
// (a moving one's also in DIR/colliders/<name>/frame_NNNNN.ply); the surfacer turns each into a level set at
// its own voxel size (tools::meshToVolume) and uses it twice:
//  1. Before smoothing, the raw water level set is extended into the collider's solid where the water touches
//     it: every voxel of the solid within `depth` of its surface takes the water's value at the point a short
//     way out of the solid along the collider's normal (in the plane of the centres of a layer of particles
//     resting on it), and the water between the wall and that plane is made at least as deep as there. The
//     water then goes on through the wall as a straight continuation of itself, and the smoothing and the
//     erosion cannot round it off, and pull it away, where it meets the wall.
//  2. After the erosion, the water's level set is clipped by the collider: phi = max(phi_water, -phi_solid)
//     (phi_solid negative in the solid: a container's outside, the side a plane's normal points away from),
//     so the water's surface lies on the collider's surface wherever they meet and never inside the solid;
//     the mesh's vertices that the mesher still puts inside (at the solid's convex edges) are moved onto it.
// A scene without colliders never reaches this file. Included only by surfacer.cpp (it pulls in OpenVDB).
#pragma once

#include <openvdb/openvdb.h>

#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/files.h"
#include "core/ply.h"
#include "core/scene.h"

namespace surge {

// A collider's triangles in the world, for the exact surface near a point: each triangle's unit normal turned
// to the fluid (by the mesh's vertex normals, which point into the fluid), and for every voxel of the level
// set's band the index of its nearest triangle (tools::meshToVolume's polygon index grid).
struct ColliderTriangles {
  std::vector<Eigen::Vector3d> positions;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<Eigen::Vector3d> facing;
  openvdb::Int32Grid::Ptr nearest;
};

// One collider at one frame, on the surfacer's voxels.
struct SurfaceCollider {
  std::string name;
  // The shape's level set (negative inside the shape; for a container the fluid is inside), its solid side's
  // band wide enough for the extension, cut to ColliderGrids::region; null for a plane.
  openvdb::FloatGrid::ConstPtr grid;
  // The same, its band trimmed to the surface's half-width, named "collider_<name>", with a bool metadata
  // "container": the grid the VDB holds.
  openvdb::FloatGrid::ConstPtr output;
  std::shared_ptr<const ColliderTriangles> triangles;  // with the grid
  double shell =
      0;  // an open mesh: the solid is within shell / 2 of its triangles (grid = distance - shell / 2)
  bool container = false;
  // 2D: the collider is its cross-section at z = 0 drawn out along z (the simulator's collider), whatever the
  // mesh does away from z = 0 (a sphere, a box only so deep), through the slab the surfacer makes of the
  // water.
  bool flat = false;
  openvdb::CoordBBox bounds;  // of the grid's leaves, in voxels (along z without end when flat)
  // A plane: the solid is {x : normal . x < offset}; `normal` (unit) points into the fluid.
  bool plane = false;
  openvdb::Vec3d normal{0, 1, 0};
  double offset = 0;
};

// How the colliders' level sets are made.
struct ColliderGrids {
  double voxel = 0;
  // The narrow band, in voxels: `fluid` on the fluid's side of the collider's surface (the clip needs the
  // water's band there), `solid` on the solid's side (the extension's depth and its band, and a voxel for the
  // gradient); `output` each side in the VDB.
  float fluid = 4, solid = 10, output = 3;
  // Where the water may be, with room for the extension (world units): the grids are cut to it, so a collider
  // much larger than the tank (a heightfield's skirt, a 2D scene's deep prism) costs only its part inside.
  // Empty: no cut. A flat collider's mesh has its vertices' z clamped into it first (its z = 0 section kept).
  Eigen::AlignedBox3d region;
  bool flat = false;  // a 2D scene
};

// The colliders and bodies of an output folder (core/scene.h's solidFiles). The standing ones are read and
// converted once, by the constructor; a moving one (keyframed, or a body) at every frame (its frame file, or
// <name>.ply when that frame's file is missing).
class SurfaceColliders {
 public:
  // Reads and converts the standing solids among `solids` (nothing when it is empty). `spacing` is the shell
  // thickness of an open mesh whose `thickness` is 0. Throws InputError naming the file if a solid's mesh is
  // missing or unreadable, or names a vertex it does not have.
  SurfaceColliders(const fs::path& dir, const std::vector<SolidFiles>& solids, double spacing,
                   const ColliderGrids& grids);

  bool empty() const { return solids_.empty(); }
  // Every solid as it stands at `frame`, in the scene's order.
  std::vector<SurfaceCollider> atFrame(int frame) const;

 private:
  fs::path dir_;
  std::vector<SolidFiles> solids_;
  std::vector<double> thickness_;          // an open mesh's shell thickness
  std::vector<SurfaceCollider> standing_;  // one per collider; a moving one's is rebuilt at every frame
  ColliderGrids grids_;
};

// The per-frame files of the scene's moving colliders that exist in dir/colliders/ for `frame`: inputs of
// that frame's surface (for --resume). A standing collider's <name>.ply is rewritten by every `surge sim
// --resume` and follows from scene.json, an input already (as in render's ColliderMeshes::frameFiles).
std::vector<fs::path> colliderFrameFiles(const fs::path& dir, const Scene& scene, int frame);

// Builds a collider from its world mesh (an open mesh of shape "mesh" is a shell `thickness` thick about its
// triangles, as the simulator treats it).
SurfaceCollider makeSurfaceCollider(const ColliderSettings& settings, const TriangleMesh& mesh,
                                    const ColliderGrids& grids, double thickness);

struct ExtensionParameters {
  double band = 0;   // the raw level set's clamp, world units
  double depth = 0;  // how deep into the solid the water goes on; below that it ends (rounded by a band)
  // How far out of the solid, along its normal, the water's value is read: the lower of the values at both
  // distances (the same for `spheres`; for a field whose raw surface lies under the fluid's face, `far` is
  // below that surface on a resting block, `near` is the centres of a one-particle film).
  double near = 0, far = 0;
};

// Step 1 on the raw level set `raw` (every voxel of a leaf active, the tiles signed by a flood fill): in the
// solid to `depth` the water's value is replaced by the one read out of it, and between the solid and `far`
// it becomes the lower of its own and the one read further out (so the water next to the wall is not lower
// there than a little way from it). The leaves it needs are added; colliders away from the water are skipped.
void extendIntoColliders(openvdb::FloatGrid& raw, const std::vector<SurfaceCollider>& colliders,
                         const ExtensionParameters& e);

// Step 2 on a finished narrow band of half-width `band` (world units): values are clamped to +-band, only
// voxels inside (-band, band) stay active, leaves with none of them become tiles.
void clipByColliders(openvdb::FloatGrid& water, const std::vector<SurfaceCollider>& colliders, double band);

// Moves every vertex of `mesh` that lies less than a voxel inside a collider's solid onto its surface: to the
// nearest point of the nearest of the collider's triangles that the 8 voxels around the vertex name (a plane:
// along its normal). The clipped level set keeps the water out of the solid's level set, but that is
// trilinear between exact distances, and by a convex edge of the solid its zero lies inside the solid (by up
// to a quarter of a voxel at a right angle), and the mesher puts a vertex on the chord between the faces.
void snapOutOfColliders(TriangleMesh& mesh, const std::vector<SurfaceCollider>& colliders, double voxel);

}  // namespace surge

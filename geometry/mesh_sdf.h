// A mesh's level set by OpenVDB's mesh to volume, the one conversion that both the simulator's baked distance
// (bakeMeshDistance, geometry/collider_shape.h) and the surfacer's colliders (surface/collider_clip.cpp) use.
// Include it only where OpenVDB is linked (geometry/mesh_sdf.cpp, surface/).
#pragma once

#include <openvdb/openvdb.h>

#include "core/mesh.h"

namespace surge {

// The signed distance to the mesh's triangles on `transform`'s voxels, `exterior` voxels of band outside and
// `interior` inside (the unsigned distance when `unsignedDistance`); `nearest`, if given, gets every band
// voxel's nearest triangle.
openvdb::FloatGrid::Ptr meshLevelSet(const TriangleMesh& mesh, const openvdb::math::Transform& transform,
                                     float exterior, float interior, bool unsignedDistance,
                                     openvdb::Int32Grid* nearest = nullptr);

}  // namespace surge

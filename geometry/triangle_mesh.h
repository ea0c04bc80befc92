// What geometry/ computes on a triangle mesh (core/mesh.h): whether it is closed, its vertex normals. Its
// level set by OpenVDB is in geometry/mesh_sdf.h.
#pragma once

#include "core/mesh.h"

namespace surge {

// True if every edge of the mesh is shared by exactly two triangles (a closed, manifold surface). The
// simulator and the surfacer both ask this, so they take an open mesh for a shell alike.
bool isClosedManifold(const TriangleMesh& mesh);

// Per-vertex normals as area-weighted sums of the faces' normals.
void computeVertexNormals(TriangleMesh& mesh);

}  // namespace surge

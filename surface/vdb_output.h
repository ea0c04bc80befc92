// The VDB file of a surface frame, by Houdini's and Blender's conventions: the level set `surface` (grid class
// level set; the first fluid's in a scene of several, the others' `surface_<name>` after it), and on request a velocity grid `v` (a vector grid, vector type
// contravariant-relative, as Houdini writes velocity fields) and the particles as a PointDataGrid `points` with a
// float vector attribute `v`; the whitewater as a PointDataGrid `whitewater` with `v`, `id`, `type` (0 spray,
// 1 foam, 2 bubble) and `lifetime` when the folder has it; after them the colliders' level sets `collider_<name>` (collider_clip.h).
// Included only by surfacer.cpp (it pulls in OpenVDB's core headers).
#pragma once

#include <openvdb/openvdb.h>

#include <Eigen/Core>
#include <vector>

#include "core/files.h"
#include "core/ply.h"
#include "surface/particle_field.h"

namespace surge {

struct VdbExtras {
  const BlockField* velocity = nullptr;  // blocks of 3 floats per voxel, on the surface's leaves
  const std::vector<Eigen::Vector3f>* pointPositions = nullptr;
  const std::vector<Eigen::Vector3f>* pointVelocities = nullptr;
  double pointVoxel = 0;  // the points grid's voxel size
  // The frame's whitewater as a PointDataGrid "whitewater" with v, id, type and lifetime (whitewater/ frames).
  const DiffuseFrame* whitewater = nullptr;
  // The other fluids' level sets of a scene of several, `surface_<name>`, written right after `surface`.
  std::vector<openvdb::FloatGrid::ConstPtr> fluids;
  std::vector<openvdb::FloatGrid::ConstPtr> colliders;  // written as they are (named), after the others
};

// Writes the grids to `path` atomically (a temporary name in the same folder, then rename). Throws RunError.
void writeSurfaceVdb(const fs::path& path, const openvdb::FloatGrid::Ptr& surface, const VdbExtras& extras);

}  // namespace surge

// The surface stage: particle frames -> narrow-band level sets (OpenVDB) -> triangle meshes.
//
// Method (all OpenVDB 10, kept inside surfacer.cpp so that no other file pays for its headers):
//  1. Rasterise one sphere per particle, radius scene.surface.particle_radius, into a narrow-band level set of
//     voxel size scene.surface.voxel_size and half-width 3 voxels (tools::ParticlesToLevelSet, the union of
//     the spheres' signed distances). No particle may be dropped: spheres under 1.5 voxels make this throw.
//  2. Re-distance the union from its zero crossing (tools::sdfToSdf), smooth it by mean-curvature flow and
//     erode it back to the fluid's volume (tools::LevelSetFilter; spheres of radius ~ spacing make a block
//     fatter than its N * spacing^3 of fluid).
//  3. Mesh the zero crossing (tools::volumeToMesh), split quads into triangles, orient them outward and give
//     each vertex the normalised level-set gradient as its normal.
// 2D frames (z = 0) are extruded into a closed slab a few particles thick (see surfacer.cpp).
#pragma once

#include <cstddef>

#include "core/files.h"
#include "core/ply.h"
#include "core/progress.h"
#include "core/scene.h"

namespace surge {

struct SurfaceStats {
  size_t particles = 0, activeVoxels = 0, vertices = 0, triangles = 0;
  double voxelSize = 0;
};

// Level set of one particle frame -> mesh. Writes vdbPath (a level-set grid named "surface") and meshPath
// (binary PLY with vertex normals), each atomically (temporary name in the same folder, then rename).
// Throws RunError if OpenVDB would drop a particle (sphere under 1.5 voxels), Interrupted on Ctrl-C.
SurfaceStats surfaceFrame(const ParticleFrame& frame, const Scene& scene, const fs::path& vdbPath,
                          const fs::path& meshPath);

// The stage: for every dir/particles/frame_NNNNN.ply within range, writes dir/surface/frame_NNNNN.vdb and
// dir/surface/frame_NNNNN.ply. Reports progress per frame ("surface") and checks for Ctrl-C between frames.
// Throws InputError naming dir if there is no particle frame (in range).
void surfaceFrames(const fs::path& dir, const Scene& scene, const FrameRange& range, Progress& progress);

// For tests: the mesh of a frame, with no file written.
TriangleMesh meshParticles(const ParticleFrame& frame, const Scene& scene);

// For tests: the signed distance (world units, negative inside) at a world point of the level set that
// surfaceFrame builds for this frame; the background value (+3 voxels) far from the surface.
double signedDistanceAt(const ParticleFrame& frame, const Scene& scene, const Eigen::Vector3d& point);

}  // namespace surge

// The surface stage: particle frames -> narrow-band level sets (OpenVDB) -> triangle meshes.
//
// Method (OpenVDB 10 in surfacer.cpp, collider_clip.cpp and vdb_output.cpp only, so that no other file pays
// for its headers):
//  1. A raw narrow-band level set of voxel size scene.surface.voxel_size and half-width 3 voxels, by
//     scene.surface.method (particle_field.h, our own gather rasteriser, which never drops a particle):
//     `spheres` (union of spheres of radius surface.particle_radius), `smooth_spheres` (Zhu & Bridson 2005),
//     `anisotropic` (Yu & Turk 2013, anisotropy.h; iso-value half the rest field, dilated back to the fluid's
//     faces by an inset measured on a block). Spheres under 1.5 voxels
//     throw: the smoothing would erase them.
//  2. Make it a distance, smooth it by surface.smoothing_steps of mean-curvature flow, and erode (or, for
//     `anisotropic`, dilate) it back to the fluid's volume (spheres of radius ~ spacing make a block fatter
//     than its N * spacing^3 of fluid), re-distancing after each step. `spheres` does this on narrow_band.h's
//     blocks; the blended fields with OpenVDB's LevelSetTracker and LevelSetFilter.
//  3. Mesh the zero crossing (tools::volumeToMesh), split quads into triangles, orient them outward and give
//     each vertex the normalised level-set gradient as its normal.
// 2D frames (z = 0) are extruded into a closed slab a few particles thick (see surfacer.cpp).
// Where the scene has colliders (surfaceFrames, from dir/colliders/), the raw level set goes on into each
// collider's solid before step 2 and is clipped by it after, and the mesh's vertices are kept out of it
// (collider_clip.h): the water's surface lies on the collider's where they meet.
#pragma once

#include <cstddef>
#include <vector>

#include "core/files.h"
#include "core/ply.h"
#include "core/progress.h"
#include "core/scene.h"

namespace surge {

struct SurfaceStats {
  size_t particles = 0, activeVoxels = 0, vertices = 0, triangles = 0;
  double voxelSize = 0;
};

// Level set of one particle frame -> mesh. Writes vdbPath (a level-set grid named "surface"; with
// surface.write_velocity a vector grid "v", with surface.write_points a PointDataGrid "points" with attribute
// "v") and meshPath (binary PLY with vertex normals; with surface.write_obj also an .obj beside it), each
// atomically (temporary name in the same folder, then rename). Throws RunError if OpenVDB would drop a
// particle (sphere under 1.5 voxels), Interrupted on Ctrl-C. The scene's colliders are not used here.
SurfaceStats surfaceFrame(const ParticleFrame& frame, const Scene& scene, const fs::path& vdbPath,
                          const fs::path& meshPath);

// The stage: for every dir/particles/frame_NNNNN.ply within range, writes dir/surface/frame_NNNNN.vdb and
// dir/surface/frame_NNNNN.ply, frames in parallel (parallelFor, one frame a chunk: the same bytes at any
// thread count). With colliders in the scene, the water meets them (see above) and the VDB also holds their
// level sets "collider_<name>" (all but planes; collider_clip.h); their meshes are read from
// dir/colliders/<name>.ply, a moving one's from dir/colliders/<name>/frame_NNNNN.ply when present. Reports
// progress per frame ("surface") and checks for Ctrl-C between frames. Throws InputError naming dir if there
// is no particle frame (in range), naming the file if a collider's mesh is missing or bad. With `resume`, a
// frame whose files are up to date (isUpToDate against its particle frame, the surface settings
// dir/surface_settings.json (writeStageSettings) and the frame files of its moving colliders) is left as it is.
void surfaceFrames(const fs::path& dir, const Scene& scene, const FrameRange& range, Progress& progress,
                   bool resume = false);

// The names surface.method may take, in the surfacer's table (core/scene_fields.cpp's choices must be these; a
// test checks). Another name is an InputError naming `surface.method`.
std::vector<std::string> surfaceMethods();

// For tests: the mesh of a frame, with no file written.
TriangleMesh meshParticles(const ParticleFrame& frame, const Scene& scene);

// For tests: the signed distances (world units, negative inside, trilinear) at world points of the level set
// that surfaceFrame builds for this frame; the background value (+3 voxels) far from the surface.
std::vector<double> signedDistancesAt(const ParticleFrame& frame, const Scene& scene,
                                      const std::vector<Eigen::Vector3d>& points);

}  // namespace surge

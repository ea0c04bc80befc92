// The surfacer: particles -> level set -> mesh, with OpenVDB 10. This is the one file of Surge that includes
// OpenVDB's tools (40-55 s to compile); everything else sees only surfacer.h.
//
// Method: the union of particle spheres (tools::ParticlesToLevelSet, Museth's narrow-band rasteriser),
// re-distanced by fast sweeping (tools::sdfToSdf), smoothed by mean-curvature flow and eroded back to the
// fluid's volume (tools::LevelSetFilter, which renormalises the band with LevelSetTracker after every step),
// meshed by tools::volumeToMesh at isovalue 0.
#include "surface/surfacer.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <unistd.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/parallel.h"

namespace surge {
namespace {

using openvdb::FloatGrid;

// Narrow-band half-width in voxels, on each side of the surface.
constexpr double kHalfWidthVoxels = 3.0;
// 2D frames become a slab of 2 * kSlabHalfLayers + 1 copies of the particle plane, spaced particle_spacing
// along z (z = -3h .. +3h): a closed solid about 7 spacings thick once eroded, thick enough that the two
// faces of the slab never merge under smoothing, and thin enough to cost only 7x the spheres of the frame.
constexpr int kSlabHalfLayers = 3;
// Mean-curvature flow steps, before the erosion: enough to take out the bumps of the sphere union (on a flat
// face they go from 0.04 to 0.004 spacings rms in two steps; each step moves the surface by a third of a voxel
// times its curvature in voxels), few enough to keep edges and small droplets.
constexpr int kSmoothingSteps = 2;
// How far below the sphere tops (in spacings) the smoothed union of spheres of radius = spacing lies on a flat
// face of a square lattice, measured: with it, the faces of a 20x10x10 block's mesh land within 0.002
// spacings of the fluid's faces (the mean bump height alone, computed, would give 0.089; the smoothing takes
// the rest). For radii other than the spacing it is an approximation.
constexpr double kDentFill = 0.15;

void initOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

struct Parameters {
  double spacing = 0, radius = 0, voxel = 0;
  int layers = 1;  // copies of each particle along z (1 in 3D)
};

Parameters resolve(const ParticleFrame& frame, const Scene& scene) {
  Parameters p;
  p.spacing = scene.particle_spacing;
  if (!(p.spacing > 0)) throw RunError("surface: particle_spacing must be positive");
  p.radius = scene.surface.particle_radius > 0 ? scene.surface.particle_radius : p.spacing;
  p.voxel = scene.surface.voxel_size > 0 ? scene.surface.voxel_size : p.radius / 2;
  p.layers = frame.dimensions == 2 ? 2 * kSlabHalfLayers + 1 : 1;
  return p;
}

// The particle list that ParticlesToLevelSet reads (a duck-typed interface): positions straight out of the
// ParticleFrame, no copy. In 2D, index i is layer i % layers of particle i / layers, shifted along z.
class ParticleAdapter {
 public:
  using PosType = openvdb::Vec3R;  // what PointPartitioner expects

  ParticleAdapter(const ParticleFrame& frame, const Parameters& p) : frame_(frame), p_(p) {}

  size_t size() const { return frame_.size() * size_t(p_.layers); }

  void getPos(size_t i, openvdb::Vec3R& xyz) const {
    const size_t layers = size_t(p_.layers);
    const Eigen::Vector3f& x = frame_.position[i / layers];
    const double z = layers == 1 ? double(x.z()) : (double(i % layers) - kSlabHalfLayers) * p_.spacing;
    xyz = openvdb::Vec3R(x.x(), x.y(), z);
  }

  void getPosRad(size_t i, openvdb::Vec3R& xyz, openvdb::Real& radius) const {
    getPos(i, xyz);
    radius = p_.radius;
  }

 private:
  const ParticleFrame& frame_;
  const Parameters& p_;
};

// OpenVDB's interrupter interface over Surge's Ctrl-C flag: a long frame stops inside OpenVDB's loops, and the
// caller turns the flag into surge::Interrupted with Progress::checkInterrupt().
struct CtrlCInterrupter {
  void start(const char* = nullptr) {}
  void end() {}
  bool wasInterrupted(int = -1) { return Progress::wasInterrupted(); }
};

FloatGrid::Ptr emptyLevelSet(double voxel) {
  FloatGrid::Ptr grid = openvdb::createLevelSet<FloatGrid>(voxel, kHalfWidthVoxels);
  grid->setName("surface");
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  return grid;
}

// The level set of a frame: sphere union, re-distancing, smoothing, erosion.
FloatGrid::Ptr buildLevelSet(const ParticleFrame& frame, const Scene& scene) {
  initOpenVdb();
  const Parameters p = resolve(frame, scene);
  FloatGrid::Ptr grid = emptyLevelSet(p.voxel);
  if (frame.size() == 0) return grid;

  CtrlCInterrupter interrupter;
  const ParticleAdapter particles(frame, p);
  {
    openvdb::tools::ParticlesToLevelSet<FloatGrid, void, CtrlCInterrupter> raster(*grid, &interrupter);
    // Spheres under getRmin() (1.5) voxels are skipped without a word; the scene loader forbids that
    // voxel size, but a hand-made Scene may not have gone through it.
    if (p.radius / p.voxel < raster.getRmin())
      throw RunError("surface: particle_radius " + std::to_string(p.radius) + " is under 1.5 voxels of " +
                     std::to_string(p.voxel) + "; OpenVDB would drop every particle");
    // The fixed-radius path counts skipped particles exactly (all or none); the per-particle-radius path
    // (getPosRad) is there for later, with radii per particle.
    raster.rasterizeSpheres(particles, p.radius);
    raster.finalize(/*prune=*/true);
    if (raster.getMinCount() != 0 || raster.getMaxCount() != 0)
      throw RunError("surface: OpenVDB dropped " + std::to_string(raster.getMinCount() + raster.getMaxCount()) +
                     " particle spheres as too small or too large for voxel size " + std::to_string(p.voxel));
  }
  Progress::checkInterrupt();

  // The union of sphere distances is exact outside the spheres but not inside them (deep inside, a voxel holds
  // the distance to the surface of its nearest sphere, not of the union), so the band is first re-distanced
  // from its zero crossing (tools::sdfToSdf, fast sweeping) and trimmed back to the narrow band.
  // sdfToSdf leaves an asymmetric background (the extreme distances found); it is set back to +-3 voxels.
  grid = openvdb::tools::sdfToSdf(*grid);
  grid->setName("surface");
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  openvdb::tools::changeLevelSetBackground(grid->tree(), float(kHalfWidthVoxels * p.voxel));
  Progress::checkInterrupt();
  openvdb::tools::LevelSetFilter<FloatGrid, FloatGrid, CtrlCInterrupter> filter(*grid, &interrupter);
  filter.prune();  // voxels now beyond the band become inactive background

  // Smooth first, erode second: mean-curvature flow fills the dents between the spheres and rounds the sphere
  // caps, the erosion then takes the surface back to the fluid. (Eroding first would leave a lone particle
  // a sphere of one voxel, which smoothing then erases.)
  for (int i = 0; i < kSmoothingSteps; ++i) filter.meanCurvature();
  // Each particle stands for a cube of fluid of side h = spacing, so a flat face of the fluid lies h/2 beyond
  // the centres of its outer layer, while the sphere union reaches `radius` beyond them at the centres and
  // h/sqrt(2) (for radius = h) between them. Eroding by radius - h/2 would put the sphere tops on the
  // fluid's face; the smoothed surface lies kDentFill * h under the tops, so that much less is eroded and the
  // faces land on the fluid's (a 20x10x10 block then encloses N h^3 less 1.7%, lost at its rounded edges).
  // Positive offsets shrink the level set (phi + offset, phi < 0 inside).
  const double erosion = p.radius - 0.5 * p.spacing - kDentFill * p.spacing;
  if (erosion != 0) filter.offset(float(erosion));
  Progress::checkInterrupt();
  return grid;
}

// volumeToMesh's polygons wind clockwise seen from outside (their right-hand normal points into the
// level set, towards negative values); Surge's meshes wind counter-clockwise, so every polygon is reversed.
void addTriangle(TriangleMesh& mesh, uint32_t a, uint32_t b, uint32_t c) {
  mesh.triangles.push_back({a, c, b});
}

TriangleMesh meshLevelSet(const FloatGrid& grid, double adaptivity) {
  TriangleMesh mesh;
  if (grid.activeVoxelCount() == 0) return mesh;
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(grid, points, triangles, quads, /*isovalue=*/0.0, adaptivity);

  mesh.positions.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) mesh.positions[i] = Eigen::Vector3f(points[i].x(), points[i].y(), points[i].z());
  mesh.triangles.reserve(triangles.size() + 2 * quads.size());
  for (const auto& t : triangles) addTriangle(mesh, t[0], t[1], t[2]);
  // Quads are split along their shorter diagonal, which gives the better-shaped pair of triangles.
  for (const auto& q : quads) {
    const auto& x = mesh.positions;
    if ((x[q[0]] - x[q[2]]).squaredNorm() <= (x[q[1]] - x[q[3]]).squaredNorm()) {
      addTriangle(mesh, q[0], q[1], q[2]);
      addTriangle(mesh, q[0], q[2], q[3]);
    } else {
      addTriangle(mesh, q[0], q[1], q[3]);
      addTriangle(mesh, q[1], q[2], q[3]);
    }
  }

  // Vertex normals: the gradient of the level set, by central differences of trilinear samples half a voxel
  // either side, normalised. Where it vanishes (never on a proper level set), the area-weighted face normal.
  mesh.normals.assign(mesh.positions.size(), Eigen::Vector3f::Zero());
  const openvdb::math::Transform& transform = grid.transform();
  parallelFor(0, mesh.positions.size(), [&](size_t begin, size_t end) {
    const auto accessor = grid.getConstAccessor();
    const auto sample = [&](const openvdb::Vec3d& ijk) {
      return double(openvdb::tools::BoxSampler::sample(accessor, ijk));
    };
    for (size_t i = begin; i < end; ++i) {
      const Eigen::Vector3f& x = mesh.positions[i];
      const openvdb::Vec3d c = transform.worldToIndex(openvdb::Vec3d(x.x(), x.y(), x.z()));
      Eigen::Vector3d g;
      for (int k = 0; k < 3; ++k) {
        openvdb::Vec3d plus = c, minus = c;
        plus[k] += 0.5;
        minus[k] -= 0.5;
        g[k] = sample(plus) - sample(minus);
      }
      if (g.norm() > 1e-12) mesh.normals[i] = g.normalized().cast<float>();
    }
  });
  std::vector<Eigen::Vector3f> faceSum;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f n = (mesh.positions[t[1]] - mesh.positions[t[0]])
                                  .cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    for (uint32_t v : t) {
      if (mesh.normals[v].squaredNorm() > 0) continue;
      if (faceSum.empty()) faceSum.assign(mesh.positions.size(), Eigen::Vector3f::Zero());
      faceSum[v] += n;
    }
  }
  for (size_t i = 0; i < faceSum.size(); ++i)
    if (mesh.normals[i].squaredNorm() == 0 && faceSum[i].squaredNorm() > 0) mesh.normals[i] = faceSum[i].normalized();
  return mesh;
}

// openvdb::io::File writes to a path, not a stream, so the atomic write is done here: a temporary name in
// the same folder (same file system, so the rename is atomic), then rename.
void writeVdbAtomically(const FloatGrid::Ptr& grid, const fs::path& path) {
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  fs::path temporary = path;
  temporary += ".tmp" + std::to_string(::getpid());
  try {
    openvdb::io::File file(temporary.string());
    file.write(openvdb::GridPtrVec{grid});
    file.close();
    fs::rename(temporary, path);
  } catch (const openvdb::Exception& e) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw RunError("cannot write " + path.string() + ": " + e.what());
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
}

}  // namespace

SurfaceStats surfaceFrame(const ParticleFrame& frame, const Scene& scene, const fs::path& vdbPath,
                          const fs::path& meshPath) {
  const FloatGrid::Ptr grid = buildLevelSet(frame, scene);
  const TriangleMesh mesh = meshLevelSet(*grid, scene.surface.adaptivity);
  writeVdbAtomically(grid, vdbPath);
  writeMeshPly(meshPath, mesh);
  SurfaceStats stats;
  stats.particles = frame.size();
  stats.activeVoxels = size_t(grid->activeVoxelCount());
  stats.vertices = mesh.positions.size();
  stats.triangles = mesh.triangles.size();
  stats.voxelSize = grid->voxelSize()[0];
  return stats;
}

void surfaceFrames(const fs::path& dir, const Scene& scene, const FrameRange& range, Progress& progress) {
  const std::vector<int> all = listFrames(dir, "particles", "ply");
  if (all.empty()) throw InputError(dir.string(), "no particle frames (particles/frame_NNNNN.ply) to surface");
  std::vector<int> frames;
  std::copy_if(all.begin(), all.end(), std::back_inserter(frames), [&](int f) { return range.contains(f); });
  if (frames.empty())
    throw InputError(dir.string(), "--frames", "no particle frame in " + std::to_string(range.first) + ":" +
                                                  std::to_string(range.last));
  progress.start("surface", frames.size());
  for (int f : frames) {
    Progress::checkInterrupt();
    const ParticleFrame frame = readParticlePly(framePath(dir, "particles", f, "ply"));
    surfaceFrame(frame, scene, framePath(dir, "surface", f, "vdb"), framePath(dir, "surface", f, "ply"));
    progress.advance();
  }
  progress.finish();
}

TriangleMesh meshParticles(const ParticleFrame& frame, const Scene& scene) {
  const FloatGrid::Ptr grid = buildLevelSet(frame, scene);
  return meshLevelSet(*grid, scene.surface.adaptivity);
}

double signedDistanceAt(const ParticleFrame& frame, const Scene& scene, const Eigen::Vector3d& point) {
  const FloatGrid::Ptr grid = buildLevelSet(frame, scene);
  const openvdb::Vec3d ijk = grid->transform().worldToIndex(openvdb::Vec3d(point.x(), point.y(), point.z()));
  return double(openvdb::tools::BoxSampler::sample(grid->getConstAccessor(), ijk));
}

}  // namespace surge

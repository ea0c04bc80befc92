// The surfacer: particles -> level set -> mesh, with OpenVDB 10. This is the one file of Surge that includes
// OpenVDB's tools (40-55 s to compile); everything else sees only surfacer.h.
//
// Method: a raw level set from particle_field.h (union of spheres, Zhu & Bridson blend or Yu & Turk
// anisotropic kernels, by surface.method), re-distanced (LevelSetTracker), smoothed by mean-curvature flow and
// eroded back to the fluid's volume (tools::LevelSetFilter; the erosion added to the distances in one pass),
// meshed by tools::volumeToMesh at isovalue 0.
#include "surface/surfacer.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <unistd.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/parallel.h"
#include "surface/anisotropy.h"
#include "surface/particle_field.h"
#include "surface/vdb_output.h"

namespace surge {
namespace {

using openvdb::FloatGrid;

// Narrow-band half-width in voxels, on each side of the surface.
constexpr double kHalfWidthVoxels = 3.0;
// 2D frames become a slab of 2 * kSlabHalfLayers + 1 copies of the particle plane, spaced particle_spacing
// along z (z = -3h .. +3h): a closed solid about 7 spacings thick once eroded, thick enough that the two
// faces of the slab never merge under smoothing, and thin enough to cost only 7x the spheres of the frame.
constexpr int kSlabHalfLayers = 3;
// How far below the sphere tops (in spacings) the smoothed union of spheres of radius = spacing lies on a flat
// face of a square lattice, measured: with it, the faces of a 20x10x10 block's mesh land within 0.002
// spacings of the fluid's faces (measured with the re-distancing below; it was 0.15 with three Eikonal
// iterations after every smoothing step). For radii other than the spacing it is an approximation.
constexpr double kDentFill = 0.17;
// Eikonal iterations of the re-distancing: the band is 3 voxels each side and one iteration moves correct
// distances about a voxel, so 3 reach across it (LevelSetTracker's default is 1, meant for a band already
// nearly right after one step of motion).
constexpr int kRenormalise = 3;
// `spheres` gets a raw field whose inside is a distance already (chamferInside), so it needs only
// kSpheresFirstIterations before smoothing and kSpheresErodeIterations in the erosion's track (against 3 and 6
// for the other fields): 3.8 s instead of 6.6 s on the 1M-particle benchmark frame, with the band deeper
// inside as true as before (docs/performance.md).
constexpr int kChamferPasses = 4;
constexpr int kSpheresFirstIterations = 1;
constexpr int kSpheresErodeIterations = 2;

void initOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

// Smooth spheres (ZB05): weights' support R = 2 spacings (the simulator's kernel radius), sphere radius r as
// for `spheres`. The blend x-bar lies under the outer layer of a flat face, by kZbInset spacings (measured on
// the test block), so the erosion for this method is r - 0.5 h - kZbInset h.
constexpr double kZbSupport = 2.0;
constexpr double kZbInset = 0.0;
// Anisotropic (YT13): kernel support h = 2 spacings, PCA radius 3 spacings (YT13 take 2h; 3 spacings already
// gives 60 neighbours to a particle of a flat face, above N_epsilon = 25, for a third of the cost), iso-value
// half the rest field (f = 1 inside a fluid at rest, exactly: AnisotropicKernels::particleVolume; 0.5 is where
// an unsmoothed half-space of fluid ends), and kAnisoInset: where that surface lies under the fluid's face
// on the test block (20x10x10, every face), measured. The smoothed centres of the outer layer sit 0.62
// spacings inside it and their kernels are flattened to 0.8 spacings across, so f = 0.5 lies 0.72 spacings
// under the fluid's face after the smoothing steps (0.74 before); 0.753 puts the faces within 0.001 spacings of
// the fluid's (the rest of the 2.7% that the block loses is at its edges and corners, where the centres move
// inward along two or three axes). The level set is dilated by that much after smoothing.
constexpr double kAnisoSupport = 2.0;
constexpr double kAnisoPca = 3.0;
constexpr double kAnisoIso = 0.5;
constexpr double kAnisoInset = 0.753;

FloatGrid::Ptr emptyLevelSet(double voxel) {
  FloatGrid::Ptr grid = openvdb::createLevelSet<FloatGrid>(voxel, kHalfWidthVoxels);
  grid->setName("surface");
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  return grid;
}

struct Parameters {
  double spacing = 0, radius = 0, voxel = 0;
  int layers = 1;  // copies of each particle along z (1 in 3D)
  std::string method;
};

Parameters resolve(const ParticleFrame& frame, const Scene& scene) {
  Parameters p;
  p.spacing = scene.particle_spacing;
  if (!(p.spacing > 0)) throw RunError("surface: particle_spacing must be positive");
  p.radius = scene.surface.particle_radius > 0 ? scene.surface.particle_radius : p.spacing;
  p.voxel = scene.surface.voxel_size > 0 ? scene.surface.voxel_size : p.radius / 2;
  p.layers = frame.dimensions == 2 ? 2 * kSlabHalfLayers + 1 : 1;
  p.method = scene.surface.method;
  return p;
}

// Particles as the surfacer sees them: the frame's, or in 2D 2 * kSlabHalfLayers + 1 copies of them spaced
// particle_spacing along z (positions; velocities are copied with vz = 0).
std::vector<Eigen::Vector3f> slabPositions(const ParticleFrame& frame, const Parameters& p,
                                           const std::vector<Eigen::Vector3f>& values, bool isPosition) {
  if (p.layers == 1) return values;
  std::vector<Eigen::Vector3f> out(values.size() * size_t(p.layers));
  for (size_t i = 0; i < out.size(); ++i) {
    Eigen::Vector3f x = values[i / size_t(p.layers)];
    x.z() = isPosition ? float((double(i % size_t(p.layers)) - kSlabHalfLayers) * p.spacing) : 0.f;
    out[i] = x;
  }
  (void)frame;
  return out;
}

// A level set from blocks of distances (particle_field.h): one leaf per block, every voxel of it active, the
// tiles around them given their sign by a flood fill (blocks wholly inside were never made).
FloatGrid::Ptr gridFromBlocks(const BlockField& blocks, double voxel) {
  FloatGrid::Ptr grid = emptyLevelSet(voxel);
  auto& tree = grid->tree();
  for (size_t b = 0; b < blocks.origins.size(); ++b) {
    const Eigen::Vector3i& o = blocks.origins[b];
    auto* leaf = new FloatGrid::TreeType::LeafNodeType(openvdb::Coord(o.x(), o.y(), o.z()), 0.f, true);
    std::copy(blocks.values.begin() + ptrdiff_t(b * kBlockVoxels),
              blocks.values.begin() + ptrdiff_t((b + 1) * kBlockVoxels), leaf->buffer().data());
    tree.addLeaf(leaf);
  }
  openvdb::tools::signedFloodFill(tree);
  return grid;
}

// The raw sphere union's inside values are the depth under the nearest sphere's surface, not
// under the union's, so they never reach -radius and fall to -0.27 voxels between particles. Keep the voxels
// outside (exact distances) and the first inside layer (a 6-neighbour outside), and give every other inside
// voxel the chamfer depth max_y (phi(y) - |x - y|) over its 26 neighbours, `passes` Jacobi passes
// (each reaches a voxel or more deeper; 4 cover the 3-voxel band). Upper bounds on the depth along 26-neighbour
// paths, at most 8% too deep on oblique paths, which the Eikonal iterations then fix; measured on the test
// block, the band 1.5 spacings under the top face holds -1.47 spacings (-1.40 with the old 3 + 6 iterations).
// Jacobi (read the previous pass, write this one): the same values at any thread count.
void chamferInside(FloatGrid& grid, double voxel, int passes) {
  using LeafT = FloatGrid::TreeType::LeafNodeType;
  const float band = float(kHalfWidthVoxels * voxel);
  const FloatGrid::Ptr raw = grid.deepCopy();
  const auto deep = [&](const FloatGrid::ConstAccessor& a, const openvdb::Coord& c, float v) {
    if (v >= 0) return false;
    for (int k = 0; k < 3; ++k)
      for (int s = -1; s <= 1; s += 2) {
        openvdb::Coord n = c;
        n[k] += s;
        if (a.getValue(n) >= 0) return false;
      }
    return true;
  };
  float step[27];
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz)
        step[(dx + 1) * 9 + (dy + 1) * 3 + dz + 1] = float(voxel * std::sqrt(double(dx * dx + dy * dy + dz * dz)));
  openvdb::tree::LeafManager<FloatGrid::TreeType> leaves(grid.tree());
  leaves.foreach([&](LeafT& leaf, size_t) {
    const auto a = raw->getConstAccessor();
    for (auto it = leaf.beginValueOn(); it; ++it)
      if (deep(a, it.getCoord(), *it)) it.setValue(-band);
  });
  for (int pass = 0; pass < passes; ++pass) {
    const FloatGrid::Ptr prev = grid.deepCopy();
    leaves.foreach([&](LeafT& leaf, size_t) {
      const auto a = raw->getConstAccessor();
      const auto b = prev->getConstAccessor();
      for (auto it = leaf.beginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        if (!deep(a, c, a.getValue(c))) continue;
        float best = -band;
        for (int dx = -1; dx <= 1; ++dx)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dz = -1; dz <= 1; ++dz) {
              const float y = b.getValue(c.offsetBy(dx, dy, dz));
              if (y < 0) best = std::max(best, y - step[(dx + 1) * 9 + (dy + 1) * 3 + dz + 1]);
            }
        it.setValue(best);
      }
    });
  }
}

// OpenVDB's interrupter interface over Surge's Ctrl-C flag: a long frame stops inside OpenVDB's loops, and the
// caller turns the flag into surge::Interrupted with Progress::checkInterrupt().
struct CtrlCInterrupter {
  void start(const char* = nullptr) {}
  void end() {}
  bool wasInterrupted(int = -1) { return Progress::wasInterrupted(); }
};

// The raw level set of a frame's particles, by method: distances right near the zero crossing, roughly
// right (clamped to the band) elsewhere.
FloatGrid::Ptr rawLevelSet(const ParticleFrame& frame, const Parameters& p) {
  const std::vector<Eigen::Vector3f> x = slabPositions(frame, p, frame.position, true);
  const double band = kHalfWidthVoxels * p.voxel;
  FieldParticles particles;
  particles.position = &x;
  FieldParameters f;
  f.voxel = p.voxel;
  f.band = band;
  f.radius = p.radius;
  f.occupancyCell = 2 * p.spacing;
  AnisotropicKernels kernels;
  if (p.method == "spheres") {
    f.kind = FieldKind::Spheres;
  } else if (p.method == "smooth_spheres") {
    f.kind = FieldKind::SmoothSpheres;
    f.support = kZbSupport * p.spacing;
  } else if (p.method == "anisotropic") {
    AnisotropyParameters a;
    a.spacing = p.spacing;
    a.supportRadius = kAnisoSupport * p.spacing;
    a.pcaRadius = kAnisoPca * p.spacing;
    kernels = anisotropicKernels(x, a);
    particles.kernels = &kernels;
    f.kind = FieldKind::Anisotropic;
    f.iso = kAnisoIso;
    f.volume = kernels.particleVolume;
  } else {
    throw RunError("surface: unknown surface.method \"" + p.method + "\"");
  }
  Progress::checkInterrupt();
  return gridFromBlocks(rasterizeField(particles, f), p.voxel);
}

// How far to erode (positive) the smoothed level set of each method so that a flat face of a resting fluid
// lands on the fluid's face, h/2 beyond the centres of its outer layer.
double erosionOf(const Parameters& p) {
  // Each particle stands for a cube of fluid of side h = spacing, so a flat face of the fluid lies h/2 beyond
  // the centres of its outer layer, while the sphere union reaches `radius` beyond them at the centres and
  // h/sqrt(2) (for radius = h) between them. Eroding by radius - h/2 would put the sphere tops on the
  // fluid's face; the smoothed surface lies kDentFill * h under the tops, so that much less is eroded and the
  // faces land on the fluid's (a 20x10x10 block then encloses N h^3 less 1.1%, lost at its rounded edges;
  // 0.6% before chamferInside made the raw inside a distance).
  if (p.method == "spheres") return p.radius - 0.5 * p.spacing - kDentFill * p.spacing;
  if (p.method == "smooth_spheres") return p.radius - 0.5 * p.spacing - kZbInset * p.spacing;
  return -kAnisoInset * p.spacing;
}

// The level set of a frame: raw field, re-distancing, smoothing, erosion.
FloatGrid::Ptr buildLevelSet(const ParticleFrame& frame, const Scene& scene) {
  initOpenVdb();
  const Parameters p = resolve(frame, scene);
  FloatGrid::Ptr grid = emptyLevelSet(p.voxel);
  if (frame.size() == 0) return grid;
  // Spheres under 1.5 voxels are under-resolved: OpenVDB's own rasteriser skips them without a word, and the
  // smoothing below would erase what is left. The scene loader forbids such voxels; a hand-made Scene may not
  // have gone through it.
  if (p.radius / p.voxel < 1.5)
    throw RunError("surface: particle_radius " + std::to_string(p.radius) + " is under 1.5 voxels of " +
                   std::to_string(p.voxel) + "; the particles' spheres would be lost");
  CtrlCInterrupter interrupter;
  grid = rawLevelSet(frame, p);
  Progress::checkInterrupt();

  // The raw distances are right outside the spheres but not inside them (a voxel holds the distance to the
  // surface of its nearest sphere, not of the union), nor for the blended fields. LevelSetTracker's
  // normalisation (Eikonal iterations in the band, kRenormalise of them) puts the band right from the zero
  // crossing outward, and trims it back to the narrow band. For `spheres` the inside is made a distance first
  // (chamferInside), so one iteration does. (tools::sdfToSdf, fast sweeping, did the same
  // here first and took 90% of the time: 85 s for a million particles, against 1.5 s for this.)
  const bool spheres = p.method == "spheres";
  if (spheres) chamferInside(*grid, p.voxel, kChamferPasses);
  Progress::checkInterrupt();
  openvdb::tools::LevelSetFilter<FloatGrid, FloatGrid, CtrlCInterrupter> filter(*grid, &interrupter);
  filter.setNormCount(spheres ? kSpheresFirstIterations : kRenormalise);
  filter.normalize();
  filter.prune();  // voxels now beyond the band become inactive background
  Progress::checkInterrupt();
  // After each smoothing step one Eikonal iteration (LevelSetTracker's default): a step moves the surface by a
  // fraction of a voxel, and a band that was a distance stays nearly one. 3 iterations a step (as before)
  // cost 40% of a frame and changed the block's volume by 0.5% and the ball's radius by 0.03 voxels. The
  // anisotropic field keeps 3: its dilation below moves the surface 1.5 voxels in CFL steps, and with one
  // iteration a step the block lost 9% more.
  const bool anisotropic = p.method == "anisotropic";
  filter.setNormCount(anisotropic ? kRenormalise : 1);

  // Smooth first, erode second: mean-curvature flow fills the dents between the spheres and rounds the sphere
  // caps, the erosion then takes the surface back to the fluid. (Eroding first would leave a lone particle
  // a sphere of one voxel, which smoothing then erases.)
  // Mean-curvature flow steps (surface.smoothing_steps, default 2): enough to take out the bumps of the sphere
  // union (on a flat face they go from 0.04 to 0.004 spacings rms in two steps; each step moves the surface by
  // a third of a voxel times its curvature in voxels), few enough to keep edges and small droplets.
  for (int i = 0; i < scene.surface.smoothing_steps; ++i) filter.meanCurvature();
  // Positive offsets shrink the level set (phi + offset, phi < 0 inside).
  const double erosion = erosionOf(p);
  if (erosion > 0) {
    // Eroding a signed distance is adding a constant to it, exactly: one pass over the band, then one track
    // (dilate the band a voxel on the inside, re-distance, trim the outside) per voxel of erosion, rather
    // than LevelSetFilter::offset's CFL steps of half a voxel, each followed by a track.
    openvdb::tree::LeafManager<FloatGrid::TreeType> leaves(grid->tree());
    const float c = float(erosion);
    leaves.foreach([c](FloatGrid::TreeType::LeafNodeType& leaf, size_t) {
      for (auto it = leaf.beginValueOn(); it; ++it) it.setValue(*it + c);
    });
    const int tracks = int(std::ceil(erosion / p.voxel - 1e-9));
    filter.setNormCount(spheres ? kSpheresErodeIterations : 2 * kRenormalise);
    for (int i = 0; i < tracks; ++i) filter.track();
  } else if (erosion < 0) {
    // Dilation (anisotropic): the outer band must grow as the surface moves out, which the CFL steps do.
    filter.offset(float(erosion));
  }
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

// OBJ with vertex normals (v, vn, f a//a), 1-based indices, as text: Blender and Houdini read it.
void writeMeshObj(const fs::path& path, const TriangleMesh& mesh) {
  writeFileAtomically(path, [&](std::ostream& out) {
    char line[128];
    for (const auto& x : mesh.positions) {
      std::snprintf(line, sizeof line, "v %.7g %.7g %.7g\n", double(x.x()), double(x.y()), double(x.z()));
      out << line;
    }
    for (const auto& n : mesh.normals) {
      std::snprintf(line, sizeof line, "vn %.6g %.6g %.6g\n", double(n.x()), double(n.y()), double(n.z()));
      out << line;
    }
    const bool normals = !mesh.normals.empty();
    for (const auto& t : mesh.triangles) {
      if (normals)
        std::snprintf(line, sizeof line, "f %u//%u %u//%u %u//%u\n", t[0] + 1, t[0] + 1, t[1] + 1, t[1] + 1,
                      t[2] + 1, t[2] + 1);
      else
        std::snprintf(line, sizeof line, "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
      out << line;
    }
  });
}

}  // namespace

SurfaceStats surfaceFrame(const ParticleFrame& frame, const Scene& scene, const fs::path& vdbPath,
                          const fs::path& meshPath) {
  const FloatGrid::Ptr grid = buildLevelSet(frame, scene);
  const TriangleMesh mesh = meshLevelSet(*grid, scene.surface.adaptivity);

  const Parameters p = resolve(frame, scene);
  VdbExtras extras;
  BlockField velocity;
  std::vector<Eigen::Vector3f> x, v;
  if (scene.surface.write_velocity || scene.surface.write_points) {
    x = slabPositions(frame, p, frame.position, true);
    v = slabPositions(frame, p, frame.velocity, false);
  }
  if (scene.surface.write_velocity) {
    // The Shepard average of the particle velocities (ZB05 weights, support 2 spacings) on every voxel of the
    // surface's leaves, where a renderer's motion blur or a re-simulation looks them up.
    std::vector<Eigen::Vector3i> leaves;
    for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
      const openvdb::Coord o = leaf->origin();
      leaves.emplace_back(o.x(), o.y(), o.z());
    }
    FieldParticles particles;
    particles.position = &x;
    particles.velocity = &v;
    FieldParameters f;
    f.kind = FieldKind::Velocity;
    f.voxel = p.voxel;
    f.support = kZbSupport * p.spacing;
    velocity = rasterizeField(particles, f, &leaves);
    extras.velocity = &velocity;
  }
  if (scene.surface.write_points) {
    extras.pointPositions = &x;
    extras.pointVelocities = &v;
    extras.pointVoxel = 4 * p.spacing;  // about 64 particles per voxel of the points grid
  }
  writeSurfaceVdb(vdbPath, grid, extras);
  writeMeshPly(meshPath, mesh);
  if (scene.surface.write_obj) {
    fs::path obj = meshPath;
    writeMeshObj(obj.replace_extension(".obj"), mesh);
  }
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
  // Frames in parallel, one chunk each (OpenVDB's and our own loops inside a frame share the same oneTBB
  // workers). Each frame's files depend only on its particles, so the bytes are the same at any thread count.
  std::mutex advance;
  parallelFor(
      0, frames.size(),
      [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) {
          Progress::checkInterrupt();
          const int f = frames[i];
          const ParticleFrame frame = readParticlePly(framePath(dir, "particles", f, "ply"));
          surfaceFrame(frame, scene, framePath(dir, "surface", f, "vdb"), framePath(dir, "surface", f, "ply"));
          const std::lock_guard<std::mutex> lock(advance);
          progress.advance();
        }
      },
      1);
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
